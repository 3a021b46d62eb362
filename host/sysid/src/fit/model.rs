//! The numeric state-space model `M ẋ = F x + G u_a(t − τ)`, `y = H0 x + H1 ẋ`, where
//! `u_a` is each control after its known actuator `A_j(s)` (identity when it has none),
//! and its transfer function
//!
//! ```text
//! T(s) = (H0 + s·H1) (s·M − F)⁻¹ G · diag(A_j(s) e^{−τ_j s}),   s = jω
//! A_j(s) = ω_j² / (s² + 2 ζ_j ω_j s + ω_j²)      (a second-order servo, ω_j ζ_j known)
//! ```
//!
//! evaluated by an LU solve of the small complex matrix `sM − F` per frequency (never an
//! explicit inverse). The actuator is a factor per control, not extra states, so that it
//! costs the fit nothing; [`Model::with_actuator_states`] writes it as states for the
//! time-domain simulation.

use nalgebra::{DMatrix, DVector};
use num_complex::Complex64;
use serde::{Deserialize, Serialize};

/// A linear model with named states, controls and outputs.
#[derive(Clone, Debug, PartialEq)]
pub struct Model {
    /// State names.
    pub states: Vec<String>,
    /// Control names.
    pub controls: Vec<String>,
    /// Output names.
    pub outputs: Vec<String>,
    /// Mass matrix, states × states.
    pub m: DMatrix<f64>,
    /// Dynamics matrix, states × states.
    pub f: DMatrix<f64>,
    /// Control matrix, states × controls.
    pub g: DMatrix<f64>,
    /// Output matrix on states, outputs × states.
    pub h0: DMatrix<f64>,
    /// Output matrix on state derivatives, outputs × states.
    pub h1: DMatrix<f64>,
    /// Delay per control \[s\].
    pub delays: Vec<f64>,
    /// Known actuator per control (`None`: the control acts directly).
    pub actuators: Vec<Option<Actuator>>,
}

/// A known second-order actuator (a servo): `A(s) = ω² / (s² + 2ζω s + ω²)`, unit gain at
/// steady state. Known from the servo's data, not identified: written into the structure
/// file (`[actuators]`) so that the fitted delays and rotor terms need not absorb it.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Actuator {
    /// Natural frequency ω \[rad/s\], > 0.
    pub natural_frequency_rad_s: f64,
    /// Damping ratio ζ, > 0.
    pub damping: f64,
}

impl Actuator {
    /// Whether ω and ζ are finite and positive.
    pub fn is_valid(&self) -> bool {
        self.natural_frequency_rad_s.is_finite()
            && self.natural_frequency_rad_s > 0.0
            && self.damping.is_finite()
            && self.damping > 0.0
    }

    /// A(s).
    pub fn response(&self, s: Complex64) -> Complex64 {
        let w = self.natural_frequency_rad_s;
        let w2 = Complex64::new(w * w, 0.0);
        w2 / (s * s + s * (2.0 * self.damping * w) + w2)
    }
}

/// What one LU solve at one frequency gives for one input/output pair: enough for the
/// response and its derivatives with respect to every matrix entry.
#[derive(Clone, Debug)]
pub(crate) struct PairSolution {
    /// s = jω.
    pub s: Complex64,
    /// x = (sM − F)⁻¹ g_j, the state response to input j.
    pub x: DVector<Complex64>,
    /// w = (sM − F)⁻ᵀ c_i with c_i = row i of (H0 + sH1): T = wᵀ g_j = c_iᵀ x.
    pub w: DVector<Complex64>,
    /// T including the input factor A_j(s)·e^{−τ_j s}.
    pub response: Complex64,
    /// A_j(s)·e^{−τ_j s}: the actuator and the delay of input j (fixed in the fit, so
    /// every matrix entry's derivative carries it as a factor).
    pub delay_factor: Complex64,
}

/// Row-major matrix for JSON: `rows × cols` numbers, row after row.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct RowMajor {
    /// Number of rows.
    pub rows: usize,
    /// Number of columns.
    pub cols: usize,
    /// Values, row after row.
    pub data: Vec<f64>,
}

impl RowMajor {
    /// Copy a nalgebra matrix (column-major inside) out row by row.
    pub fn from_matrix(matrix: &DMatrix<f64>) -> Self {
        let mut data = Vec::with_capacity(matrix.len());
        for row in 0..matrix.nrows() {
            for col in 0..matrix.ncols() {
                data.push(matrix[(row, col)]);
            }
        }
        Self {
            rows: matrix.nrows(),
            cols: matrix.ncols(),
            data,
        }
    }

    /// Back to a nalgebra matrix; `None` when `data` has the wrong length.
    pub fn to_matrix(&self) -> Option<DMatrix<f64>> {
        (self.data.len() == self.rows * self.cols)
            .then(|| DMatrix::from_row_slice(self.rows, self.cols, &self.data))
    }
}

impl Model {
    /// All-zero matrices of the right sizes and zero delays.
    pub fn zeros(states: Vec<String>, controls: Vec<String>, outputs: Vec<String>) -> Self {
        let (n, m, p) = (states.len(), controls.len(), outputs.len());
        Self {
            m: DMatrix::zeros(n, n),
            f: DMatrix::zeros(n, n),
            g: DMatrix::zeros(n, m),
            h0: DMatrix::zeros(p, n),
            h1: DMatrix::zeros(p, n),
            delays: vec![0.0; m],
            actuators: vec![None; m],
            states,
            controls,
            outputs,
        }
    }

    /// Index of a control by name.
    pub fn control_index(&self, name: &str) -> Option<usize> {
        self.controls.iter().position(|c| c == name)
    }

    /// Index of an output by name.
    pub fn output_index(&self, name: &str) -> Option<usize> {
        self.outputs.iter().position(|o| o == name)
    }

    /// The factor of control `input` at s: its actuator's response times its delay
    /// `A_j(s)·e^{−τ_j s}`.
    pub(crate) fn input_factor(&self, input: usize, s: Complex64) -> Complex64 {
        let delay = (-s * self.delays[input]).exp();
        match self.actuators.get(input).copied().flatten() {
            Some(actuator) => actuator.response(s) * delay,
            None => delay,
        }
    }

    /// The same model with every actuator written as two states (`<control>_actuator`
    /// and `<control>_actuator_rate`: `ẍ_a = ω²(u − x_a) − 2ζω ẋ_a`), the control's G
    /// column moved to the actuator position's F column, and no actuator left: the same
    /// transfer function, in the form a time-domain simulation steps. A model without
    /// actuators is returned as it is.
    pub fn with_actuator_states(&self) -> Model {
        let actuated: Vec<(usize, Actuator)> = self
            .actuators
            .iter()
            .enumerate()
            .filter_map(|(j, a)| a.map(|a| (j, a)))
            .collect();
        if actuated.is_empty() {
            return self.clone();
        }
        let n = self.states.len();
        let mut states = self.states.clone();
        for &(j, _) in &actuated {
            states.push(format!("{}_actuator", self.controls[j]));
            states.push(format!("{}_actuator_rate", self.controls[j]));
        }
        let mut model = Model::zeros(states, self.controls.clone(), self.outputs.clone());
        let size = model.states.len();
        for i in 0..size {
            model.m[(i, i)] = 1.0;
        }
        model.m.view_mut((0, 0), (n, n)).copy_from(&self.m);
        model.f.view_mut((0, 0), (n, n)).copy_from(&self.f);
        model
            .g
            .view_mut((0, 0), (n, self.controls.len()))
            .copy_from(&self.g);
        model
            .h0
            .view_mut((0, 0), (self.outputs.len(), n))
            .copy_from(&self.h0);
        model
            .h1
            .view_mut((0, 0), (self.outputs.len(), n))
            .copy_from(&self.h1);
        model.delays = self.delays.clone();
        for (k, &(j, actuator)) in actuated.iter().enumerate() {
            let (position, rate) = (n + 2 * k, n + 2 * k + 1);
            let w = actuator.natural_frequency_rad_s;
            for i in 0..n {
                model.f[(i, position)] = self.g[(i, j)];
                model.g[(i, j)] = 0.0;
            }
            model.f[(position, rate)] = 1.0;
            model.f[(rate, position)] = -w * w;
            model.f[(rate, rate)] = -2.0 * actuator.damping * w;
            model.g[(rate, j)] = w * w;
        }
        model
    }

    /// `sM − F` at s = jω.
    fn system_matrix(&self, s: Complex64) -> DMatrix<Complex64> {
        let n = self.states.len();
        DMatrix::from_fn(n, n, |i, j| {
            s * self.m[(i, j)] - Complex64::new(self.f[(i, j)], 0.0)
        })
    }

    /// Row `output` of (H0 + sH1).
    fn output_row(&self, output: usize, s: Complex64) -> DVector<Complex64> {
        DVector::from_fn(self.states.len(), |j, _| {
            Complex64::new(self.h0[(output, j)], 0.0) + s * self.h1[(output, j)]
        })
    }

    /// T_{output,input}(jω). Returns NaN when `sM − F` is singular at ω (a pole on the
    /// jω axis) or an index is out of range.
    pub fn frequency_response(
        &self,
        input_index: usize,
        output_index: usize,
        omega: f64,
    ) -> Complex64 {
        if input_index >= self.controls.len() || output_index >= self.outputs.len() {
            return Complex64::new(f64::NAN, f64::NAN);
        }
        let s = Complex64::new(0.0, omega);
        let lu = self.system_matrix(s).lu();
        let column = DVector::from_fn(self.states.len(), |i, _| {
            Complex64::new(self.g[(i, input_index)], 0.0)
        });
        match lu.solve(&column) {
            Some(x) => {
                let row = self.output_row(output_index, s);
                row.dot(&x) * self.input_factor(input_index, s)
            }
            None => Complex64::new(f64::NAN, f64::NAN),
        }
    }

    /// Everything the fit needs at one frequency for one pair: the response and the two
    /// solves x = A⁻¹g_j and w = A⁻ᵀc_i (A = sM − F). `None` when A is singular.
    pub(crate) fn pair_solution(
        &self,
        input_index: usize,
        output_index: usize,
        omega: f64,
    ) -> Option<PairSolution> {
        let s = Complex64::new(0.0, omega);
        let system = self.system_matrix(s);
        let column = DVector::from_fn(self.states.len(), |i, _| {
            Complex64::new(self.g[(i, input_index)], 0.0)
        });
        let row = self.output_row(output_index, s);
        let x = system.clone().lu().solve(&column)?;
        // Aᵀ w = c: the transposed (not conjugated) system, since T = cᵀ A⁻¹ g.
        let w = system.transpose().lu().solve(&row)?;
        let delay_factor = self.input_factor(input_index, s);
        let response = row.dot(&x) * delay_factor;
        Some(PairSolution {
            s,
            x,
            w,
            response,
            delay_factor,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::PI;

    fn names(list: &[&str]) -> Vec<String> {
        list.iter().map(|s| s.to_string()).collect()
    }

    #[test]
    fn first_order_lag_with_delay() {
        // ẋ = a x + b u(t − τ), y = x  →  T = b e^{−τs} / (s − a).
        let mut model = Model::zeros(names(&["x"]), names(&["u"]), names(&["x"]));
        model.m[(0, 0)] = 1.0;
        model.f[(0, 0)] = -2.0;
        model.g[(0, 0)] = 3.0;
        model.h0[(0, 0)] = 1.0;
        model.delays[0] = 0.05;
        for omega in [0.1, 1.0, 7.0, 30.0] {
            let s = Complex64::new(0.0, omega);
            let expected = 3.0 * (-s * 0.05).exp() / (s + 2.0);
            let got = model.frequency_response(0, 0, omega);
            assert!((got - expected).norm() < 1e-12 * expected.norm());
        }
    }

    #[test]
    fn a_known_actuator_multiplies_the_response_and_its_state_form_agrees() {
        // ẋ = a x + b u_a(t − τ), u_a = ω²/(s² + 2ζωs + ω²) u, y = [x, ẋ]:
        // T = b A(s) e^{−τs} / (s − a), and s times that for ẋ.
        let mut model = Model::zeros(names(&["x"]), names(&["u"]), names(&["x", "xdot"]));
        model.m[(0, 0)] = 1.0;
        model.f[(0, 0)] = -2.0;
        model.g[(0, 0)] = 3.0;
        model.h0[(0, 0)] = 1.0;
        model.h1[(1, 0)] = 1.0;
        model.delays[0] = 0.01;
        let servo = Actuator {
            natural_frequency_rad_s: 60.0,
            damping: 0.7,
        };
        model.actuators[0] = Some(servo);
        let states = model.with_actuator_states();
        assert_eq!(
            states.states,
            names(&["x", "u_actuator", "u_actuator_rate"])
        );
        assert!(states.actuators.iter().all(Option::is_none));
        for omega in [0.1, 1.0, 7.0, 30.0, 60.0, 200.0] {
            let s = Complex64::new(0.0, omega);
            let actuator = 3600.0 / (s * s + s * 84.0 + 3600.0);
            let expected = 3.0 * actuator * (-s * 0.01).exp() / (s + 2.0);
            for (output, scale) in [(0, Complex64::new(1.0, 0.0)), (1, s)] {
                let expected = expected * scale;
                for got in [
                    model.frequency_response(0, output, omega),
                    states.frequency_response(0, output, omega),
                    model.pair_solution(0, output, omega).unwrap().response,
                ] {
                    assert!((got - expected).norm() < 1e-12 * expected.norm(), "{omega}");
                }
            }
        }
        // At ω_n the servo is −90° and 1/(2ζ) in gain.
        let at = servo.response(Complex64::new(0.0, 60.0));
        assert!((at.norm() - 1.0 / 1.4).abs() < 1e-12 && (at.arg() + PI / 2.0).abs() < 1e-12);
        assert!(servo.is_valid());
        assert!(!Actuator {
            damping: 0.0,
            ..servo
        }
        .is_valid());
        assert!(!Actuator {
            natural_frequency_rad_s: f64::NAN,
            ..servo
        }
        .is_valid());
    }

    #[test]
    fn second_order_with_mass_matrix_and_derivative_output() {
        // States [x, v]: ẋ = v, 2 v̇ = −k x − c v + u;  y = v̇ (H1 row) → T = s² / (2s² + cs + k).
        let (k, c) = (8.0, 1.5);
        let mut model = Model::zeros(names(&["x", "v"]), names(&["u"]), names(&["a"]));
        model.m[(0, 0)] = 1.0;
        model.m[(1, 1)] = 2.0;
        model.f[(0, 1)] = 1.0;
        model.f[(1, 0)] = -k;
        model.f[(1, 1)] = -c;
        model.g[(1, 0)] = 1.0;
        model.h1[(0, 1)] = 1.0;
        for omega in [0.3, 2.0, 11.0] {
            let s = Complex64::new(0.0, omega);
            let expected = s * s / (2.0 * s * s + c * s + k);
            let got = model.frequency_response(0, 0, omega);
            assert!(
                (got - expected).norm() < 1e-12 * expected.norm(),
                "{got} {expected}"
            );
            let solution = model.pair_solution(0, 0, omega).unwrap();
            assert!((solution.response - expected).norm() < 1e-12 * expected.norm());
        }
    }

    #[test]
    fn singular_system_gives_nan() {
        // A pure integrator has its pole at s = 0: evaluating at ω = 0 is singular.
        let mut model = Model::zeros(names(&["x"]), names(&["u"]), names(&["x"]));
        model.m[(0, 0)] = 1.0;
        model.g[(0, 0)] = 1.0;
        model.h0[(0, 0)] = 1.0;
        assert!(model.frequency_response(0, 0, 0.0).re.is_nan());
        assert!(model.frequency_response(5, 0, 1.0).re.is_nan());
    }

    #[test]
    fn row_major_round_trip() {
        let matrix = DMatrix::from_row_slice(2, 3, &[1.0, 2.0, 3.0, 4.0, 5.0, 6.0]);
        let row_major = RowMajor::from_matrix(&matrix);
        assert_eq!(row_major.data, vec![1.0, 2.0, 3.0, 4.0, 5.0, 6.0]);
        assert_eq!(row_major.to_matrix().unwrap(), matrix);
    }
}
