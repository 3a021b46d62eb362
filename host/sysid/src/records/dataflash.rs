//! ArduPilot DataFlash binary logs (`.bin`), after ArduPilot's `LogStructure.h`.
//!
//! Every message is `A3 95 <type id>` and a payload whose layout the log defines itself:
//! the FMT message (type id 128; `B Type, B Length, n Name, N Format, Z Columns`) gives
//! each type its name, total length (header included), format characters and column
//! names. The format characters read here:
//!
//! | char | type | | char | type |
//! |---|---|---|---|---|
//! | `b` `B` | i8, u8 | | `c` `C` | i16, u16 × 0.01 |
//! | `h` `H` | i16, u16 | | `e` `E` | i32, u32 × 0.01 |
//! | `i` `I` | i32, u32 | | `L` | i32 × 1e-7 (latitude, longitude) |
//! | `q` `Q` | i64, u64 | | `M` | u8 (flight mode) |
//! | `f` `d` | f32, f64 | | `n` `N` `Z` | text of 4, 16, 64 bytes |
//! | `a` | 32 × i16, as fields `NAME[0]`…`NAME[31]` | | | |
//!
//! The scaled types (`c C e E L`) are read as pymavlink reads them, scale applied. FMTU
//! messages give each column a unit id and a multiplier id, resolved through the UNIT
//! and MULT messages into [`Field::unit`] and [`Field::multiplier`]; a multiplier is
//! kept only where the type has not applied one already and the log gives a number
//! (MULT `-`, "no multiplier", is 0 in the log). A column whose unit is `#` numbers the
//! instances of a multi-instance type ([`Topic::instance_field`], e.g. `IMU.I`). A
//! topic's time is its `TimeUS` column (or `TimeMS`), as seconds.
//!
//! **Damage.** Where the two header bytes are not found, or the type id has no FMT
//! before it, the reader moves on one byte at a time until it finds a message again, as
//! pymavlink does, and reports each run of skipped bytes; a last message cut off by the
//! end of the file is dropped and reported.

use std::collections::HashMap;

use super::binary::{text, Bytes, Primitive};
use super::log::{Field, Log, LogError, LogFormat, Topic, Values};

/// First header byte of every message.
pub const HEAD1: u8 = 0xA3;
/// Second header byte.
pub const HEAD2: u8 = 0x95;
/// Type id of the FMT message.
pub const FMT_ID: u8 = 128;
/// Length of the FMT message, header included.
const FMT_LEN: usize = 89;

/// How one format character is read.
#[derive(Clone, Copy, Debug)]
enum Column {
    Number(Primitive, f64),
    Text(usize),
    Array,
}

fn column(c: u8) -> Option<Column> {
    use Primitive::*;
    Some(match c {
        b'b' => Column::Number(I8, 1.0),
        b'B' | b'M' => Column::Number(U8, 1.0),
        b'h' => Column::Number(I16, 1.0),
        b'H' => Column::Number(U16, 1.0),
        b'i' => Column::Number(I32, 1.0),
        b'I' => Column::Number(U32, 1.0),
        b'q' => Column::Number(I64, 1.0),
        b'Q' => Column::Number(U64, 1.0),
        b'f' => Column::Number(F32, 1.0),
        b'd' => Column::Number(F64, 1.0),
        b'c' => Column::Number(I16, 0.01),
        b'C' => Column::Number(U16, 0.01),
        b'e' => Column::Number(I32, 0.01),
        b'E' => Column::Number(U32, 0.01),
        b'L' => Column::Number(I32, 1e-7),
        b'n' => Column::Text(4),
        b'N' => Column::Text(16),
        b'Z' => Column::Text(64),
        b'a' => Column::Array,
        _ => return None,
    })
}

impl Column {
    fn size(self) -> usize {
        match self {
            Column::Number(p, _) => p.size(),
            Column::Text(n) => n,
            Column::Array => 64,
        }
    }
}

/// `x` scaled as pymavlink scales it: a scale below 1 as a division by its inverse
/// (`1e-7` as `/ 1e7`, which rounds differently from `* 1e-7`).
fn scaled(x: f64, scale: f64) -> f64 {
    if scale > 0.0 && scale < 1.0 {
        x / (1.0 / scale)
    } else {
        x * scale
    }
}

/// A message type as its FMT message defines it.
struct Definition {
    topic: usize,
    length: usize,
    columns: Vec<Column>,
    /// Index of the time column among the topic's fields, and its counts per second.
    time: Option<(usize, f64)>,
}

/// Parse a whole DataFlash log. `source` names it in messages.
pub fn parse(bytes: &[u8], source: &str) -> Result<Log, LogError> {
    if !bytes.starts_with(&[HEAD1, HEAD2, FMT_ID]) {
        return Err(LogError::Format {
            path: source.to_string(),
            offset: 0,
            message: "not a DataFlash log (it does not start with an FMT message)".into(),
        });
    }
    let mut log = Log {
        source: source.to_string(),
        format: LogFormat::DataFlash,
        topics: Vec::new(),
        info: Vec::new(),
        parameters: Vec::new(),
        dropped: Vec::new(),
        bytes: bytes.len(),
    };
    let mut definitions: HashMap<u8, Definition> = HashMap::new();
    let mut skipped: Option<(usize, usize)> = None; // (first offset, bytes) of a run
    let mut pos = 0;
    while pos < bytes.len() {
        let id = match bytes.get(pos..pos + 3) {
            Some([HEAD1, HEAD2, id]) if *id == FMT_ID || definitions.contains_key(id) => *id,
            Some(_) => {
                let run = skipped.get_or_insert((pos, 0));
                run.1 += 1;
                pos += 1;
                continue;
            }
            None => {
                log.dropped.push(format!(
                    "byte {pos}: last {} bytes are a cut-off message header",
                    bytes.len() - pos
                ));
                break;
            }
        };
        if let Some((from, n)) = skipped.take() {
            log.dropped.push(format!(
                "byte {from}: {n} bytes skipped (no message header there)"
            ));
        }
        let length = if id == FMT_ID {
            FMT_LEN
        } else {
            definitions[&id].length
        };
        let Some(payload) = bytes.get(pos + 3..pos + length) else {
            let name = if id == FMT_ID {
                "FMT"
            } else {
                &log.topics[definitions[&id].topic].name
            };
            log.dropped.push(format!(
                "byte {pos}: last message ({name}, {length} bytes) cut off by the end of the file ({} bytes there)",
                bytes.len() - pos
            ));
            break;
        };
        if id == FMT_ID {
            if let Err(message) = define(payload, &mut log, &mut definitions) {
                log.dropped.push(format!("byte {pos}: FMT: {message}"));
            }
        }
        // FMT messages are a topic too (when the log defines FMT, as it does).
        if let Some(definition) = definitions.get(&id) {
            append(payload, definition, &mut log.topics[definition.topic]);
        }
        pos += length;
    }
    if let Some((from, n)) = skipped {
        log.dropped.push(format!(
            "byte {from}: {n} bytes skipped (no message header there)"
        ));
    }
    apply_units(&mut log);
    Ok(log)
}

/// Read an FMT payload and define (or redefine) its type.
fn define(
    payload: &[u8],
    log: &mut Log,
    definitions: &mut HashMap<u8, Definition>,
) -> Result<(), String> {
    let mut p = Bytes::new(payload);
    let (Some(id), Some(length)) = (p.u8(), p.u8()) else {
        return Err("too short".into());
    };
    let name = text(p.take(4).unwrap_or(&[]));
    let format = text(p.take(16).unwrap_or(&[]));
    let names = text(p.take(64).unwrap_or(&[]));
    let names: Vec<&str> = if names.is_empty() {
        Vec::new()
    } else {
        names.split(',').collect()
    };
    let columns = format
        .bytes()
        .map(|c| {
            column(c).ok_or_else(|| format!("{name}: unknown format character `{}`", char::from(c)))
        })
        .collect::<Result<Vec<_>, _>>()?;
    if columns.len() != names.len() {
        return Err(format!(
            "{name}: {} format characters for {} columns",
            columns.len(),
            names.len()
        ));
    }
    let size: usize = 3 + columns.iter().map(|c| c.size()).sum::<usize>();
    if size != usize::from(length) {
        return Err(format!(
            "{name}: length {length}, but its format `{format}` takes {size}"
        ));
    }
    let mut fields = Vec::new();
    for (column, field) in columns.iter().zip(&names) {
        let mut push = |name: String, values: Values| {
            fields.push(Field {
                name,
                unit: None,
                multiplier: None,
                values,
            })
        };
        match column {
            Column::Number(..) => push(field.to_string(), Values::Numbers(Vec::new())),
            Column::Text(_) => push(field.to_string(), Values::Text(Vec::new())),
            Column::Array => {
                (0..32).for_each(|i| push(format!("{field}[{i}]"), Values::Numbers(Vec::new())))
            }
        }
    }
    let time = names.iter().enumerate().find_map(|(i, n)| match *n {
        "TimeUS" => Some((i, 1e6)),
        "TimeMS" => Some((i, 1e3)),
        _ => None,
    });
    // Field index of the time column (an `a` column before it would shift it).
    let time = time.and_then(|(i, scale)| {
        fields
            .iter()
            .position(|f| f.name == names[i])
            .map(|k| (k, scale))
    });
    let topic = match log.topics.iter().position(|t| t.name == name) {
        Some(k) if log.topics[k].is_empty() => {
            log.topics[k].fields = fields;
            k
        }
        Some(_) => {
            return Err(format!(
                "{name} defined again after its messages; the first definition kept"
            ))
        }
        None => {
            log.topics.push(Topic {
                name,
                instance: None,
                instance_field: None,
                time_s: Vec::new(),
                fields,
            });
            log.topics.len() - 1
        }
    };
    definitions.insert(
        id,
        Definition {
            topic,
            length: usize::from(length),
            columns,
            time,
        },
    );
    Ok(())
}

/// Append one message's values to its topic. `payload` holds exactly the columns.
fn append(payload: &[u8], definition: &Definition, topic: &mut Topic) {
    let mut r = Bytes::new(payload);
    let mut fields = topic.fields.iter_mut();
    for column in &definition.columns {
        let bytes = r.take(column.size()).unwrap_or(&[]);
        match *column {
            Column::Number(p, scale) => {
                if let Some(Field {
                    values: Values::Numbers(v),
                    ..
                }) = fields.next()
                {
                    v.push(p.read(bytes).map_or(f64::NAN, |x| scaled(x, scale)));
                }
            }
            Column::Text(_) => {
                if let Some(Field {
                    values: Values::Text(v),
                    ..
                }) = fields.next()
                {
                    v.push(text(bytes));
                }
            }
            Column::Array => {
                for i in 0..32 {
                    if let Some(Field {
                        values: Values::Numbers(v),
                        ..
                    }) = fields.next()
                    {
                        v.push(
                            Primitive::I16
                                .read(bytes.get(2 * i..).unwrap_or(&[]))
                                .unwrap_or(f64::NAN),
                        );
                    }
                }
            }
        }
    }
    if let Some((k, per_second)) = definition.time {
        if let Some(Values::Numbers(v)) = topic.fields.get(k).map(|f| &f.values) {
            if let Some(t) = v.last() {
                topic.time_s.push(t / per_second);
            }
        }
    }
}

/// Units and multipliers from the FMTU, UNIT and MULT topics onto the topics' fields.
fn apply_units(log: &mut Log) {
    let lookup = |log: &Log, topic: &str, value: &str| -> HashMap<u8, String> {
        let Some(t) = log.topic(topic) else {
            return HashMap::new();
        };
        let (Some(ids), Some(values)) = (t.numbers("Id"), t.field(value)) else {
            return HashMap::new();
        };
        let values: Vec<String> = match &values.values {
            Values::Text(v) => v.clone(),
            Values::Numbers(v) => v.iter().map(|x| x.to_string()).collect(),
        };
        ids.iter()
            .zip(values)
            .map(|(id, v)| (*id as i64 as u8, v))
            .collect()
    };
    let units = lookup(log, "UNIT", "Label");
    let multipliers = lookup(log, "MULT", "Mult");
    let Some(fmtu) = log.topic("FMTU") else {
        return;
    };
    let (
        Some(types),
        Some(Field {
            values: Values::Text(unit_ids),
            ..
        }),
        Some(Field {
            values: Values::Text(mult_ids),
            ..
        }),
    ) = (
        fmtu.numbers("FmtType"),
        fmtu.field("UnitIds"),
        fmtu.field("MultIds"),
    )
    else {
        return;
    };
    let Some(fmt) = log.topic("FMT") else {
        return;
    };
    let (
        Some(fmt_types),
        Some(Field {
            values: Values::Text(fmt_names),
            ..
        }),
        Some(Field {
            values: Values::Text(fmt_formats),
            ..
        }),
    ) = (fmt.numbers("Type"), fmt.field("Name"), fmt.field("Format"))
    else {
        return;
    };
    let mut plan = Vec::new();
    for ((ty, unit_ids), mult_ids) in types.iter().zip(unit_ids).zip(mult_ids) {
        let Some(k) = fmt_types.iter().rposition(|t| t == ty) else {
            continue;
        };
        plan.push((
            fmt_names[k].clone(),
            fmt_formats[k].clone(),
            unit_ids.clone(),
            mult_ids.clone(),
        ));
    }
    for (name, format, unit_ids, mult_ids) in plan {
        let Some(topic) = log.topics.iter_mut().find(|t| t.name == name) else {
            continue;
        };
        // Format characters, unit ids and multiplier ids run in step with the columns;
        // an `a` column is 32 fields.
        let mut field = 0;
        for (i, c) in format.bytes().enumerate() {
            let width = if c == b'a' { 32 } else { 1 };
            let unit_id = unit_ids.as_bytes().get(i).copied();
            let mult_id = mult_ids.as_bytes().get(i).copied();
            let prescaled = matches!(c, b'c' | b'C' | b'e' | b'E' | b'L');
            for f in topic.fields.iter_mut().skip(field).take(width) {
                if let Some(label) = unit_id.and_then(|u| units.get(&u)) {
                    if unit_id == Some(b'#') {
                        topic.instance_field = Some(f.name.clone());
                    }
                    if !label.is_empty() {
                        f.unit = Some(label.clone());
                    }
                }
                let multiplier = mult_id
                    .and_then(|m| multipliers.get(&m))
                    .and_then(|m| m.parse::<f64>().ok())
                    .filter(|m| *m != 0.0 && m.is_finite());
                if !prescaled {
                    f.multiplier = multiplier;
                }
            }
            field += width;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// An FMT message defining `id` as `name` with `format` and `columns`.
    pub(crate) fn fmt(id: u8, name: &str, format: &str, columns: &str) -> Vec<u8> {
        let length: usize = 3 + format
            .bytes()
            .map(|c| column(c).unwrap().size())
            .sum::<usize>();
        let mut m = vec![HEAD1, HEAD2, FMT_ID, id, length as u8];
        let mut pad = |s: &str, n: usize| {
            let mut b = s.as_bytes().to_vec();
            b.resize(n, 0);
            m.extend(b);
        };
        pad(name, 4);
        pad(format, 16);
        pad(columns, 64);
        m
    }

    fn fmt_of_fmt() -> Vec<u8> {
        fmt(FMT_ID, "FMT", "BBnNZ", "Type,Length,Name,Format,Columns")
    }

    #[test]
    fn reads_scaled_text_and_array_columns() {
        let mut b = fmt_of_fmt();
        b.extend(fmt(5, "TST", "QcLNa", "TimeUS,Ang,Lat,Name,Arr"));
        let mut m = vec![HEAD1, HEAD2, 5];
        m.extend(2_500_000u64.to_le_bytes());
        m.extend((-1234i16).to_le_bytes());
        m.extend(515_000_000i32.to_le_bytes());
        let mut name = b"hello".to_vec();
        name.resize(16, 0);
        m.extend(name);
        for i in 0..32i16 {
            m.extend((i - 3).to_le_bytes());
        }
        b.extend(&m);
        let log = parse(&b, "t.bin").unwrap();
        assert!(log.dropped.is_empty(), "{:?}", log.dropped);
        let t = log.topic("TST").unwrap();
        assert_eq!(t.time_s, [2.5]);
        assert_eq!(t.numbers("Ang").unwrap(), [-12.34]);
        assert_eq!(t.numbers("Lat").unwrap(), [51.5]);
        assert_eq!(
            t.field("Name").unwrap().values,
            Values::Text(vec!["hello".into()])
        );
        assert_eq!(t.numbers("Arr[31]").unwrap(), [28.0]);
        assert_eq!(log.topic("FMT").unwrap().len(), 2);
    }

    #[test]
    fn garbage_between_messages_is_skipped_and_reported() {
        let mut b = fmt_of_fmt();
        b.extend(fmt(5, "TST", "Qf", "TimeUS,X"));
        let message = |t: u64, x: f32| {
            let mut m = vec![HEAD1, HEAD2, 5];
            m.extend(t.to_le_bytes());
            m.extend(x.to_le_bytes());
            m
        };
        b.extend(message(1, 1.0));
        let garbage_at = b.len();
        b.extend([0xA3, 0x00, 7, 7, 7]);
        b.extend(message(2, 2.0));
        let log = parse(&b, "t.bin").unwrap();
        assert_eq!(log.topic("TST").unwrap().numbers("X").unwrap(), [1.0, 2.0]);
        assert_eq!(
            log.dropped,
            [format!(
                "byte {garbage_at}: 5 bytes skipped (no message header there)"
            )]
        );
    }
}
