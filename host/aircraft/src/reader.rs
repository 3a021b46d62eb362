//! Reading one file's written values: each value in its dimension, checked against its
//! range, with every error naming the file, line and field. Shared by the physical tables
//! (`check`) and the flight controller's settings (`flight_controller`).

use std::f64::consts::PI;

use crate::quantity::{self, Dimension, Quantity};
use crate::schema::{self, Value, Values};
use crate::{AircraftError, Gearing, Surface};

pub(crate) const DEG: f64 = PI / 180.0;

/// The range a value must lie in.
#[derive(Clone, Copy)]
pub(crate) enum Range {
    /// (0, max].
    Positive(f64),
    /// [0, max].
    NonNegative(f64),
    /// [min, max].
    Between(f64, f64),
}

impl Range {
    fn admits(self, x: f64) -> bool {
        match self {
            Range::Positive(max) => x > 0.0 && x <= max,
            Range::NonNegative(max) => (0.0..=max).contains(&x),
            Range::Between(min, max) => (min..=max).contains(&x),
        }
    }

    fn describe(self, dimension: Dimension) -> String {
        let unit = si_unit(dimension);
        match self {
            Range::Positive(max) => format!("must be positive and at most {max} {unit}"),
            Range::NonNegative(max) => format!("must be between 0 and {max} {unit}"),
            Range::Between(min, max) => format!("must be between {min} and {max} {unit}"),
        }
    }

    /// Only a value that must be positive has a σ that can exceed it meaningfully: a
    /// signed value (a position, an angle) may be 0 ± σ.
    fn must_exceed_sigma(self) -> bool {
        matches!(self, Range::Positive(_))
    }
}

fn si_unit(dimension: Dimension) -> &'static str {
    match dimension {
        Dimension::Mass => "kg",
        Dimension::Length => "m",
        Dimension::Area => "m^2",
        Dimension::Inertia => "kg*m^2",
        Dimension::Angle => "rad",
        Dimension::AngularSpeed => "rad/s",
        Dimension::Density => "kg/m^3",
        Dimension::Acceleration => "m/s^2",
        Dimension::PerAngle => "/rad",
        Dimension::Stiffness => "N*m/rad",
        Dimension::PerAngleTime => "/(rad*s)",
        Dimension::TimePerAngle => "s/rad",
        Dimension::Time => "s",
        Dimension::PerTime => "/s",
        Dimension::PulseWidth => "us",
        Dimension::Frequency => "Hz",
        Dimension::Dimensionless => "",
    }
}

/// Reads values of one file, naming file, line and field in every error.
pub(crate) struct Reader<'a> {
    pub(crate) text: &'a str,
    pub(crate) source_name: &'a str,
}

impl Reader<'_> {
    pub(crate) fn error(
        &self,
        offset: usize,
        field: &str,
        message: impl Into<String>,
    ) -> AircraftError {
        AircraftError::Field {
            source_name: self.source_name.to_string(),
            line: crate::line_of(self.text, offset),
            field: field.to_string(),
            message: message.into(),
        }
    }

    pub(crate) fn value(
        &self,
        written: &Value,
        field: &str,
        dimension: Dimension,
        range: Range,
    ) -> Result<Quantity, AircraftError> {
        let offset = written.span().start;
        let quantity = quantity::read(&written.get_ref().written(), dimension)
            .map_err(|message| self.error(offset, field, message))?;
        if !range.admits(quantity.value) {
            return Err(self.error(
                offset,
                field,
                format!("{} {}", show(quantity.value), range.describe(dimension)),
            ));
        }
        if let Some(sigma) = quantity.sigma {
            if range.must_exceed_sigma() && sigma >= quantity.value {
                return Err(self.error(
                    offset,
                    field,
                    format!(
                        "the uncertainty {} is not smaller than the value {}",
                        show(sigma),
                        show(quantity.value)
                    ),
                ));
            }
        }
        Ok(quantity)
    }

    pub(crate) fn values<const N: usize>(
        &self,
        written: &Values,
        field: &str,
        dimension: Dimension,
        range: Range,
    ) -> Result<[Quantity; N], AircraftError> {
        let list = written.get_ref();
        if list.len() != N {
            return Err(self.error(
                written.span().start,
                field,
                format!("expected {N} values, found {}", list.len()),
            ));
        }
        let mut out = [Quantity::exact(0.0); N];
        for (i, (slot, value)) in out.iter_mut().zip(list).enumerate() {
            *slot = self.value(value, &format!("{field}[{i}]"), dimension, range)?;
        }
        Ok(out)
    }

    pub(crate) fn blades(&self, written: &Value, field: &str) -> Result<u32, AircraftError> {
        let count = self.value(
            written,
            field,
            Dimension::Dimensionless,
            Range::Between(1.0, 12.0),
        )?;
        if count.value.fract() != 0.0 || count.sigma.is_some() {
            return Err(self.error(
                written.span().start,
                field,
                format!("{} is not a whole number of blades", show(count.value)),
            ));
        }
        Ok(count.value as u32)
    }

    pub(crate) fn position(
        &self,
        written: &Values,
        field: &str,
    ) -> Result<[Quantity; 3], AircraftError> {
        self.values(
            written,
            field,
            Dimension::Length,
            Range::Between(-50.0, 50.0),
        )
    }

    pub(crate) fn surface(
        &self,
        s: &schema::Surface,
        table: &str,
    ) -> Result<Surface, AircraftError> {
        let field = |key: &str| format!("{table}.{key}");
        Ok(Surface {
            area: self.value(
                &s.area,
                &field("area"),
                Dimension::Area,
                Range::NonNegative(100.0),
            )?,
            incidence: self.value(
                &s.incidence,
                &field("incidence"),
                Dimension::Angle,
                Range::Between(-30.0 * DEG, 30.0 * DEG),
            )?,
            lift_slope: self.lift_slope(&s.lift_slope, &field("lift_slope"))?,
            position: self.position(&s.position, &field("position"))?,
            stall_angle: self.value(
                &s.stall_angle,
                &field("stall_angle"),
                Dimension::Angle,
                Range::Positive(90.0 * DEG),
            )?,
        })
    }

    pub(crate) fn lift_slope(
        &self,
        written: &Value,
        field: &str,
    ) -> Result<Quantity, AircraftError> {
        // Thin-aerofoil theory gives 2π per radian; no real blade or fin exceeds it by much.
        self.value(written, field, Dimension::PerAngle, Range::Positive(7.0))
    }

    pub(crate) fn profile_drag(
        &self,
        written: &Values,
        field: &str,
    ) -> Result<[Quantity; 2], AircraftError> {
        let [d0, d2] = self.values::<2>(
            written,
            field,
            Dimension::Dimensionless,
            Range::NonNegative(100.0),
        )?;
        if d0.value > 0.1 {
            return Err(self.error(
                written.span().start,
                &format!("{field}[0]"),
                format!("δ0 = {} must be at most 0.1", show(d0.value)),
            ));
        }
        Ok([d0, d2])
    }

    pub(crate) fn gearing(
        &self,
        g: &schema::Gearing,
        field: &str,
    ) -> Result<Gearing, AircraftError> {
        let centre = self.value(
            &g.centre,
            &format!("{field}.centre"),
            Dimension::Angle,
            Range::Between(-45.0 * DEG, 45.0 * DEG),
        )?;
        let per_stick = self.value(
            &g.per_stick,
            &format!("{field}.per_stick"),
            Dimension::Angle,
            Range::Between(-45.0 * DEG, 45.0 * DEG),
        )?;
        if per_stick.value == 0.0 {
            return Err(self.error(
                g.per_stick.span().start,
                &format!("{field}.per_stick"),
                "must not be zero: the stick would move nothing",
            ));
        }
        Ok(Gearing { centre, per_stick })
    }
}

pub(crate) fn show(x: f64) -> String {
    format!("{x}")
}
