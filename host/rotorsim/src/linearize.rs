//! Linearization about a trim by central differences, and the quasi-static (flapping
//! residualized) 6-DOF derivatives.
//!
//! State order `x = [u v w p q r phi theta psi beta1c beta1s]` (plus `lambda0`, the main-
//! rotor induced inflow, with dynamic inflow), controls `u = [lat lon ped col]` in stick
//! fractions, outputs `y = [u v w p q r ax ay az phi theta]` with (ax, ay, az) the specific
//! force a CG-mounted accelerometer reads (aerodynamic force / mass, ≈ (0, 0, −g) in
//! hover). The model is `ẋ = A x + B u`, `y = C x + D u` in perturbations from trim. The
//! actuator dynamics and the transport delay of [`crate::Sim`] are NOT part of A, B: these
//! are the blade-pitch-to-response dynamics of the airframe, with the stick gearing folded
//! into B.
//!
//! Quasi-static reduction: with f the flapping (and inflow) states and s the others,
//! `x_f = −A_ff⁻¹(A_fs x_s + B_f u)`; the aerodynamic loads F(x, u) then give the 6-DOF
//! derivatives `∂F/∂x_s − ∂F/∂x_f · A_ff⁻¹ A_fs` and likewise for controls. Forces are
//! divided by the mass, M by Iyy, and L, N by the inertia matrix including Ixz (the
//! "primed" derivatives L' = (Izz L + Ixz N)/(Ixx Izz − Ixz²), N' = (Ixz L + Ixx N)/(…)),
//! which is Padfield's normalisation: his Bo-105 Np = −2.43 and Lθ0tr = 6.20 are only
//! reproduced that way. The uncoupled L/Ixx, N/Izz are available as `Lp_raw`, `Nr_raw`, ….

use std::collections::BTreeMap;

use nalgebra::DMatrix;

use crate::model::{self, Model, ModelFlags, STATE_LEN};
use crate::trim::{Trim, CONTROL_NAMES};
use crate::vehicle::Helicopter;

/// State names in linearization order (without the optional inflow state).
pub const STATE_NAMES: [&str; 11] = [
    "u", "v", "w", "p", "q", "r", "phi", "theta", "psi", "beta1c", "beta1s",
];
/// Output names in order.
pub const OUTPUT_NAMES: [&str; 11] = [
    "u", "v", "w", "p", "q", "r", "ax", "ay", "az", "phi", "theta",
];
const STATE_INDEX: [usize; 11] = [
    model::U,
    model::V,
    model::W,
    model::P,
    model::Q,
    model::R,
    model::PHI,
    model::THETA,
    model::PSI,
    model::BETA1C,
    model::BETA1S,
];
/// Blade-pitch names matching the stick channels [lat, lon, ped, col].
pub const PITCH_NAMES: [&str; 4] = ["theta1c", "theta1s", "theta0tr", "theta0"];
const AXIS_NAMES: [&str; 6] = ["X", "Y", "Z", "L", "M", "N"];

/// A linear model about a trim.
#[derive(Clone, Debug, PartialEq)]
pub struct Linearization {
    /// Trim speed \[kt\].
    pub speed_kt: f64,
    /// State names in order.
    pub states: Vec<&'static str>,
    /// Control names in order (stick fractions).
    pub controls: Vec<&'static str>,
    /// Output names in order.
    pub outputs: Vec<&'static str>,
    /// State matrix, row-major.
    pub a: Vec<Vec<f64>>,
    /// Control matrix (per stick fraction), row-major.
    pub b: Vec<Vec<f64>>,
    /// Output matrix, row-major.
    pub c: Vec<Vec<f64>>,
    /// Feed-through matrix, row-major.
    pub d: Vec<Vec<f64>>,
    /// Flap time constant \[s\] from the flapping block: −1/Re(λ) of A_ff.
    pub tau_f_s: f64,
    /// Eigenvalues of A as (re, im), sorted by real part.
    pub eigenvalues: Vec<(f64, f64)>,
    /// Eigenvalues of the quasi-static (flapping residualized) state matrix.
    pub quasi_static_eigenvalues: Vec<(f64, f64)>,
    /// Named quasi-static derivatives (`Xu`, `Lp`, `Mlon`, `Ztheta0`, …; L and N primed,
    /// plus `L…_raw`, `N…_raw` divided by Ixx, Izz alone).
    pub quasi_static: BTreeMap<String, f64>,
}

/// One evaluation: selected state derivative, outputs and loads (force, moment).
fn evaluate(
    model: &Model,
    x: &[f64; STATE_LEN],
    controls: [f64; 4],
    flags: ModelFlags,
    index: &[usize],
) -> (Vec<f64>, Vec<f64>, [f64; 6]) {
    let mut warm = [0.0, 0.0];
    let pitch = model.heli.blade_pitch(controls);
    let (dx, loads) = model.derivative(x, &pitch, [0.0; 3], flags, &mut warm);
    let m = model.heli.mass;
    let selected = index.iter().map(|&i| dx[i]).collect();
    let outputs = vec![
        x[model::U],
        x[model::V],
        x[model::W],
        x[model::P],
        x[model::Q],
        x[model::R],
        loads.force[0] / m,
        loads.force[1] / m,
        loads.force[2] / m,
        x[model::PHI],
        x[model::THETA],
    ];
    let f = loads.force;
    let mo = loads.moment;
    (selected, outputs, [f[0], f[1], f[2], mo[0], mo[1], mo[2]])
}

fn eigenvalues_of(matrix: &DMatrix<f64>) -> Vec<(f64, f64)> {
    let mut values: Vec<(f64, f64)> = matrix
        .complex_eigenvalues()
        .iter()
        .map(|z| (z.re, z.im))
        .collect();
    values.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.total_cmp(&b.1)));
    values
}

fn to_rows(matrix: &DMatrix<f64>) -> Vec<Vec<f64>> {
    (0..matrix.nrows())
        .map(|i| matrix.row(i).iter().copied().collect())
        .collect()
}

/// Linearize about `trim` with the iterated (quasi-static) inflow.
pub fn linearize(heli: &Helicopter, trim: &Trim) -> Linearization {
    linearize_with(heli, trim, false)
}

/// Linearize about `trim`; with `dynamic_inflow` the main-rotor inflow λ0 is a state (last).
pub fn linearize_with(heli: &Helicopter, trim: &Trim, dynamic_inflow: bool) -> Linearization {
    let model = Model::new(heli.clone());
    let flags = ModelFlags {
        dynamic_inflow,
        ..ModelFlags::default()
    };
    let mut index: Vec<usize> = STATE_INDEX.to_vec();
    let mut states: Vec<&'static str> = STATE_NAMES.to_vec();
    if dynamic_inflow {
        index.push(model::LAMBDA);
        states.push("lambda0");
    }
    let n = index.len();
    let x0 = trim.state.0;
    let u0 = trim.controls;
    let h = 1e-5;

    let mut a = DMatrix::zeros(n, n);
    let mut c = DMatrix::zeros(OUTPUT_NAMES.len(), n);
    let mut loads_x = DMatrix::zeros(6, n);
    for (j, &state) in index.iter().enumerate() {
        let mut plus = x0;
        plus[state] += h;
        let mut minus = x0;
        minus[state] -= h;
        let (dp, yp, lp) = evaluate(&model, &plus, u0, flags, &index);
        let (dm, ym, lm) = evaluate(&model, &minus, u0, flags, &index);
        for i in 0..n {
            a[(i, j)] = (dp[i] - dm[i]) / (2.0 * h);
        }
        for i in 0..OUTPUT_NAMES.len() {
            c[(i, j)] = (yp[i] - ym[i]) / (2.0 * h);
        }
        for i in 0..6 {
            loads_x[(i, j)] = (lp[i] - lm[i]) / (2.0 * h);
        }
    }
    let mut b = DMatrix::zeros(n, 4);
    let mut d = DMatrix::zeros(OUTPUT_NAMES.len(), 4);
    let mut loads_u = DMatrix::zeros(6, 4);
    for j in 0..4 {
        let mut plus = u0;
        plus[j] += h;
        let mut minus = u0;
        minus[j] -= h;
        let (dp, yp, lp) = evaluate(&model, &x0, plus, flags, &index);
        let (dm, ym, lm) = evaluate(&model, &x0, minus, flags, &index);
        for i in 0..n {
            b[(i, j)] = (dp[i] - dm[i]) / (2.0 * h);
        }
        for i in 0..OUTPUT_NAMES.len() {
            d[(i, j)] = (yp[i] - ym[i]) / (2.0 * h);
        }
        for i in 0..6 {
            loads_u[(i, j)] = (lp[i] - lm[i]) / (2.0 * h);
        }
    }

    // Flapping block and τ_f = −1/Re(λ) of its slowest eigenvalue.
    let flap = [9usize, 10];
    let a_flap = DMatrix::from_fn(2, 2, |i, j| a[(flap[i], flap[j])]);
    let tau_f_s = eigenvalues_of(&a_flap)
        .iter()
        .map(|&(re, _)| -1.0 / re)
        .fold(0.0_f64, f64::max);

    // Quasi-static reduction: fast = flapping (+ inflow), slow = the rest.
    let fast: Vec<usize> = (9..n).collect();
    let slow: Vec<usize> = (0..9).collect();
    let pick = |m: &DMatrix<f64>, rows: &[usize], cols: &[usize]| {
        DMatrix::from_fn(rows.len(), cols.len(), |i, j| m[(rows[i], cols[j])])
    };
    let all_controls = [0usize, 1, 2, 3];
    let a_ff = pick(&a, &fast, &fast);
    let a_ff_inv = a_ff
        .clone()
        .try_inverse()
        .unwrap_or_else(|| DMatrix::zeros(fast.len(), fast.len()));
    let a_fs = pick(&a, &fast, &slow);
    let b_f = pick(&b, &fast, &all_controls);
    let six: Vec<usize> = (0..6).collect();
    let l_f = pick(&loads_x, &six, &fast);
    let loads_slow = pick(&loads_x, &six, &slow) - &l_f * &a_ff_inv * &a_fs;
    let loads_ctrl = &loads_u - &l_f * &a_ff_inv * &b_f;
    let a_qs = pick(&a, &slow, &slow) - pick(&a, &slow, &fast) * &a_ff_inv * &a_fs;

    // Normalisation like Padfield's Helisim tables: forces / mass, M / Iyy, and the roll
    // and yaw moments through the inverse of the xz inertia block (the "primed"
    // derivatives, which are what enters ṗ and ṙ):
    //   L' = (Izz L + Ixz N)/(Ixx Izz − Ixz²),  N' = (Ixz L + Ixx N)/(Ixx Izz − Ixz²).
    // The uncoupled L/Ixx and N/Izz are kept too, as `L…_raw` and `N…_raw`.
    let det = heli.ixx * heli.izz - heli.ixz * heli.ixz;
    let normalise = |column: &[f64; 6]| -> ([f64; 6], [f64; 2]) {
        let [x, y, z, l, m, n] = *column;
        let primed = [
            x / heli.mass,
            y / heli.mass,
            z / heli.mass,
            (heli.izz * l + heli.ixz * n) / det,
            m / heli.iyy,
            (heli.ixz * l + heli.ixx * n) / det,
        ];
        (primed, [l / heli.ixx, n / heli.izz])
    };
    let mut quasi_static = BTreeMap::new();
    let mut insert = |suffix: &str, column: [f64; 6]| {
        let (primed, raw) = normalise(&column);
        for (axis, name) in AXIS_NAMES.iter().enumerate() {
            quasi_static.insert(format!("{name}{suffix}"), primed[axis]);
        }
        quasi_static.insert(format!("L{suffix}_raw"), raw[0]);
        quasi_static.insert(format!("N{suffix}_raw"), raw[1]);
    };
    for (j, state) in STATE_NAMES[..6].iter().enumerate() {
        insert(state, std::array::from_fn(|axis| loads_slow[(axis, j)]));
    }
    for j in 0..4 {
        let per_stick: [f64; 6] = std::array::from_fn(|axis| loads_ctrl[(axis, j)]);
        insert(CONTROL_NAMES[j], per_stick);
        insert(PITCH_NAMES[j], per_stick.map(|v| v / heli.gearing[j].gain));
    }

    Linearization {
        speed_kt: trim.speed_kt,
        states,
        controls: CONTROL_NAMES.to_vec(),
        outputs: OUTPUT_NAMES.to_vec(),
        eigenvalues: eigenvalues_of(&a),
        quasi_static_eigenvalues: eigenvalues_of(&a_qs),
        a: to_rows(&a),
        b: to_rows(&b),
        c: to_rows(&c),
        d: to_rows(&d),
        tau_f_s,
        quasi_static,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::trim::trim;

    /// Padfield's Helisim Bo-105 hover derivatives.
    const PADFIELD: [(&str, f64); 10] = [
        ("Xu", -0.0211),
        ("Yv", -0.0405),
        ("Zw", -0.322),
        ("Lp", -14.1949),
        ("Mq", -3.7472),
        ("Nr", -0.3185),
        ("Ztheta0", -92.96),
        ("Mtheta1s", 45.00),
        ("Ltheta1c", -170.08),
        ("Ntheta0tr", -15.46),
    ];

    #[test]
    fn bo105_hover_quasi_static_derivatives_within_35_percent_of_helisim() {
        let heli = Helicopter::bo105();
        let lin = linearize(&heli, &trim(&heli, 0.0).unwrap());
        for (name, padfield) in PADFIELD {
            let ours = lin.quasi_static[name];
            assert!(
                ours.signum() == padfield.signum(),
                "{name}: {ours} vs {padfield}"
            );
            let ratio = ours / padfield;
            assert!(
                (0.65..=1.35).contains(&ratio),
                "{name}: {ours} vs {padfield} ({ratio:.2})"
            );
        }
    }

    #[test]
    fn bo105_tau_f_from_blade_data_and_matrix_shapes() {
        let heli = Helicopter::bo105();
        let lin = linearize(&heli, &trim(&heli, 0.0).unwrap());
        assert!((0.06..0.08).contains(&lin.tau_f_s), "tau_f {}", lin.tau_f_s);
        assert_eq!(lin.a.len(), 11);
        assert!(lin.a.iter().all(|row| row.len() == 11));
        assert_eq!(lin.b.len(), 11);
        assert_eq!(lin.c.len(), 11);
        assert!(lin.d.iter().all(|row| row.len() == 4));
        // The eigenvalues sum to the trace (a check on the eigen solver).
        let trace: f64 = (0..11).map(|i| lin.a[i][i]).sum();
        let sum: f64 = lin.eigenvalues.iter().map(|e| e.0).sum();
        assert!(
            (trace - sum).abs() < 1e-8 * trace.abs().max(1.0),
            "{trace} vs {sum}"
        );
        let imag: f64 = lin.eigenvalues.iter().map(|e| e.1).sum();
        assert!(imag.abs() < 1e-9);
    }

    #[test]
    fn dynamic_inflow_adds_a_stable_inflow_state() {
        let heli = Helicopter::bo105();
        let lin = linearize_with(&heli, &trim(&heli, 0.0).unwrap(), true);
        assert_eq!(lin.states.last(), Some(&"lambda0"));
        assert!(lin.a[11][11] < 0.0);
    }
}
