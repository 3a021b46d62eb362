//! Parsers for the numeric options of every verb: each range is enforced while the command
//! line is read, before any work starts, and the message says what was expected.
//!
//! Options that take these parsers are declared with `allow_hyphen_values = true`, so
//! that `--seed -1` reaches the parser (and is refused with a reason) instead of being
//! taken for an unknown flag.

/// A whole number in `MIN..=MAX`, for counts.
pub fn count<const MIN: usize, const MAX: usize>(text: &str) -> Result<usize, String> {
    match text.trim().parse::<usize>() {
        Ok(n) if (MIN..=MAX).contains(&n) => Ok(n),
        _ => Err(format!("expected a whole number from {MIN} to {MAX}")),
    }
}

/// A seed: any whole number from 0 to 2⁶⁴ − 1.
pub fn seed(text: &str) -> Result<u64, String> {
    text.trim()
        .parse::<u64>()
        .map_err(|_| format!("expected a whole number from 0 to {}", u64::MAX))
}

/// A finite number in `[min, max]` (either end open when `None`), with its unit in the
/// message.
fn number_in(text: &str, min: Option<f64>, max: Option<f64>, what: &str) -> Result<f64, String> {
    let value = text
        .trim()
        .parse::<f64>()
        .ok()
        .filter(|v| v.is_finite())
        .ok_or_else(|| format!("expected {what}"))?;
    if min.is_some_and(|m| value < m) || max.is_some_and(|m| value > m) {
        return Err(format!("expected {what}"));
    }
    Ok(value)
}

/// A finite number from 0 to 1 (coherence γ²).
pub fn unit_interval(text: &str) -> Result<f64, String> {
    number_in(text, Some(0.0), Some(1.0), "a number from 0 to 1")
}

/// The overlap of consecutive FRF windows: a fraction from 0 to 0.95.
pub fn window_overlap(text: &str) -> Result<f64, String> {
    number_in(text, Some(0.0), Some(0.95), "a fraction from 0 to 0.95")
}

/// A trim speed in knots, from 0 (hover) to the simulator's largest
/// ([`rotorsim::trim::MAX_TRIM_SPEED_KT`]).
pub fn trim_speed_kt(text: &str) -> Result<f64, String> {
    let max = rotorsim::trim::MAX_TRIM_SPEED_KT;
    number_in(
        text,
        Some(0.0),
        Some(max),
        &format!("a speed from 0 to {max} kt"),
    )
}

/// A fraction of stick travel from 0 up to (not including) 0.5.
pub fn below_half(text: &str) -> Result<f64, String> {
    let what = "a fraction from 0 to below 0.5";
    let value = number_in(text, Some(0.0), Some(0.5), what)?;
    if value == 0.5 {
        return Err(format!("expected {what}"));
    }
    Ok(value)
}

/// A finite number ≥ 0.
pub fn non_negative(text: &str) -> Result<f64, String> {
    number_in(text, Some(0.0), None, "a finite number >= 0")
}

/// A probability in [0, 1].
pub fn probability(text: &str) -> Result<f64, String> {
    number_in(text, Some(0.0), Some(1.0), "a probability from 0 to 1")
}

/// A finite number of seconds > 0.
pub fn positive_seconds(text: &str) -> Result<f64, String> {
    let value = number_in(text, Some(0.0), None, "a number of seconds > 0")?;
    if value == 0.0 {
        return Err("expected a number of seconds > 0".to_string());
    }
    Ok(value)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ranges_are_enforced_with_a_reason() {
        assert_eq!(count::<2, 200>("20"), Ok(20));
        for bad in [
            "1",
            "201",
            "18446744073709551615",
            "4294967296",
            "1e9",
            "-3",
            "x",
            "",
        ] {
            let error = count::<2, 200>(bad).unwrap_err();
            assert!(error.contains("from 2 to 200"), "{bad}: {error}");
        }
        assert_eq!(seed("0"), Ok(0));
        assert_eq!(seed("18446744073709551615"), Ok(u64::MAX));
        assert!(seed("-1").is_err() && seed("1.5").is_err());
        assert_eq!(non_negative("0"), Ok(0.0));
        for bad in ["-1", "nan", "NaN", "inf", "-inf", "x"] {
            assert!(non_negative(bad).is_err(), "{bad}");
            assert!(probability(bad).is_err(), "{bad}");
            assert!(positive_seconds(bad).is_err(), "{bad}");
        }
        assert!(probability("1.01").is_err() && probability("1").is_ok());
        assert!(positive_seconds("0").is_err() && positive_seconds("0.5").is_ok());
        for bad in ["nan", "-0.1", "1.5", "inf", ""] {
            assert!(unit_interval(bad).is_err(), "{bad}");
            assert!(window_overlap(bad).is_err(), "{bad}");
            assert!(below_half(bad).is_err(), "{bad}");
        }
        for bad in ["nan", "-0.1", "120.01", "inf", "", "fast"] {
            assert!(trim_speed_kt(bad).is_err(), "{bad}");
        }
        assert_eq!(unit_interval("1"), Ok(1.0));
        assert!(window_overlap("0.96").is_err() && window_overlap("0.95").is_ok());
        assert!(trim_speed_kt("200").is_err() && trim_speed_kt("120").is_ok());
        assert!(below_half("0.5").is_err() && below_half("0.49").is_ok());
    }
}
