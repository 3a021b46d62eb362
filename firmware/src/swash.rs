//! Swashplate geometry: where the swash servos sit, hence how much of each cyclic
//! command every servo gets, and the cyclic ring.
//!
//! # Conventions
//!
//! Azimuths ψ are measured clockwise from the nose seen from above. A servo at ψ must
//! raise its ball by
//!
//! ```text
//! h(ψ) = δ_lon·cos(ψ − φ) − δ_lat·sin(ψ − φ)
//! ```
//!
//! per unit cyclic, where φ is the phase angle (`SWASH_PHASE`): positive lon raises the
//! front against the rear (the plate tilts aft, nose up), positive lat lowers the right
//! side (roll right). The pair (cos, sin) of each servo are its *mixing factors*
//! (`h = lon·cos − lat·sin`); collective raises every swash servo of a CCPM plate by the
//! same amount. φ is subtracted from the azimuth as ArduPilot's `H_SW_H3_PHANG` does
//! (`cos(pos − phase)`): a phase angle φ makes a pure forward command act as if the
//! plate were rotated by −φ, which cancels a rotor that answers with a lag of φ.
//!
//! # Swash types
//!
//! A three-servo CCPM plate of angle A ([`SwashType::H3_120`], [`SwashType::H3_135`],
//! [`SwashType::H3_140`]) has one servo on the fore-aft axis (the *lead* servo, at
//! ψ = 0, front) and the two others at ψ = +A (right-rear) and ψ = −A (left-rear): the
//! angle between the lead servo and each of the others is A. This is Rotorflight's
//! layout (`mixerUpdateSwash`: servo 1 `−SP`, servos 2/3 `±sin(180° − A)·SR +
//! cos(180° − A)·SP`) and ArduPilot's generic H3 with servo positions 180°, ±(180° − A)
//! turned by 180° (an elevator servo at the rear is the same geometry with φ = 180°).
//! Which output is the lead servo is `SWASH_LEAD`; the outputs after it follow
//! clockwise. [`SwashType::H1`] is a mechanically mixed head: output 1 takes the lateral
//! cyclic, output 2 the longitudinal cyclic, output 3 the collective (ArduPilot's H1).
//!
//! ArduPilot's own H3_140 table is *not* geometric (it gives both pairs the factor 1,
//! "1:1 pure input"); this module follows the geometry, as Rotorflight does.
//!
//! # Cyclic ring
//!
//! The cyclic command (lat, lon) is limited to a circle of radius `CYC_RING` (in stick
//! fractions) before mixing: a vector longer than the ring is scaled back onto it,
//! keeping its direction, so a corner stick cannot tilt the plate further than a pure
//! fore-aft or lateral command (Rotorflight's `swash_ring`, ArduPilot's `H_CYC_MAX`).
//! The default, 1.5, is beyond √2 and never limits commands within ±1.

/// The swashplate type.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[allow(non_camel_case_types)]
pub enum SwashType {
    /// Mechanical mixing: output 1 lateral, output 2 longitudinal, output 3 collective.
    H1,
    /// Three servos, 120° apart.
    H3_120,
    /// Three servos, the two side servos 135° from the lead servo.
    H3_135,
    /// Three servos, the two side servos 140° from the lead servo.
    H3_140,
}

impl SwashType {
    /// The parameter code: the plate angle in degrees, 0 for H1.
    pub const fn code(self) -> u16 {
        match self {
            SwashType::H1 => 0,
            SwashType::H3_120 => 120,
            SwashType::H3_135 => 135,
            SwashType::H3_140 => 140,
        }
    }

    /// The type of a parameter code (0, 120, 135, 140).
    pub const fn from_code(code: u16) -> Option<SwashType> {
        match code {
            0 => Some(SwashType::H1),
            120 => Some(SwashType::H3_120),
            135 => Some(SwashType::H3_135),
            140 => Some(SwashType::H3_140),
            _ => None,
        }
    }

    /// (cos A, sin A) of the side servos' azimuth A, correctly rounded to f32 (the
    /// 120° values are the ones the CCPM-120 mixer has always used). `None` for H1.
    const fn side_cos_sin(self) -> Option<(f32, f32)> {
        match self {
            SwashType::H1 => None,
            SwashType::H3_120 => Some((-0.5, 0.866_025_4)),
            SwashType::H3_135 => Some((
                -core::f32::consts::FRAC_1_SQRT_2,
                core::f32::consts::FRAC_1_SQRT_2,
            )),
            SwashType::H3_140 => Some((-0.766_044_4, 0.642_787_6)),
        }
    }
}

/// Why a swash geometry was refused.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum SwashError {
    /// The phase angle is not finite or outside ±180°.
    PhaseOutOfRange,
    /// The lead servo is not 1, 2 or 3.
    LeadOutOfRange,
}

/// Largest accepted phase angle magnitude \[°\].
pub const MAX_PHASE_DEG: f32 = 180.0;

/// The mixing factors of the three swash outputs, computed once from the type, the
/// phase angle and the lead servo.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct SwashGeometry {
    kind: SwashType,
    phase_deg: f32,
    lead: u8,
    /// Per output: (factor on lon, factor on −lat) for a CCPM plate, i.e. (cos, sin)
    /// of its azimuth minus the phase.
    factors: [(f32, f32); 3],
    /// (cos φ, sin φ): the turn of the cyclic vector an H1 head gets.
    turn: (f32, f32),
}

impl SwashGeometry {
    /// CCPM-120, no phase angle, output 1 leading (front): the layout the mixer has
    /// always had.
    pub const H3_120: SwashGeometry = SwashGeometry {
        kind: SwashType::H3_120,
        phase_deg: 0.0,
        lead: 1,
        factors: [(1.0, 0.0), (-0.5, 0.866_025_4), (-0.5, -0.866_025_4)],
        turn: (1.0, 0.0),
    };

    /// The geometry of `kind` with phase angle `phase_deg` (clockwise positive,
    /// ±180°) and output `lead` (1–3) on the fore-aft axis.
    pub fn new(kind: SwashType, phase_deg: f32, lead: u8) -> Result<Self, SwashError> {
        if !(phase_deg.is_finite() && phase_deg.abs() <= MAX_PHASE_DEG) {
            return Err(SwashError::PhaseOutOfRange);
        }
        if !(1..=3).contains(&lead) {
            return Err(SwashError::LeadOutOfRange);
        }
        // Azimuths clockwise from the lead output: 0, +A, −A. Without a phase angle the
        // correctly rounded constants are used, so the default plate mixes exactly as
        // before; with one, cos/sin of (ψ − φ) by the angle-difference identities.
        let (cos_a, sin_a) = kind.side_cos_sin().unwrap_or((1.0, 0.0));
        let by_position = [(1.0, 0.0), (cos_a, sin_a), (cos_a, -sin_a)];
        let turn = if phase_deg == 0.0 {
            (1.0, 0.0)
        } else {
            let phi = phase_deg.to_radians();
            (libm::cosf(phi), libm::sinf(phi))
        };
        let (cos_p, sin_p) = turn;
        // cos(ψ − φ) = cosψ·cosφ + sinψ·sinφ; sin(ψ − φ) = sinψ·cosφ − cosψ·sinφ (exact
        // for φ = 0: the factors are then the constants themselves).
        let rotated = by_position.map(|(c, s)| (c * cos_p + s * sin_p, s * cos_p - c * sin_p));
        let mut factors = [(1.0, 0.0); 3];
        for (position, factor) in rotated.into_iter().enumerate() {
            // Output (lead − 1 + position) mod 3 sits at this position.
            let output = (usize::from(lead) - 1 + position) % 3;
            if let Some(slot) = factors.get_mut(output) {
                *slot = factor;
            }
        }
        Ok(SwashGeometry {
            kind,
            phase_deg,
            lead,
            factors,
            turn,
        })
    }

    /// The swash type.
    pub const fn kind(&self) -> SwashType {
        self.kind
    }

    /// The phase angle \[°\].
    pub const fn phase_deg(&self) -> f32 {
        self.phase_deg
    }

    /// The output on the fore-aft axis (1–3; an H1 head ignores it).
    pub const fn lead(&self) -> u8 {
        self.lead
    }

    /// Per output 1–3: (cos, sin) of its azimuth minus the phase angle; a CCPM servo's
    /// cyclic height is `lon·cos − lat·sin`.
    pub const fn factors(&self) -> [(f32, f32); 3] {
        self.factors
    }

    /// The heights of the three outputs for the cyclic command (lat, lon) at
    /// `cyclic_scale` height per unit, and the collective height `collective`.
    pub fn heights(&self, lat: f32, lon: f32, cyclic_scale: f32, collective: f32) -> [f32; 3] {
        match self.kind {
            SwashType::H1 => {
                // The phase angle turns the cyclic vector as it turns a CCPM plate's
                // factors: h(ψ) = lon'·cosψ − lat'·sinψ with lon' = lon·cosφ +
                // lat·sinφ and lat' = lat·cosφ − lon·sinφ.
                let (c, s) = self.turn;
                let lon_turned = lon * c + lat * s;
                let lat_turned = lat * c - lon * s;
                [
                    cyclic_scale * lat_turned,
                    cyclic_scale * lon_turned,
                    collective,
                ]
            }
            SwashType::H3_120 | SwashType::H3_135 | SwashType::H3_140 => {
                // The CCPM-120 mixer's expression, operation for operation.
                self.factors
                    .map(|(c, s)| collective + cyclic_scale * (lon * c - lat * s))
            }
        }
    }
}

impl SwashGeometry {
    /// The inverse of [`heights`](Self::heights) at unit cyclic scale: the cyclic heights
    /// (lat', lon') and the collective height that give the three outputs `heights`, or
    /// `None` for a plate whose outputs do not determine them (never for a geometry
    /// [`new`](Self::new) accepts).
    ///
    /// A CCPM plate's outputs are `hᵢ = C + lon'·cᵢ − lat'·sᵢ` ((cᵢ, sᵢ) its factors): three
    /// equations in (C, lon', lat'), solved by Cramer's rule. With the outputs at
    /// azimuths 0, ±A (less the phase, which turns all three alike) the determinant's
    /// magnitude is `4·sin A·sin²(A/2)`: 2.60 at 120°, 2.41 at 135°, 2.27 at 140°. An H1
    /// head's outputs are lat', lon' turned by the phase angle, and C: turned back.
    pub fn unmix(&self, heights: [f32; 3]) -> Option<(f32, f32, f32)> {
        match self.kind {
            SwashType::H1 => {
                let (c, s) = self.turn;
                let [lat_turned, lon_turned, collective] = heights;
                Some((
                    lat_turned * c + lon_turned * s,
                    lon_turned * c - lat_turned * s,
                    collective,
                ))
            }
            SwashType::H3_120 | SwashType::H3_135 | SwashType::H3_140 => {
                // Rows (1, cᵢ, −sᵢ) · (C, lon', lat') = hᵢ.
                let [(c1, s1), (c2, s2), (c3, s3)] = self.factors;
                let det3 = |a: [f32; 3], b: [f32; 3], c: [f32; 3]| {
                    a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0])
                        + a[2] * (b[0] * c[1] - b[1] * c[0])
                };
                let columns = [[1.0, 1.0, 1.0], [c1, c2, c3], [-s1, -s2, -s3]];
                let det = det3(columns[0], columns[1], columns[2]);
                // A NaN determinant (a corrupt geometry) is refused too.
                if det.abs() <= 1e-3 || det.is_nan() {
                    return None;
                }
                let collective = det3(heights, columns[1], columns[2]) / det;
                let lon = det3(columns[0], heights, columns[2]) / det;
                let lat = det3(columns[0], columns[1], heights) / det;
                Some((lat, lon, collective))
            }
        }
    }
}

/// The cyclic command limited to the ring of radius `ring`: (lat, lon) unchanged when
/// inside, otherwise scaled onto the ring. A ring that is not positive and finite
/// leaves the command unchanged (the configuration check refuses it).
pub fn limit_to_ring(lat: f32, lon: f32, ring: f32) -> (f32, f32) {
    let squared = lat * lat + lon * lon;
    if ring > 0.0 && ring.is_finite() && squared > ring * ring {
        let scale = ring / libm::sqrtf(squared);
        (lat * scale, lon * scale)
    } else {
        (lat, lon)
    }
}

#[cfg(test)]
#[path = "swash_tests.rs"]
mod tests;
