//! Vehicle parameter sets: the Bo-105 (Padfield, *Helicopter Flight Dynamics*, Helisim
//! data) and an approximate TREX 700L-class radio-controlled helicopter.
//!
//! Axes: body x forward, y right, z down, origin at the centre of gravity (CG). Positions
//! below are from the CG in metres. Both main rotors turn anticlockwise seen from above
//! (Padfield's convention for the Bo-105), so the tail rotor pushes to the right (+y) and
//! a positive tail-rotor collective yaws the nose left.

use aircraft::Aircraft;

/// A shipped aircraft file; the `aircraft` crate's tests read every one of them.
fn shipped(name: &str) -> Aircraft {
    aircraft::shipped(name).expect("a shipped aircraft")
}

/// Blade and hub data of one rotor. The flap time constant is derived from these (Lock
/// number, rotor speed, hub stiffness), never typed in: see [`Rotor::flap_time_constant`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Rotor {
    /// Radius R \[m\].
    pub radius: f64,
    /// Rotor speed Ω [rad/s].
    pub omega: f64,
    /// Number of blades N_b.
    pub blades: f64,
    /// Blade chord c \[m\].
    pub chord: f64,
    /// Linear twist θ_tw \[rad\] (root to tip; negative = washout). Blade pitch at radius
    /// fraction x is θ0 + x·θ_tw.
    pub twist: f64,
    /// Blade lift-curve slope a [1/rad].
    pub lift_slope: f64,
    /// Blade flap moment of inertia about the hub I_β [kg·m²].
    pub flap_inertia: f64,
    /// Equivalent centre-spring hub stiffness K_β [N·m/rad] per blade.
    pub hub_stiffness: f64,
    /// Profile drag δ = δ0 + δ2·C_T².
    pub profile_drag: [f64; 2],
    /// Hub position from the CG, body axes \[m\].
    pub hub: [f64; 3],
}

impl Rotor {
    /// Solidity σ = N_b·c/(πR).
    pub fn solidity(&self) -> f64 {
        self.blades * self.chord / (std::f64::consts::PI * self.radius)
    }

    /// Disc area πR² \[m²\].
    pub fn disc_area(&self) -> f64 {
        std::f64::consts::PI * self.radius * self.radius
    }

    /// Tip speed ΩR [m/s].
    pub fn tip_speed(&self) -> f64 {
        self.omega * self.radius
    }

    /// Lock number γ = ρ·a·c·R⁴ / I_β.
    pub fn lock_number(&self, air_density: f64) -> f64 {
        air_density * self.lift_slope * self.chord * self.radius.powi(4) / self.flap_inertia
    }

    /// Flap-frequency ratio excess λ_β² − 1 = K_β / (I_β Ω²).
    pub fn stiffness_excess(&self) -> f64 {
        self.hub_stiffness / (self.flap_inertia * self.omega * self.omega)
    }

    /// Stiffness number S_β = 8(λ_β² − 1)/γ.
    pub fn stiffness_number(&self, air_density: f64) -> f64 {
        8.0 * self.stiffness_excess() / self.lock_number(air_density)
    }

    /// Tip-path-plane flap time constant τ_f \[s\] in hover, from the blade data.
    ///
    /// The first-order multiblade flap equations (second derivatives dropped, see
    /// `rotor.rs`) in hover are `M·β' = N·β + forcing`, with g = γ/8, s = λ_β² − 1,
    /// `M = [[g, 2], [−2, g]]`, `N = [[−s, −g], [g, −s]]` (′ = d/dψ). Their eigenvalues are
    /// `Ω·(−g(2+s) ± i(2s − g²)) / (g² + 4)`, so
    ///
    /// ```text
    /// τ_f = (g² + 4) / (Ω·g·(2 + s))   ≈ 16/(γΩ) for small g and s.
    /// ```
    pub fn flap_time_constant(&self, air_density: f64) -> f64 {
        let g = self.lock_number(air_density) / 8.0;
        let s = self.stiffness_excess();
        (g * g + 4.0) / (self.omega * g * (2.0 + s))
    }

    /// Cross-coupling K_cs of the two tip-path-plane modes in hover, from the blade data:
    /// the coefficient of the other flapping state in the first-order flap equations
    /// written with unit damping, `τ_f β̇1c = −β1c + K_cs β1s + …`,
    /// `τ_f β̇1s = −β1s − K_cs β1c + …`.
    ///
    /// From the same `M·β' = N·β` as [`Rotor::flap_time_constant`],
    /// `M⁻¹N = [[−g(2+s), 2s − g²], [g² − 2s, −g(2+s)]] / (g² + 4)`; dividing by the
    /// diagonal rate `g(2+s)/(g² + 4)` (that is, multiplying by Ω·τ_f) leaves
    ///
    /// ```text
    /// K_cs = (2s − g²) / (g·(2 + s)),   g = γ/8,  s = λ_β² − 1
    /// ```
    ///
    /// Zero for an articulated rotor with λ_β² − 1 = g²/2; positive for a stiff hingeless
    /// rotor. It is a property of the rotor design (Lock number, flap frequency), so a
    /// flight-test engineer knows it before flying — the 9-DOF structure fixes it from
    /// this value because the sweeps barely inform it (insensitivity ~14 %).
    pub fn flap_cross_coupling(&self, air_density: f64) -> f64 {
        let g = self.lock_number(air_density) / 8.0;
        let s = self.stiffness_excess();
        (2.0 * s - g * g) / (g * (2.0 + s))
    }
}

/// A lifting surface (vertical fin or horizontal tailplane).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Surface {
    /// Area \[m²\].
    pub area: f64,
    /// Incidence \[rad\] (fin: toward +y side force in forward flight; tailplane: leading
    /// edge up).
    pub incidence: f64,
    /// Lift-curve slope [1/rad].
    pub lift_slope: f64,
    /// Position from the CG, body axes \[m\].
    pub position: [f64; 3],
    /// Angle of attack where the linear lift stops growing (crude stall) \[rad\].
    pub stall_angle: f64,
}

/// Linear gearing of one control channel: `blade pitch = centre + gain·stick`, stick
/// fraction in [−1, 1].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Gearing {
    /// Blade pitch at centred stick \[rad\].
    pub centre: f64,
    /// Blade pitch per unit stick fraction \[rad\].
    pub gain: f64,
}

impl Gearing {
    /// Blade pitch for a stick fraction.
    pub fn pitch(&self, stick: f64) -> f64 {
        self.centre + self.gain * stick
    }

    /// Stick fraction for a blade pitch.
    pub fn stick(&self, pitch: f64) -> f64 {
        (pitch - self.centre) / self.gain
    }
}

/// The full parameter set of a helicopter.
#[derive(Clone, Debug, PartialEq)]
pub struct Helicopter {
    /// Display name.
    pub name: String,
    /// Mass \[kg\].
    pub mass: f64,
    /// Roll inertia I_xx [kg·m²].
    pub ixx: f64,
    /// Pitch inertia I_yy [kg·m²].
    pub iyy: f64,
    /// Yaw inertia I_zz [kg·m²].
    pub izz: f64,
    /// Product of inertia I_xz [kg·m²] (positive: principal axis nose-down of x).
    pub ixz: f64,
    /// Air density ρ [kg/m³].
    pub air_density: f64,
    /// Gravity g [m/s²].
    pub gravity: f64,
    /// Main rotor (hub position = rotor hub).
    pub main_rotor: Rotor,
    /// Forward tilt of the main-rotor shaft \[rad\] (Padfield's γ_s; top of the shaft
    /// leans forward).
    pub shaft_tilt: f64,
    /// Tail rotor (thrust along +y for positive pitch; flap data unused).
    pub tail_rotor: Rotor,
    /// Fuselage equivalent flat-plate drag areas along x, y, z \[m²\].
    pub fuselage_drag_area: [f64; 3],
    /// Vertical fin.
    pub fin: Surface,
    /// Horizontal tailplane.
    pub tailplane: Surface,
    /// Stick → blade pitch gearing, in control order [lat → θ1c, lon → θ1s,
    /// ped → θ0_TR, col → θ0].
    pub gearing: [Gearing; 4],
}

impl Helicopter {
    /// The MBB Bo-105 from Padfield's Helisim data: the shipped aircraft file `bo105`.
    pub fn bo105() -> Helicopter {
        Helicopter::from_aircraft(&shipped("bo105"))
    }

    /// A TREX 700L-class RC helicopter, **approximate** (no published identified model
    /// exists): the shipped aircraft file `trex700l`, whose header says where its numbers
    /// come from.
    pub fn trex700l() -> Helicopter {
        Helicopter::from_aircraft(&shipped("trex700l"))
    }

    /// The simulator's parameter set of an aircraft file. The tail rotor's flap data are
    /// not used by the model (its blades do not flap) and are set to 1 kg·m² and 0.
    pub fn from_aircraft(aircraft: &Aircraft) -> Helicopter {
        let xyz = |q: &[aircraft::Quantity; 3]| [q[0].value, q[1].value, q[2].value];
        let pair = |q: &[aircraft::Quantity; 2]| [q[0].value, q[1].value];
        let m = &aircraft.main_rotor;
        let t = &aircraft.tail_rotor;
        let surface = |s: &aircraft::Surface| Surface {
            area: s.area.value,
            incidence: s.incidence.value,
            lift_slope: s.lift_slope.value,
            position: xyz(&s.position),
            stall_angle: s.stall_angle.value,
        };
        let gearing = |g: &aircraft::Gearing| Gearing {
            centre: g.centre.value,
            gain: g.per_stick.value,
        };
        let c = &aircraft.controls;
        Helicopter {
            name: aircraft.title.clone(),
            mass: aircraft.airframe.mass.value,
            ixx: aircraft.airframe.ixx.value,
            iyy: aircraft.airframe.iyy.value,
            izz: aircraft.airframe.izz.value,
            ixz: aircraft.airframe.ixz.value,
            air_density: aircraft.environment.air_density.value,
            gravity: aircraft.environment.gravity.value,
            main_rotor: Rotor {
                radius: m.radius.value,
                omega: m.head_speed.value,
                blades: f64::from(m.blades),
                chord: m.chord.value,
                twist: m.twist.value,
                lift_slope: m.lift_slope.value,
                flap_inertia: m.flap_inertia.value,
                hub_stiffness: m.hub_stiffness.value,
                profile_drag: pair(&m.profile_drag),
                hub: xyz(&m.hub),
            },
            shaft_tilt: m.shaft_tilt.value,
            tail_rotor: Rotor {
                radius: t.radius.value,
                omega: t.speed.value,
                blades: f64::from(t.blades),
                chord: t.chord.value,
                twist: t.twist.value,
                lift_slope: t.lift_slope.value,
                flap_inertia: 1.0,
                hub_stiffness: 0.0,
                profile_drag: pair(&t.profile_drag),
                hub: xyz(&t.hub),
            },
            fuselage_drag_area: xyz(&aircraft.airframe.drag_area),
            fin: surface(&aircraft.fin),
            tailplane: surface(&aircraft.tailplane),
            gearing: [
                gearing(&c.lat),
                gearing(&c.lon),
                gearing(&c.ped),
                gearing(&c.col),
            ],
        }
    }

    /// Main-rotor flap time constant τ_f \[s\] in hover, from blade data.
    pub fn flap_time_constant(&self) -> f64 {
        self.main_rotor.flap_time_constant(self.air_density)
    }

    /// Main-rotor flap cross-coupling K_cs in hover, from blade data
    /// ([`Rotor::flap_cross_coupling`]).
    pub fn flap_cross_coupling(&self) -> f64 {
        self.main_rotor.flap_cross_coupling(self.air_density)
    }

    /// Blade pitches for stick fractions `[lat, lon, ped, col]`.
    pub fn blade_pitch(&self, controls: [f64; 4]) -> BladePitch {
        BladePitch {
            theta1c: self.gearing[0].pitch(controls[0]),
            theta1s: self.gearing[1].pitch(controls[1]),
            theta0_tr: self.gearing[2].pitch(controls[2]),
            theta0: self.gearing[3].pitch(controls[3]),
        }
    }

    /// Stick fractions `[lat, lon, ped, col]` for blade pitches.
    pub fn controls_for(&self, pitch: &BladePitch) -> [f64; 4] {
        [
            self.gearing[0].stick(pitch.theta1c),
            self.gearing[1].stick(pitch.theta1s),
            self.gearing[2].stick(pitch.theta0_tr),
            self.gearing[3].stick(pitch.theta0),
        ]
    }
}

/// Blade pitch angles \[rad\] (Padfield's conventions: θ = θ0 + θ1s sin ψ + θ1c cos ψ,
/// ψ from the tail, anticlockwise; positive θ1s tilts the disc aft → nose up; positive θ1c
/// tilts it left → roll left).
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub struct BladePitch {
    /// Main-rotor collective θ0 (at the blade root).
    pub theta0: f64,
    /// Longitudinal cyclic θ1s.
    pub theta1s: f64,
    /// Lateral cyclic θ1c.
    pub theta1c: f64,
    /// Tail-rotor collective θ0_TR.
    pub theta0_tr: f64,
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bo105_derived_blade_data_match_design() {
        let heli = Helicopter::bo105();
        let gamma = heli.main_rotor.lock_number(heli.air_density);
        assert!((gamma - 5.1).abs() < 0.1, "Lock number {gamma}");
        let sigma = heli.main_rotor.solidity();
        assert!((sigma - 0.070).abs() < 0.002, "solidity {sigma}");
        let tau = heli.flap_time_constant();
        assert!((0.06..0.08).contains(&tau), "tau_f {tau}");
        // The small-g approximation 16/(γΩ) is within a few percent.
        let approx = 16.0 / (gamma * heli.main_rotor.omega);
        assert!((tau / approx - 1.0).abs() < 0.05, "{tau} vs {approx}");
    }

    #[test]
    fn flap_cross_coupling_is_the_flap_block_of_the_multiblade_equations() {
        // The closed form against the 2×2 solve of M·β' = N·β it comes from: K_cs is the
        // off-diagonal of M⁻¹N over its (negated) diagonal.
        for heli in [Helicopter::bo105(), Helicopter::trex700l()] {
            let rotor = heli.main_rotor;
            let g = rotor.lock_number(heli.air_density) / 8.0;
            let s = rotor.stiffness_excess();
            let (m, n) = ([[g, 2.0], [-2.0, g]], [[-s, -g], [g, -s]]);
            let det = m[0][0] * m[1][1] - m[0][1] * m[1][0];
            let inverse = [
                [m[1][1] / det, -m[0][1] / det],
                [-m[1][0] / det, m[0][0] / det],
            ];
            let entry = |i: usize, j: usize| inverse[i][0] * n[0][j] + inverse[i][1] * n[1][j];
            let from_solve = entry(0, 1) / -entry(0, 0);
            let closed_form = heli.flap_cross_coupling();
            assert!(
                (closed_form - from_solve).abs() < 1e-12,
                "{closed_form} vs {from_solve}"
            );
            // Antisymmetric: the β1s row carries −K_cs.
            assert!((entry(1, 0) / -entry(1, 1) + closed_form).abs() < 1e-12);
        }
        // Bo-105: γ = 5.07, λ_β = 1.117 → K_cs = 0.066.
        let bo105 = Helicopter::bo105().flap_cross_coupling();
        assert!((bo105 - 0.0662).abs() < 5e-4, "{bo105}");
    }

    #[test]
    fn gearing_round_trips() {
        let heli = Helicopter::bo105();
        let sticks = [0.1, -0.3, 0.25, 0.4];
        let back = heli.controls_for(&heli.blade_pitch(sticks));
        for (a, b) in sticks.iter().zip(back) {
            assert!((a - b).abs() < 1e-12);
        }
    }
}
