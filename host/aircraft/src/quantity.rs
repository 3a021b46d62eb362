//! Physical values as an aircraft file writes them: a number, its unit, and optionally its
//! standard uncertainty — `"5.0 kg"`, `"1900 rpm"`, `"0.12 ± 0.01 kg*m^2"` (`+-` works as
//! `±`). Every dimensional value carries its unit, so a value in the wrong unit is refused
//! (`"5 m"` for a mass) instead of silently read in another scale. Dimensionless values
//! (blade count, damping ratio, drag coefficients) are bare numbers.
//!
//! Conversions multiply by the unit's factor to SI (rpm: `x·2·π/60`, degrees: `x·π/180`),
//! in that order of operations, so a value written in the file gives bit for bit the
//! number the same conversion gives in code.

use std::f64::consts::PI;

/// A value in SI units and its standard uncertainty σ (same unit), when the file gives one.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Quantity {
    /// The value, SI.
    pub value: f64,
    /// Standard uncertainty σ ≥ 0, SI; `None` when the file states none.
    pub sigma: Option<f64>,
}

impl Quantity {
    /// A value without uncertainty.
    pub fn exact(value: f64) -> Quantity {
        Quantity { value, sigma: None }
    }
}

/// What a value measures: which units it may be written in.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Dimension {
    /// kg.
    Mass,
    /// m.
    Length,
    /// m².
    Area,
    /// kg·m².
    Inertia,
    /// rad.
    Angle,
    /// rad/s.
    AngularSpeed,
    /// kg/m³.
    Density,
    /// m/s².
    Acceleration,
    /// 1/rad (a lift-curve slope).
    PerAngle,
    /// N·m/rad (a hub spring).
    Stiffness,
    /// 1/(rad·s) (an integral gain: stick fraction per radian-second).
    PerAngleTime,
    /// s/rad (a rate gain: stick fraction per rad/s).
    TimePerAngle,
    /// s.
    Time,
    /// 1/s (a rate of a dimensionless quantity, e.g. stick fraction per second).
    PerTime,
    /// A servo pulse width, kept in µs (the servo world's unit, exact for whole µs).
    PulseWidth,
    /// Hz (a frame rate).
    Frequency,
    /// A bare number.
    Dimensionless,
}

impl Dimension {
    /// Units accepted, with their factor to SI, as written after normalization (spaces and
    /// `·` become `*`, `²`/`³` become `^2`/`^3`). The first is the SI unit.
    fn units(self) -> &'static [(&'static str, Factor)] {
        use Factor::{Degrees, Per, Rpm, Si};
        match self {
            Dimension::Mass => &[("kg", Si), ("g", Per(1e3))],
            Dimension::Length => &[("m", Si), ("cm", Per(1e2)), ("mm", Per(1e3))],
            Dimension::Area => &[("m^2", Si), ("cm^2", Per(1e4)), ("mm^2", Per(1e6))],
            Dimension::Inertia => &[("kg*m^2", Si), ("g*cm^2", Per(1e7)), ("kg*cm^2", Per(1e4))],
            Dimension::Angle => &[("rad", Si), ("deg", Degrees), ("°", Degrees)],
            Dimension::AngularSpeed => &[("rad/s", Si), ("rpm", Rpm), ("deg/s", Degrees)],
            Dimension::Density => &[("kg/m^3", Si)],
            Dimension::Acceleration => &[("m/s^2", Si)],
            Dimension::PerAngle => &[("/rad", Si), ("1/rad", Si)],
            Dimension::Stiffness => &[("N*m/rad", Si)],
            Dimension::PerAngleTime => &[("/(rad*s)", Si), ("1/(rad*s)", Si)],
            Dimension::TimePerAngle => &[("s/rad", Si)],
            Dimension::Time => &[("s", Si), ("ms", Per(1e3))],
            Dimension::PerTime => &[("/s", Si), ("1/s", Si)],
            Dimension::PulseWidth => &[("us", Si), ("µs", Si)],
            Dimension::Frequency => &[("Hz", Si)],
            Dimension::Dimensionless => &[],
        }
    }

    /// The accepted units, for messages.
    fn unit_list(self) -> String {
        self.units()
            .iter()
            .map(|(unit, _)| *unit)
            .collect::<Vec<_>>()
            .join(", ")
    }
}

/// How a unit converts to SI.
#[derive(Clone, Copy, Debug)]
enum Factor {
    /// Already SI.
    Si,
    /// Divide by this (a unit a power of ten smaller than SI: `5600 g` is 5.6 kg to the
    /// last bit, which `5600·0.001` is not).
    Per(f64),
    /// Degrees: `x·π/180`.
    Degrees,
    /// Revolutions per minute: `x·2·π/60`.
    Rpm,
}

impl Factor {
    fn to_si(self, x: f64) -> f64 {
        match self {
            Factor::Si => x,
            Factor::Per(divisor) => x / divisor,
            Factor::Degrees => x * (PI / 180.0),
            Factor::Rpm => x * 2.0 * PI / 60.0,
        }
    }
}

/// A value as the file writes it: a number, or text with a number, σ and unit.
#[derive(Clone, Debug, PartialEq)]
pub enum Written {
    /// A bare number (dimensionless values only).
    Number(f64),
    /// `"VALUE [± SIGMA] UNIT"`.
    Text(String),
}

/// Read a written value of the given dimension. The message says what is wrong and what
/// is expected; the caller adds the field and line.
pub fn read(written: &Written, dimension: Dimension) -> Result<Quantity, String> {
    match written {
        Written::Number(x) if dimension == Dimension::Dimensionless => {
            finite(*x, "value").map(Quantity::exact)
        }
        Written::Number(x) => Err(format!(
            "`{x}` has no unit: write it as a string with one of {} (e.g. \"{x} {}\")",
            dimension.unit_list(),
            dimension.units()[0].0
        )),
        Written::Text(text) => read_text(text, dimension),
    }
}

fn finite(x: f64, what: &str) -> Result<f64, String> {
    if x.is_finite() {
        Ok(x)
    } else {
        Err(format!("the {what} is not a finite number"))
    }
}

fn read_text(text: &str, dimension: Dimension) -> Result<Quantity, String> {
    let normalized = text.replace('±', " +- ");
    let mut words = normalized.split_whitespace();
    let number = |word: Option<&str>, what: &str| -> Result<f64, String> {
        let word = word.ok_or_else(|| format!("`{text}`: no {what}"))?;
        let x: f64 = word
            .parse()
            .map_err(|_| format!("`{text}`: `{word}` is not a number"))?;
        finite(x, what)
    };
    let value = number(words.next(), "value")?;
    let rest: Vec<&str> = words.collect();
    let (sigma, unit_words) = match rest.first() {
        Some(&"+-") => (
            Some(number(rest.get(1).copied(), "uncertainty after ±")?),
            &rest[2.min(rest.len())..],
        ),
        _ => (None, &rest[..]),
    };
    if let Some(sigma) = sigma {
        if sigma < 0.0 {
            return Err(format!("`{text}`: the uncertainty must not be negative"));
        }
    }
    let unit = normalize_unit(&unit_words.join(" "));
    if dimension == Dimension::Dimensionless {
        if !unit.is_empty() {
            return Err(format!("`{text}`: a dimensionless value takes no unit"));
        }
        return Ok(Quantity { value, sigma });
    }
    if unit.is_empty() {
        return Err(format!(
            "`{text}` has no unit: expected one of {}",
            dimension.unit_list()
        ));
    }
    let factor = dimension
        .units()
        .iter()
        .find(|(name, _)| *name == unit)
        .map(|(_, factor)| *factor)
        .ok_or_else(|| {
            format!(
                "`{text}`: unit `{unit}` is not one of {}",
                dimension.unit_list()
            )
        })?;
    Ok(Quantity {
        value: factor.to_si(value),
        sigma: sigma.map(|s| factor.to_si(s)),
    })
}

/// `kg m²` → `kg*m^2`, `N·m/rad` → `N*m/rad`.
fn normalize_unit(unit: &str) -> String {
    unit.trim()
        .replace('²', "^2")
        .replace('³', "^3")
        .replace('·', "*")
        .split_whitespace()
        .collect::<Vec<_>>()
        .join("*")
}

#[cfg(test)]
mod tests {
    use super::*;

    fn text(s: &str, dimension: Dimension) -> Result<Quantity, String> {
        read(&Written::Text(s.into()), dimension)
    }

    #[test]
    fn units_convert_to_si_as_the_code_would() {
        let rpm = text("1900 rpm", Dimension::AngularSpeed).unwrap();
        assert_eq!(rpm.value, 1900.0 * 2.0 * PI / 60.0);
        let deg = text("-8 deg", Dimension::Angle).unwrap();
        assert_eq!(deg.value, -8.0 * (PI / 180.0));
        let mm = text("780 mm", Dimension::Length).unwrap();
        assert!((mm.value - 0.78).abs() < 1e-15);
        let inertia = text("0.12 ± 0.01 kg m²", Dimension::Inertia).unwrap();
        assert_eq!(
            inertia,
            Quantity {
                value: 0.12,
                sigma: Some(0.01)
            }
        );
        let spring = text("350 +- 50 N·m/rad", Dimension::Stiffness).unwrap();
        assert_eq!(spring.sigma, Some(50.0));
        let sigma_deg = text("2 ± 0.5 deg", Dimension::Angle).unwrap();
        assert_eq!(sigma_deg.sigma, Some(0.5 * (PI / 180.0)));
    }

    #[test]
    fn a_wrong_or_missing_unit_is_refused_with_the_accepted_ones() {
        let wrong = text("5 m", Dimension::Mass).unwrap_err();
        assert!(wrong.contains("unit `m` is not one of kg, g"), "{wrong}");
        let bare = read(&Written::Number(5.0), Dimension::Mass).unwrap_err();
        assert!(bare.contains("has no unit"), "{bare}");
        let none = text("5", Dimension::Mass).unwrap_err();
        assert!(none.contains("has no unit"), "{none}");
        assert!(text("nan kg", Dimension::Mass).is_err());
        assert!(text("inf kg", Dimension::Mass).is_err());
        assert!(text("5 ± -1 kg", Dimension::Mass).is_err());
        assert!(text("5 ± kg", Dimension::Mass).is_err());
        assert!(text("2 blades", Dimension::Dimensionless).is_err());
        assert_eq!(
            read(&Written::Number(0.7), Dimension::Dimensionless).unwrap(),
            Quantity::exact(0.7)
        );
    }
}
