//! Units of CSV columns: what a logger writes (deg/s, ms) converted to the SI units the
//! rest of the tool expects (rad/s, rad, s), and the rules that notice a column left in
//! the logger's units.
//!
//! - **Time**: s, ms or µs, as given; when not given, a median step above
//!   [`SECONDS_STEP_LIMIT`] (0.5, a rate below 2 Hz if it were seconds, too slow for any
//!   sweep) is read as ms, and one above [`MILLISECONDS_STEP_LIMIT`] (500) as µs, with a
//!   note.
//! - **Channels**: rad/s, deg/s, rad, deg; a channel without a unit is used as written.
//!   A channel without a unit whose name says it is a body rate (`p`, `q`, `r`, `gx`,
//!   `gy`, `gz`, or a name holding `rate` or `gyro`) and whose largest magnitude exceeds
//!   [`RATE_LIMIT_RAD_S`] (15 rad/s, 860 °/s: beyond what a sweep flies, while a sweep
//!   logged in deg/s passes it at 15 °/s) gets a note that it looks like deg/s.

use std::f64::consts::PI;

/// Unit of a channel column.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Unit {
    /// rad/s (SI, kept).
    RadPerS,
    /// deg/s, converted to rad/s.
    DegPerS,
    /// rad (SI, kept).
    Rad,
    /// deg, converted to rad.
    Deg,
}

impl Unit {
    /// The unit written as `text` (`rad/s`, `deg/s`, `rad`, `deg`).
    pub fn parse(text: &str) -> Option<Unit> {
        match text.trim() {
            "rad/s" => Some(Unit::RadPerS),
            "deg/s" => Some(Unit::DegPerS),
            "rad" => Some(Unit::Rad),
            "deg" => Some(Unit::Deg),
            _ => None,
        }
    }

    /// The factor from this unit to SI.
    pub fn to_si(self) -> f64 {
        match self {
            Unit::RadPerS | Unit::Rad => 1.0,
            Unit::DegPerS | Unit::Deg => PI / 180.0,
        }
    }
}

/// Unit of the time column.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TimeUnit {
    /// Seconds.
    Seconds,
    /// Milliseconds.
    Milliseconds,
    /// Microseconds.
    Microseconds,
}

impl TimeUnit {
    /// The unit written as `text` (`s`, `ms`, `us` or `µs`).
    pub fn parse(text: &str) -> Option<TimeUnit> {
        match text.trim() {
            "s" => Some(TimeUnit::Seconds),
            "ms" => Some(TimeUnit::Milliseconds),
            "us" | "µs" => Some(TimeUnit::Microseconds),
            _ => None,
        }
    }

    /// The factor to seconds.
    pub fn to_seconds(self) -> f64 {
        match self {
            TimeUnit::Seconds => 1.0,
            TimeUnit::Milliseconds => 1e-3,
            TimeUnit::Microseconds => 1e-6,
        }
    }

    /// How it is written.
    pub fn symbol(self) -> &'static str {
        match self {
            TimeUnit::Seconds => "s",
            TimeUnit::Milliseconds => "ms",
            TimeUnit::Microseconds => "µs",
        }
    }
}

/// A median time step above this (as written) is not seconds.
pub const SECONDS_STEP_LIMIT: f64 = 0.5;

/// A median time step above this (as written) is not milliseconds either.
pub const MILLISECONDS_STEP_LIMIT: f64 = 500.0;

/// The time unit a column with this median step (as written) is read in when none is
/// given (module docs).
pub fn detected_time_unit(median_step: f64) -> TimeUnit {
    if median_step > MILLISECONDS_STEP_LIMIT {
        TimeUnit::Microseconds
    } else if median_step > SECONDS_STEP_LIMIT {
        TimeUnit::Milliseconds
    } else {
        TimeUnit::Seconds
    }
}

/// A body rate above this [rad/s] in a channel without a unit looks like deg/s.
pub const RATE_LIMIT_RAD_S: f64 = 15.0;

/// `true` when the channel name says it is a body rate (module docs).
pub fn is_rate_name(name: &str) -> bool {
    let name = name.to_ascii_lowercase();
    ["p", "q", "r", "gx", "gy", "gz"].contains(&name.as_str())
        || name.contains("rate")
        || name.contains("gyro")
}

/// The note for a channel without a unit that looks like deg/s, if it does.
pub fn deg_per_s_note(source: &str, name: &str, values: &[f64]) -> Option<String> {
    let peak = values.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    (is_rate_name(name) && peak > RATE_LIMIT_RAD_S).then(|| {
        format!(
            "{source}: `{name}` peaks at {peak:.1}, above {RATE_LIMIT_RAD_S} rad/s: it looks like deg/s and is used as rad/s; give its unit (--units {name}=deg/s, or {name}=rad/s to keep it)"
        )
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn units_parse_and_convert() {
        assert_eq!(Unit::parse("deg/s"), Some(Unit::DegPerS));
        assert!((Unit::DegPerS.to_si() * 180.0 - PI).abs() < 1e-15);
        assert_eq!(Unit::parse("rad").map(Unit::to_si), Some(1.0));
        assert_eq!(Unit::parse("m/s"), None);
        assert_eq!(TimeUnit::parse("µs"), TimeUnit::parse("us"));
        assert_eq!(TimeUnit::parse("ms").map(TimeUnit::to_seconds), Some(1e-3));
    }

    #[test]
    fn time_units_are_told_by_the_median_step() {
        assert_eq!(detected_time_unit(0.01), TimeUnit::Seconds);
        assert_eq!(detected_time_unit(0.5), TimeUnit::Seconds);
        assert_eq!(detected_time_unit(10.0), TimeUnit::Milliseconds);
        assert_eq!(detected_time_unit(2500.0), TimeUnit::Microseconds);
    }

    #[test]
    fn rates_that_look_like_deg_per_s_are_noted() {
        let deg = [0.0, 85.1, -40.0];
        assert!(deg_per_s_note("x.csv", "gx", &deg)
            .unwrap()
            .contains("gx=deg/s"));
        assert!(deg_per_s_note("x.csv", "roll_rate", &deg).is_some());
        assert!(deg_per_s_note("x.csv", "p", &[1.0, -3.0]).is_none());
        // Not a rate by name: an acceleration may well exceed 15.
        assert!(deg_per_s_note("x.csv", "az", &[-9.8, -25.0]).is_none());
    }
}
