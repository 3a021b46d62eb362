//! The curves the report computes from the documents and records it is handed: phase
//! unwrapping, a model's frequency response on the data's frequencies, and the applied
//! amplitude of a sweep.

use sysid::document::PairResponse;
use sysid::fit::Model;

/// Unwrap a phase series \[deg\] so that consecutive points differ by less than 180°.
pub fn unwrap_deg(phase: &[f64]) -> Vec<f64> {
    let mut out = Vec::with_capacity(phase.len());
    let mut offset = 0.0;
    let mut previous: Option<f64> = None;
    for &p in phase {
        if let Some(prev) = previous {
            if p.is_finite() && prev.is_finite() {
                let jump = p + offset - out.last().copied().unwrap_or(prev);
                offset -= 360.0 * (jump / 360.0).round();
            }
        }
        out.push(p + offset);
        if p.is_finite() {
            previous = Some(p);
        }
    }
    out
}

/// A model's response on the data's frequencies: magnitude \[dB\] and phase \[deg\], the
/// phase unwrapped and shifted by whole turns onto the data at the fit range's start.
pub fn model_response(
    model: &Model,
    pair: &PairResponse,
    anchor: Option<f64>,
) -> Option<(Vec<f64>, Vec<f64>)> {
    let input = model.control_index(&pair.input)?;
    let output = model.output_index(&pair.output)?;
    let responses: Vec<_> = pair
        .omega
        .iter()
        .map(|&w| model.frequency_response(input, output, w))
        .collect();
    let magnitude: Vec<f64> = responses.iter().map(|t| 20.0 * t.norm().log10()).collect();
    let mut phase = unwrap_deg(
        &responses
            .iter()
            .map(|t| t.arg().to_degrees())
            .collect::<Vec<_>>(),
    );
    // Turns are arbitrary: align with the data where the fit starts.
    let at = anchor.unwrap_or(pair.omega[0]);
    let k = pair.omega.iter().position(|&w| w >= at).unwrap_or(0);
    if let (Some(data), Some(model)) = (pair.phase_deg.get(k), phase.get(k)) {
        if data.is_finite() && model.is_finite() {
            let shift = 360.0 * ((data - model) / 360.0).round();
            phase.iter_mut().for_each(|p| *p += shift);
        }
    }
    Some((magnitude, phase))
}

/// The peak |x| of each half cycle of `values` (the stretches between sign changes),
/// repeated over that half cycle: the amplitude of a sweep whose amplitude changes only at
/// its zero crossings.
pub fn half_cycle_envelope(values: &[f64]) -> Vec<f64> {
    let mut envelope = vec![0.0; values.len()];
    let mut start = 0;
    for k in 1..=values.len() {
        let crossed = k == values.len() || (values[k] > 0.0) != (values[k - 1] > 0.0);
        if crossed {
            let peak = values[start..k].iter().fold(0.0f64, |m, v| m.max(v.abs()));
            envelope[start..k].iter_mut().for_each(|e| *e = peak);
            start = k;
        }
    }
    envelope
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn unwrap_removes_turns() {
        let wrapped = [170.0, -175.0, -160.0, 175.0];
        let unwrapped = unwrap_deg(&wrapped);
        assert_eq!(unwrapped, vec![170.0, 185.0, 200.0, 175.0]);
    }

    #[test]
    fn model_phase_is_put_on_the_data_branch_at_the_fit_range() {
        // p/lat = 3/(s + 2): phase from −2.9° to −84° over 0.1–20 rad/s.
        let mut model = Model::zeros(vec!["p".into()], vec!["lat".into()], vec!["p".into()]);
        model.m[(0, 0)] = 1.0;
        model.f[(0, 0)] = -2.0;
        model.g[(0, 0)] = 3.0;
        model.h0[(0, 0)] = 1.0;
        let omega: Vec<f64> = (0..30).map(|k| 0.1 * 1.2f64.powi(k)).collect();
        let exact: Vec<f64> = omega
            .iter()
            .map(|w| -(w / 2.0).atan().to_degrees())
            .collect();
        let pair = PairResponse {
            input: "lat".into(),
            output: "p".into(),
            omega: omega.clone(),
            mag_db: vec![0.0; omega.len()],
            // The data sit one turn down, as an unwrapped estimate may.
            phase_deg: exact.iter().map(|p| p - 360.0).collect(),
            coherence: vec![1.0; omega.len()],
            random_error: vec![0.0; omega.len()],
            valid_range: None,
            group: None,
            multiple_coherence: Vec::new(),
        };
        let (magnitude, phase) = model_response(&model, &pair, Some(0.5)).unwrap();
        let gain_db = 20.0 * (3.0 / (omega[0].powi(2) + 4.0).sqrt()).log10();
        assert!((magnitude[0] - gain_db).abs() < 1e-9);
        for (p, e) in phase.iter().zip(&exact) {
            assert!((p - (e - 360.0)).abs() < 1e-9, "{p} vs {e}");
        }
        let other = PairResponse {
            input: "lon".into(),
            ..pair
        };
        assert!(model_response(&model, &other, None).is_none());
    }

    #[test]
    fn the_half_cycle_envelope_is_each_half_cycles_peak() {
        // Two half cycles of amplitude 1, then two of amplitude 3 (a step at a zero
        // crossing, as the adaptive sweep makes it).
        let values: Vec<f64> = (0..40)
            .map(|k| {
                let amplitude = if k < 20 { 1.0 } else { 3.0 };
                amplitude * (std::f64::consts::PI * (k as f64 + 0.5) / 10.0).sin()
            })
            .collect();
        let envelope = half_cycle_envelope(&values);
        let peak_1 = (std::f64::consts::PI * 4.5 / 10.0).sin();
        assert!((envelope[0] - peak_1).abs() < 1e-12 && (envelope[19] - peak_1).abs() < 1e-12);
        assert!((envelope[20] - 3.0 * peak_1).abs() < 1e-12);
        assert!((envelope[39] - 3.0 * peak_1).abs() < 1e-12);
        assert!(half_cycle_envelope(&[]).is_empty());
    }
}
