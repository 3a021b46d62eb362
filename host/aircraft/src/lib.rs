//! Aircraft files: one description of a helicopter — airframe, main and tail rotor, fin
//! and tailplane, control gearing, servos — that the simulator flies and the
//! identification takes its a-priori constants from.
//!
//! A file is TOML (format, field by field with units: `docs/formats.md`, "Aircraft
//! files"). Every dimensional value is written with its unit and may carry its standard
//! uncertainty σ (`"0.12 ± 0.01 kg*m^2"`); reading it checks units, ranges and the
//! consistency between values (inertia triangle inequalities, tip speeds, blade count),
//! and any problem is one line naming the file, line and field.
//!
//! The shipped aircraft (`bo105`, `trex700l`, `fbl700`) are files in this crate's `vehicles/`
//! folder, compiled in ([`shipped`]); [`resolve`] takes a shipped name or the path of a
//! user's file.
//!
//! **Its room and what it may import.** The description of an aircraft and its checks,
//! nothing that flies or identifies one. serde, toml and thiserror; no other crate of the
//! workspace.
//! The simulator, the identification's priors and the command-line tool import it.
#![forbid(unsafe_code)]
#![warn(missing_docs)]

mod check;
mod flight_controller;
pub mod quantity;
mod reader;
mod schema;
mod swash;

use std::path::{Path, PathBuf};

pub use flight_controller::{
    CollectiveSource, FlightController, HoldGains, HoldReference, FIRMWARE_PRESETS,
};
pub use quantity::{Dimension, Quantity};
pub use swash::{ServoOutput, Swash, SwashKind};

/// A helicopter as its aircraft file describes it. Values in SI units, body axes x
/// forward, y right, z down, positions from the centre of gravity (CG).
#[derive(Clone, Debug, PartialEq)]
pub struct Aircraft {
    /// Short name, as on the command line (`trex700l`).
    pub name: String,
    /// Display name (`TREX 700L class`); the name when the file gives none.
    pub title: String,
    /// One line on what it is.
    pub description: String,
    /// Air density ρ and gravity g.
    pub environment: Environment,
    /// Mass, inertias, fuselage drag.
    pub airframe: Airframe,
    /// Main rotor.
    pub main_rotor: MainRotor,
    /// Tail rotor.
    pub tail_rotor: TailRotor,
    /// Vertical fin.
    pub fin: Surface,
    /// Horizontal tailplane.
    pub tailplane: Surface,
    /// Stick → blade pitch gearing per control.
    pub controls: Controls,
    /// The swashplate and tail servos.
    pub servos: Servos,
    /// The servo geometry (`[swash]`; the presets' 120° plate when the file has none).
    pub swash: Swash,
    /// What the flight controller flies.
    pub flight_controller: FlightController,
    /// How the campaign identifies it.
    pub identification: Identification,
}

impl Aircraft {
    /// Every physical value of the file, each with its σ, in file order: for a caller that
    /// propagates the file's uncertainties by varying one value at a time.
    pub fn quantities_mut(&mut self) -> Vec<&mut Quantity> {
        let Aircraft {
            environment: e,
            airframe: a,
            main_rotor: m,
            tail_rotor: t,
            fin,
            tailplane,
            controls: c,
            servos: s,
            ..
        } = self;
        let mut all = vec![&mut e.air_density, &mut e.gravity];
        all.extend([&mut a.mass, &mut a.ixx, &mut a.iyy, &mut a.izz, &mut a.ixz]);
        all.extend(a.drag_area.iter_mut());
        all.extend([
            &mut m.radius,
            &mut m.head_speed,
            &mut m.chord,
            &mut m.twist,
            &mut m.lift_slope,
            &mut m.flap_inertia,
            &mut m.hub_stiffness,
        ]);
        all.extend(m.profile_drag.iter_mut());
        all.extend(m.hub.iter_mut());
        all.push(&mut m.shaft_tilt);
        all.extend([&mut t.radius, &mut t.speed, &mut t.chord, &mut t.twist]);
        all.push(&mut t.lift_slope);
        all.extend(t.profile_drag.iter_mut());
        all.extend(t.hub.iter_mut());
        for surface in [fin, tailplane] {
            all.extend([
                &mut surface.area,
                &mut surface.incidence,
                &mut surface.lift_slope,
                &mut surface.stall_angle,
            ]);
            all.extend(surface.position.iter_mut());
        }
        for gearing in [&mut c.lat, &mut c.lon, &mut c.ped, &mut c.col] {
            all.extend([&mut gearing.centre, &mut gearing.per_stick]);
        }
        all.extend([
            &mut s.natural_frequency,
            &mut s.damping,
            &mut s.rate_limit,
            &mut s.transport_delay,
        ]);
        all
    }
}

/// The campaign's settings for this aircraft.
#[derive(Clone, Debug, PartialEq)]
pub struct Identification {
    /// The two sweep bands flown per axis, [ω_min, ω_max] rad/s each: the first is the
    /// record the responses come from above ω_min of the second.
    pub sweep_bands: [[f64; 2]; 2],
    /// The shipped 9-DOF hybrid structure fitted (its vehicle constants come from this
    /// file), e.g. `trex700l-9dof-hybrid`.
    pub structure: String,
    /// How the trim-derived hover derivatives enter the 9-DOF fit.
    pub trim_balance: TrimBalance,
    /// Where the frequency responses' valid ranges come from.
    pub valid_ranges: ValidRanges,
}

/// How the trim-derived hover derivatives enter the fit.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TrimBalance {
    /// Derived from the trim points' steady balance and held.
    Hold,
    /// Fitted jointly with the responses under the balances' cost.
    Joint,
}

/// Where the valid frequency ranges come from.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ValidRanges {
    /// The estimate's own coherence and random error.
    Estimate,
    /// The sweep-reference estimate's, which leave out where an engaged hold, not the
    /// sweep, drives the swept control.
    SweepReference,
}

/// Where the aircraft flies.
#[derive(Clone, Debug, PartialEq)]
pub struct Environment {
    /// Air density ρ [kg/m³].
    pub air_density: Quantity,
    /// Gravity g [m/s²].
    pub gravity: Quantity,
}

/// Mass properties and fuselage drag.
#[derive(Clone, Debug, PartialEq)]
pub struct Airframe {
    /// Mass \[kg\].
    pub mass: Quantity,
    /// Roll inertia I_xx [kg·m²].
    pub ixx: Quantity,
    /// Pitch inertia I_yy [kg·m²].
    pub iyy: Quantity,
    /// Yaw inertia I_zz [kg·m²].
    pub izz: Quantity,
    /// Product of inertia I_xz [kg·m²] (positive: principal axis nose-down of x).
    pub ixz: Quantity,
    /// Equivalent flat-plate drag areas along x, y, z \[m²\].
    pub drag_area: [Quantity; 3],
}

/// Which way a rotor turns, seen from above.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Rotation {
    /// Anticlockwise seen from above (the tail rotor pushes to the right).
    Counterclockwise,
}

/// The main rotor.
#[derive(Clone, Debug, PartialEq)]
pub struct MainRotor {
    /// Radius R \[m\].
    pub radius: Quantity,
    /// Rotor speed Ω [rad/s].
    pub head_speed: Quantity,
    /// Direction of rotation.
    pub rotation: Rotation,
    /// Number of blades.
    pub blades: u32,
    /// Blade chord \[m\].
    pub chord: Quantity,
    /// Linear twist root to tip \[rad\] (negative: washout).
    pub twist: Quantity,
    /// Blade lift-curve slope [1/rad].
    pub lift_slope: Quantity,
    /// Blade flap moment of inertia about the hub [kg·m²].
    pub flap_inertia: Quantity,
    /// Equivalent centre-spring hub stiffness per blade [N·m/rad].
    pub hub_stiffness: Quantity,
    /// Profile drag coefficients δ = δ0 + δ2·C_T².
    pub profile_drag: [Quantity; 2],
    /// Hub position from the CG \[m\].
    pub hub: [Quantity; 3],
    /// Forward tilt of the shaft \[rad\] (top of the shaft forward).
    pub shaft_tilt: Quantity,
}

/// The tail rotor.
#[derive(Clone, Debug, PartialEq)]
pub struct TailRotor {
    /// Radius \[m\].
    pub radius: Quantity,
    /// Rotor speed [rad/s] (given, or the main rotor's times the gear ratio).
    pub speed: Quantity,
    /// Number of blades.
    pub blades: u32,
    /// Blade chord \[m\].
    pub chord: Quantity,
    /// Linear twist \[rad\].
    pub twist: Quantity,
    /// Blade lift-curve slope [1/rad].
    pub lift_slope: Quantity,
    /// Profile drag coefficients δ0, δ2.
    pub profile_drag: [Quantity; 2],
    /// Hub position from the CG \[m\].
    pub hub: [Quantity; 3],
}

/// A lifting surface.
#[derive(Clone, Debug, PartialEq)]
pub struct Surface {
    /// Area \[m²\].
    pub area: Quantity,
    /// Incidence \[rad\].
    pub incidence: Quantity,
    /// Lift-curve slope [1/rad].
    pub lift_slope: Quantity,
    /// Position from the CG \[m\].
    pub position: [Quantity; 3],
    /// Angle of attack where the linear lift stops growing \[rad\].
    pub stall_angle: Quantity,
}

/// Blade pitch = centre + per_stick·stick, stick fraction in [−1, 1].
#[derive(Clone, Debug, PartialEq)]
pub struct Gearing {
    /// Blade pitch at centred stick \[rad\].
    pub centre: Quantity,
    /// Blade pitch per unit stick \[rad\].
    pub per_stick: Quantity,
}

/// The gearing of the four controls: lat → θ1c, lon → θ1s, ped → tail θ0, col → θ0.
#[derive(Clone, Debug, PartialEq)]
pub struct Controls {
    /// Lateral cyclic.
    pub lat: Gearing,
    /// Longitudinal cyclic.
    pub lon: Gearing,
    /// Pedal (tail-rotor collective).
    pub ped: Gearing,
    /// Collective.
    pub col: Gearing,
}

/// The servos, as a second-order lag with a rate limit after a transport delay, acting on
/// the stick fractions.
#[derive(Clone, Debug, PartialEq)]
pub struct Servos {
    /// Natural frequency ω_n [rad/s].
    pub natural_frequency: Quantity,
    /// Damping ratio ζ.
    pub damping: Quantity,
    /// Rate limit [stick fraction per second] (full travel is 2).
    pub rate_limit: Quantity,
    /// Transport delay \[s\].
    pub transport_delay: Quantity,
}

/// Why an aircraft file could not be read. Every message is one line.
#[derive(Debug, thiserror::Error)]
pub enum AircraftError {
    /// The file could not be read.
    #[error("{}: {error}", .path.display())]
    Io {
        /// The file.
        path: PathBuf,
        /// The cause.
        error: std::io::Error,
    },
    /// A value, key or table is wrong; `field` is its dotted path (`airframe.mass`).
    #[error("{source_name}:{line}: {field}: {message}")]
    Field {
        /// The file.
        source_name: String,
        /// 1-based line.
        line: usize,
        /// Dotted path of the field.
        field: String,
        /// What is wrong.
        message: String,
    },
    /// The file is not TOML, or a key is unknown or missing.
    #[error("{source_name}:{line}: {message}")]
    Syntax {
        /// The file.
        source_name: String,
        /// 1-based line (1 when the parser gives no place).
        line: usize,
        /// The parser's message.
        message: String,
    },
    /// A name that is neither a shipped aircraft nor an existing file.
    #[error("unknown vehicle `{0}`: expected {names} or the path of an aircraft file", names = SHIPPED.iter().map(|(name, _)| *name).collect::<Vec<_>>().join(", "))]
    Unknown(String),
}

/// The shipped aircraft files, by name.
pub const SHIPPED: [(&str, &str); 3] = [
    ("bo105", include_str!("../vehicles/bo105.toml")),
    ("trex700l", include_str!("../vehicles/trex700l.toml")),
    ("fbl700", include_str!("../vehicles/fbl700.toml")),
];

/// A shipped aircraft by name (`bo105`, `trex700l`, `fbl700`; case-insensitive, `bo-105` and
/// `trex700` accepted), `None` for another name.
pub fn shipped(name: &str) -> Option<Aircraft> {
    let name = match name.to_ascii_lowercase().as_str() {
        "bo-105" => "bo105".to_string(),
        "trex700" | "trex-700l" => "trex700l".to_string(),
        other => other.to_string(),
    };
    let (file_name, text) = SHIPPED.iter().find(|(shipped, _)| *shipped == name)?;
    // The shipped files are checked by this crate's tests: reading one cannot fail.
    Some(parse(text, &format!("{file_name}.toml")).expect("shipped aircraft file reads"))
}

/// A shipped aircraft by name, else the aircraft file at that path.
pub fn resolve(name_or_path: &str) -> Result<Aircraft, AircraftError> {
    if let Some(aircraft) = shipped(name_or_path) {
        return Ok(aircraft);
    }
    let path = Path::new(name_or_path);
    let looks_like_a_file = path.extension().is_some() || name_or_path.contains('/');
    if looks_like_a_file || path.exists() {
        load(path)
    } else {
        Err(AircraftError::Unknown(name_or_path.to_string()))
    }
}

/// Read an aircraft file.
pub fn load(path: &Path) -> Result<Aircraft, AircraftError> {
    let text = std::fs::read_to_string(path).map_err(|error| AircraftError::Io {
        path: path.to_path_buf(),
        error,
    })?;
    parse(&text, &path.display().to_string())
}

/// Read aircraft-file text; `source_name` names it in messages.
pub fn parse(text: &str, source_name: &str) -> Result<Aircraft, AircraftError> {
    let file: schema::File = toml::from_str(text).map_err(|error| AircraftError::Syntax {
        source_name: source_name.to_string(),
        line: error.span().map_or(1, |span| line_of(text, span.start)),
        message: error.message().trim().replace('\n', " "),
    })?;
    check::aircraft(&file, text, source_name)
}

/// 1-based line of a byte offset.
pub(crate) fn line_of(text: &str, offset: usize) -> usize {
    text.as_bytes()[..offset.min(text.len())]
        .iter()
        .filter(|&&b| b == b'\n')
        .count()
        + 1
}
