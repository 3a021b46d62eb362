//! The `[swash]` table: the servo geometry the aircraft is built with — the swashplate
//! type, its phase angle and which servo leads, each swash servo's direction, centre,
//! throw and limits, the tail servo's, and the servos' frame rates.
//!
//! It describes the machine, not a setting: the simulated board's servo pulses reach the
//! simulated rotor through it (`--fc board-sim`), and `sweephold fc params push` turns it
//! into the board's servo parameters. The table is optional; without it the aircraft has
//! the geometry the presets' boards have always flown: a 120° plate with servo 1 in front,
//! no phase angle, standard servos (1520 µs centre, 400 µs per unit height, 1100–1940 µs),
//! frame rates the board's default. Each servo field left out is the standard servo's.
//!
//! Heights are in the mixer's units: the board's default mixer gives a swash height of
//! 0.5 per unit collective and per unit cyclic and a tail height of 1 per unit pedal, and
//! these are the heights at which the aircraft's `[controls]` gearing is stated.

use crate::quantity::Dimension;
use crate::reader::{Range, Reader, DEG};
use crate::schema;
use crate::AircraftError;

/// The plate: a mechanically mixed head or a three-servo CCPM plate of an angle.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SwashKind {
    /// Mechanical mixing: servo 1 lateral, servo 2 longitudinal, servo 3 collective.
    H1,
    /// Three servos, the side servos 120° from the lead servo.
    H3_120,
    /// 135°.
    H3_135,
    /// 140°.
    H3_140,
}

impl SwashKind {
    /// The firmware's `SWASH_TYPE` code: the plate angle, 0 for H1.
    pub fn code(self) -> u16 {
        match self {
            SwashKind::H1 => 0,
            SwashKind::H3_120 => 120,
            SwashKind::H3_135 => 135,
            SwashKind::H3_140 => 140,
        }
    }
}

/// One servo's pulse mapping \[µs\]: pulse = centre ± throw·height, within [min, max].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ServoOutput {
    /// The servo moves the other way (mounted mirrored).
    pub reversed: bool,
    /// Pulse at zero height \[µs\].
    pub centre_us: f64,
    /// Pulse per unit height \[µs\].
    pub throw_us: f64,
    /// Lowest pulse \[µs\].
    pub min_us: f64,
    /// Highest pulse \[µs\].
    pub max_us: f64,
}

impl ServoOutput {
    /// A standard 1520 µs servo: 400 µs per unit height, 1100–1940 µs (the firmware's
    /// `ServoConfig::STANDARD`).
    pub const STANDARD: ServoOutput = ServoOutput {
        reversed: false,
        centre_us: 1520.0,
        throw_us: 400.0,
        min_us: 1100.0,
        max_us: 1940.0,
    };
}

/// The servo geometry of the aircraft.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Swash {
    /// Plate type.
    pub kind: SwashKind,
    /// Phase angle, clockwise positive \[rad\].
    pub phase: f64,
    /// The swash servo on the fore-aft axis (1–3).
    pub lead: u8,
    /// Swash servos 1, 2, 3.
    pub servos: [ServoOutput; 3],
    /// The tail servo.
    pub tail: ServoOutput,
    /// Swash servo frame rate \[Hz\]; `None`: the board's default.
    pub frame_rate: Option<f64>,
    /// Tail servo frame rate \[Hz\]; `None`: the board's default.
    pub tail_frame_rate: Option<f64>,
}

impl Default for Swash {
    /// The presets' geometry: 120°, servo 1 in front, no phase, standard servos.
    fn default() -> Self {
        Swash {
            kind: SwashKind::H3_120,
            phase: 0.0,
            lead: 1,
            servos: [ServoOutput::STANDARD; 3],
            tail: ServoOutput::STANDARD,
            frame_rate: None,
            tail_frame_rate: None,
        }
    }
}

/// Pulses a servo setting may take \[µs\] (the firmware's parameter range).
const PULSE: Range = Range::Between(500.0, 2500.0);
/// Frame rates a servo output may run at \[Hz\] (the firmware's parameter range).
const FRAME_RATE: Range = Range::Between(50.0, 333.0);

/// Read and check the `[swash]` table.
pub(crate) fn read(r: &Reader, s: &schema::Swash) -> Result<Swash, AircraftError> {
    use Dimension as D;
    let kind = match s.kind.get_ref() {
        schema::RawValue::Number(x) if *x == 120.0 => SwashKind::H3_120,
        schema::RawValue::Number(x) if *x == 135.0 => SwashKind::H3_135,
        schema::RawValue::Number(x) if *x == 140.0 => SwashKind::H3_140,
        schema::RawValue::Text(t) if t == "H1" => SwashKind::H1,
        other => {
            let shown = match other {
                schema::RawValue::Number(x) => format!("{x}"),
                schema::RawValue::Text(t) => format!("\"{t}\""),
            };
            return Err(r.error(
                s.kind.span().start,
                "swash.type",
                format!("`{shown}`: expected 120, 135, 140 or \"H1\""),
            ));
        }
    };
    let phase = match &s.phase {
        Some(v) => exact(
            r,
            v,
            "swash.phase",
            r.value(
                v,
                "swash.phase",
                D::Angle,
                Range::Between(-180.0 * DEG, 180.0 * DEG),
            )?,
        )?,
        None => 0.0,
    };
    let lead = match &s.lead {
        Some(v) => {
            let q = r.value(v, "swash.lead", D::Dimensionless, Range::Between(1.0, 3.0))?;
            whole(r, v, "swash.lead", exact(r, v, "swash.lead", q)?)? as u8
        }
        None => 1,
    };
    let mut servos = [ServoOutput::STANDARD; 3];
    if let Some(written) = &s.servos {
        let list = written.get_ref();
        if list.len() != 3 {
            return Err(r.error(
                written.span().start,
                "swash.servos",
                format!("expected 3 servos (outputs 1, 2, 3), found {}", list.len()),
            ));
        }
        for (k, (slot, servo)) in servos.iter_mut().zip(list).enumerate() {
            *slot = servo_output(r, servo, &format!("swash.servos[{k}]"))?;
        }
    }
    let tail = match &s.tail {
        Some(servo) => servo_output(r, servo, "swash.tail")?,
        None => ServoOutput::STANDARD,
    };
    let rate = |written: &Option<schema::Value>, field: &str| -> Result<_, AircraftError> {
        match written {
            Some(v) => {
                let q = r.value(v, field, D::Frequency, FRAME_RATE)?;
                Ok(Some(whole(r, v, field, exact(r, v, field, q)?)?))
            }
            None => Ok(None),
        }
    };
    Ok(Swash {
        kind,
        phase,
        lead,
        servos,
        tail,
        frame_rate: rate(&s.frame_rate, "swash.frame_rate")?,
        tail_frame_rate: rate(&s.tail_frame_rate, "swash.tail_frame_rate")?,
    })
}

fn servo_output(
    r: &Reader,
    s: &schema::ServoOutput,
    table: &str,
) -> Result<ServoOutput, AircraftError> {
    let standard = ServoOutput::STANDARD;
    let pulse = |written: &Option<schema::Value>, key: &str, range: Range, default: f64| {
        let field = format!("{table}.{key}");
        match written {
            Some(v) => {
                let q = r.value(v, &field, Dimension::PulseWidth, range)?;
                exact(r, v, &field, q)
            }
            None => Ok(default),
        }
    };
    let whole_pulse = |written: &Option<schema::Value>, key: &str, default: f64| {
        let value = pulse(written, key, PULSE, default)?;
        match written {
            Some(v) => whole(r, v, &format!("{table}.{key}"), value),
            None => Ok(value),
        }
    };
    let servo = ServoOutput {
        reversed: s.reversed.unwrap_or(false),
        centre_us: whole_pulse(&s.centre, "centre", standard.centre_us)?,
        throw_us: pulse(
            &s.throw,
            "throw",
            Range::Positive(1000.0),
            standard.throw_us,
        )?,
        min_us: whole_pulse(&s.min, "min", standard.min_us)?,
        max_us: whole_pulse(&s.max, "max", standard.max_us)?,
    };
    if !(servo.min_us < servo.max_us
        && servo.min_us <= servo.centre_us
        && servo.centre_us <= servo.max_us)
    {
        let place = s
            .min
            .as_ref()
            .or(s.max.as_ref())
            .or(s.centre.as_ref())
            .map_or(0, |v| v.span().start);
        return Err(r.error(
            place,
            table,
            format!(
                "min {} µs, centre {} µs, max {} µs: the limits must surround the centre \
                 (min < max; state min and max for a servo not centred at 1520 µs)",
                servo.min_us, servo.centre_us, servo.max_us
            ),
        ));
    }
    Ok(servo)
}

fn exact(
    r: &Reader,
    written: &schema::Value,
    field: &str,
    q: crate::Quantity,
) -> Result<f64, AircraftError> {
    if q.sigma.is_some() {
        return Err(r.error(
            written.span().start,
            field,
            "the servo geometry is set, not measured: it takes no uncertainty",
        ));
    }
    Ok(q.value)
}

fn whole(r: &Reader, written: &schema::Value, field: &str, x: f64) -> Result<f64, AircraftError> {
    if x.fract() != 0.0 {
        return Err(r.error(
            written.span().start,
            field,
            format!("{x} is not a whole number"),
        ));
    }
    Ok(x)
}
