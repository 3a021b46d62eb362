//! What each state of a model is for the naming of its modes ([`super::naming`]): its
//! unit (how its eigenvector component is made comparable) and its group (which motion it
//! belongs to).
//!
//! **By name.** `u v w` are speeds, `p q r` rates, `φ θ ψ` (`phi theta psi`) and the
//! flapping `b1c b1s` (`beta1c beta1s`) angles; groups: lateral `v p φ`, longitudinal
//! `u q θ`, heave `w`, yaw `r ψ`, rotor lateral `b1s`, rotor longitudinal `b1c`.
//!
//! **Speeds in m/s or ft/s.** A speed is made an attitude through gravity (`u̇ = −g θ`),
//! so its unit matters: the model's own gravity term, the larger of `|∂u̇/∂θ|` and
//! `|∂v̇/∂φ|` of `A = M⁻¹F`, says which. When it is nearer (in ratio) 32.174 ft/s² than
//! 9.80665 m/s², speeds are in ft/s and `g` = 32.174 ([`FOOT_GRAVITY`]); otherwise, and
//! when the model has neither term, `g` = 9.80665 ([`STANDARD_GRAVITY`]). The R-50 hover
//! model of Mettler, Tischler & Kanade is in ft/s: read in m/s its heave speed weighed 11
//! times its share and named its roll–flap mode a heave oscillation.
//!
//! **States of other names** (a published model's flapping `a b`, stabilizer bar `c d`
//! or yaw damper `r_fb`) keep their own unit and take the group of the motion that drives
//! them: the named state with the largest term in their row of `A` (`|A_ji|` times the
//! state's size per radian of attitude at 1 rad/s: an angle or a rate 1, a speed `g`).
//! A state driven by a lateral or longitudinal body state is that axis's rotor (the
//! R-50's `b` and `d` are driven by `p`, `a` and `c` by `q`), one driven by `r` or `w` is
//! yaw or heave (its `r_fb`, by `r`). A state driven only by other such states takes
//! their group once theirs is known, round by round (each round uses only the groups of
//! the rounds before, so the order of the states does not matter); one that nothing
//! named drives takes the group of what it drives, by the column of `A`, the same way;
//! one connected to no named state is `other`. Models whose states all have the names
//! above (the shipped structures) are unchanged by this rule.

use nalgebra::DMatrix;

/// Gravity [m/s²] of the speed-to-attitude scaling when speeds are in m/s.
pub const STANDARD_GRAVITY: f64 = 9.80665;
/// Gravity [ft/s²] of the speed-to-attitude scaling when speeds are in ft/s.
pub const FOOT_GRAVITY: f64 = 32.174;

/// The group a state's motion belongs to.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Group {
    Lateral,
    Longitudinal,
    Heave,
    Yaw,
    RotorLateral,
    RotorLongitudinal,
    Other,
}

impl Group {
    /// The group of a state of another name driven by a state of this group.
    fn of_a_driven_state(self) -> Option<Group> {
        match self {
            Group::Lateral | Group::RotorLateral => Some(Group::RotorLateral),
            Group::Longitudinal | Group::RotorLongitudinal => Some(Group::RotorLongitudinal),
            Group::Heave => Some(Group::Heave),
            Group::Yaw => Some(Group::Yaw),
            Group::Other => None,
        }
    }
}

/// The unit of a state, which sets how its eigenvector component is scaled.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Unit {
    /// rad: as it is.
    Angle,
    /// rad/s: divided by |λ|.
    Rate,
    /// m/s or ft/s: times |λ|/g.
    Speed,
    /// Anything else: as it is.
    Own,
}

impl Unit {
    /// The state's size per radian of attitude at 1 rad/s (module documentation).
    fn size_per_radian(self, gravity: f64) -> f64 {
        match self {
            Unit::Speed => gravity,
            Unit::Angle | Unit::Rate | Unit::Own => 1.0,
        }
    }
}

/// Unit and group of a state by its name; `Other` for a name not listed.
fn by_name(state: &str) -> (Unit, Group) {
    match state {
        "u" => (Unit::Speed, Group::Longitudinal),
        "v" => (Unit::Speed, Group::Lateral),
        "w" => (Unit::Speed, Group::Heave),
        "p" => (Unit::Rate, Group::Lateral),
        "q" => (Unit::Rate, Group::Longitudinal),
        "r" => (Unit::Rate, Group::Yaw),
        "phi" => (Unit::Angle, Group::Lateral),
        "theta" => (Unit::Angle, Group::Longitudinal),
        "psi" => (Unit::Angle, Group::Yaw),
        "b1s" | "beta1s" => (Unit::Angle, Group::RotorLateral),
        "b1c" | "beta1c" => (Unit::Angle, Group::RotorLongitudinal),
        _ => (Unit::Own, Group::Other),
    }
}

/// The units and groups of a model's states, and the gravity of its speeds.
#[derive(Clone, Debug, PartialEq)]
pub(super) struct StateKinds {
    /// Per state, in the model's order.
    pub(super) kinds: Vec<(Unit, Group)>,
    /// g of the speed-to-attitude scaling, in the model's speed unit per s.
    pub(super) gravity: f64,
}

impl StateKinds {
    /// The kinds of `states`, whose state matrix is `a` (module documentation).
    pub(super) fn of(states: &[String], a: &DMatrix<f64>) -> Self {
        let gravity = gravity_of(states, a);
        let mut kinds: Vec<(Unit, Group)> = states.iter().map(|s| by_name(s)).collect();
        if a.nrows() == states.len() && a.ncols() == states.len() {
            // Driven by (row of A), then driving (column of A).
            resolve_unnamed(&mut kinds, gravity, |j, i| a[(j, i)]);
            resolve_unnamed(&mut kinds, gravity, |j, i| a[(i, j)]);
        }
        StateKinds { kinds, gravity }
    }
}

/// The model's gravity term: g in its speed unit ([`STANDARD_GRAVITY`] or
/// [`FOOT_GRAVITY`]).
fn gravity_of(states: &[String], a: &DMatrix<f64>) -> f64 {
    let index = |name: &str| states.iter().position(|s| s == name);
    let term = |row: &str, column: &str| match (index(row), index(column)) {
        (Some(i), Some(j)) if i < a.nrows() && j < a.ncols() => a[(i, j)].abs(),
        _ => 0.0,
    };
    let gravity = term("u", "theta").max(term("v", "phi"));
    if gravity.is_finite()
        && gravity > 0.0
        && (gravity / FOOT_GRAVITY).ln().abs() < (gravity / STANDARD_GRAVITY).ln().abs()
    {
        FOOT_GRAVITY
    } else {
        STANDARD_GRAVITY
    }
}

/// Give each state still in `Other` the group of the state with the largest
/// `|coupling(j, i)|·size_i` among those with a group (module documentation), in rounds
/// that each use only the groups known before the round.
fn resolve_unnamed(
    kinds: &mut [(Unit, Group)],
    gravity: f64,
    coupling: impl Fn(usize, usize) -> f64,
) {
    loop {
        let known: Vec<(Unit, Group)> = kinds.to_vec();
        let mut changed = false;
        for (j, kind) in kinds.iter_mut().enumerate() {
            if kind.1 != Group::Other {
                continue;
            }
            let strongest = known
                .iter()
                .enumerate()
                .filter(|&(i, &(_, group))| i != j && group != Group::Other)
                .map(|(i, &(unit, group))| {
                    (group, coupling(j, i).abs() * unit.size_per_radian(gravity))
                })
                .filter(|(_, weight)| weight.is_finite() && *weight > 0.0)
                .fold(
                    None,
                    |best: Option<(Group, f64)>, (group, weight)| match best {
                        Some((_, w)) if w >= weight => best,
                        _ => Some((group, weight)),
                    },
                );
            if let Some(group) = strongest.and_then(|(group, _)| group.of_a_driven_state()) {
                kind.1 = group;
                changed = true;
            }
        }
        if !changed {
            return;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn names(list: &[&str]) -> Vec<String> {
        list.iter().map(|s| s.to_string()).collect()
    }

    /// A chain q → a → c (a flap driven by the pitch rate, a bar driven by the flap), a
    /// state r_fb driven by r, and a state driven by nothing that drives v.
    #[test]
    fn unnamed_states_take_the_group_of_what_drives_them() {
        let states = names(&["u", "v", "q", "r", "theta", "a", "c", "rfb", "x"]);
        let n = states.len();
        let mut a = DMatrix::zeros(n, n);
        a[(0, 4)] = -32.17; // u' = −g θ, in ft/s
        a[(5, 2)] = -1.0; // a' ← q
        a[(6, 5)] = 2.0; // c' ← a
        a[(7, 3)] = 2.16; // rfb' ← r
        a[(1, 8)] = 0.5; // v' ← x: x drives v
        let kinds = StateKinds::of(&states, &a);
        assert_eq!(kinds.gravity, FOOT_GRAVITY);
        let group = |name: &str| kinds.kinds[states.iter().position(|s| s == name).unwrap()].1;
        assert_eq!(group("a"), Group::RotorLongitudinal);
        assert_eq!(group("c"), Group::RotorLongitudinal);
        assert_eq!(group("rfb"), Group::Yaw);
        assert_eq!(group("x"), Group::RotorLateral);
        assert_eq!(kinds.kinds[5].0, Unit::Own);
    }

    /// SI models (the shipped structures, with g·cos θ₀ in their gravity terms) keep
    /// 9.80665, as does a model without a gravity term; a state connected to nothing
    /// named stays `other`.
    #[test]
    fn si_models_and_isolated_states() {
        let states = names(&["u", "theta", "z"]);
        let mut a = DMatrix::zeros(3, 3);
        a[(0, 1)] = -9.80665 * 0.998;
        let kinds = StateKinds::of(&states, &a);
        assert_eq!(kinds.gravity, STANDARD_GRAVITY);
        assert_eq!(kinds.kinds[2].1, Group::Other);
        let kinds = StateKinds::of(&names(&["w"]), &DMatrix::from_element(1, 1, -0.6));
        assert_eq!(kinds.gravity, STANDARD_GRAVITY);
    }
}
