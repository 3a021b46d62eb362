//! Margins of L(s) = k·e^{−sτ}/(s(s + a)) against their closed forms.
//!
//! |L(jω)| = k/(ω√(ω² + a²)) = 1 at ω_c² = (√(a⁴ + 4k²) − a²)/2;
//! PM = 90° − atan(ω_c/a) − ω_c·τ; ω_180 solves atan(ω/a) + ωτ = π/2 (bisection, a
//! monotone function), GM = −20·log10|L(jω_180)|. Without the delay the phase never
//! reaches −180°: no gain margin. The sensitivity 1/(1 + L) of the delay-free loop has
//! |S|² = ω²(ω² + a²)/((k − ω²)² + a²ω²) = 1/2 at x = ω²,
//! x² + (a² + 2k)x − k² = 0: the DRB.

use control::loops::{log_grid, Sampled};
use control::margins::{disturbance_rejection_bandwidth, margins};
use num_complex::Complex64;

fn sampled(k: f64, a: f64, tau: f64, f: impl Fn(Complex64) -> Complex64) -> Sampled {
    let omega = log_grid(0.05, 500.0, 2400);
    let values = omega
        .iter()
        .map(|&w| {
            let s = Complex64::new(0.0, w);
            f(k * (-s * tau).exp() / (s * (s + a)))
        })
        .collect();
    Sampled { omega, values }
}

#[test]
fn delayed_integrator_with_a_lag_has_its_closed_form_margins() {
    for (k, a, tau) in [(20.0, 4.0, 0.05), (60.0, 10.0, 0.02), (5.0, 1.0, 0.1)] {
        let loop_response = sampled(k, a, tau, |l| l);
        let found = margins(&loop_response);
        let wc = ((a.powi(4) + 4.0 * k * k).sqrt() - a * a).sqrt() / 2f64.sqrt();
        let pm = 90.0 - (wc / a).atan().to_degrees() - (wc * tau).to_degrees();
        let (mut lo, mut hi) = (1e-6, 1e3);
        for _ in 0..200 {
            let mid = 0.5 * (lo + hi);
            if (mid / a).atan() + mid * tau < std::f64::consts::FRAC_PI_2 {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        let w180 = 0.5 * (lo + hi);
        let gm = -20.0 * (k / (w180 * (w180 * w180 + a * a).sqrt())).log10();
        let c = found.crossover_rad_s.unwrap();
        assert!((c - wc).abs() / wc < 1e-3, "wc {c} vs {wc}");
        let p = found.phase_margin_deg.unwrap();
        assert!((p - pm).abs() < 0.02, "PM {p} vs {pm}");
        let w = found.phase_crossover_rad_s.unwrap();
        assert!((w - w180).abs() / w180 < 1e-3, "w180 {w} vs {w180}");
        let g = found.gain_margin_db.unwrap();
        assert!((g - gm).abs() < 0.01, "GM {g} vs {gm}");
    }
}

#[test]
fn without_delay_there_is_no_gain_margin_and_the_drb_is_closed_form() {
    let (k, a) = (20.0, 4.0);
    let found = margins(&sampled(k, a, 0.0, |l| l));
    assert_eq!(found.gain_margin_db, None);
    assert!(found.phase_margin_deg.unwrap() > 0.0);
    let sensitivity = sampled(k, a, 0.0, |l| 1.0 / (1.0 + l));
    let b = a * a + 2.0 * k;
    let drb = ((-b + (b * b + 4.0 * k * k).sqrt()) / 2.0).sqrt();
    let ours = disturbance_rejection_bandwidth(&sensitivity).unwrap();
    assert!((ours - drb).abs() / drb < 1e-3, "DRB {ours} vs {drb}");
}
