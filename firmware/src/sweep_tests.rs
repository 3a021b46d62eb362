//! Tests of `sweep`.
use super::*;

fn paper_sweep() -> ExponentialSweep {
    ExponentialSweep::new(0.3, 31.4, 90.0)
}

#[test]
fn c2_makes_the_sweep_end_at_omega_max() {
    assert!((c2() - 0.018_657_1).abs() < 1e-6);
    let sweep = paper_sweep();
    assert!((sweep.omega(0.0) - 0.3).abs() < 1e-12);
    assert!((sweep.omega(90.0) - 31.4).abs() < 1e-9);
}

#[test]
fn numerical_derivative_of_phase_matches_omega_over_the_whole_record() {
    // Central difference dθ/dt ≈ (θ(t+h) − θ(t−h)) / 2h; the truncation error
    // θ'''h²/6 and the rounding error ε·θ/h are both far below 0.1 %.
    let sweep = paper_sweep();
    let h = 1e-4;
    let steps = 9000;
    let mut worst = 0.0f64;
    for i in 0..=steps {
        let t = 90.0 * f64::from(i) / f64::from(steps);
        let derivative = if i == 0 {
            (sweep.phase(t + h) - sweep.phase(t)) / h
        } else if i == steps {
            (sweep.phase(t) - sweep.phase(t - h)) / h
        } else {
            (sweep.phase(t + h) - sweep.phase(t - h)) / (2.0 * h)
        };
        let relative = (derivative - sweep.omega(t)).abs() / sweep.omega(t);
        worst = worst.max(relative);
    }
    assert!(worst < 1e-3, "worst relative frequency error {worst}");
    // And the frequency actually runs from ω_min to ω_max.
    let start = (sweep.phase(h) - sweep.phase(0.0)) / h;
    let end = (sweep.phase(90.0) - sweep.phase(90.0 - h)) / h;
    assert!((start - 0.3).abs() / 0.3 < 1e-3, "start {start}");
    assert!((end - 31.4).abs() / 31.4 < 1e-3, "end {end}");
}

#[test]
fn sampled_signal_frequency_matches_omega_from_zero_crossings() {
    // Independent check on the emitted samples: the count of zero crossings of the
    // sampled signal over the record equals θ(T_rec)/π to within one crossing.
    let signal = SweepSignal::new(0.05, 0.3, 31.4, 90.0, 0.0, 0);
    let rate = 1000.0;
    let mut crossings = 0u32;
    let mut previous = signal.sample(0.5 / rate).value;
    for n in 1..90_000u32 {
        let value = signal.sample((f64::from(n) + 0.5) / rate).value;
        if (value > 0.0) != (previous > 0.0) {
            crossings += 1;
        }
        previous = value;
    }
    let expected = signal.sweep().phase(90.0) / core::f64::consts::PI;
    assert!(
        (f64::from(crossings) - expected).abs() <= 2.0,
        "{crossings} vs {expected}"
    );
}

#[test]
fn phase_is_continuous_across_segments_and_fades_shape_the_envelope() {
    let signal = SweepSignal::new(0.05, 0.3, 31.4, 90.0, 2.0, 1);
    let hold = TAU / 0.3;
    let lead = 2.0 + hold;
    let eps = 1e-9;
    for boundary in [lead, lead + 90.0] {
        let (_, before, _) = signal.phase_and_omega(boundary - eps);
        let (_, after, _) = signal.phase_and_omega(boundary);
        assert!((after - before).abs() < 1e-6, "jump at {boundary}");
    }
    assert_eq!(signal.sample(0.0).envelope, 0.0);
    assert!((signal.sample(1.0).envelope - 0.5).abs() < 1e-6);
    assert_eq!(signal.sample(2.5).envelope, 1.0);
    assert_eq!(signal.sample(lead + 1.0).segment, Segment::Main);
    assert!((signal.sample(lead + 90.0 + 1.0).envelope - 0.5).abs() < 1e-6);
    assert_eq!(signal.sample(lead + 90.0 + 1.0).omega, 31.4);
    assert_eq!(signal.sample(lead + 92.0).segment, Segment::Finished);
    assert!((signal.duration_s() - (lead + 92.0)).abs() < 1e-12);
}

#[test]
fn amplitude_bounds_the_signal() {
    let signal = SweepSignal::new(0.05, 0.3, 31.4, 90.0, 2.0, 0);
    let mut peak = 0.0f32;
    for n in 0..94_000u32 {
        let sample = signal.sample(f64::from(n) / 1000.0);
        peak = peak.max(sample.value.abs());
    }
    assert!(peak <= 0.05 && peak > 0.0499, "peak {peak}");
}

/// Angular distance of two angles modulo 2π.
fn angle_between(a: f64, b: f64) -> f64 {
    let d = (a - b).rem_euclid(TAU);
    d.min(TAU - d)
}

/// The tick path against the `f64` closed form at every tick of a whole paper
/// record (fade-in, ω_min hold, 90 s sweep, fade-out) at 200 Hz: same segment at
/// every tick, phase within 10⁻⁹ rad (in order, and re-anchored out of order),
/// frequency, envelope and value to `f32` rounding.
#[test]
fn ticks_follow_the_closed_form_over_a_whole_record() {
    let rate = 200u16;
    let signal = SweepSignal::new(0.05, 0.3, 31.4, 90.0, 2.0, 1);
    let mut samples = signal.ticker(rate);
    let mut phases = signal.ticker(rate);
    let (mut worst_phase, mut worst_omega, mut worst_value) = (0.0f64, 0.0f64, 0.0f32);
    let mut n = 0u32;
    loop {
        let t = f64::from(n) / f64::from(rate);
        let reference = signal.sample(t);
        let (segment, theta, omega) = signal.phase_and_omega(t);
        let fast = samples.sample(n);
        assert_eq!(fast.segment, segment, "segment at tick {n}");
        if segment == Segment::Finished {
            assert_eq!(fast, ExcitationSample::FINISHED);
            break;
        }
        worst_phase = worst_phase.max(angle_between(phases.phase_radians(n), theta));
        if n.is_multiple_of(997) {
            let mut fresh = signal.ticker(rate);
            worst_phase = worst_phase.max(angle_between(fresh.phase_radians(n), theta));
        }
        worst_omega = worst_omega.max((f64::from(fast.omega) - omega).abs() / omega);
        worst_value = worst_value.max((fast.value - reference.value).abs());
        assert!(
            (fast.envelope - reference.envelope).abs() < 1e-6,
            "envelope at {n}"
        );
        n += 1;
    }
    assert!(n > 94 * u32::from(rate), "the record ended at tick {n}");
    assert!(worst_phase < 1e-9, "worst phase error {worst_phase} rad");
    assert!(
        worst_omega < 1e-5,
        "worst relative frequency error {worst_omega}"
    );
    assert!(worst_value < 1e-6, "worst value error {worst_value}");
}

/// The zero-crossing check of the time-based path, on the tick path at 1 kHz: the
/// crossings over the record count θ(T_rec)/π to within two.
#[test]
fn ticked_signal_crosses_zero_as_often_as_the_phase_says() {
    let signal = SweepSignal::new(0.05, 0.3, 31.4, 90.0, 0.0, 0);
    let mut ticker = signal.ticker(1000);
    let mut crossings = 0u32;
    let mut previous = ticker.sample(0).value;
    for n in 1..90_000u32 {
        let value = ticker.sample(n).value;
        if (value > 0.0) != (previous > 0.0) {
            crossings += 1;
        }
        previous = value;
    }
    let expected = signal.sweep().phase(90.0) / core::f64::consts::PI;
    assert!(
        (f64::from(crossings) - expected).abs() <= 2.0,
        "{crossings} vs {expected}"
    );
}

#[test]
fn first_tick_matches_the_time_comparison() {
    for rate in [50.0, 200.0, 333.0, 1000.0] {
        for time in [0.0, 0.005, 1.0, 2.0 + TAU / 0.3, 92.0 + TAU / 0.3, 1e-12] {
            let n = first_tick_at_or_after(time, rate);
            assert!(f64::from(n) / rate >= time);
            assert!(n == 0 || f64::from(n - 1) / rate < time, "{time} at {rate}");
        }
    }
    assert_eq!(first_tick_at_or_after(-1.0, 200.0), 0);
    assert_eq!(first_tick_at_or_after(f64::NAN, 200.0), 0);
}
