//! The `[flight_controller]` table: the firmware preset an aircraft flies, and the settings
//! of the in-loop campaign the file states instead of the preset's — the attitude hold's
//! gains and thresholds, the excitation's scale per control, the command slew, the pulse
//! width and the abort limits.
//!
//! Every setting is optional: one the file does not state is the named preset's, so a file
//! with `preset` alone flies the preset exactly. A stated setting is read with its unit and
//! checked against its range here (one line naming the field and line); the checks that
//! relate a stated value to one the preset supplies (an integrator limit above the preset's
//! output limit) are the firmware's, made when the command line builds the configuration.
//! A setting is a choice, not a measurement: it takes no σ.

use crate::quantity::{Dimension, Quantity};
use crate::reader::{Range, Reader, DEG};
use crate::schema::{self, Value, Values};
use crate::AircraftError;

/// The firmware presets a flight controller can fly: an aircraft names the one its
/// controller's settings default to. A board image is built with one preset: the command
/// line flies a file's own settings in-process and on the simulated board (`fc params push`
/// sets them on a board that takes parameters), and `fly` over its links to a board image
/// refuses them.
pub const FIRMWARE_PRESETS: [&str; 2] = ["bo105", "trex700l"];

/// What the flight controller flies. Each `Option` is `None` when the file leaves the
/// setting to the preset. Values in SI units.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct FlightController {
    /// The firmware preset, one of [`FIRMWARE_PRESETS`].
    pub preset: String,
    /// What the hold's engage and release angles are measured from.
    pub hold_reference: Option<HoldReference>,
    /// Where the collective of a test's excitation comes from.
    pub collective: Option<CollectiveSource>,
    /// Conditional attitude hold: engage angle \[rad\].
    pub hold_engage: Option<f64>,
    /// Conditional attitude hold: release angle \[rad\].
    pub hold_release: Option<f64>,
    /// Width of a pulse input's base pulse \[s\].
    pub pulse_width: Option<f64>,
    /// Fraction of the test's amplitude and noise each control gets: lat, lon, ped, col.
    pub excitation_scale: Option<[f64; 4]>,
    /// Slew limit of the excitation phases' commands [stick fraction per s]: lat, lon, ped,
    /// col; `None` inside: no limit on that control. The outer `None`: the preset's.
    pub command_slew: Option<[Option<f64>; 4]>,
    /// Slew limit of the attitude holds' share of the lat, lon and ped commands in the
    /// excitation phases [stick fraction per s]; `None` inside: no limit on that axis.
    /// The outer `None`: the preset's (none).
    pub hold_slew: Option<[Option<f64>; 3]>,
    /// Abort when |φ| or |θ| exceeds this \[rad\].
    pub attitude_limit: Option<f64>,
    /// Abort when |p|, |q| or |r| exceeds these [rad/s].
    pub rate_limits: Option<[f64; 3]>,
    /// Abort when a stick moves this far from its trim (fraction of travel).
    pub pilot_override: Option<f64>,
    /// The attitude hold's gains: lat (on φ), lon (on θ), ped (on the heading).
    pub hold: [HoldGains; 3],
}

/// What the hold's thresholds apply to on roll and pitch.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum HoldReference {
    /// The attitude φ, θ itself.
    Level,
    /// The deviation from the captured trim attitude.
    Trim,
}

/// The collective during a test's excitation.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum CollectiveSource {
    /// The captured trim collective (the in-the-loop presets' choice).
    Trim,
    /// The pilot's collective stick (the board's parameter table's choice).
    Pilot,
}

/// One held axis' gains; each `None` when the file leaves it to the preset.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct HoldGains {
    /// Proportional gain [stick fraction per rad].
    pub kp: Option<f64>,
    /// Integral gain [stick fraction per rad·s].
    pub ki: Option<f64>,
    /// Rate gain [stick fraction per rad/s].
    pub kd: Option<f64>,
    /// Authority around trim (fraction of stick travel).
    pub output_limit: Option<f64>,
    /// Integrator limit (fraction of stick travel).
    pub integrator_limit: Option<f64>,
    /// Time constant of the bumpless hand-over at engagement \[s\].
    pub bumpless_time: Option<f64>,
    /// Time constant of the output's fade after a release \[s\].
    pub release_time: Option<f64>,
    /// The axis' positive command gives a negative moment.
    pub reversed: Option<bool>,
}

impl FlightController {
    /// Whether the file states any setting besides the preset.
    pub fn states_settings(&self) -> bool {
        let only_preset = FlightController {
            preset: self.preset.clone(),
            ..FlightController::default()
        };
        *self != only_preset
    }
}

/// Read and check the `[flight_controller]` table.
pub(crate) fn read(
    r: &Reader,
    f: &schema::FlightController,
) -> Result<FlightController, AircraftError> {
    use Dimension as D;
    use Range::Positive;
    let preset = f.preset.get_ref();
    if !FIRMWARE_PRESETS.contains(&preset.as_str()) {
        return Err(r.error(
            f.preset.span().start,
            "flight_controller.preset",
            format!(
                "`{preset}` is not a firmware preset ({})",
                FIRMWARE_PRESETS.join(", ")
            ),
        ));
    }
    let hold_reference = match &f.hold_reference {
        None => None,
        Some(written) => Some(match written.get_ref().as_str() {
            "level" => HoldReference::Level,
            "trim" => HoldReference::Trim,
            other => {
                return Err(r.error(
                    written.span().start,
                    "flight_controller.hold_reference",
                    format!("`{other}`: expected level or trim"),
                ))
            }
        }),
    };
    let collective = match &f.collective {
        None => None,
        Some(written) => Some(match written.get_ref().as_str() {
            "trim" => CollectiveSource::Trim,
            "pilot" => CollectiveSource::Pilot,
            other => {
                return Err(r.error(
                    written.span().start,
                    "flight_controller.collective",
                    format!("`{other}`: expected pilot or trim"),
                ))
            }
        }),
    };
    let angle = Positive(90.0 * DEG);
    let hold_engage = setting(r, &f.hold_engage, "hold_engage", D::Angle, angle)?;
    let hold_release = setting(r, &f.hold_release, "hold_release", D::Angle, angle)?;
    if let (Some(engage), Some(release), Some(written)) =
        (hold_engage, hold_release, &f.hold_release)
    {
        if release > engage {
            return Err(r.error(
                written.span().start,
                "flight_controller.hold_release",
                "must not exceed hold_engage (the hold would never release)",
            ));
        }
    }
    let excitation_scale = match &f.excitation_scale {
        None => None,
        Some(written) => Some(settings::<4>(
            r,
            written,
            "excitation_scale",
            D::Dimensionless,
            Positive(1.0),
        )?),
    };
    let command_slew = match &f.command_slew {
        None => None,
        Some(t) => Some(slew_rates(
            r,
            [&t.lat, &t.lon, &t.ped, &t.col],
            "command_slew",
        )?),
    };
    let hold_slew = match &f.hold_slew {
        None => None,
        Some(t) => Some(slew_rates(r, [&t.lat, &t.lon, &t.ped], "hold_slew")?),
    };
    let rate_limits = match &f.rate_limits {
        None => None,
        Some(written) => Some(settings::<3>(
            r,
            written,
            "rate_limits",
            D::AngularSpeed,
            Positive(50.0),
        )?),
    };
    let mut hold = [HoldGains::default(); 3];
    if let Some(table) = &f.hold {
        let axes = [&table.lat, &table.lon, &table.ped];
        for ((slot, axis), name) in hold.iter_mut().zip(axes).zip(CONTROLS) {
            if let Some(axis) = axis {
                *slot = hold_gains(r, axis, name)?;
            }
        }
    }
    Ok(FlightController {
        preset: preset.clone(),
        hold_reference,
        collective,
        hold_engage,
        hold_release,
        pulse_width: setting(r, &f.pulse_width, "pulse_width", D::Time, Positive(60.0))?,
        excitation_scale,
        command_slew,
        hold_slew,
        attitude_limit: setting(r, &f.attitude_limit, "attitude_limit", D::Angle, angle)?,
        rate_limits,
        pilot_override: setting(
            r,
            &f.pilot_override,
            "pilot_override",
            D::Dimensionless,
            Positive(2.0),
        )?,
        hold,
    })
}

/// The controls in the order of the per-control settings.
const CONTROLS: [&str; 4] = ["lat", "lon", "ped", "col"];

fn hold_gains(r: &Reader, h: &schema::HoldAxis, axis: &str) -> Result<HoldGains, AircraftError> {
    use Dimension as D;
    use Range::{NonNegative, Positive};
    let field = |key: &str| format!("hold.{axis}.{key}");
    let gains = HoldGains {
        kp: setting(r, &h.kp, &field("kp"), D::PerAngle, NonNegative(100.0))?,
        ki: setting(r, &h.ki, &field("ki"), D::PerAngleTime, NonNegative(100.0))?,
        kd: setting(r, &h.kd, &field("kd"), D::TimePerAngle, NonNegative(10.0))?,
        output_limit: setting(
            r,
            &h.output_limit,
            &field("output_limit"),
            D::Dimensionless,
            Positive(1.0),
        )?,
        integrator_limit: setting(
            r,
            &h.integrator_limit,
            &field("integrator_limit"),
            D::Dimensionless,
            NonNegative(1.0),
        )?,
        bumpless_time: setting(
            r,
            &h.bumpless_time,
            &field("bumpless_time"),
            D::Time,
            NonNegative(10.0),
        )?,
        release_time: setting(
            r,
            &h.release_time,
            &field("release_time"),
            D::Time,
            NonNegative(10.0),
        )?,
        reversed: h.reversed,
    };
    if let (Some(output), Some(integrator), Some(written)) = (
        gains.output_limit,
        gains.integrator_limit,
        &h.integrator_limit,
    ) {
        if integrator > output {
            return Err(r.error(
                written.span().start,
                &format!("flight_controller.{}", field("integrator_limit")),
                "must not exceed output_limit",
            ));
        }
    }
    Ok(gains)
}

/// An optional setting `flight_controller.KEY`: read in its dimension and range, without σ.
/// A slew table's rates, per control in the order lat, lon, ped (, col): each optional,
/// in (0, 1000] per second; `table` names it in errors (`command_slew.ped`).
fn slew_rates<const N: usize>(
    r: &Reader,
    written: [&Option<Value>; N],
    table: &str,
) -> Result<[Option<f64>; N], AircraftError> {
    let mut out = [None; N];
    for ((slot, value), control) in out.iter_mut().zip(written).zip(CONTROLS) {
        let field = format!("{table}.{control}");
        *slot = setting(
            r,
            value,
            &field,
            Dimension::PerTime,
            Range::Positive(1000.0),
        )?;
    }
    Ok(out)
}

fn setting(
    r: &Reader,
    written: &Option<Value>,
    key: &str,
    dimension: Dimension,
    range: Range,
) -> Result<Option<f64>, AircraftError> {
    let Some(written) = written else {
        return Ok(None);
    };
    let field = format!("flight_controller.{key}");
    let quantity = r.value(written, &field, dimension, range)?;
    exact(r, written, &field, quantity).map(Some)
}

/// A list setting of `N` values, each in its dimension and range, without σ.
fn settings<const N: usize>(
    r: &Reader,
    written: &Values,
    key: &str,
    dimension: Dimension,
    range: Range,
) -> Result<[f64; N], AircraftError> {
    let field = format!("flight_controller.{key}");
    let quantities = r.values::<N>(written, &field, dimension, range)?;
    let mut out = [0.0; N];
    for (k, (slot, quantity)) in out.iter_mut().zip(quantities).enumerate() {
        *slot = exact(r, &written.get_ref()[k], &format!("{field}[{k}]"), quantity)?;
    }
    Ok(out)
}

fn exact(r: &Reader, written: &Value, field: &str, q: Quantity) -> Result<f64, AircraftError> {
    if q.sigma.is_some() {
        return Err(r.error(
            written.span().start,
            field,
            "a flight-controller setting is chosen, not measured: it takes no uncertainty",
        ));
    }
    Ok(q.value)
}
