//! Tests of the measured broken loops: known loops through the estimate, margins and their
//! uncertainty.

use super::*;
use control::margins::margins as exact_margins;
use nalgebra::Complex;
use sysid::random::SplitMix64;

/// Tischler's exponential sweep (the firmware's), closed form.
fn sweep(t: f64, duration: f64, [low, high]: [f64; 2]) -> f64 {
    let c2 = 1.0 / (4.0f64.exp() - 1.0);
    let theta =
        low * t + (high - low) * c2 * ((duration / 4.0) * ((4.0 * t / duration).exp() - 1.0) - t);
    0.05 * theta.sin()
}

/// The known loop of these tests (sampled at 200 Hz): plant P(z) = b·z^−D/(z − a) (a
/// first-order lag and D ticks of delay), controller K(z) = kp + ki·T/(z − 1) on the
/// plant's output with white noise of `noise` (rms) on the measurement; the sweep over
/// `band` added at the controller's output, 5 s at rest either side, fading in and out
/// over 2 s as the firmware flies it.
struct KnownLoop {
    t: f64,
    a: f64,
    b: f64,
    delay: i32,
    kp: f64,
    ki: f64,
}

impl KnownLoop {
    fn new() -> Self {
        let t = 1.0 / 200.0;
        let a = (-t / 0.25f64).exp();
        KnownLoop {
            t,
            a,
            b: (1.0 - a) * 4.0,
            delay: 6,
            kp: 1.2,
            ki: 2.0,
        }
    }

    fn exact(&self, omega: f64) -> Complex<f64> {
        let z = Complex::from_polar(1.0, omega * self.t);
        let plant = self.b * z.powi(-self.delay) / (z - self.a);
        let controller = self.kp + self.ki * self.t / (z - 1.0);
        controller * plant
    }

    fn margins(&self, band: [f64; 2]) -> Margins {
        let grid = control::loops::log_grid(band[0], band[1], 2400);
        exact_margins(&Sampled {
            values: grid.iter().map(|w| self.exact(*w)).collect(),
            omega: grid,
        })
    }

    /// The injection d and the total u of a 90 s loop test.
    fn fly(&self, band: [f64; 2], noise: f64, seed: u64) -> (Vec<f64>, Vec<f64>) {
        let (t, a, b, kp, ki) = (self.t, self.a, self.b, self.kp, self.ki);
        let duration = 90.0;
        let lead = 5.0;
        let n = ((duration + 2.0 * lead) / t) as usize;
        let fade = |time: f64| {
            let edge = time.min(duration - time).clamp(0.0, 2.0) / 2.0;
            0.5 - 0.5 * (std::f64::consts::PI * edge).cos()
        };
        let mut random = SplitMix64::new(seed);
        let (mut x, mut integral) = (0.0, 0.0);
        let mut history = vec![0.0f64; self.delay as usize + 1];
        let (mut d, mut u) = (Vec::with_capacity(n), Vec::with_capacity(n));
        for k in 0..n {
            let y = history[0] + noise * random.normal_pair().0;
            let c = -(kp * y + integral);
            integral += ki * t * y;
            let time = k as f64 * t - lead;
            let injection = if (0.0..=duration).contains(&time) {
                fade(time) * sweep(time, duration, band)
            } else {
                0.0
            };
            let total = c + injection;
            d.push(injection);
            u.push(total);
            x = a * x + b * total;
            history.rotate_left(1);
            *history.last_mut().unwrap() = x;
        }
        (d, u)
    }
}

/// The measured broken loop of the known loop matches L = K·P on its valid points and
/// its margins match the exact loop's.
#[test]
fn the_measured_broken_loop_of_a_known_loop_matches_it() {
    let known = KnownLoop::new();
    let band = [0.5, 60.0];
    let (d, u) = known.fly(band, 0.002, 7);
    let measured = broken_loop(&d, &u, 200.0, band, &BrokenLoopOptions::default()).unwrap();
    let mut compared = 0;
    for ((w, l), g) in measured
        .omega
        .iter()
        .zip(&measured.values)
        .zip(&measured.coherence)
    {
        // Below `resolved_from_rad_s` the windows' resolution biases the estimate
        // (−2.3 dB, −18° at 0.5 rad/s here); at the top the sweep fades out (7.6° at
        // 58.6 of 60 rad/s).
        if *g < 0.9 || *w < measured.resolved_from_rad_s || *w > 50.0 {
            continue;
        }
        compared += 1;
        let truth = known.exact(*w);
        let db = 20.0 * (l.norm() / truth.norm()).log10();
        let degrees = (l / truth).arg().to_degrees();
        assert!(
            db.abs() < 0.5 && degrees.abs() < 3.0,
            "{w}: {db} dB, {degrees}°"
        );
    }
    assert!(compared > 100, "{compared} points of coherence ≥ 0.9");
    assert!(
        measured.resolved_from_rad_s < 1.5,
        "{}",
        measured.resolved_from_rad_s
    );
    let truth = known.margins(band);
    let (found, valid) = valid_margins(&measured, MAX_RANDOM_ERROR);
    assert!(valid > 150);
    let pair = |a: Option<f64>, b: Option<f64>| (a.unwrap(), b.unwrap());
    let (gm, gm_true) = pair(found.gain_margin_db, truth.gain_margin_db);
    let (pm, pm_true) = pair(found.phase_margin_deg, truth.phase_margin_deg);
    let (wc, wc_true) = pair(found.crossover_rad_s, truth.crossover_rad_s);
    // A loop with real margins to find: neither huge nor negative.
    assert!((3.0..20.0).contains(&gm_true) && (20.0..90.0).contains(&pm_true));
    assert!((gm - gm_true).abs() < 0.3, "GM {gm} vs {gm_true}");
    assert!((pm - pm_true).abs() < 1.5, "PM {pm} vs {pm_true}");
    assert!((wc / wc_true - 1.0).abs() < 0.02, "wc {wc} vs {wc_true}");
}

/// With measurement noise large enough that the coherence near the phase crossover
/// (50 rad/s) falls to 0.3–0.5 (the loop's output there small against the noise it
/// carries, as on a heading loop), the random error still bounds the estimate: over
/// ten noise seeds the valid points of coherence below 0.6 lie within their random
/// error of the truth (rms of |L̂/L − 1| against the rms εr), and the gain margin is
/// measured on every seed within 1 dB of the exact one (−0.05 to +0.8 dB here; the
/// band reaches 80 rad/s so that the crossover lies clear of the sweep's fade-out),
/// its rms error within its stated uncertainty ([`margin_uncertainty`]).
#[test]
fn points_of_low_coherence_are_valid_within_their_random_error() {
    let known = KnownLoop::new();
    let band = [0.5, 80.0];
    let truth = known.margins(band).gain_margin_db.unwrap();
    let (mut error2, mut bound2, mut low) = (0.0, 0.0, 0usize);
    let (mut gm_error2, mut gm_sigma2) = (0.0, 0.0);
    for seed in 1..=10 {
        let (d, u) = known.fly(band, 0.025, seed);
        let measured = broken_loop(&d, &u, 200.0, band, &BrokenLoopOptions::default()).unwrap();
        let (found, _) = valid_margins(&measured, MAX_RANDOM_ERROR);
        let gm = found.gain_margin_db.expect("a gain margin on every seed");
        assert!((gm - truth).abs() < 1.0, "seed {seed}: GM {gm} vs {truth}");
        let [_, sigma] = margin_uncertainty(
            &measured,
            found.crossover_rad_s,
            found.phase_crossover_rad_s,
        );
        let sigma = sigma.expect("an uncertainty with every gain margin");
        gm_error2 += (gm - truth).powi(2);
        gm_sigma2 += sigma * sigma;
        for k in 0..measured.omega.len() {
            let (w, e, g) = (
                measured.omega[k],
                measured.random_error[k],
                measured.coherence[k],
            );
            if e <= MAX_RANDOM_ERROR && g < 0.6 && w >= measured.resolved_from_rad_s && w < 50.0 {
                low += 1;
                error2 += (measured.values[k] / known.exact(w) - 1.0).norm_sqr();
                bound2 += e * e;
            }
        }
    }
    assert!(low > 100, "{low} valid points of coherence below 0.6");
    let (rms_error, rms_bound) = ((error2 / low as f64).sqrt(), (bound2 / low as f64).sqrt());
    assert!(
        rms_error < 1.5 * rms_bound,
        "rms error {rms_error} against rms random error {rms_bound}"
    );
    // The gain margin's stated uncertainty covers its error over the seeds.
    let (gm_rms, gm_sigma) = ((gm_error2 / 10.0).sqrt(), (gm_sigma2 / 10.0).sqrt());
    assert!(
        gm_rms < 1.5 * gm_sigma && gm_sigma < 2.0,
        "GM rms error {gm_rms} dB against stated {gm_sigma} dB"
    );
}

/// A loop whose phase crosses −180° below its crossover too (two integrators and a slow
/// pole, as a heading hold on a lightly damped yaw): python-control's least |GM| is the
/// negative one there (the gain reduction the loop tolerates); the margin above the
/// crossover is the increase, as `tune` constrains it.
#[test]
fn a_loop_crossing_minus_180_below_its_crossover_has_both_gain_margins() {
    // L(s) = k (s + 1)² / (s² (s + 0.2)(s/40 + 1)²), k = 2: phase below −180° up to about
    // 0.8 rad/s (+15 dB there), crossover near 2 rad/s, phase crossover again near 38
    // rad/s (−31 dB).
    let exact = |w: f64| {
        let s = Complex::new(0.0, w);
        let k = 2.0;
        k * (s + 1.0).powi(2) / (s * s * (s + 0.2) * (s / 40.0 + 1.0).powi(2))
    };
    let omega = control::loops::log_grid(0.05, 200.0, 2400);
    let values: Vec<Complex<f64>> = omega.iter().map(|&w| exact(w)).collect();
    let truth = Sampled {
        omega: omega.clone(),
        values: values.clone(),
    };
    let (_, exact_upper) = upper_margins(&truth);
    let exact_least = exact_margins(&truth);
    let measured = BrokenLoop {
        random_error: vec![0.01; omega.len()],
        coherence: vec![0.99; omega.len()],
        resolved_from_rad_s: 0.05,
        omega,
        values,
    };
    let (least, _) = valid_margins(&measured, MAX_RANDOM_ERROR);
    let upper = valid_upper_gain_margin(&measured, MAX_RANDOM_ERROR).unwrap();
    let least_gm = least.gain_margin_db.unwrap();
    assert!(
        least_gm < -6.0,
        "the low crossing's reduction margin: {least_gm}"
    );
    assert!(least.phase_crossover_rad_s.unwrap() < least.crossover_rad_s.unwrap());
    assert_eq!(least_gm, exact_least.gain_margin_db.unwrap());
    assert!(upper > 6.0, "{upper}");
    assert_eq!(Some(upper), exact_upper);
    // The closed form's (numpy, 20 000 points): −15.43 dB at 0.819 rad/s, 31.22 dB at
    // 38.15 rad/s.
    assert!((least_gm + 15.43).abs() < 0.05, "{least_gm}");
    assert!((upper - 31.22).abs() < 0.05, "{upper}");
}
