//! The classical fourth-order Runge–Kutta step at a fixed step size, shared by the
//! nonlinear simulation ([`crate::sim`]) and the linearized plant it can fly instead.

use crate::model::{Loads, Model, ModelFlags, STATE_LEN};
use crate::vehicle::BladePitch;

/// One classical RK4 step of size h with fixed blade pitch and wind; returns k1's loads.
#[inline]
pub(crate) fn rk4_step(
    model: &Model,
    x: &mut [f64; STATE_LEN],
    pitch: &BladePitch,
    wind: [f64; 3],
    flags: ModelFlags,
    warm: &mut [f64; 2],
    h: f64,
) -> Loads {
    let (k1, loads) = model.derivative(x, pitch, wind, flags, warm);
    rk4_from(x, h, k1, |stage| {
        model.derivative(stage, pitch, wind, flags, warm).0
    });
    loads
}

/// One classical RK4 step of ẋ = f(x) from `x`, given k1 = f(x) (the caller evaluates it,
/// to keep what comes with it, e.g. the loads):
/// x_{n+1} = x_n + h/6 (k1 + 2k2 + 2k3 + k4). The linearized plant steps with it too.
#[inline]
pub(crate) fn rk4_from<const N: usize>(
    x: &mut [f64; N],
    h: f64,
    k1: [f64; N],
    mut f: impl FnMut(&[f64; N]) -> [f64; N],
) {
    let mut stage = [0.0; N];
    for i in 0..N {
        stage[i] = x[i] + 0.5 * h * k1[i];
    }
    let k2 = f(&stage);
    for i in 0..N {
        stage[i] = x[i] + 0.5 * h * k2[i];
    }
    let k3 = f(&stage);
    for i in 0..N {
        stage[i] = x[i] + h * k3[i];
    }
    let k4 = f(&stage);
    let sixth_h = h * (1.0 / 6.0);
    for i in 0..N {
        x[i] += sixth_h * (k1[i] + 2.0 * (k2[i] + k3[i]) + k4[i]);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model;
    use crate::trim::trim;
    use crate::vehicle::Helicopter;

    #[test]
    fn rk4_error_shrinks_sixteenfold_when_the_step_halves() {
        let heli = Helicopter::bo105();
        let t = trim(&heli, 20.0).unwrap();
        let model = Model::new(heli);
        let pitch = t.blade_pitch_rad;
        let mut start = t.state.0;
        start[model::P] += 0.2;
        start[model::Q] -= 0.1;
        start[model::BETA1C] += 0.01;
        let run = |h: f64| {
            let mut x = start;
            let mut warm = [t.inflow, t.tail_inflow];
            let steps = (0.4 / h).round() as usize;
            for _ in 0..steps {
                rk4_step(
                    &model,
                    &mut x,
                    &pitch,
                    [0.0; 3],
                    ModelFlags::default(),
                    &mut warm,
                    h,
                );
            }
            x
        };
        let coarse = run(0.008);
        let medium = run(0.004);
        let fine = run(0.002);
        let error = |a: &[f64; STATE_LEN], b: &[f64; STATE_LEN]| {
            (0..11).map(|i| (a[i] - b[i]).abs()).fold(0.0, f64::max)
        };
        let ratio = error(&coarse, &medium) / error(&medium, &fine);
        eprintln!("RK4 error ratio on halving the step: {ratio:.2}");
        assert!((13.0..19.0).contains(&ratio), "error ratio {ratio}");
    }
}
