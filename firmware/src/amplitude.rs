//! The adaptive sweep amplitude ([`InputKind::AdaptiveSweep`](sweephold_protocol::InputKind::AdaptiveSweep)): the sweep's amplitude
//! shaped with frequency so that the attitudes stay inside the conditional hold's release
//! band — small where the aircraft answers strongly (low frequency), larger where it
//! barely answers (high frequency, where the flapping response is small) — as a pilot
//! flying a sweep by hand does.
//!
//! # The law
//!
//! The applied excitation is `u = s·A·e(t)·sin θ(t)`: the configured amplitude A, the
//! fade envelope e and the sweep phase θ as in [`SweepSignal`](crate::sweep::SweepSignal),
//! and a scale s that the shaper adapts while the sweep runs. Over each half cycle of the
//! sweep (between zero crossings of sin θ) it correlates every held axis' attitude
//! deviation from trim and body rate x with the applied input and its quadrature `u_c = s·A·e·cos θ`
//! (a lock-in at the sweep's own frequency):
//!
//! ```text
//! g_x = sqrt( (Σ x·u / Σ u²)² + (Σ x·u_c / Σ u_c²)² )      over the last cycle
//! ```
//!
//! — the magnitude of the frequency response from the primary input to x at the current
//! frequency, whatever the amplitude was. At each zero crossing (where the excitation is
//! zero, so the applied signal stays continuous) the scale becomes
//!
//! ```text
//! s ← min over lat, lon, ped of  min( k_a·release / (A·g_angle),  k_r·rate limit / (A·g_rate) )
//! ```
//!
//! the amplitude that puts the sweep's own share of every attitude at k_a times the
//! release angle and of every rate at k_r times its abort limit
//! ([`AdaptiveSettings::angle_target`], [`AdaptiveSettings::rate_target`]), limited to a
//! fall by at most [`AdaptiveSettings::max_fall`] and a rise by at most
//! [`AdaptiveSettings::max_rise`] per half cycle, and bounded every tick:
//! `min_scale ≤ s ≤ max_scale`, s·A within the stick travel left beside the trim
//! (1 − |trim|, at most [`MAX_AMPLITUDE`]) and s·A·ω within
//! [`AdaptiveSettings::max_slope_per_s`] (the servos' rate limit, with margin). Over the
//! first half cycle, before any response is measured, s = 1 (the configured amplitude).
//!
//! Why the sweep's share and not the raw envelope: flown against the simulator, the
//! released hover drifts (its unstable hover modes and the off-axis noise) to the engage
//! angle at every frequency of the sweep, so an envelope of the raw attitude shrinks the
//! amplitude to its floor everywhere while the hold stays as busy as before; the lock-in
//! sees only what the sweep itself drives.
//!
//! Everything is `f32` arithmetic on a few numbers per tick: bounded time, no allocation,
//! deterministic (the same measurements give the same amplitudes). A NaN or infinite
//! measurement is not accumulated (the safety checks abort on such a sample in the same
//! tick anyway); the scale stays finite and inside its bounds.

/// Largest accepted sweep or pulse amplitude, fraction of stick travel: the bound of
/// every excitation amplitude, fixed (checked by [`Config::validate`](crate::Config::validate))
/// or adapted here.
pub const MAX_AMPLITUDE: f32 = 0.5;

/// The adaptive-amplitude law's settings (firmware presets; not on the wire).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AdaptiveSettings {
    /// The sweep's share of each attitude aimed at, as a fraction k_a of the release angle.
    pub angle_target: f32,
    /// The sweep's share of each rate aimed at, as a fraction k_r of its abort limit.
    pub rate_target: f32,
    /// Largest rise of the scale per half cycle (factor ≥ 1).
    pub max_rise: f32,
    /// Largest fall of the scale per half cycle (factor in (0, 1]).
    pub max_fall: f32,
    /// Smallest scale (fraction of the configured amplitude).
    pub min_scale: f32,
    /// Largest scale.
    pub max_scale: f32,
    /// Largest slope s·A·ω of the excitation [stick travel per second].
    pub max_slope_per_s: f32,
}

impl AdaptiveSettings {
    /// The presets' law: the sweep's share of each attitude at half the release angle
    /// (2° of 4°: the other half is left to the drift of the released hover), of each rate
    /// at a quarter of its abort limit, ×1.25 / ×0.7 per half cycle, 0.2–2 times the
    /// configured amplitude, slope at most 2 per second (half the simulator's servo rate
    /// limit of 4 per second).
    pub const PRESET: AdaptiveSettings = AdaptiveSettings {
        angle_target: 0.5,
        rate_target: 0.25,
        max_rise: 1.25,
        max_fall: 0.7,
        min_scale: 0.2,
        max_scale: 2.0,
        max_slope_per_s: 2.0,
    };

    /// Whether every setting is finite and in range: targets and slope positive,
    /// rise ≥ 1, fall in (0, 1], 0 < min_scale ≤ 1 ≤ max_scale ≤ 20.
    pub fn is_valid(&self) -> bool {
        let positive = |v: f32| v.is_finite() && v > 0.0;
        positive(self.angle_target)
            && positive(self.rate_target)
            && positive(self.max_slope_per_s)
            && self.max_rise.is_finite()
            && self.max_rise >= 1.0
            && positive(self.max_fall)
            && self.max_fall <= 1.0
            && positive(self.min_scale)
            && self.min_scale <= 1.0
            && self.max_scale.is_finite()
            && (1.0..=20.0).contains(&self.max_scale)
    }
}

/// What the shaper reads of one held axis in one tick.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AxisEnvelope {
    /// Attitude deviation from trim \[rad\] (heading: wrapped ψ − ψ_trim).
    pub deviation: f32,
    /// The matching body rate [rad/s].
    pub rate: f32,
}

/// Lock-in sums of one half cycle: Σu², Σu_c², and Σx·u, Σx·u_c for the six channels
/// (hold angles of lat, lon, ped, then their rates).
#[derive(Clone, Copy, Debug, PartialEq)]
struct HalfCycle {
    in_phase_power: f32,
    quadrature_power: f32,
    in_phase: [f32; 6],
    quadrature: [f32; 6],
}

impl HalfCycle {
    const EMPTY: HalfCycle = HalfCycle {
        in_phase_power: 0.0,
        quadrature_power: 0.0,
        in_phase: [0.0; 6],
        quadrature: [0.0; 6],
    };

    fn add(&mut self, u: f32, u_c: f32, x: &[f32; 6]) {
        if !(u.is_finite() && u_c.is_finite() && x.iter().all(|v| v.is_finite())) {
            return;
        }
        self.in_phase_power += u * u;
        self.quadrature_power += u_c * u_c;
        for ((i, q), &v) in self.in_phase.iter_mut().zip(&mut self.quadrature).zip(x) {
            *i += v * u;
            *q += v * u_c;
        }
    }
}

/// The adaptive amplitude's state: the scale s and the lock-in sums of the last cycle.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AmplitudeShaper {
    settings: AdaptiveSettings,
    /// k_a·release (three times), then k_r·rate limit per axis: the targets of the six
    /// channels.
    targets: [f32; 6],
    /// The configured amplitude A.
    amplitude: f32,
    scale: f32,
    current: HalfCycle,
    previous: Option<HalfCycle>,
    /// Sign of sin θ at the last tick (`None` before the first).
    last_positive: Option<bool>,
}

impl AmplitudeShaper {
    /// A shaper for amplitude A = `amplitude`, the hold's release angle \[rad\] and the
    /// held axes' rate abort limits [rad/s] (lat, lon, ped). The arguments are assumed
    /// validated (positive, finite); see `Config::validate`.
    pub fn new(
        settings: AdaptiveSettings,
        amplitude: f32,
        release_rad: f32,
        rate_limits_rad_s: [f32; 3],
    ) -> AmplitudeShaper {
        let angle = settings.angle_target * release_rad;
        let [lat, lon, ped] = rate_limits_rad_s.map(|l| settings.rate_target * l);
        AmplitudeShaper {
            settings,
            targets: [angle, angle, angle, lat, lon, ped],
            amplitude,
            scale: 1.0,
            current: HalfCycle::EMPTY,
            previous: None,
            last_positive: None,
        }
    }

    /// Back to the start of an excitation (scale 1, nothing measured).
    pub fn reset(&mut self) {
        self.scale = 1.0;
        self.current = HalfCycle::EMPTY;
        self.previous = None;
        self.last_positive = None;
    }

    /// The current scale s (applied amplitude / configured amplitude).
    pub fn scale(&self) -> f32 {
        self.scale
    }

    /// One tick: the applied excitation for the unscaled sweep value `value` = A·e·sin θ
    /// and its quadrature `quadrature` = A·e·cos θ at instantaneous frequency `omega`
    /// [rad/s], with `trim_stick` the primary axis' trim and `axes` this tick's
    /// measurements of the held axes (lat, lon, ped).
    pub fn shape(
        &mut self,
        value: f32,
        quadrature: f32,
        omega: f32,
        trim_stick: f32,
        axes: &[AxisEnvelope; 3],
    ) -> f32 {
        let positive = value >= 0.0;
        let crossed = matches!(self.last_positive, Some(last) if last != positive);
        self.last_positive = Some(positive);
        if crossed {
            if let Some(previous) = self.previous {
                self.adapt(&previous);
            }
            self.previous = Some(self.current);
            self.current = HalfCycle::EMPTY;
        }
        self.scale = self.bounded(self.scale, omega, trim_stick);
        let applied = value * self.scale;
        let [lat, lon, ped] = *axes;
        let x = [
            lat.deviation,
            lon.deviation,
            ped.deviation,
            lat.rate,
            lon.rate,
            ped.rate,
        ];
        self.current.add(applied, quadrature * self.scale, &x);
        applied
    }

    /// The scale from the last cycle (`previous` and the current half cycle).
    fn adapt(&mut self, previous: &HalfCycle) {
        let settings = self.settings;
        let current = &self.current;
        let power = previous.in_phase_power + current.in_phase_power;
        let quadrature_power = previous.quadrature_power + current.quadrature_power;
        if !(power > 0.0 && quadrature_power > 0.0 && self.amplitude > 0.0) {
            return;
        }
        let mut wanted = settings.max_scale;
        for (n, target) in self.targets.iter().enumerate() {
            let sum = |h: &HalfCycle, q: bool| {
                let bins = if q { &h.quadrature } else { &h.in_phase };
                bins.get(n).copied().unwrap_or(0.0)
            };
            let g_in = (sum(previous, false) + sum(current, false)) / power;
            let g_q = (sum(previous, true) + sum(current, true)) / quadrature_power;
            let gain = libm::sqrtf(g_in * g_in + g_q * g_q);
            if gain > 0.0 {
                wanted = wanted.min(target / (self.amplitude * gain));
            }
        }
        let low = self.scale * settings.max_fall;
        let high = self.scale * settings.max_rise;
        if wanted.is_finite() {
            self.scale = wanted.max(low).min(high);
        }
    }

    /// `scale` within the bounds of the module documentation (a NaN becomes the
    /// smallest scale).
    fn bounded(&self, scale: f32, omega: f32, trim_stick: f32) -> f32 {
        let settings = &self.settings;
        let amplitude = self.amplitude;
        let mut upper = settings.max_scale;
        if amplitude > 0.0 {
            let travel = (1.0 - trim_stick.abs()).clamp(0.0, MAX_AMPLITUDE);
            upper = upper.min(travel / amplitude);
            let slope = amplitude * omega.abs();
            if slope > 0.0 {
                upper = upper.min(settings.max_slope_per_s / slope);
            }
        }
        let lower = settings.min_scale;
        // The travel and slope bounds may fall below min_scale: they win.
        let upper = if upper.is_nan() { lower } else { upper };
        let scale = if scale.is_nan() { lower } else { scale };
        scale.max(lower).min(upper).max(0.0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const DEG: f32 = core::f32::consts::PI / 180.0;

    fn shaper() -> AmplitudeShaper {
        AmplitudeShaper::new(AdaptiveSettings::PRESET, 0.05, 4.0 * DEG, [90.0 * DEG; 3])
    }

    /// A linear "aircraft": roll deviation = gain · applied input, 90° behind, plus a
    /// slow drift of `drift_deg` at 0.05 rad/s that the sweep does not cause. Returns the
    /// shaper and the peak sweep-driven roll over the second half.
    fn fly(gain_deg: f32, drift_deg: f32, omega: f32, seconds: f32) -> (AmplitudeShaper, f32) {
        let mut s = shaper();
        let dt = 0.005f32;
        let ticks = (seconds / dt) as u32;
        let mut peak_late = 0.0f32;
        let mut roll = 0.0f32;
        for n in 0..ticks {
            let t = n as f32 * dt;
            let (sin, cos) = (libm::sinf(omega * t), libm::cosf(omega * t));
            let axes = [
                AxisEnvelope {
                    deviation: roll * DEG,
                    rate: 0.0,
                },
                AxisEnvelope {
                    deviation: 0.0,
                    rate: 0.0,
                },
                AxisEnvelope {
                    deviation: 0.0,
                    rate: 0.0,
                },
            ];
            s.shape(0.05 * sin, 0.05 * cos, omega, 0.0, &axes);
            let driven = gain_deg * 0.05 * s.scale() * -cos;
            roll = driven + drift_deg * libm::sinf(0.05 * t);
            if n > ticks / 2 {
                peak_late = peak_late.max(driven.abs());
            }
        }
        (s, peak_late)
    }

    #[test]
    fn the_sweeps_share_settles_on_half_the_release_angle() {
        // 200°/stick: the fixed 5 % sweep would drive 10°; the shaper brings it to 2°.
        let (s, peak) = fly(200.0, 0.0, 2.0, 40.0);
        assert!((peak - 2.0).abs() < 0.1, "peak {peak}°");
        assert!((s.scale() - 0.2).abs() < 0.01, "scale {}", s.scale());
        // 20°/stick (1° at 5 %): the amplitude grows to 2×, where its share is 2°.
        let (s, peak) = fly(20.0, 0.0, 2.0, 40.0);
        assert!((s.scale() - 2.0).abs() < 0.05, "scale {}", s.scale());
        assert!((peak - 2.0).abs() < 0.1, "peak {peak}°");
    }

    #[test]
    fn a_drift_the_sweep_does_not_cause_barely_moves_the_amplitude() {
        let (clean, _) = fly(40.0, 0.0, 3.0, 40.0);
        let (drifting, _) = fly(40.0, 5.0, 3.0, 40.0);
        let ratio = drifting.scale() / clean.scale();
        assert!(
            (ratio - 1.0).abs() < 0.1,
            "{} vs {}",
            drifting.scale(),
            clean.scale()
        );
    }

    #[test]
    fn slope_and_travel_bound_the_amplitude() {
        let mut s = shaper();
        let still = [AxisEnvelope {
            deviation: 0.0,
            rate: 0.0,
        }; 3];
        // 2 per second at 30 rad/s: A ≤ 0.0667, scale ≤ 1.33.
        for _ in 0..10_000 {
            s.shape(0.01, 0.01, 30.0, 0.0, &still);
            s.shape(-0.01, 0.01, 30.0, 0.0, &still);
        }
        assert!(
            (s.scale() - 2.0 / (0.05 * 30.0)).abs() < 1e-4,
            "{}",
            s.scale()
        );
        // Trim at 0.95: 0.05 of travel left, scale ≤ 1.
        s.shape(0.01, 0.0, 1.0, 0.95, &still);
        assert!(s.scale() <= 1.0 + 1e-6);
    }

    #[test]
    fn non_finite_measurements_keep_the_scale_finite_and_bounded() {
        let mut s = shaper();
        let bad = [f32::NAN, f32::INFINITY, f32::NEG_INFINITY, 0.0, 1e30];
        for (n, &x) in bad.iter().cycle().take(4000).enumerate() {
            let value = if n % 7 < 3 { 0.01 } else { -0.01 };
            let axes = [AxisEnvelope {
                deviation: x,
                rate: x,
            }; 3];
            let out = s.shape(value, x, x, x, &axes);
            assert!(out.is_finite(), "output {out} at {n}");
            assert!(s.scale().is_finite() && s.scale() >= 0.0 && s.scale() <= 4.0);
        }
    }

    #[test]
    fn same_inputs_same_amplitudes_and_reset_restarts() {
        let (a, _) = fly(100.0, 2.0, 1.0, 20.0);
        let (b, _) = fly(100.0, 2.0, 1.0, 20.0);
        assert_eq!(a, b);
        let mut c = a;
        c.reset();
        assert_eq!(c.scale(), 1.0);
        assert_eq!(c, shaper());
    }

    #[test]
    fn preset_is_valid_and_bad_settings_are_not() {
        assert!(AdaptiveSettings::PRESET.is_valid());
        let mut bad = AdaptiveSettings::PRESET;
        bad.max_fall = 0.0;
        assert!(!bad.is_valid());
        let mut bad = AdaptiveSettings::PRESET;
        bad.min_scale = f32::NAN;
        assert!(!bad.is_valid());
        let mut bad = AdaptiveSettings::PRESET;
        bad.max_scale = 0.5;
        assert!(!bad.is_valid());
    }
}
