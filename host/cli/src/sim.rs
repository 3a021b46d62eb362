//! `sweephold sim`: trim and linearize a simulated helicopter (crate `rotorsim`): a shipped
//! aircraft or an aircraft file.
//!
//! ```text
//! sweephold sim trim      --vehicle bo105 [--speed KT] [--json]
//! sweephold sim linearize --vehicle bo105 [--speed KT] [--dynamic-inflow] [--json]
//! sweephold sim trim-points --vehicle bo105 [--out FILE]
//! ```
//!
//! The vehicle and the speed are checked while the command line is read (clap's value
//! parsers, `crate::arg_values`): out of range is exit status 2, like every other option.

use std::fmt::Write as _;

use std::path::PathBuf;

use anyhow::Context;

use crate::vehicle::Vehicle;
use clap::{Args, Subcommand};
use rotorsim::{linearize_with, trim, trim_steady, Helicopter, Linearization, SteadyFlight, Trim};
use serde_json::{json, Map, Value};
use sysid::fit::trim::{TrimPoint, TrimPoints};

/// Arguments of `sweephold sim`.
#[derive(Args, Debug)]
pub struct SimArgs {
    /// What to compute.
    #[command(subcommand)]
    pub command: SimCommand,
}

/// The `sim` sub-verbs.
#[derive(Subcommand, Debug)]
pub enum SimCommand {
    /// Trim in level flight: stick positions, blade pitches, attitude, flapping, inflow.
    Trim(CaseArgs),
    /// Linearize about a trim: A, B, C, D, eigenvalues, τ_f and quasi-static derivatives.
    Linearize(LinearizeArgs),
    /// Trim points for `fit --trim-points`: the nonlinear model trimmed in hover, 1 m/s
    /// forward, aft, right and left, climbing and descending at 0.5 m/s and turning on the
    /// spot at ±0.1 rad/s (CSV: body velocities, rates, attitude and sticks per point).
    TrimPoints(TrimPointsArgs),
}

/// Arguments of `sim trim-points`.
#[derive(Args, Debug)]
pub struct TrimPointsArgs {
    /// Vehicle: a shipped aircraft (bo105, trex700l, fbl700) or the path of an aircraft file.
    #[arg(long, default_value = "bo105", value_name = "NAME|FILE", value_parser = Vehicle::parse)]
    pub vehicle: Vehicle,
    /// Write the CSV here (atomically) instead of to standard output.
    #[arg(long, value_name = "FILE")]
    pub out: Option<PathBuf>,
}

/// The steady flights of [`simulator_trim_points`]: label, velocity over the ground
/// (north, east, down) [m/s], turn rate [rad/s]. Small, so that the hover linearization
/// holds (the fuselage drag's u·|u| is the largest departure: 4 % of the u row's terms at
/// 0.05 m/s, linear in the speed), and symmetric, so that the even part of that
/// departure cancels in the least-squares gradient.
pub const TRIM_FLIGHTS: [(&str, [f64; 3], f64); 9] = [
    ("hover", [0.0, 0.0, 0.0], 0.0),
    ("forward", [1.0, 0.0, 0.0], 0.0),
    ("aft", [-1.0, 0.0, 0.0], 0.0),
    ("right", [0.0, 1.0, 0.0], 0.0),
    ("left", [0.0, -1.0, 0.0], 0.0),
    ("descent", [0.0, 0.0, 0.5], 0.0),
    ("climb", [0.0, 0.0, -0.5], 0.0),
    ("turn right", [0.0, 0.0, 0.0], 0.1),
    ("turn left", [0.0, 0.0, 0.0], -0.1),
];

/// The trim points of `heli` (called `name` in messages) at [`TRIM_FLIGHTS`]: what a
/// pilot would record flying them, taken from the nonlinear model's trims (exact: no
/// measurement noise).
pub fn simulator_trim_points(heli: &Helicopter, name: &str) -> anyhow::Result<TrimPoints> {
    let points = TRIM_FLIGHTS
        .iter()
        .map(|&(label, velocity_ned, turn_rate)| {
            let flight = SteadyFlight {
                velocity_ned,
                turn_rate,
            };
            let t = trim_steady(heli, &flight)
                .with_context(|| format!("{name} trim point `{label}`"))?;
            let x = &t.state.0;
            let mut states = [0.0; 8];
            states.copy_from_slice(&x[..8]);
            Ok(TrimPoint {
                label: label.to_string(),
                states,
                controls: t.controls,
            })
        })
        .collect::<anyhow::Result<Vec<_>>>()?;
    Ok(TrimPoints { points })
}

/// Which aircraft and flight condition.
#[derive(Args, Debug)]
pub struct CaseArgs {
    /// Vehicle: a shipped aircraft (bo105, trex700l, fbl700) or the path of an aircraft file.
    #[arg(long, default_value = "bo105", value_name = "NAME|FILE", value_parser = Vehicle::parse)]
    pub vehicle: Vehicle,
    /// Forward speed in knots, 0 (hover) to 120.
    #[arg(
        long,
        default_value = "0",
        value_name = "KT",
        allow_hyphen_values = true,
        value_parser = crate::arg_values::trim_speed_kt
    )]
    pub speed: f64,
    /// Machine-readable JSON on standard output instead of tables.
    #[arg(long)]
    pub json: bool,
}

/// Arguments of `sim linearize`.
#[derive(Args, Debug)]
pub struct LinearizeArgs {
    /// Vehicle, speed, output format.
    #[command(flatten)]
    pub case: CaseArgs,
    /// Model the main-rotor inflow as a Pitt–Peters state (adds `lambda0` to the states).
    #[arg(long)]
    pub dynamic_inflow: bool,
}

const DEG: f64 = 180.0 / std::f64::consts::PI;

/// Run `sweephold sim`.
pub fn run(args: &SimArgs) -> anyhow::Result<()> {
    let text = match &args.command {
        SimCommand::Trim(case) => {
            let (vehicle, heli, trimmed) = trimmed_case(case)?;
            if case.json {
                serde_json::to_string_pretty(&trim_json(vehicle, &heli, &trimmed))? + "\n"
            } else {
                trim_table(&heli, &trimmed)
            }
        }
        SimCommand::Linearize(lin) => {
            let (vehicle, heli, trimmed) = trimmed_case(&lin.case)?;
            let model = linearize_with(&heli, &trimmed, lin.dynamic_inflow);
            if lin.case.json {
                serde_json::to_string_pretty(&linearization_json(vehicle, &trimmed, &model))? + "\n"
            } else {
                linearization_table(&heli, &trimmed, &model)
            }
        }
        SimCommand::TrimPoints(points) => {
            let vehicle = &points.vehicle;
            let csv = simulator_trim_points(&vehicle.helicopter(), vehicle.name())?.to_csv();
            match &points.out {
                Some(path) => {
                    crate::output::write_atomic(path, csv.as_bytes())?;
                    return Ok(());
                }
                None => csv,
            }
        }
    };
    crate::output::print(&text)
}

/// Parse the vehicle and speed and trim.
fn trimmed_case(case: &CaseArgs) -> anyhow::Result<(&Vehicle, Helicopter, Trim)> {
    let (vehicle, speed) = (&case.vehicle, case.speed);
    let heli = vehicle.helicopter();
    let trimmed = trim(&heli, speed).with_context(|| format!("{vehicle} at {speed} kt"))?;
    Ok((vehicle, heli, trimmed))
}

fn trim_json(vehicle: &Vehicle, heli: &Helicopter, t: &Trim) -> Value {
    let p = t.blade_pitch_rad;
    json!({
        "vehicle": vehicle.name(),
        "speed_kt": t.speed_kt,
        "controls": { "lat": t.controls[0], "lon": t.controls[1], "ped": t.controls[2], "col": t.controls[3] },
        "blade_pitch_deg": {
            "theta0": p.theta0 * DEG, "theta1s": p.theta1s * DEG,
            "theta1c": p.theta1c * DEG, "theta0_tr": p.theta0_tr * DEG,
        },
        "attitude_deg": { "phi": t.phi * DEG, "theta": t.theta * DEG },
        "flapping_deg": { "beta1c": t.beta1c * DEG, "beta1s": t.beta1s * DEG, "beta0": t.coning * DEG },
        "inflow": { "main": t.inflow, "tail": t.tail_inflow },
        "thrust_n": { "main": t.main_thrust, "tail": t.tail_thrust },
        "tau_f_s": heli.flap_time_constant(),
        "residual": t.residual,
        "iterations": t.iterations,
    })
}

fn matrix_json(rows: &[Vec<f64>]) -> Value {
    Value::Array(rows.iter().map(|row| json!(row)).collect())
}

fn linearization_json(vehicle: &Vehicle, t: &Trim, lin: &Linearization) -> Value {
    let eig = |values: &[(f64, f64)]| {
        Value::Array(
            values
                .iter()
                .map(|&(re, im)| json!({ "re": re, "im": im }))
                .collect(),
        )
    };
    let quasi: Map<String, Value> = lin
        .quasi_static
        .iter()
        .map(|(k, v)| (k.clone(), json!(v)))
        .collect();
    json!({
        "vehicle": vehicle.name(),
        "speed_kt": t.speed_kt,
        "states": lin.states,
        "controls": lin.controls,
        "outputs": lin.outputs,
        "A": matrix_json(&lin.a),
        "B": matrix_json(&lin.b),
        "C": matrix_json(&lin.c),
        "D": matrix_json(&lin.d),
        "tau_f_s": lin.tau_f_s,
        "eigenvalues": eig(&lin.eigenvalues),
        "quasi_static_eigenvalues": eig(&lin.quasi_static_eigenvalues),
        "quasi_static": Value::Object(quasi),
        "trim_residual": t.residual,
    })
}

fn trim_table(heli: &Helicopter, t: &Trim) -> String {
    let p = t.blade_pitch_rad;
    let mut out = String::new();
    let _ = writeln!(
        out,
        "{} trim at {} kt (residual {:.1e}, {} Newton iterations)",
        heli.name, t.speed_kt, t.residual, t.iterations
    );
    let _ = writeln!(
        out,
        "\n{:<8}{:>10}   {:<10}{:>9}",
        "control", "stick", "pitch", "deg"
    );
    let rows = [
        ("lat", "theta1c", p.theta1c),
        ("lon", "theta1s", p.theta1s),
        ("ped", "theta0_tr", p.theta0_tr),
        ("col", "theta0", p.theta0),
    ];
    for (i, (stick, pitch, value)) in rows.iter().enumerate() {
        let _ = writeln!(
            out,
            "{:<8}{:>10.4}   {:<10}{:>9.3}",
            stick,
            t.controls[i],
            pitch,
            value * DEG
        );
    }
    let _ = writeln!(out, "\n{:<22}{:>10}", "quantity", "value");
    let quantities = [
        ("phi [deg]", t.phi * DEG),
        ("theta [deg]", t.theta * DEG),
        ("beta1c [deg]", t.beta1c * DEG),
        ("beta1s [deg]", t.beta1s * DEG),
        ("coning beta0 [deg]", t.coning * DEG),
        ("main inflow lambda_i", t.inflow),
        ("tail inflow lambda_i", t.tail_inflow),
        ("main thrust [N]", t.main_thrust),
        ("tail thrust [N]", t.tail_thrust),
        ("tau_f [s]", heli.flap_time_constant()),
    ];
    for (name, value) in quantities {
        let _ = writeln!(out, "{name:<22}{value:>10.4}");
    }
    out
}

fn matrix_table(out: &mut String, title: &str, rows: &[&str], cols: &[&str], m: &[Vec<f64>]) {
    let _ = writeln!(out, "\n{title}");
    let _ = write!(out, "{:>8}", "");
    for c in cols {
        let _ = write!(out, "{c:>11}");
    }
    let _ = writeln!(out);
    for (name, row) in rows.iter().zip(m) {
        let _ = write!(out, "{name:>8}");
        for v in row {
            let _ = write!(out, "{v:>11.4}");
        }
        let _ = writeln!(out);
    }
}

fn eigen_table(out: &mut String, title: &str, values: &[(f64, f64)]) {
    let _ = writeln!(
        out,
        "\n{title}\n{:>12}{:>12}{:>12}{:>10}",
        "re [1/s]", "im [rad/s]", "wn [rad/s]", "zeta"
    );
    for &(re, im) in values {
        let wn = (re * re + im * im).sqrt();
        let zeta = if wn > 0.0 { -re / wn } else { 0.0 };
        let _ = writeln!(out, "{re:>12.4}{im:>12.4}{wn:>12.4}{zeta:>10.3}");
    }
}

fn linearization_table(heli: &Helicopter, t: &Trim, lin: &Linearization) -> String {
    let mut out = String::new();
    let _ = writeln!(
        out,
        "{} linearized at {} kt; tau_f = {:.4} s (flapping block)",
        heli.name, t.speed_kt, lin.tau_f_s
    );
    let _ = writeln!(
        out,
        "states: {}; controls: {} (stick fractions); outputs: {}",
        lin.states.join(" "),
        lin.controls.join(" "),
        lin.outputs.join(" ")
    );
    matrix_table(&mut out, "A", &lin.states, &lin.states, &lin.a);
    matrix_table(&mut out, "B", &lin.states, &lin.controls, &lin.b);
    matrix_table(&mut out, "C", &lin.outputs, &lin.states, &lin.c);
    matrix_table(&mut out, "D", &lin.outputs, &lin.controls, &lin.d);
    eigen_table(&mut out, "eigenvalues of A", &lin.eigenvalues);
    eigen_table(
        &mut out,
        "eigenvalues, quasi-static (flapping residualized)",
        &lin.quasi_static_eigenvalues,
    );
    let _ = writeln!(out, "\nquasi-static derivatives (forces / mass, moments / inertia; per stick fraction and per rad of blade pitch)");
    let columns = [
        "u", "v", "w", "p", "q", "r", "lat", "lon", "ped", "col", "theta1c", "theta1s", "theta0tr",
        "theta0",
    ];
    let _ = write!(out, "{:>4}", "");
    for c in columns {
        let _ = write!(out, "{c:>11}");
    }
    let _ = writeln!(out);
    for axis in ["X", "Y", "Z", "L", "M", "N"] {
        let _ = write!(out, "{axis:>4}");
        for c in columns {
            let v = lin
                .quasi_static
                .get(&format!("{axis}{c}"))
                .copied()
                .unwrap_or(f64::NAN);
            let _ = write!(out, "{v:>11.4}");
        }
        let _ = writeln!(out);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn case(vehicle: &str, speed: f64) -> CaseArgs {
        CaseArgs {
            vehicle: Vehicle::shipped(vehicle),
            speed,
            json: true,
        }
    }

    #[test]
    fn bad_vehicle_and_speed_are_refused_while_parsing() {
        use clap::Parser;
        for (vehicle, speed) in [("ec135", "0"), ("bo105", "fast"), ("bo105", "-5")] {
            let args = [
                "sweephold",
                "sim",
                "trim",
                "--vehicle",
                vehicle,
                "--speed",
                speed,
            ];
            let error = crate::Cli::try_parse_from(args).unwrap_err();
            assert_eq!(error.kind(), clap::error::ErrorKind::ValueValidation);
        }
        let unknown = Vehicle::parse("ec135").unwrap_err();
        assert!(
            !unknown.contains('\n') && unknown.contains("ec135"),
            "{unknown}"
        );
    }

    #[test]
    fn json_documents_have_the_documented_keys() {
        let case = case("bo105", 20.0);
        let (vehicle, heli, t) = trimmed_case(&case).unwrap();
        let doc = trim_json(vehicle, &heli, &t);
        for key in ["controls", "blade_pitch_deg", "attitude_deg", "residual"] {
            assert!(doc.get(key).is_some(), "{key}");
        }
        assert!(doc["controls"]["col"].is_f64());
        let lin = linearize_with(&heli, &t, false);
        let doc = linearization_json(vehicle, &t, &lin);
        for key in [
            "states",
            "controls",
            "outputs",
            "A",
            "B",
            "C",
            "D",
            "tau_f_s",
            "eigenvalues",
            "quasi_static",
        ] {
            assert!(doc.get(key).is_some(), "{key}");
        }
        assert_eq!(doc["A"].as_array().unwrap().len(), 11);
        assert!(doc["quasi_static"]["Mtheta1s"].is_f64());
        assert!(doc["eigenvalues"][0]["re"].is_f64());
    }
}
