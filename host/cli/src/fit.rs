//! `sweephold fit`: fit a state-space model structure to frequency responses (CIFER
//! DERIVID-like), print the parameter table (value, Cramér–Rao bound, insensitivity,
//! flags) and the cost per pair, and optionally write `model.json`.

use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::fs;
use std::path::{Path, PathBuf};

use crate::arg_values;
use crate::fit_tables::{
    cost_table, parameter_table, parameter_table_with_truth, reduction_table, truth_cost_table,
};
use crate::mode_text::{hover_summary, mode_table, origin_text};
use crate::output::{check_input_file, refuse_inputs_as_outputs, write_json};
use crate::vehicle::Vehicle;
use anyhow::{bail, Context};
use clap::Args;
use sysid::document::FrfDocument;
use sysid::fit::degenerate::describe as describe_degenerate;
use sysid::fit::equation_error::equation_error_start;
use sysid::fit::modes::{
    eigenvalue_text, mode_records, poles_at_origin, ModeComparison, ModeError, ModeRecord,
    HOVER_MODE_LIMIT_RAD_S,
};
use sysid::fit::plausible::{describe, implausible_parameters};
use sysid::fit::report::{ScoredModelDocument, TruthSection};
use sysid::fit::trim::{TrimBalance, TrimPoints};
use sysid::fit::{
    fit_from_alternative_starts, measured_outputs, reduce_to_measured, start_from_quasi_steady,
    FitOptions, ModelDocument, ModelStructure,
};

/// Arguments of `sweephold fit`.
#[derive(Args, Debug)]
#[command(
    after_help = "Shipped structures (compiled in; --model NAME): bo105-6dof (quasi-steady \
6-DOF with equivalent delays), bo105-9dof-hybrid (rigid body + first-order flapping, the \
paper's Table 2), trex700l-6dof and trex700l-9dof-hybrid (the same structures with the TREX \
700L's geometry, flap cross-coupling and hover trim). The structure file format and the \
model.json layout are described in the models README of the sysid crate.\n\nGuidelines (paper, Tischler & Remple): J_ave <= 100 acceptable, \
<= 50 excellent; Cramér–Rao bound <= 20 %, insensitivity <= 10 %, |correlation| <= 0.9.\n\n\
Physical ranges: every fitted parameter is judged by its part of each F or G entry against \
that entry's dimension (e.g. 1000 m/s² per stick, 300 /s, 100 rad/s² per m/s); a fit outside \
is run again with those parameters held at the structure file's values, and exits 1 without a model \
when that fails (docs/method.md, physical ranges).\n\nDegenerate minima: a fit whose model \
has a parameter outside its physical range or a free one on a bound of its structure file \
that is not zero (tau_f on its 0.005 s floor; a bound of zero is a sign, and resting there \
is physical) runs its search again with up to three other seeds and keeps the first model \
that is not degenerate; otherwise the model is written with `degenerate` (the reasons) and \
a warning line (`identify --strict` and `campaign --strict` exit 1 on it)."
)]
pub struct FitArgs {
    /// Frequency responses to fit (`frf.json` as `sweephold frf` writes it).
    #[arg(long, value_name = "FILE")]
    pub frf: PathBuf,
    /// Model structure: a structure file (TOML), or the name of a shipped structure
    /// (listed below). An existing file wins over a name.
    #[arg(long, value_name = "NAME|FILE")]
    pub model: PathBuf,
    /// Write the fitted model here (`model.json`).
    #[arg(long, value_name = "FILE")]
    pub out: Option<PathBuf>,
    /// Drop poorly identified parameters one at a time while the cost allows it.
    #[arg(long)]
    pub reduce: bool,
    /// Seed of the perturbed restarts (same seed, same result).
    #[arg(long, default_value_t = 1, value_parser = arg_values::seed, allow_hyphen_values = true)]
    pub seed: u64,
    /// Take start values from a quasi-steady 6-DOF `model.json` (paper Eq. 26–27); the
    /// structure file's own start values are tried too, and the lower J_ave is kept.
    #[arg(long, value_name = "model6.json")]
    pub start_from: Option<PathBuf>,
    /// Also start from a frequency-domain equation-error fit of the same responses: the
    /// state equations solved by linear least squares with the measured state responses
    /// (every state must be an output or follow from known rows, as in the 6-DOF); the
    /// lower J_ave of the start sets is kept.
    #[arg(long)]
    pub equation_error_start: bool,
    /// Most optimizer starts, 1–64. The local search (default): the structure's start
    /// values and two perturbations of them (±30 %) explore, later starts perturb the best
    /// minimum so far (±10 %); stops earlier once a minimum is found twice. With `--search
    /// global` a budget, all spent (see there).
    #[arg(long, default_value_t = 8, value_parser = arg_values::count::<1, 64>, allow_hyphen_values = true)]
    pub max_starts: usize,
    /// `local` (default) or `global`: every one of `--max-starts` made, the structure's
    /// start values, then half the starts drawn across the parameter box (each free
    /// value's magnitude log-uniform within half a decade of its start value, sign kept,
    /// bounds honoured), the rest perturbing the best plausible minimum (±10 %, doubled
    /// after every four perturbations in a row that find nothing lower, up to ±80 %); the
    /// minimum counts as confirmed only when two independent starts reach it. For
    /// structures started from rough values (e.g. `--search global --max-starts 64`).
    #[arg(long, value_enum, default_value_t = SearchArg::Local, value_name = "HOW")]
    pub search: SearchArg,
    /// Fit frequencies per pair (n_ω; CIFER uses 20), 2–200: the fit's time grows with it.
    #[arg(long, default_value_t = 20, value_parser = arg_values::count::<2, 200>, allow_hyphen_values = true)]
    pub points: usize,
    /// Score the fit against the simulator's linearization at hover of an aircraft (a
    /// shipped one, `bo105`, `trex700l`, or an aircraft file): truth and error % per
    /// parameter, J against the truth model per pair.
    #[arg(long, value_name = "NAME|FILE", value_parser = Vehicle::parse)]
    pub truth: Option<Vehicle>,
    /// Set one of the structure file's `[constants]`, e.g. `--constant hub_height=0.25` to
    /// fit the shipped Bo-105 file to another aircraft's geometry; repeatable. A name the
    /// file does not declare is an error.
    #[arg(long = "constant", value_name = "NAME=VALUE", value_parser = parse_constant)]
    pub constants: Vec<(String, f64)>,
    /// Trim points (CSV: label, u v w p q r phi theta, lat lon ped col per steady flight;
    /// `sweephold sim trim-points` writes the simulator's): the structure's `trim_derived`
    /// parameters (the shipped 6-DOF: Lv Mu Nv Zw Nr; the hybrid: Mfu Lfu Nv Zw Nr) are
    /// derived from the steady-state balance at the points and held (status `trim`) until
    /// they settle; `--trim-balance` says what follows. Implausible, repeated or collinear
    /// points are refused. Like any fit, one whose parameters land outside physical ranges
    /// is run again with them held at the structure file's values, and no model is written when
    /// that does not bring them inside.
    #[arg(long, value_name = "FILE")]
    pub trim_points: Option<PathBuf>,
    /// How the trim points enter the fit: `hold` keeps the derived parameters at the
    /// balance's values (status `trim`); `joint` then releases them (status `free`) and
    /// refits with the balances as weighted residuals of the cost (stick uncertainty
    /// 3.5·10⁻⁴ of travel, an SBUS count).
    #[arg(long, value_enum, default_value_t = TrimBalanceArg::Hold, value_name = "HOW")]
    pub trim_balance: TrimBalanceArg,
}

/// `--search` of `fit`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum SearchArg {
    /// Restarts about the start values, then about the best minimum, until it is found twice.
    Local,
    /// The whole `--max-starts` budget, half of it drawn across the parameter box.
    Global,
}

/// `--trim-balance` of `fit` and `campaign`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum TrimBalanceArg {
    /// Derived from the balance and held (status `trim`).
    Hold,
    /// Held until they settle, then fitted with the others under the balances' cost.
    Joint,
}

impl TrimBalanceArg {
    /// The fit's setting.
    pub fn balance(self) -> TrimBalance {
        match self {
            TrimBalanceArg::Hold => TrimBalance::Hold,
            TrimBalanceArg::Joint => TrimBalance::Joint {
                stick_sigma: sysid::fit::trim::joint::DEFAULT_STICK_SIGMA,
            },
        }
    }

    /// The aircraft file's `identification.trim_balance`.
    pub fn of_vehicle(vehicle: &crate::vehicle::Vehicle) -> TrimBalanceArg {
        match vehicle.trim_balance() {
            aircraft::TrimBalance::Hold => TrimBalanceArg::Hold,
            aircraft::TrimBalance::Joint => TrimBalanceArg::Joint,
        }
    }

    /// The value as written on the command line.
    pub fn as_arg(self) -> &'static str {
        match self {
            TrimBalanceArg::Hold => "hold",
            TrimBalanceArg::Joint => "joint",
        }
    }
}

impl FitArgs {
    /// The fit's options these arguments give, with the trim points of `--trim-points`
    /// (read by the caller).
    pub fn options(&self, trim_points: Option<TrimPoints>) -> FitOptions {
        FitOptions {
            points_per_pair: self.points,
            max_starts: self.max_starts.max(1),
            global_search: self.search == SearchArg::Global,
            seed: self.seed,
            reduce: self.reduce,
            trim_points,
            trim_balance: self.trim_balance.balance(),
            ..FitOptions::default()
        }
    }
}

/// `NAME=VALUE` of `--constant`.
fn parse_constant(text: &str) -> Result<(String, f64), String> {
    let (name, value) = text
        .split_once('=')
        .ok_or_else(|| format!("`{text}` is not NAME=VALUE"))?;
    let name = name.trim();
    if name.is_empty() {
        return Err(format!("`{text}` has no name before `=`"));
    }
    let value: f64 = value
        .trim()
        .parse()
        .map_err(|_| format!("`{}` is not a number", value.trim()))?;
    if !value.is_finite() {
        return Err(format!("`{}` is not a finite number", value));
    }
    Ok((name.to_string(), value))
}

/// `--model`: an existing path is read as a structure file; anything else must be the
/// name of a shipped structure.
fn model_structure(
    model: &Path,
    constants: &BTreeMap<String, f64>,
) -> anyhow::Result<ModelStructure> {
    if model.exists() {
        check_input_file("--model", model)?;
        return Ok(ModelStructure::from_path_with_constants(model, constants)?);
    }
    let name = model.to_string_lossy();
    crate::structures::shipped(&name, constants).unwrap_or_else(|| {
        bail!(
            "--model {}: no such file, and no shipped structure of that name ({})",
            model.display(),
            sysid::models::shipped_names()
        )
    })
}

/// Run `sweephold fit`.
pub fn run(args: &FitArgs) -> anyhow::Result<()> {
    let mut inputs = vec![args.frf.as_path()];
    inputs.extend(args.start_from.as_deref());
    inputs.extend(args.trim_points.as_deref());
    if args.model.is_file() {
        inputs.push(args.model.as_path());
    }
    if let Some(out) = &args.out {
        refuse_inputs_as_outputs(&inputs, &[("--out", out)])?;
    }
    check_input_file("--frf", &args.frf)?;
    if let Some(path) = &args.start_from {
        check_input_file("--start-from", path)?;
    }
    let trim_points = match &args.trim_points {
        None => None,
        Some(path) => {
            check_input_file("--trim-points", path)?;
            let text = fs::read_to_string(path)
                .with_context(|| format!("cannot read {}", path.display()))?;
            Some(
                TrimPoints::parse_csv(&text)
                    .map_err(|e| anyhow::anyhow!("{}: {e}", path.display()))?,
            )
        }
    };
    let frf_text = fs::read_to_string(&args.frf)
        .with_context(|| format!("cannot read {}", args.frf.display()))?;
    let data: FrfDocument = serde_json::from_str(&frf_text).with_context(|| {
        format!(
            "{} is not a frequency-response document",
            args.frf.display()
        )
    })?;
    let constants: BTreeMap<String, f64> = args.constants.iter().cloned().collect();
    let structure = model_structure(&args.model, &constants)?;
    // A board without air data gives no response of u, v, w: those pairs are left out.
    let (structure, unmeasured) = reduce_to_measured(structure, &measured_outputs(&data))?;

    // Everything goes to one report printed at the end (see `emit`).
    let mut report = String::new();
    if !unmeasured.is_empty() {
        let _ = writeln!(
            report,
            "pairs of {} left out: {} holds no response of them\n",
            unmeasured.join(", "),
            args.frf.display()
        );
    }
    let mut starts = Vec::new();
    if let Some(path) = &args.start_from {
        let text =
            fs::read_to_string(path).with_context(|| format!("cannot read {}", path.display()))?;
        let previous: ModelDocument = serde_json::from_str(&text)
            .with_context(|| format!("{} is not a model.json", path.display()))?;
        let (started, notes) = start_from_quasi_steady(&structure, &previous)?;
        let _ = writeln!(
            report,
            "start values from {} ({}):",
            path.display(),
            previous.structure
        );
        for note in &notes {
            let _ = writeln!(
                report,
                "  {:<10} {:>14.6}  {}",
                note.parameter, note.value, note.source
            );
        }
        let _ = writeln!(report);
        starts.push((
            format!("{} ({})", path.display(), previous.structure),
            started,
        ));
    }
    if args.equation_error_start {
        let solved = equation_error_start(&structure, &data)?;
        let _ = writeln!(
            report,
            "start values from an equation-error fit: {} blocks (state/control), weighted \
             equation error {:.4} -> {:.4} in {} iteration(s){}",
            solved.blocks.len(),
            solved.cost[0],
            solved.cost[1],
            solved.iterations,
            if solved.uninformed.is_empty() {
                String::new()
            } else {
                format!("; not informed, kept: {}", solved.uninformed.join(" "))
            }
        );
        let _ = writeln!(report);
        starts.push(("equation error".to_string(), solved.structure));
    }
    starts.push((
        format!("{} (the file's start values)", args.model.display()),
        structure,
    ));

    let options = args.options(trim_points);
    // With --start-from, the file's own starts are the fallback: the lower J_ave wins.
    let (result, outcomes) = fit_from_alternative_starts(&starts, &data, &options)?;
    if outcomes.len() > 1 {
        let _ = writeln!(report, "start sets (lowest J_ave kept, then reduced):");
        for outcome in &outcomes {
            match &outcome.average_cost {
                Ok(cost) => {
                    let _ = writeln!(report, "  J_ave {cost:>12.4}  {}", outcome.label);
                }
                Err(error) => {
                    let _ = writeln!(report, "  failed: {error}  {}", outcome.label);
                }
            }
        }
        let _ = writeln!(report);
    }

    let scored = match &args.truth {
        Some(vehicle) => Some(truth::score_fit_with_modes(
            &result,
            &truth::VehicleTruth::at_hover(vehicle.aircraft())?,
        )?),
        None => None,
    };
    // The modes, paired with the truth's when scored; an error (a model without
    // eigenvalues) is printed, not fatal.
    let modes = match &scored {
        Some(scored) => scored
            .modes
            .clone()
            .map(|compared| ModesReport::Compared(Box::new(compared))),
        None => mode_records(&result.model).map(ModesReport::Alone),
    };
    let truth = scored.map(|scored| scored.section);
    write_report(&mut report, &result, truth.as_ref()).expect("writing to a String cannot fail");
    write_modes(&mut report, &modes).expect("writing to a String cannot fail");
    if !result.average_cost.is_finite() {
        bail!(
            "the fit's cost is not finite (J_ave {}): the responses in {} are not a plausible \
             frequency response for this structure; no model written",
            result.average_cost,
            args.frf.display()
        );
    }
    refuse_implausible(&result, &args.frf)?;
    if let Some(path) = &args.out {
        let document = ScoredModelDocument {
            model: result.to_document(),
            truth,
            modes: match modes {
                Ok(ModesReport::Compared(compared)) => compared.identified,
                Ok(ModesReport::Alone(records)) => records,
                Err(_) => Vec::new(),
            },
        };
        write_json(path, &document)?;
        let _ = writeln!(report, "\nwrote {}", path.display());
    }
    crate::output::print(&report)?;
    warn_degenerate(&result, args.out.as_deref());
    Ok(())
}

/// The one-line warning (standard error) of a fit whose model is degenerate even after
/// its restarts elsewhere ([`sysid::fit::degenerate`]): parameters on a range bound of
/// the structure file. `out` is the model file written, marked `degenerate`.
pub fn warn_degenerate(result: &sysid::fit::FitResult, out: Option<&Path>) {
    if result.degenerate.is_empty() {
        return;
    }
    crate::note!(
        "warning: the fit is degenerate after {} restart(s) elsewhere: {}{}",
        result.degenerate_restarts.len(),
        describe_degenerate(&result.degenerate),
        out.map_or(String::new(), |out| format!(
            "; {} is marked `degenerate`, not a usable model",
            out.display()
        ))
    );
}

/// Refuse a fit whose parameters lie outside their physical range
/// ([`sysid::fit::plausible`]) even after the fit's recovery: a degenerate minimum is
/// never written as a success. `frf` names the responses in the message.
pub fn refuse_implausible(result: &sysid::fit::FitResult, frf: &Path) -> anyhow::Result<()> {
    let found = implausible_parameters(&result.structure, &result.values);
    if found.is_empty() {
        return Ok(());
    }
    bail!(
        "the fit is degenerate: {} of {} on {} lie orders of magnitude outside what a \
         helicopter's model can hold (docs/method.md, physical ranges){}; no model written",
        describe(&found),
        result.structure.name,
        frf.display(),
        if result.trim.is_some() {
            ": the trim balance scales the fitted control derivatives, which these \
             responses leave undetermined"
        } else {
            ""
        }
    )
}

/// The modes of the fitted model, alone or against the truth's.
enum ModesReport {
    /// Without a truth.
    Alone(Vec<ModeRecord>),
    /// Paired with the truth model's modes (`--truth`).
    Compared(Box<ModeComparison>),
}

/// The modes table, and against a truth its hover-mode line and the truth modes no
/// identified mode was paired with.
fn write_modes(out: &mut String, modes: &Result<ModesReport, ModeError>) -> std::fmt::Result {
    writeln!(
        out,
        "\nmodes (eigenvalues of M⁻¹F, named from their eigenvectors; hover: \
|λ| < {HOVER_MODE_LIMIT_RAD_S} rad/s):"
    )?;
    match modes {
        Err(error) => writeln!(out, "  not computed: {error}"),
        Ok(ModesReport::Alone(records)) => {
            write!(out, "{}", mode_table(records))?;
            writeln!(out, "{}", origin_text(poles_at_origin(records)))
        }
        Ok(ModesReport::Compared(compared)) => {
            write!(out, "{}", mode_table(&compared.identified))?;
            for unpaired in compared.truth.iter().filter(|t| t.identified.is_none()) {
                writeln!(
                    out,
                    "truth mode {} {} has no identified counterpart",
                    unpaired.name,
                    eigenvalue_text(unpaired.eigenvalue)
                )?;
            }
            writeln!(
                out,
                "{}",
                hover_summary(&compared.hover, compared.poles_at_origin)
            )
        }
    }
}

/// The text report: starts, reduction steps, parameter table, cost table.
fn write_report(
    out: &mut String,
    result: &sysid::fit::FitResult,
    truth: Option<&TruthSection>,
) -> std::fmt::Result {
    writeln!(
        out,
        "structure {} ({} states, {} controls, {} outputs), {} pairs, {} free parameters",
        result.structure.name,
        result.structure.states.len(),
        result.structure.controls.len(),
        result.structure.outputs.len(),
        result.pairs.len(),
        result.correlation_names.len()
    )?;
    for (number, start) in result.starts.iter().enumerate() {
        match start.average_cost {
            Some(cost) => writeln!(
                out,
                "  start {}: J_ave {:.4} after {} iterations ({})",
                number + 1,
                cost,
                start.iterations,
                start.stop
            )?,
            None => writeln!(out, "  start {}: {}", number + 1, start.stop)?,
        }
    }
    writeln!(
        out,
        "  minimum {}",
        if result.minimum_confirmed {
            "found twice (taken as global)"
        } else {
            "NOT confirmed by a second start"
        }
    )?;
    if !result.implausible_held.is_empty() {
        writeln!(
            out,
            "  a degenerate minimum put parameters outside their physical range (value it \
             gave below): fitted again with them held at the structure file's values:"
        )?;
        for dropped in &result.implausible_held {
            writeln!(out, "    {:<10} {:>14.6e}", dropped.name, dropped.value)?;
        }
    }
    if !result.degenerate_restarts.is_empty() {
        writeln!(
            out,
            "  the model was degenerate: the search ran again with seed(s) {}{}",
            result
                .degenerate_restarts
                .iter()
                .map(u64::to_string)
                .collect::<Vec<_>>()
                .join(", "),
            if result.degenerate.is_empty() {
                ", which found a model that is not"
            } else {
                ", none found a model that is not"
            }
        )?;
    }
    for reason in &result.degenerate {
        writeln!(out, "  DEGENERATE: {}", reason.describe())?;
    }
    if !result.reduction.is_empty() {
        writeln!(out, "\nreduction:")?;
        write!(out, "{}", reduction_table(&result.reduction))?;
    }
    writeln!(out)?;
    match truth {
        Some(section) => {
            writeln!(
                out,
                "truth: {} linearized at hover trim (error % = 100·(value − truth)/|truth|)",
                section.vehicle
            )?;
            write!(out, "{}", parameter_table_with_truth(result, section))?;
        }
        None => write!(out, "{}", parameter_table(result))?,
    }
    if result.hessian_singular {
        writeln!(
            out,
            "warning: the Hessian is singular — some parameter combination does not affect \
             the cost (Cramér–Rao bounds infinite)"
        )?;
    }
    writeln!(out)?;
    write!(out, "{}", cost_table(result))?;
    if let Some(section) = truth {
        writeln!(out)?;
        write!(out, "{}", truth_cost_table(section))?;
    }
    if !result.skipped_pairs.is_empty() {
        writeln!(out, "\nskipped (no usable coherent range in the data):")?;
        for pair in &result.skipped_pairs {
            writeln!(
                out,
                "  {}/{} (line {}): {}",
                pair.output, pair.input, pair.line, pair.reason
            )?;
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests;
