//! The params file (`sweephold fc params pull`, read by `push` and `diff`): TOML, a
//! `[source]` table naming where the values came from and the protocol version of the
//! host that read them, then `[params]`, one `NAME = value` per parameter in the
//! board's order. `docs/formats.md` describes it.
//!
//! Values are written in Rust's shortest decimal form of the `f32` (it reads back to the
//! same `f32`); a whole number is written without a fraction (a TOML integer).

use anyhow::{anyhow, bail, Context};
use sweephold_protocol::PROTOCOL_VERSION;

use super::client::BoardValue;

/// Where a pulled set came from.
#[derive(Clone, Debug, PartialEq)]
pub struct Source {
    /// The link (`qemu-usart`, `serial:/dev/ttyACM0`).
    pub fc: String,
    /// The board image booted in QEMU, if any.
    pub image: Option<String>,
}

/// The text of a params file holding `values`.
pub fn write(source: &Source, values: &[BoardValue]) -> String {
    let mut text =
        String::from("# sweephold flight-controller parameters (sweephold fc params pull)\n");
    text.push_str("[source]\n");
    text.push_str(&format!("fc = {}\n", quoted(&source.fc)));
    if let Some(image) = &source.image {
        text.push_str(&format!("image = {}\n", quoted(image)));
    }
    push_protocol_and_params(&mut text, values);
    text
}

/// The text of a params file holding `values` designed by `sweephold tune` on `model`
/// for `vehicle`: the same `[params]` as a pulled file, its `[source]` naming the model.
pub fn write_tuned(model: &str, vehicle: &str, values: &[BoardValue]) -> String {
    let mut text = String::from("# sweephold flight-controller parameters (sweephold tune)\n");
    text.push_str("[source]\n");
    text.push_str(&format!("tune = {}\n", quoted(model)));
    text.push_str(&format!("vehicle = {}\n", quoted(vehicle)));
    push_protocol_and_params(&mut text, values);
    text
}

/// The end of every params file's `[source]` (the protocol, the count) and its `[params]`.
fn push_protocol_and_params(text: &mut String, values: &[BoardValue]) {
    text.push_str(&format!(
        "protocol = \"{}.{}\"\n",
        PROTOCOL_VERSION.major, PROTOCOL_VERSION.minor
    ));
    text.push_str(&format!("count = {}\n\n[params]\n", values.len()));
    for value in values {
        text.push_str(&format!("{} = {}\n", value.name, number(value.value)));
    }
}

/// A TOML basic string.
fn quoted(text: &str) -> String {
    toml::Value::String(text.to_string()).to_string()
}

/// `value` as a TOML number that reads back to the same `f32`.
fn number(value: f32) -> String {
    // Display gives the shortest digits that round-trip and never an exponent; `-0`
    // stays a float so that its sign survives.
    if value == 0.0 && value.is_sign_negative() {
        return "-0.0".to_string();
    }
    format!("{value}")
}

/// The parameters of a params file's text, in name order (the TOML table's). `what` names the file in
/// errors.
pub fn parse(text: &str, what: &str) -> anyhow::Result<Vec<BoardValue>> {
    let table: toml::Table = text
        .parse()
        .map_err(|e: toml::de::Error| anyhow!("{what} is not TOML: {}", e.message()))?;
    for key in table.keys() {
        if key != "source" && key != "params" {
            bail!("{what}: unknown table or key `{key}` (a params file has [source] and [params])");
        }
    }
    let params = table
        .get("params")
        .and_then(toml::Value::as_table)
        .with_context(|| format!("{what} has no [params] table"))?;
    let mut values = Vec::with_capacity(params.len());
    for (name, value) in params {
        let number = match value {
            toml::Value::Float(x) => *x,
            toml::Value::Integer(n) => *n as f64,
            other => bail!("{what}: {name} = {other} is not a number",),
        };
        let single = number as f32;
        if number.is_finite() && !single.is_finite() {
            bail!("{what}: {name} = {number} does not fit a 32-bit float");
        }
        values.push(BoardValue {
            name: name.clone(),
            value: single,
        });
    }
    Ok(values)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn value(name: &str, value: f32) -> BoardValue {
        BoardValue {
            name: name.to_string(),
            value,
        }
    }

    #[test]
    fn a_written_file_reads_back_to_the_same_f32_values() {
        let values = vec![
            value("SWASH_TYPE", 140.0),
            value("SWASH_PHASE", -7.25),
            value("TINY", 1.0e-7),
            value("THIRD", 1.0 / 3.0),
            value("BIG", 16_777_216.0),
            value("NEG_ZERO", -0.0),
        ];
        let source = Source {
            fc: "qemu-usart".into(),
            image: Some("target/x \"quoted\"".into()),
        };
        let text = write(&source, &values);
        let back = parse(&text, "test").unwrap();
        assert_eq!(back.len(), values.len());
        let mut values = values;
        values.sort_by(|a, b| a.name.cmp(&b.name));
        for (a, b) in back.iter().zip(&values) {
            assert_eq!(a.name, b.name);
            assert_eq!(a.value.to_bits(), b.value.to_bits(), "{}", a.name);
        }
        assert!(text.contains("protocol = \"1."), "{text}");
    }

    #[test]
    fn a_tuned_file_reads_back_to_the_same_f32_values() {
        let values = vec![value("PM_ROLL_KP", 0.0416), value("PM_LEVEL_K", 1.0 / 3.0)];
        let text = write_tuned("out/\"x\"/model9.json", "trex700l", &values);
        let back = parse(&text, "test").unwrap();
        assert_eq!(back.len(), 2);
        assert_eq!(back[0].name, "PM_LEVEL_K");
        assert_eq!(back[0].value.to_bits(), (1.0f32 / 3.0).to_bits());
        assert_eq!(back[1].value.to_bits(), 0.0416f32.to_bits());
        assert!(text.contains("count = 2"), "{text}");
    }

    #[test]
    fn bad_files_are_refused_with_the_reason() {
        let cases = [
            ("[source]\nfc = \"qemu-usart\"", "no [params] table"),
            ("SWASH_TYPE = 120", "unknown table or key `SWASH_TYPE`"),
            ("[params]\nSWASH_TYPE = \"120\"", "is not a number"),
            ("[params]\nX = 1e40", "does not fit a 32-bit float"),
            ("[other]\n[params]\n", "unknown table or key `other`"),
            ("[params\n", "is not TOML"),
        ];
        for (text, expected) in cases {
            let error = parse(text, "f.toml").expect_err(text).to_string();
            assert!(error.contains(expected), "{text}: {error}");
        }
    }
}
