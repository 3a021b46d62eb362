//! Tests of the time-domain verification: the exact discretisation, fractional delays,
//! scores on self-generated and noisy data, segments, mismatches and the trim bias.

use nalgebra::DMatrix;

use super::score::rms;
use super::*;
use crate::records::Channel;

fn names(list: &[&str]) -> Vec<String> {
    list.iter().map(|s| s.to_string()).collect()
}

/// ẋ = −a x + b u(t − τ), y = x (and y2 = ẋ through H1).
fn lag(a: f64, b: f64, delay: f64) -> Model {
    let mut model = Model::zeros(names(&["x"]), names(&["lat"]), names(&["p", "pdot"]));
    model.m[(0, 0)] = 1.0;
    model.f[(0, 0)] = -a;
    model.g[(0, 0)] = b;
    model.h0[(0, 0)] = 1.0;
    model.h1[(1, 0)] = 1.0;
    model.delays[0] = delay;
    model
}

#[test]
fn ramp_response_is_exact() {
    // u = t: x(t) = (b/a)(t − (1 − e^{−at})/a), ẋ = (b/a)(1 − e^{−at}).
    let (a, b, rate) = (3.0, 2.0, 50.0);
    let times: Vec<f64> = (0..200).map(|k| k as f64 / rate).collect();
    let model = lag(a, b, 0.0);
    let y = simulate(&model, std::slice::from_ref(&times), rate).unwrap();
    for (k, t) in times.iter().enumerate() {
        let x = b / a * (t - (1.0 - (-a * t).exp()) / a);
        let xdot = b / a * (1.0 - (-a * t).exp());
        assert!((y[0][k] - x).abs() < 1e-12, "{k}: {} vs {x}", y[0][k]);
        assert!((y[1][k] - xdot).abs() < 1e-12, "{k}: {} vs {xdot}", y[1][k]);
    }
}

#[test]
fn a_known_actuator_is_simulated_as_its_frequency_response_says() {
    // A sine through a 60 rad/s, ζ 0.7 servo into the lag: after the transients the
    // output is |T(jω)| sin(ωt + ∠T(jω)), T including the servo and the delay. The
    // first-order hold of a sampled sine (20 samples per period at 10 rad/s, 200 Hz) is
    // within 0.1 % of it.
    let (rate, omega) = (200.0, 10.0);
    let mut model = lag(3.0, 2.0, 0.01);
    model.actuators[0] = Some(crate::fit::model::Actuator {
        natural_frequency_rad_s: 60.0,
        damping: 0.7,
    });
    let times: Vec<f64> = (0..1200).map(|k| k as f64 / rate).collect();
    let input: Vec<f64> = times.iter().map(|t| (omega * t).sin()).collect();
    let y = simulate(&model, &[input], rate).unwrap();
    let response = model.frequency_response(0, 0, omega);
    let without = lag(3.0, 2.0, 0.01).frequency_response(0, 0, omega);
    // The servo is there: 20° more lag at 10 rad/s than the delay alone.
    assert!((without.arg() - response.arg()).to_degrees() > 10.0);
    for (k, t) in times.iter().enumerate().skip(800) {
        let expected = response.norm() * (omega * t + response.arg()).sin();
        assert!(
            (y[0][k] - expected).abs() < 1e-3 * response.norm(),
            "{k}: {} vs {expected}",
            y[0][k]
        );
    }
}

#[test]
fn delay_shifts_by_fractional_samples() {
    let (a, b, rate) = (3.0, 2.0, 50.0);
    let tau = 0.047; // 2.35 samples
    let times: Vec<f64> = (0..200).map(|k| k as f64 / rate).collect();
    let y = simulate(&lag(a, b, tau), std::slice::from_ref(&times), rate).unwrap();
    for (k, t) in times.iter().enumerate() {
        let shifted = (t - tau).max(0.0);
        let x = b / a * (shifted - (1.0 - (-a * shifted).exp()) / a);
        // The delayed ramp is exact except its kink at t = τ, which falls between
        // samples and is smoothed over that interval: the input error there is at
        // most 0.35·0.65·h, worth ≤ b·h·0.23·h ≈ 1.8e-4 of x, decaying with e^{−at}.
        let tolerance = if *t < 1.0 { 2e-4 } else { 1e-5 };
        assert!((y[0][k] - x).abs() < tolerance, "{k}: {} vs {x}", y[0][k]);
    }
    assert_eq!(delayed(&[1.0, 2.0, 3.0], 0.5), vec![0.5, 1.5, 2.5]);
    assert_eq!(delayed(&[1.0, 2.0, 3.0], 1.0), vec![0.0, 1.0, 2.0]);
}

fn two_axis_model() -> Model {
    // A lightly damped oscillator and a first-order lag, coupled, with a mass matrix
    // that is not the identity and a delay.
    let mut model = Model::zeros(
        names(&["p", "phi", "q"]),
        names(&["lat", "lon"]),
        names(&["p", "q", "phi", "ay"]),
    );
    model.m = DMatrix::from_row_slice(3, 3, &[1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.5]);
    model.f = DMatrix::from_row_slice(3, 3, &[-2.0, -9.0, 0.3, 1.0, 0.0, 0.0, 0.0, 0.0, -1.5]);
    model.g = DMatrix::from_row_slice(3, 2, &[10.0, 1.0, 0.0, 0.0, 0.5, 4.0]);
    model.h0[(0, 0)] = 1.0;
    model.h0[(1, 2)] = 1.0;
    model.h0[(2, 1)] = 1.0;
    model.h1[(3, 0)] = 0.3;
    model.h0[(3, 1)] = -9.8;
    model.delays = vec![0.02, 0.013];
    model
}

fn record_of(model: &Model, noise: f64) -> Record {
    let rate = 100.0;
    let n = 3000;
    let trim = [0.1, -0.2];
    // Perturbations that start at 0, as verify takes them (recorded minus first sample).
    let inputs: Vec<Vec<f64>> = (0..2)
        .map(|j| {
            let raw: Vec<f64> = (0..n)
                .map(|k| {
                    let t = k as f64 / rate;
                    0.05 * (t * (0.5 + 0.1 * t) + j as f64).sin()
                        + 0.02 * (7.0 * t + 0.3 * j as f64).sin()
                })
                .collect();
            raw.iter().map(|v| v - raw[0]).collect()
        })
        .collect();
    let clean = simulate(model, &inputs, rate).unwrap();
    // Deterministic pseudo-noise, scaled to `noise` × RMS.
    let mut random = crate::random::SplitMix64::new(0x9e37_79b9_7f4a_7c15);
    let mut next = || random.symmetric();
    let outputs = model
        .outputs
        .iter()
        .zip(&clean)
        .enumerate()
        .map(|(i, (name, series))| {
            let level = noise * rms(series.iter().copied(), series.len()) * 3f64.sqrt();
            // A trim offset per output, which the bias must absorb.
            let offset = 0.7 * i as f64 - 1.0;
            Channel::new(
                name.clone(),
                series.iter().map(|v| v + offset + level * next()).collect(),
            )
        })
        .collect();
    Record {
        source: "synthetic".into(),
        sample_rate_hz: rate,
        primary: "lat".into(),
        primary_guessed: false,
        sweep_band: None,
        inputs: inputs
            .iter()
            .zip(["lat", "lon"])
            .zip(trim)
            .map(|((series, name), t)| Channel::new(name, series.iter().map(|v| v + t).collect()))
            .collect(),
        outputs,
        references: Vec::new(),
        notes: Vec::new(),
        trim_samples: 0,
        measurement_filter: None,
    }
}

/// The verification with the fitted bias, as it was before the trim bias existed.
fn verify_fitted(model: &Model, record: &Record) -> Result<Verification, VerifyError> {
    verify_record_in_segments(model, record, None, BiasMode::Fitted)
}

#[test]
fn self_generated_data_scores_zero_and_noise_raises_the_tic() {
    let model = two_axis_model();
    let clean_record = record_of(&model, 0.0);
    let exact = verify_fitted(&model, &clean_record).unwrap();
    assert_eq!(exact.outputs.len(), 4);
    for score in &exact.outputs {
        assert!(score.theil < 1e-9, "{}: {}", score.output, score.theil);
        let offset = 0.7 * model.output_index(&score.output).unwrap() as f64 - 1.0;
        assert!((score.bias - offset).abs() < 1e-9, "{score:?}");
    }
    let mut previous = exact.theil_mean;
    for noise in [0.05, 0.2, 0.5] {
        let noisy = verify_fitted(&model, &record_of(&model, noise)).unwrap();
        assert!(
            noisy.theil_mean > previous,
            "noise {noise}: {} after {previous}",
            noisy.theil_mean
        );
        previous = noisy.theil_mean;
    }
    assert!(previous > 0.1 && previous < 1.0, "{previous}");
    // A wrong model scores clearly worse than the right one on clean data.
    let mut wrong = model.clone();
    wrong.g.scale_mut(-1.0);
    let bad = verify_fitted(&wrong, &clean_record).unwrap();
    // (A pure sign flip would give 1; the fitted bias takes out the means.)
    assert!(bad.theil_mean > 0.7, "{}", bad.theil_mean);
}

#[test]
fn segments_restart_an_unstable_model_from_the_measured_state() {
    // The q lag made unstable (pole +0.6 /s): the data come from it, the model to
    // verify has the pole at +0.8 /s. Over the whole 30 s record the small error
    // grows without bound; restarted every 3 s from the measured state it cannot.
    let mut truth = two_axis_model();
    truth.f[(2, 2)] = 0.3; // M[q,q] = 0.5: pole +0.6
    let record = record_of(&truth, 0.0);
    let mut wrong = truth.clone();
    wrong.f[(2, 2)] = 0.4;
    let whole = verify_fitted(&wrong, &record).unwrap();
    let segmented =
        verify_record_in_segments(&wrong, &record, Some(3.0), BiasMode::Fitted).unwrap();
    let q_whole = whole
        .outputs
        .iter()
        .find(|o| o.output == "q")
        .unwrap()
        .theil;
    let q_segmented = segmented
        .outputs
        .iter()
        .find(|o| o.output == "q")
        .unwrap()
        .theil;
    assert!(q_whole > 0.2, "{q_whole}");
    assert!(q_segmented < 0.5 * q_whole, "{q_segmented} vs {q_whole}");
    // The right model restarted from measured states still predicts well (the
    // restarts use trim estimated from the first second, so not exactly).
    let right = verify_record_in_segments(&truth, &record, Some(3.0), BiasMode::Fitted).unwrap();
    assert!(right.theil_mean < 0.1, "{}", right.theil_mean);
    let error =
        verify_record_in_segments(&truth, &record, Some(0.001), BiasMode::Fitted).unwrap_err();
    assert!(error.to_string().contains("segment"), "{error}");
}

#[test]
fn mismatches_are_reported() {
    let model = two_axis_model();
    let mut record = record_of(&model, 0.0);
    record.inputs.retain(|c| c.name != "lon");
    let error = verify_fitted(&model, &record).unwrap_err();
    assert!(matches!(error, VerifyError::MissingInput { ref control, .. } if control == "lon"));
    assert!(error.to_string().contains("`lon`"), "{error}");

    let mut record = record_of(&model, 0.0);
    for channel in &mut record.outputs {
        channel.name = format!("other_{}", channel.name);
    }
    let error = verify_fitted(&model, &record).unwrap_err();
    assert!(
        matches!(error, VerifyError::NoCommonOutput { .. }),
        "{error}"
    );

    let mut singular = model.clone();
    singular.m[(2, 2)] = 0.0;
    let error = verify_fitted(&singular, &record_of(&model, 0.0)).unwrap_err();
    assert!(error.to_string().contains("singular"), "{error}");

    let mut short = record_of(&model, 0.0);
    for channel in short.inputs.iter_mut().chain(short.outputs.iter_mut()) {
        channel.values.truncate(1);
    }
    let error = verify_fitted(&model, &short).unwrap_err();
    assert!(matches!(error, VerifyError::BadRecord { .. }), "{error}");

    // A model that runs away is a result (TIC 1 everywhere), not an error.
    let mut unstable = model.clone();
    unstable.f[(2, 2)] = 50.0;
    let result = verify_fitted(&unstable, &record_of(&model, 0.0)).unwrap();
    let at = result.diverged_at_s.expect("diverged");
    assert!(at > 0.0 && at < 30.0, "{at}");
    assert!(result.outputs.iter().all(|o| o.theil == 1.0));
    assert!(result.measured.is_empty());

    // So is one so fast that e^{A·h} overflows in the first sample step.
    let mut explosive = model.clone();
    explosive.f[(2, 2)] = 1.0e6;
    let result = verify_fitted(&explosive, &record_of(&model, 0.0)).unwrap();
    assert_eq!(result.diverged_at_s, Some(0.0));
    assert!(result.outputs.iter().all(|o| o.theil == 1.0));

    // An output missing from the record is listed, not an error.
    let mut partial = record_of(&model, 0.0);
    partial.outputs.retain(|c| c.name != "ay");
    let result = verify_fitted(&model, &partial).unwrap();
    assert_eq!(result.not_measured, vec!["ay".to_string()]);
    assert_eq!(result.outputs.len(), 3);

    // So is one the record holds as zeros throughout (a board without the sensor): it
    // is neither scored nor in the mean.
    let mut zeroed = record_of(&model, 0.0);
    let full = verify_fitted(&model, &zeroed).unwrap();
    let kept: Vec<f64> = full
        .outputs
        .iter()
        .filter(|o| o.output != "ay")
        .map(|o| o.theil)
        .collect();
    for channel in zeroed.outputs.iter_mut().filter(|c| c.name == "ay") {
        channel.values.iter_mut().for_each(|v| *v = 0.0);
    }
    let result = verify_fitted(&model, &zeroed).unwrap();
    assert_eq!(result.not_measured, vec!["ay".to_string()]);
    let scored: Vec<f64> = result.outputs.iter().map(|o| o.theil).collect();
    assert_eq!(scored, kept);
    let mean = kept.iter().sum::<f64>() / kept.len() as f64;
    assert!(
        (result.theil_mean - mean).abs() < 1e-12,
        "{}",
        result.theil_mean
    );
}

/// Trim samples at 100 Hz in front of the excitation of [`record_with_trim`].
const TRIM: usize = 150;

/// `model` flown from trim: `TRIM` samples with the sticks at `stick_trim` (plus
/// `stick_trim_wobble`, one value per trim sample and control, which the caller keeps at
/// zero mean), then 28.5 s of excitation; each output is the model's response to the
/// sticks minus their trim mean, plus the offset 0.7·i − 1 (its trim value). Returns
/// the record and the perturbation inputs the outputs were simulated with.
fn record_with_trim(
    model: &Model,
    stick_trim_wobble: &dyn Fn(usize, usize) -> f64,
) -> (Record, Vec<Vec<f64>>) {
    let rate = 100.0;
    let n = 3000;
    let stick_trim = [0.1, -0.2];
    let perturbations: Vec<Vec<f64>> = (0..2)
        .map(|j| {
            (0..n)
                .map(|k| {
                    if k < TRIM {
                        return stick_trim_wobble(k, j);
                    }
                    // Starts at 0 when the excitation starts.
                    let t = (k - TRIM) as f64 / rate;
                    0.05 * (t * (0.5 + 0.1 * t) + j as f64).sin() - 0.05 * (j as f64).sin()
                        + 0.02 * (7.0 * t).sin()
                })
                .collect()
        })
        .collect();
    let clean = simulate(model, &perturbations, rate).unwrap();
    let outputs = model
        .outputs
        .iter()
        .zip(&clean)
        .enumerate()
        .map(|(i, (name, series))| {
            let offset = 0.7 * i as f64 - 1.0;
            Channel::new(name.clone(), series.iter().map(|v| v + offset).collect())
        })
        .collect();
    let record = Record {
        source: "trimmed".into(),
        sample_rate_hz: rate,
        primary: "lat".into(),
        primary_guessed: false,
        sweep_band: None,
        inputs: perturbations
            .iter()
            .zip(["lat", "lon"])
            .zip(stick_trim)
            .map(|((series, name), t)| Channel::new(name, series.iter().map(|v| v + t).collect()))
            .collect(),
        outputs,
        references: Vec::new(),
        notes: Vec::new(),
        trim_samples: TRIM,
        measurement_filter: None,
    };
    (record, perturbations)
}

#[test]
fn the_trim_bias_is_the_mean_before_the_excitation() {
    let model = two_axis_model();
    let (record, _) = record_with_trim(&model, &|_, _| 0.0);
    let exact = verify_record(&model, &record).unwrap();
    assert_eq!(exact.bias, BiasMode::Trim);
    assert_eq!(exact.trim_samples, TRIM);
    assert_eq!(exact.outputs.len(), 4);
    for score in &exact.outputs {
        let offset = 0.7 * model.output_index(&score.output).unwrap() as f64 - 1.0;
        assert!((score.bias - offset).abs() < 1e-12, "{score:?}");
        assert!(score.theil < 1e-9, "{}: {}", score.output, score.theil);
    }
    // The fitted bias finds the same offsets on exact data.
    let fitted = verify_fitted(&model, &record).unwrap();
    assert_eq!(fitted.bias, BiasMode::Fitted);
    assert_eq!(fitted.trim_samples, 0);
    assert!(fitted.theil_mean < 1e-9, "{}", fitted.theil_mean);

    // An error the model makes as a constant during the excitation (here: the
    // measured q settles 0.02 rad/s higher than predicted once the excitation starts).
    // The trim bias counts it; the fitted bias takes most of it out.
    let mut offset_q = record.clone();
    let q = offset_q.outputs.iter_mut().find(|c| c.name == "q").unwrap();
    for value in &mut q.values[TRIM..] {
        *value += 0.02;
    }
    let tic_q = |v: &Verification| v.outputs.iter().find(|o| o.output == "q").unwrap().theil;
    let trim = verify_record(&model, &offset_q).unwrap();
    let fitted = verify_fitted(&model, &offset_q).unwrap();
    assert!(tic_q(&trim) > 0.05, "{}", tic_q(&trim));
    assert!(
        tic_q(&fitted) < 0.5 * tic_q(&trim),
        "{} vs {}",
        tic_q(&fitted),
        tic_q(&trim)
    );
    // The other outputs are untouched either way.
    for v in [&trim, &fitted] {
        for o in v.outputs.iter().filter(|o| o.output != "q") {
            assert!(o.theil < 1e-9, "{o:?}");
        }
    }
}

#[test]
fn inputs_are_taken_from_the_same_trim_as_the_outputs() {
    // The sticks wobble during the trim capture (zero mean): the first sample is
    // 0.01 off the trim. The outputs were simulated on the sticks minus their trim
    // mean, so that is what the model must be driven with.
    let wobble = |k: usize, _: usize| {
        if k == 0 {
            0.01
        } else {
            -0.01 / (TRIM - 1) as f64
        }
    };
    let model = two_axis_model();
    let (record, perturbations) = record_with_trim(&model, &wobble);
    let verification = verify_record(&model, &record).unwrap();
    let expected = simulate(&model, &perturbations, record.sample_rate_hz).unwrap();
    for (score, predicted) in verification.outputs.iter().zip(&verification.predicted) {
        let index = model.output_index(&score.output).unwrap();
        for (a, b) in predicted.iter().zip(&expected[index]) {
            assert!((a - b).abs() < 1e-12, "{}: {a} vs {b}", score.output);
        }
        // The bias is the measured trim mean: the offset plus the (small) response
        // to the wobble over the trim samples; what is left is that constant.
        let offset = 0.7 * index as f64 - 1.0;
        let response = expected[index][..TRIM].iter().sum::<f64>() / TRIM as f64;
        assert!(
            (score.bias - offset - response).abs() < 1e-12,
            "{}: {} vs {}",
            score.output,
            score.bias,
            offset + response
        );
    }
    // Driven from the first sample instead, the model sees a 0.01 step held over the
    // whole record, and misses: the fitted bias (which takes its inputs from there)
    // scores worse although it fits the constant.
    let fitted = verify_fitted(&model, &record).unwrap();
    assert!(
        fitted.theil_mean > 10.0 * verification.theil_mean,
        "{} vs {}",
        fitted.theil_mean,
        verification.theil_mean
    );
}

#[test]
fn the_trim_bias_needs_trim_samples() {
    let model = two_axis_model();
    let record = record_of(&model, 0.0);
    let error = verify_record(&model, &record).unwrap_err();
    assert_eq!(
        error,
        VerifyError::NoTrim {
            record: "synthetic".into()
        }
    );
    assert!(
        error.to_string().starts_with("synthetic: no trim samples"),
        "{error}"
    );
    let mut overlong = record;
    overlong.trim_samples = overlong.len() + 1;
    let error = verify_record(&model, &overlong).unwrap_err();
    assert!(matches!(error, VerifyError::BadRecord { .. }), "{error}");
}
