//! The pilot mode's gains and limits: one rate loop's ([`RateAxisGains`]) and the whole
//! mode's ([`PilotModeGains`]), with the presets' values and their validation.

use super::*;

/// Gains and limits of one rate loop. Units: stick fractions, rad, s.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RateAxisGains {
    /// Rate at full stick ω_max [rad/s]; also the clamp on any desired rate.
    pub max_rate_rad_s: f32,
    /// Largest change of the shaped target α_max [rad/s²].
    pub max_accel_rad_s2: f32,
    /// Rate feed-forward FF_ω [stick/(rad/s)].
    pub ff_rate: f32,
    /// Acceleration feed-forward FF_α [stick/(rad/s²)].
    pub ff_accel: f32,
    /// Proportional gain on the rate error [stick/(rad/s)].
    pub kp: f32,
    /// Integral gain [stick/rad].
    pub ki: f32,
    /// Integrator limit \[stick\].
    pub integrator_limit: f32,
    /// Output limit \[stick\], in (0, 1].
    pub output_limit: f32,
}

impl RateAxisGains {
    /// Whether every field is finite, the limits positive, the gains ≥ 0, the output
    /// limit in (0, 1] and the integrator limit in [0, output limit].
    pub fn is_valid(&self) -> bool {
        let fields = [
            self.max_rate_rad_s,
            self.max_accel_rad_s2,
            self.ff_rate,
            self.ff_accel,
            self.kp,
            self.ki,
            self.integrator_limit,
            self.output_limit,
        ];
        fields.iter().all(|v| v.is_finite() && *v >= 0.0)
            && self.max_rate_rad_s > 0.0
            && self.max_accel_rad_s2 > 0.0
            && self.output_limit > 0.0
            && self.output_limit <= 1.0
            && self.integrator_limit <= self.output_limit
    }
}

/// Everything the stabilised pilot mode needs.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PilotModeGains {
    /// Roll-rate loop (lat cyclic on p).
    pub roll: RateAxisGains,
    /// Pitch-rate loop (lon cyclic on q).
    pub pitch: RateAxisGains,
    /// Yaw-rate loop (pedal on r).
    pub yaw: RateAxisGains,
    /// Level stick: desired rate per rad of attitude error K_lvl \[1/s\].
    pub level_gain: f32,
    /// Level stick: attitude at full stick (also the clamp on any attitude target)
    /// \[rad\], in (0, π/2).
    pub max_angle_rad: f32,
    /// Heading hold: desired yaw rate per rad of heading error K_ψ \[1/s\].
    pub heading_gain: f32,
    /// Heading hold: largest heading error acted on \[rad\], in (0, π].
    pub heading_error_limit_rad: f32,
    /// Pedal dead band in which the heading is held (fraction), in [0, 1).
    pub pedal_deadband: f32,
    /// Tail servo rate limit [stick fraction per s].
    pub tail_slew_per_s: f32,
    /// τ_B of the bumpless-transfer remainder \[s\] (0: dropped at once).
    pub transfer_time_s: f32,
    /// Time constant of the integrators' leak while the rotor is not under power \[s\]
    /// (0: emptied at once).
    pub ground_leak_time_s: f32,
    /// Stick mode of the mode switch's positions Low, Middle, High.
    pub switch_modes: [StickMode; 3],
}

impl PilotModeGains {
    /// Conservative starting gains for a TREX 700L-class flybarless helicopter, sized on
    /// the host simulator's `trex700l` (an approximation: no identified model of the
    /// real aircraft exists). Re-tune on the aircraft.
    ///
    /// * Roll: L_δ ≈ 350 rad/s² per stick, L_p ≈ −67 /s (model inverse FF_ω 0.19).
    ///   FF_ω 0.1, FF_α 0.0023 (0.8/L_δ), Kp 0.024 (a rate-loop crossover near 8 rad/s,
    ///   well inside the servo's ~60 rad/s and the flapping at ~43 rad/s), Ki 0.4,
    ///   I_max 0.4. 200°/s and 1100°/s²: sport-flying rates, far below the aircraft's
    ///   3D rates, and the abort limits of a test are 200°/s.
    /// * Pitch: the same hub moment on I_yy ≈ 3.3·I_xx: M_δ ≈ 105, M_q ≈ −20 /s (inverse
    ///   0.19). FF_ω 0.1, FF_α 0.0076, Kp 0.05, Ki 0.4, I_max 0.4; 200°/s, 1100°/s².
    /// * Yaw: N_ped ≈ 95 rad/s² per stick and N_r ≈ −2 /s, rough estimates from the
    ///   simulator's tail-rotor data (0.135 m radius at a 0.95 m arm, 25° of pitch per
    ///   stick). FF_ω 0.01, FF_α 0.0084, Kp 0.15, Ki 0.3,
    ///   I_max 0.4 (room for the tail trim); 180°/s, 270°/s².
    ///
    /// On these rate models behind the simulator's servo (60 rad/s, ζ 0.7), the flap lag
    /// (τ_f 0.023 s) and one tick of delay, a step in the desired rate settles within
    /// 5 % in about 1.1 s on roll and pitch without overshoot and in 0.4 s with 6 %
    /// overshoot on the tail; an aircraft with more rotor damping than assumed
    /// undershoots instead. One with less than about half of it (roll L_p above
    /// −35 /s) overshoots: there, lower FF_ω.
    ///
    /// Level 3 /s with 25° at full stick (the outer loop several times slower than the
    /// rate loop); heading hold 2.5 /s on at most 20° of error with a 5 % pedal dead
    /// band; tail servo 4 /s, the actuator rate limit the project's simulator models;
    /// transfer τ_B 0.5 s; integrators leak with 0.5 s on the ground. Mode switch: Low
    /// Rate, Middle and High Level.
    pub const fn trex700l() -> Self {
        PilotModeGains {
            roll: RateAxisGains {
                max_rate_rad_s: 200.0 * DEG,
                max_accel_rad_s2: 1100.0 * DEG,
                ff_rate: 0.1,
                ff_accel: 0.0023,
                kp: 0.024,
                ki: 0.4,
                integrator_limit: 0.4,
                output_limit: 1.0,
            },
            pitch: RateAxisGains {
                max_rate_rad_s: 200.0 * DEG,
                max_accel_rad_s2: 1100.0 * DEG,
                ff_rate: 0.1,
                ff_accel: 0.0076,
                kp: 0.05,
                ki: 0.4,
                integrator_limit: 0.4,
                output_limit: 1.0,
            },
            yaw: RateAxisGains {
                max_rate_rad_s: 180.0 * DEG,
                max_accel_rad_s2: 270.0 * DEG,
                ff_rate: 0.01,
                ff_accel: 0.0084,
                kp: 0.15,
                ki: 0.3,
                integrator_limit: 0.4,
                output_limit: 1.0,
            },
            level_gain: 3.0,
            max_angle_rad: 25.0 * DEG,
            heading_gain: 2.5,
            heading_error_limit_rad: 20.0 * DEG,
            pedal_deadband: 0.05,
            tail_slew_per_s: 4.0,
            transfer_time_s: 0.5,
            ground_leak_time_s: 0.5,
            switch_modes: [StickMode::Rate, StickMode::Level, StickMode::Level],
        }
    }

    /// Starting gains for the Bo-105 simulator, sized from the quasi-static derivatives
    /// listed at [`Gains::bo105`](crate::Gains::bo105) (roll L_δ ≈ 24, L_p ≈ −14;
    /// pitch M_δ ≈ 7.9, M_q ≈ −3.7; yaw N_δ ≈ 4.5, N_r ≈ −0.3), with FF_ω about half
    /// of each model inverse and FF_α 0.8/L_δ; full-scale rates (40°/s roll, 30°/s
    /// pitch and yaw) and accelerations (100, 60, 60°/s²). Not flown on an aircraft.
    pub const fn bo105() -> Self {
        PilotModeGains {
            roll: RateAxisGains {
                max_rate_rad_s: 40.0 * DEG,
                max_accel_rad_s2: 100.0 * DEG,
                ff_rate: 0.3,
                ff_accel: 0.033,
                kp: 0.15,
                ki: 0.5,
                integrator_limit: 0.5,
                output_limit: 1.0,
            },
            pitch: RateAxisGains {
                max_rate_rad_s: 30.0 * DEG,
                max_accel_rad_s2: 60.0 * DEG,
                ff_rate: 0.25,
                ff_accel: 0.1,
                kp: 0.4,
                ki: 0.6,
                integrator_limit: 0.5,
                output_limit: 1.0,
            },
            yaw: RateAxisGains {
                max_rate_rad_s: 30.0 * DEG,
                max_accel_rad_s2: 60.0 * DEG,
                ff_rate: 0.03,
                ff_accel: 0.18,
                kp: 0.8,
                ki: 0.5,
                integrator_limit: 0.5,
                output_limit: 1.0,
            },
            level_gain: 1.5,
            max_angle_rad: 20.0 * DEG,
            heading_gain: 1.0,
            heading_error_limit_rad: 20.0 * DEG,
            pedal_deadband: 0.05,
            tail_slew_per_s: 4.0,
            transfer_time_s: 1.0,
            ground_leak_time_s: 0.5,
            switch_modes: [StickMode::Rate, StickMode::Level, StickMode::Level],
        }
    }

    /// Whether every loop and every setting is finite and in range.
    pub fn is_valid(&self) -> bool {
        let non_negative = |v: f32| v.is_finite() && v >= 0.0;
        self.roll.is_valid()
            && self.pitch.is_valid()
            && self.yaw.is_valid()
            && non_negative(self.level_gain)
            && non_negative(self.max_angle_rad)
            && self.max_angle_rad > 0.0
            && self.max_angle_rad < 0.5 * PI
            && non_negative(self.heading_gain)
            && non_negative(self.heading_error_limit_rad)
            && self.heading_error_limit_rad > 0.0
            && self.heading_error_limit_rad <= PI
            && non_negative(self.pedal_deadband)
            && self.pedal_deadband < 1.0
            && non_negative(self.tail_slew_per_s)
            && self.tail_slew_per_s > 0.0
            && non_negative(self.transfer_time_s)
            && non_negative(self.ground_leak_time_s)
    }
}
