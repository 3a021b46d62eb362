//! `fly --gust-pulse AT_S:U,V,W`: one discrete gust while flying on after the test
//! (`--fly-on`), the pilot's hands at trim, and the peak attitude excursion it causes.
//!
//! The gust is the "1 − cos" shape of the discrete gust of MIL-F-8785C (§3.7.2.4) and of
//! FAR/CS-25's gust loads: the air velocity relative to the ground in body axes, added to
//! the simulator's (`rotorsim::Sim::set_wind`), rises from zero to (U, V, W) and falls
//! back over [`GUST_LENGTH_S`], `w(t) = W/2·(1 − cos(2πt/T))`. A hovering helicopter has
//! no airspeed to turn a gust length into a time: the length is stated in seconds. The
//! excursion is measured on the simulated aircraft (not the board's estimate) from its
//! attitude at the gust's onset to the end of the flight, and its trace is kept
//! ([`TRACE_STEP_S`]): the same flight in still air (the gust's components zero; the same
//! seed and board fly the same flight up to the onset) subtracted from it leaves the
//! attitude response to the gust alone, free of the hover's own motion
//! (`docs/tuned_gains.py`).

use std::f64::consts::PI;

use super::summary::{AttitudeDeg, ExcursionTrace, GustPulseSummary};

/// Duration of the gust's rise and fall \[s\]: about the roll and pitch attitude loops'
/// period (ω_c 4–10 rad/s), where a gust disturbs them most.
pub const GUST_LENGTH_S: f64 = 1.0;

/// Largest body-axis gust component \[m/s\] accepted: a severe gust by MIL-F-8785C's
/// tables at low altitude is about 15 m/s.
pub const MAX_GUST_M_S: f64 = 20.0;

/// Spacing of the excursion's trace in the summary \[s\] (50 Hz: ten samples per period
/// of the fastest attitude loop's crossover, 30 rad/s).
pub const TRACE_STEP_S: f64 = 0.02;

/// A planned gust: its onset after the test's end and its peak air velocity.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GustPulse {
    /// Onset, seconds after the test ended (flying on).
    pub at_s: f64,
    /// Peak body-axis air velocity (u, v, w) \[m/s\].
    pub body_wind_m_s: [f64; 3],
}

impl GustPulse {
    /// `AT_S:U,V,W`, e.g. `5:0,4,0` (a 4 m/s lateral gust 5 s after the test).
    pub fn parse(text: &str) -> Result<GustPulse, String> {
        let (at, wind) = text
            .split_once(':')
            .ok_or("expected AT_S:U,V,W, e.g. 5:0,4,0")?;
        let at_s = match at.trim().parse::<f64>() {
            Ok(t) if t.is_finite() && t >= 0.0 => t,
            _ => return Err(format!("`{at}`: expected seconds >= 0 after the test")),
        };
        let parts: Vec<&str> = wind.split(',').collect();
        let [u, v, w] = parts.as_slice() else {
            return Err(format!("`{wind}`: expected three components U,V,W in m/s"));
        };
        let mut body_wind_m_s = [0.0; 3];
        for (slot, part) in body_wind_m_s.iter_mut().zip([u, v, w]) {
            *slot = match part.trim().parse::<f64>() {
                Ok(x) if x.is_finite() && x.abs() <= MAX_GUST_M_S => x,
                _ => {
                    return Err(format!(
                        "`{part}`: expected a component in m/s within ±{MAX_GUST_M_S}"
                    ))
                }
            };
        }
        Ok(GustPulse {
            at_s,
            body_wind_m_s,
        })
    }

    /// The air velocity `t` seconds after the test ended \[m/s\].
    pub fn wind(&self, t: f64) -> [f64; 3] {
        let s = t - self.at_s;
        if !(0.0..=GUST_LENGTH_S).contains(&s) {
            return [0.0; 3];
        }
        let shape = 0.5 * (1.0 - (2.0 * PI * s / GUST_LENGTH_S).cos());
        self.body_wind_m_s.map(|w| w * shape)
    }
}

/// The aircraft's response to the gust, followed tick by tick.
#[derive(Clone, Debug)]
pub struct GustResponse {
    plan: GustPulse,
    /// φ, θ at the onset \[rad\].
    onset: Option<[f64; 2]>,
    /// Peak |φ − φ_onset|, |θ − θ_onset| \[rad\].
    peak: [f64; 2],
    /// φ − φ_onset, θ − θ_onset every [`TRACE_STEP_S`] from the onset \[rad\].
    trace: Vec<[f64; 2]>,
}

impl GustResponse {
    /// Nothing flown yet.
    pub fn new(plan: GustPulse) -> Self {
        GustResponse {
            plan,
            onset: None,
            peak: [0.0; 2],
            trace: Vec::new(),
        }
    }

    /// The wind to fly `t` seconds after the test ended, with the aircraft at `attitude`
    /// (φ, θ, ψ \[rad\]) at that moment.
    pub fn step(&mut self, t: f64, attitude: [f64; 3]) -> [f64; 3] {
        if t >= self.plan.at_s {
            let onset = *self.onset.get_or_insert([attitude[0], attitude[1]]);
            for (peak, (now, start)) in self.peak.iter_mut().zip(attitude.iter().zip(onset)) {
                *peak = peak.max((now - start).abs());
            }
            // The first tick at or after each multiple of the step from the onset.
            let due = self.trace.len() as f64 * TRACE_STEP_S;
            if t - self.plan.at_s >= due - 1e-9 {
                self.trace
                    .push([attitude[0] - onset[0], attitude[1] - onset[1]]);
            }
        }
        self.plan.wind(t)
    }

    /// The summary, if the gust began before the flight ended.
    pub fn summary(&self) -> Option<GustPulseSummary> {
        self.onset.map(|_| GustPulseSummary {
            at_s: self.plan.at_s,
            length_s: GUST_LENGTH_S,
            body_wind_m_s: self.plan.body_wind_m_s,
            peak_excursion_deg: AttitudeDeg {
                phi: self.peak[0].to_degrees(),
                theta: self.peak[1].to_degrees(),
            },
            excursion_deg: ExcursionTrace {
                step_s: TRACE_STEP_S,
                // 10⁻⁴ degree: far below any attitude the simulator resolves that matters,
                // and it keeps the summary small.
                phi: self
                    .trace
                    .iter()
                    .map(|e| round4(e[0].to_degrees()))
                    .collect(),
                theta: self
                    .trace
                    .iter()
                    .map(|e| round4(e[1].to_degrees()))
                    .collect(),
            },
        })
    }
}

fn round4(x: f64) -> f64 {
    (x * 1e4).round() / 1e4
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_gust_rises_and_falls_as_one_minus_cosine() {
        let gust = GustPulse::parse("2:1,-4,0.5").unwrap();
        assert_eq!(gust.body_wind_m_s, [1.0, -4.0, 0.5]);
        assert_eq!(gust.wind(1.99), [0.0; 3]);
        assert_eq!(gust.wind(2.0 + GUST_LENGTH_S + 0.01), [0.0; 3]);
        let peak = gust.wind(2.0 + 0.5 * GUST_LENGTH_S);
        for (a, b) in peak.iter().zip([1.0, -4.0, 0.5]) {
            assert!((a - b).abs() < 1e-12, "{peak:?}");
        }
        let quarter = gust.wind(2.0 + 0.25 * GUST_LENGTH_S);
        assert!((quarter[1] + 2.0).abs() < 1e-12, "{quarter:?}");
    }

    #[test]
    fn bad_gusts_are_refused() {
        for text in [
            "",
            "5",
            "5:1,2",
            "-1:0,1,0",
            "x:0,1,0",
            "5:0,nan,0",
            "5:0,21,0",
        ] {
            assert!(GustPulse::parse(text).is_err(), "{text}");
        }
    }

    #[test]
    fn the_excursion_is_measured_from_the_attitude_at_the_onset() {
        let mut response = GustResponse::new(GustPulse::parse("1:0,3,0").unwrap());
        // Before the onset: not counted.
        response.step(0.5, [0.3, 0.3, 0.0]);
        assert!(response.summary().is_none());
        response.step(1.0, [0.1, -0.05, 0.0]);
        response.step(1.5, [0.15, -0.08, 0.0]);
        response.step(2.0, [0.08, 0.0, 0.0]);
        let summary = response.summary().unwrap();
        assert!((summary.peak_excursion_deg.phi - 0.05f64.to_degrees()).abs() < 1e-9);
        assert!((summary.peak_excursion_deg.theta - 0.05f64.to_degrees()).abs() < 1e-9);
        assert_eq!(summary.length_s, GUST_LENGTH_S);
        // The trace: the onset, then one sample per step (the ticks here 0.5 s apart).
        assert_eq!(summary.excursion_deg.phi.len(), 3);
        assert_eq!(summary.excursion_deg.phi[0], 0.0);
        assert!((summary.excursion_deg.phi[1] - round4(0.05f64.to_degrees())).abs() < 1e-12);
        assert!((summary.excursion_deg.theta[2] - round4(0.05f64.to_degrees())).abs() < 1e-12);
    }

    #[test]
    fn the_trace_samples_every_step_from_the_onset() {
        let mut response = GustResponse::new(GustPulse::parse("1:0,3,0").unwrap());
        let tick = 0.005;
        for k in 0..=400 {
            let t = k as f64 * tick;
            response.step(t, [0.01 * t, 0.0, 0.0]);
        }
        let summary = response.summary().unwrap();
        // 1 s flown from the onset at 50 Hz: 51 samples, each 0.02 s of φ-rate 0.01 rad/s.
        assert_eq!(summary.excursion_deg.phi.len(), 51);
        let step = round4((0.01 * TRACE_STEP_S).to_degrees());
        assert!((summary.excursion_deg.phi[1] - step).abs() < 2e-4);
        assert!((summary.excursion_deg.phi[50] - round4(0.01f64.to_degrees())).abs() < 2e-4);
    }
}
