//! The aircraft file's tables and keys exactly as written, before units and ranges are
//! checked: every value keeps its place in the file ([`Spanned`]) so that a later check
//! can name the line. Unknown keys and missing keys are refused here, by serde.

use serde::Deserialize;
use toml::Spanned;

use crate::quantity::Written;

/// A written value with its place in the file.
pub(crate) type Value = Spanned<RawValue>;
/// A written list of values with its place in the file.
pub(crate) type Values = Spanned<Vec<Value>>;

/// A number or a string, as TOML holds it.
#[derive(Clone, Debug, Deserialize)]
#[serde(untagged)]
pub(crate) enum RawValue {
    Number(f64),
    Text(String),
}

impl RawValue {
    pub(crate) fn written(&self) -> Written {
        match self {
            RawValue::Number(x) => Written::Number(*x),
            RawValue::Text(text) => Written::Text(text.clone()),
        }
    }
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct File {
    pub name: Spanned<String>,
    pub title: Option<String>,
    #[serde(default)]
    pub description: String,
    pub environment: Environment,
    pub airframe: Airframe,
    pub main_rotor: MainRotor,
    pub tail_rotor: TailRotor,
    pub fin: Surface,
    pub tailplane: Surface,
    pub controls: Controls,
    pub servos: Servos,
    pub swash: Option<Swash>,
    pub flight_controller: FlightController,
    pub identification: Identification,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct FlightController {
    pub preset: Spanned<String>,
    pub hold_reference: Option<Spanned<String>>,
    pub collective: Option<Spanned<String>>,
    pub hold_engage: Option<Value>,
    pub hold_release: Option<Value>,
    pub pulse_width: Option<Value>,
    pub excitation_scale: Option<Values>,
    pub command_slew: Option<PerControl>,
    pub hold_slew: Option<PerHeldAxis>,
    pub attitude_limit: Option<Value>,
    pub rate_limits: Option<Values>,
    pub pilot_override: Option<Value>,
    pub hold: Option<Hold>,
}

/// A value per control, each optional.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct PerControl {
    pub lat: Option<Value>,
    pub lon: Option<Value>,
    pub ped: Option<Value>,
    pub col: Option<Value>,
}

/// A value per held axis (lat, lon, ped), each optional.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct PerHeldAxis {
    pub lat: Option<Value>,
    pub lon: Option<Value>,
    pub ped: Option<Value>,
}

/// The attitude hold's gains of the three held axes, each optional.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct Hold {
    pub lat: Option<HoldAxis>,
    pub lon: Option<HoldAxis>,
    pub ped: Option<HoldAxis>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct HoldAxis {
    pub kp: Option<Value>,
    pub ki: Option<Value>,
    pub kd: Option<Value>,
    pub output_limit: Option<Value>,
    pub integrator_limit: Option<Value>,
    pub bumpless_time: Option<Value>,
    pub release_time: Option<Value>,
    pub reversed: Option<bool>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct Identification {
    pub sweep_bands: Spanned<Vec<Values>>,
    pub structure: Spanned<String>,
    pub trim_balance: Spanned<String>,
    pub valid_ranges: Spanned<String>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct Environment {
    pub air_density: Value,
    pub gravity: Value,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct Airframe {
    pub mass: Value,
    pub ixx: Value,
    pub iyy: Value,
    pub izz: Value,
    pub ixz: Value,
    pub drag_area: Values,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct MainRotor {
    pub radius: Value,
    pub head_speed: Value,
    pub rotation: Spanned<String>,
    pub blades: Value,
    pub chord: Value,
    pub twist: Value,
    pub lift_slope: Value,
    pub flap_inertia: Value,
    pub hub_stiffness: Value,
    pub profile_drag: Values,
    pub hub: Values,
    pub shaft_tilt: Value,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct TailRotor {
    pub radius: Value,
    pub speed: Option<Value>,
    pub gear_ratio: Option<Value>,
    pub blades: Value,
    pub chord: Value,
    pub twist: Value,
    pub lift_slope: Value,
    pub profile_drag: Values,
    pub hub: Values,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct Surface {
    pub area: Value,
    pub incidence: Value,
    pub lift_slope: Value,
    pub position: Values,
    pub stall_angle: Value,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct Controls {
    pub lat: Gearing,
    pub lon: Gearing,
    pub ped: Gearing,
    pub col: Gearing,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct Gearing {
    pub centre: Value,
    pub per_stick: Value,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct Servos {
    pub natural_frequency: Value,
    pub damping: Value,
    pub rate_limit: Value,
    pub transport_delay: Value,
}

/// The `[swash]` table: the servo geometry the aircraft is built with.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct Swash {
    #[serde(rename = "type")]
    pub kind: Value,
    pub phase: Option<Value>,
    pub lead: Option<Value>,
    pub servos: Option<Spanned<Vec<ServoOutput>>>,
    pub tail: Option<ServoOutput>,
    pub frame_rate: Option<Value>,
    pub tail_frame_rate: Option<Value>,
}

/// One servo output of the `[swash]` table.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct ServoOutput {
    pub reversed: Option<bool>,
    pub centre: Option<Value>,
    pub throw: Option<Value>,
    pub min: Option<Value>,
    pub max: Option<Value>,
}
