//! Unit quaternions for attitude: Hamilton convention, scalar first, `f32`.
//!
//! `q = (w, x, y, z)` represents the rotation that takes body-axis vectors to earth
//! axes (NED: x north, y east, z down; body: x forward, y right, z down):
//!
//! ```text
//! v_earth = q ⊗ (0, v_body) ⊗ q*
//! ```
//!
//! with the Hamilton product
//!
//! ```text
//! (w₁, v₁) ⊗ (w₂, v₂) = (w₁w₂ − v₁·v₂,  w₁v₂ + w₂v₁ + v₁ × v₂)
//! ```
//!
//! Euler angles are the aerospace ZYX sequence (yaw ψ, then pitch θ, then roll φ):
//! `q = q_z(ψ) ⊗ q_y(θ) ⊗ q_x(φ)`.

/// A quaternion `w + x·i + y·j + z·k`.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Quaternion {
    /// Scalar part.
    pub w: f32,
    /// i component.
    pub x: f32,
    /// j component.
    pub y: f32,
    /// k component.
    pub z: f32,
}

impl Default for Quaternion {
    fn default() -> Self {
        Quaternion::IDENTITY
    }
}

/// Below this half angle h = |v|/2 the exponential map uses its Taylor series: the
/// first omitted terms, h⁶/720 (cos h) and h⁶/5040 (sin h/h), are at most 1.4·10⁻⁹ and
/// 2·10⁻¹⁰ there, far below the `f32` resolution of 6·10⁻⁸.
const SERIES_HALF_ANGLE: f32 = 0.1;

/// The Hamilton product `self ⊗ rhs` (apply `rhs` first, then `self`).
impl core::ops::Mul for Quaternion {
    type Output = Quaternion;

    fn mul(self, rhs: Quaternion) -> Quaternion {
        let (a, b) = (self, rhs);
        Quaternion {
            w: a.w * b.w - a.x * b.x - a.y * b.y - a.z * b.z,
            x: a.w * b.x + a.x * b.w + a.y * b.z - a.z * b.y,
            y: a.w * b.y - a.x * b.z + a.y * b.w + a.z * b.x,
            z: a.w * b.z + a.x * b.y - a.y * b.x + a.z * b.w,
        }
    }
}

impl Quaternion {
    /// No rotation.
    pub const IDENTITY: Quaternion = Quaternion {
        w: 1.0,
        x: 0.0,
        y: 0.0,
        z: 0.0,
    };

    /// The components as `[w, x, y, z]`.
    pub const fn to_array(self) -> [f32; 4] {
        [self.w, self.x, self.y, self.z]
    }

    /// The conjugate `(w, −x, −y, −z)`: the inverse rotation of a unit quaternion.
    pub const fn conjugate(self) -> Quaternion {
        Quaternion {
            w: self.w,
            x: -self.x,
            y: -self.y,
            z: -self.z,
        }
    }

    /// The Euclidean norm.
    pub fn norm(self) -> f32 {
        libm::sqrtf(self.w * self.w + self.x * self.x + self.y * self.y + self.z * self.z)
    }

    /// Whether every component is finite.
    pub fn is_finite(self) -> bool {
        self.w.is_finite() && self.x.is_finite() && self.y.is_finite() && self.z.is_finite()
    }

    /// `self / |self|`, or `None` if the norm is zero or not finite.
    pub fn normalized(self) -> Option<Quaternion> {
        let norm = self.norm();
        if !(norm.is_finite() && norm > 0.0) {
            return None;
        }
        let inverse = 1.0 / norm;
        Some(Quaternion {
            w: self.w * inverse,
            x: self.x * inverse,
            y: self.y * inverse,
            z: self.z * inverse,
        })
    }

    /// The rotation by the vector `v` (axis v/|v|, angle |v| rad): the exponential map
    ///
    /// ```text
    /// exp(v/2) = (cos(|v|/2),  sin(|v|/2)·v/|v|)
    /// ```
    ///
    /// with cos h ≈ 1 − h²/2 + h⁴/24 and sin h/h ≈ 1 − h²/6 + h⁴/120 for h = |v|/2 < 0.1.
    pub fn from_rotation_vector(v: [f32; 3]) -> Quaternion {
        let [vx, vy, vz] = v;
        let half_sq = 0.25 * (vx * vx + vy * vy + vz * vz);
        let (cos, sin_over_angle) = if half_sq < SERIES_HALF_ANGLE * SERIES_HALF_ANGLE {
            let h2 = half_sq;
            (
                1.0 - h2 * (0.5 - h2 * (1.0 / 24.0)),
                // sin(h)/h · ½, because v/|v| · sin h = v · (sin h / h) / 2.
                0.5 * (1.0 - h2 * (1.0 / 6.0 - h2 * (1.0 / 120.0))),
            )
        } else {
            let half = libm::sqrtf(half_sq);
            let (sin, cos) = libm::sincosf(half);
            (cos, 0.5 * sin / half)
        };
        Quaternion {
            w: cos,
            x: vx * sin_over_angle,
            y: vy * sin_over_angle,
            z: vz * sin_over_angle,
        }
    }

    /// The ZYX rotation: yaw `psi`, then pitch `theta`, then roll `phi` \[rad\].
    ///
    /// ```text
    /// w = cφ cθ cψ + sφ sθ sψ      x = sφ cθ cψ − cφ sθ sψ
    /// y = cφ sθ cψ + sφ cθ sψ      z = cφ cθ sψ − sφ sθ cψ        (half angles)
    /// ```
    pub fn from_euler(phi: f32, theta: f32, psi: f32) -> Quaternion {
        let (sp, cp) = libm::sincosf(0.5 * phi);
        let (st, ct) = libm::sincosf(0.5 * theta);
        let (ss, cs) = libm::sincosf(0.5 * psi);
        Quaternion {
            w: cp * ct * cs + sp * st * ss,
            x: sp * ct * cs - cp * st * ss,
            y: cp * st * cs + sp * ct * ss,
            z: cp * ct * ss - sp * st * cs,
        }
    }

    /// ZYX Euler angles (φ, θ, ψ) of a unit quaternion:
    ///
    /// ```text
    /// φ = atan2(2(wx + yz), 1 − 2(x² + y²))
    /// θ = asin(clamp(2(wy − zx), −1, 1))
    /// ψ = atan2(2(wz + xy), 1 − 2(y² + z²)),  −π mapped to π so that ψ ∈ (−π, π]
    /// ```
    pub fn to_euler(self) -> (f32, f32, f32) {
        let Quaternion { w, x, y, z } = self;
        let phi = libm::atan2f(2.0 * (w * x + y * z), 1.0 - 2.0 * (x * x + y * y));
        let theta = libm::asinf((2.0 * (w * y - z * x)).clamp(-1.0, 1.0));
        let psi = libm::atan2f(2.0 * (w * z + x * y), 1.0 - 2.0 * (y * y + z * z));
        let psi = if psi <= -core::f32::consts::PI {
            core::f32::consts::PI
        } else {
            psi
        };
        (phi, theta, psi)
    }

    /// `q ⊗ (0, v) ⊗ q*`: a body vector in earth axes (for a unit quaternion).
    pub fn rotate(self, v: [f32; 3]) -> [f32; 3] {
        let [x, y, z] = v;
        let p = Quaternion { w: 0.0, x, y, z };
        let r = self * p * self.conjugate();
        [r.x, r.y, r.z]
    }

    /// `q* ⊗ (0, v) ⊗ q`: an earth vector in body axes (for a unit quaternion).
    pub fn rotate_inverse(self, v: [f32; 3]) -> [f32; 3] {
        self.conjugate().rotate(v)
    }

    /// The earth z axis (down) in body axes, `q* ⊗ (0, 0, 0, 1) ⊗ q`, in closed form:
    ///
    /// ```text
    /// (2(xz − wy),  2(yz + wx),  w² − x² − y² + z²)
    /// ```
    pub fn down_in_body(self) -> [f32; 3] {
        let Quaternion { w, x, y, z } = self;
        [
            2.0 * (x * z - w * y),
            2.0 * (y * z + w * x),
            w * w - x * x - y * y + z * z,
        ]
    }
}
