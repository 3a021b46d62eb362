//! PX4 ULog files, after PX4's "ULog File Format" specification.
//!
//! A 16-byte header (`ULog` `01 12 35`, version, start time in µs) is followed by
//! messages `{u16 size, u8 type, size bytes}`. Read here: `F` (format definitions
//! `name:type field;…`, nested formats and fixed arrays allowed), `A` (a subscription:
//! multi id, message id, format name), `D` (data of a subscription), `I` (information),
//! `P` (parameters), `O` (dropouts, reported). `B`, `M`, `Q`, `R`, `L`, `C` and `S` are
//! passed over; other types are counted in [`Log::dropped`].
//!
//! Field names follow pyulog: arrays flattened to `name[i]`, nested formats to
//! `parent.child` (`parent[i].child` in arrays); `_padding` fields at the end of the
//! flattened list are left out (the logger does not write them), others kept, as pyulog
//! does. A data message may be longer than its format (the extra bytes are ignored). Each
//! subscription is one [`Topic`] with its multi id as [`Topic::instance`]; its time is the
//! `timestamp` field in µs, as seconds.
//!
//! **Damage.** A message cut off by the end of the file is dropped and reported; a
//! message whose type byte is not one of the specification's is taken as corruption:
//! the reader looks for the next sync message (`2F 73 13 20 25 0C BB 12`) and reports the
//! bytes it skipped; a data message for an unknown subscription, or shorter than its
//! format, is dropped and counted.

use std::collections::HashMap;

use super::binary::{text, Bytes, Primitive};
use super::log::{Field, Log, LogError, LogFormat, Topic, Values};

/// The first seven bytes of a ULog file.
pub const MAGIC: &[u8] = b"ULog\x01\x12\x35";
/// The payload of a sync message.
const SYNC: [u8; 8] = [0x2F, 0x73, 0x13, 0x20, 0x25, 0x0C, 0xBB, 0x12];
/// Message types of the specification.
const KNOWN_TYPES: &[u8] = b"BFIMPQADLCSOR";
/// The largest payload a message can have (its size is a u16).
const MAX_MESSAGE: usize = u16::MAX as usize;
/// Fields visited while flattening one format, at most (a message holds at most 65535
/// bytes, so a real format has fewer).
const MAX_WORK: usize = 1 << 20;
/// Nesting depth of formats at which a definition is taken as circular.
const MAX_DEPTH: usize = 16;

/// A field's type in a format definition.
#[derive(Clone, Debug)]
enum FieldType {
    Primitive(Primitive),
    Nested(String),
}

/// One field of a format definition: type, array length, name.
#[derive(Clone, Debug)]
struct FormatField {
    kind: FieldType,
    array: Option<usize>,
    name: String,
}

/// A primitive at an offset in a data message, with pyulog's flattened name.
#[derive(Clone, Debug)]
struct FlatField {
    name: String,
    kind: Primitive,
    offset: usize,
}

/// A subscription: the topic it fills and its flattened layout.
struct Subscription {
    topic: usize,
    layout: Vec<FlatField>,
    size: usize,
    timestamp: Option<usize>,
}

fn primitive(name: &str) -> Option<Primitive> {
    Some(match name {
        "int8_t" | "char" => Primitive::I8,
        "uint8_t" | "bool" => Primitive::U8,
        "int16_t" => Primitive::I16,
        "uint16_t" => Primitive::U16,
        "int32_t" => Primitive::I32,
        "uint32_t" => Primitive::U32,
        "int64_t" => Primitive::I64,
        "uint64_t" => Primitive::U64,
        "float" => Primitive::F32,
        "double" => Primitive::F64,
        _ => return None,
    })
}

/// `type[n]` → (type, Some(n)); `type` → (type, None).
fn split_array(kind: &str) -> Option<(&str, Option<usize>)> {
    match kind.split_once('[') {
        Some((base, rest)) => {
            let n = rest.strip_suffix(']')?.parse().ok()?;
            Some((base, Some(n)))
        }
        None => Some((kind, None)),
    }
}

/// `name:type field;type[n] field;…` → (name, fields).
fn parse_format(definition: &str) -> Option<(String, Vec<FormatField>)> {
    let (name, body) = definition.split_once(':')?;
    let mut fields = Vec::new();
    for item in body.split(';').map(str::trim).filter(|s| !s.is_empty()) {
        let (kind, field) = item.split_once(' ')?;
        let (base, array) = split_array(kind.trim())?;
        let kind = match primitive(base) {
            Some(p) => FieldType::Primitive(p),
            None => FieldType::Nested(base.to_string()),
        };
        fields.push(FormatField {
            kind,
            array,
            name: field.trim().to_string(),
        });
    }
    Some((name.to_string(), fields))
}

/// Flatten `format` into primitives at offsets (pyulog's names), appending to `out`.
/// Returns the format's size, or an error naming the missing or circular format.
fn flatten(
    formats: &HashMap<String, Vec<FormatField>>,
    format: &str,
    prefix: &str,
    base: usize,
    depth: usize,
    work: &mut usize,
    out: &mut Vec<FlatField>,
) -> Result<usize, String> {
    if depth > MAX_DEPTH {
        return Err(format!(
            "format `{format}` nests deeper than {MAX_DEPTH} levels"
        ));
    }
    let fields = formats
        .get(format)
        .ok_or_else(|| format!("format `{format}` is not defined"))?;
    let mut offset = base;
    for field in fields {
        let count = field.array.unwrap_or(1);
        for i in 0..count {
            // Empty nested formats in arrays would otherwise cost time without bytes.
            *work += 1;
            if *work > MAX_WORK {
                return Err(format!("format `{format}` has too many fields to flatten"));
            }
            if offset - base > MAX_MESSAGE {
                return Err(format!("format `{format}` is longer than a message can be"));
            }
            let name = match field.array {
                Some(_) => format!("{prefix}{}[{i}]", field.name),
                None => format!("{prefix}{}", field.name),
            };
            match &field.kind {
                FieldType::Primitive(p) => {
                    out.push(FlatField {
                        name,
                        kind: *p,
                        offset,
                    });
                    offset += p.size();
                }
                FieldType::Nested(inner) => {
                    let size = flatten(
                        formats,
                        inner,
                        &format!("{name}."),
                        offset,
                        depth + 1,
                        work,
                        out,
                    )?;
                    offset += size;
                }
            }
        }
    }
    Ok(offset - base)
}

/// Parse a whole ULog file. `source` names it in messages.
pub fn parse(bytes: &[u8], source: &str) -> Result<Log, LogError> {
    let bad = |offset: usize, message: String| LogError::Format {
        path: source.to_string(),
        offset,
        message,
    };
    if !bytes.starts_with(MAGIC) {
        return Err(bad(0, "not a ULog file (no `ULog` magic)".into()));
    }
    if bytes.len() < 16 {
        return Err(bad(
            bytes.len(),
            "file ends inside the 16-byte header".into(),
        ));
    }
    let mut log = Log {
        source: source.to_string(),
        format: LogFormat::ULog,
        topics: Vec::new(),
        info: Vec::new(),
        parameters: Vec::new(),
        dropped: Vec::new(),
        bytes: bytes.len(),
    };
    let mut formats: HashMap<String, Vec<FormatField>> = HashMap::new();
    let mut subscriptions: HashMap<u16, Subscription> = HashMap::new();
    let mut unknown_data: HashMap<u16, (usize, usize)> = HashMap::new();
    let mut short_data = 0usize;
    let mut dropouts = (0usize, 0u64);
    let mut pos = 16;
    while pos < bytes.len() {
        let mut r = Bytes::new(&bytes[pos..]);
        let (Some(size), Some(kind)) = (r.u16(), r.u8()) else {
            log.dropped.push(format!(
                "byte {pos}: last {} bytes are a cut-off message header",
                bytes.len() - pos
            ));
            break;
        };
        if !KNOWN_TYPES.contains(&kind) {
            let from = pos;
            match find_sync(bytes, pos + 1) {
                Some(next) => {
                    log.dropped.push(format!(
                        "byte {from}: unknown message type 0x{kind:02x}: skipped {} bytes to the next sync message",
                        next - from
                    ));
                    pos = next;
                    continue;
                }
                None => {
                    log.dropped.push(format!(
                        "byte {from}: unknown message type 0x{kind:02x} and no sync message after it: last {} bytes not read",
                        bytes.len() - from
                    ));
                    break;
                }
            }
        }
        let Some(payload) = r.take(usize::from(size)) else {
            log.dropped.push(format!(
                "byte {pos}: last message (type `{}`, {size} bytes) cut off by the end of the file",
                char::from(kind)
            ));
            break;
        };
        match kind {
            b'F' => {
                let definition = text(payload);
                match parse_format(&definition) {
                    Some((name, fields)) => {
                        formats.insert(name, fields);
                    }
                    None => log.dropped.push(format!(
                        "byte {pos}: unreadable format definition `{definition}`"
                    )),
                }
            }
            b'A' => {
                let mut p = Bytes::new(payload);
                let (Some(multi_id), Some(msg_id)) = (p.u8(), p.u16()) else {
                    log.dropped
                        .push(format!("byte {pos}: subscription message too short"));
                    pos += 3 + usize::from(size);
                    continue;
                };
                let name = text(p.rest());
                let mut layout = Vec::new();
                match flatten(&formats, &name, "", 0, 0, &mut 0, &mut layout) {
                    Ok(_) => {
                        // The logger leaves out the padding at the end of a message.
                        while layout
                            .last()
                            .is_some_and(|f| f.name.starts_with("_padding"))
                        {
                            layout.pop();
                        }
                        let size = layout.last().map_or(0, |f| f.offset + f.kind.size());
                        let timestamp = layout.iter().position(|f| f.name == "timestamp");
                        log.topics.push(Topic {
                            name,
                            instance: Some(multi_id),
                            instance_field: None,
                            time_s: Vec::new(),
                            fields: layout
                                .iter()
                                .map(|f| Field {
                                    name: f.name.clone(),
                                    unit: None,
                                    multiplier: None,
                                    values: Values::Numbers(Vec::new()),
                                })
                                .collect(),
                        });
                        subscriptions.insert(
                            msg_id,
                            Subscription {
                                topic: log.topics.len() - 1,
                                layout,
                                size,
                                timestamp,
                            },
                        );
                    }
                    Err(message) => log
                        .dropped
                        .push(format!("byte {pos}: subscription `{name}`: {message}")),
                }
            }
            b'D' => {
                let mut p = Bytes::new(payload);
                let Some(msg_id) = p.u16() else {
                    short_data += 1;
                    pos += 3 + usize::from(size);
                    continue;
                };
                let data = p.rest();
                match subscriptions.get(&msg_id) {
                    Some(sub) if data.len() >= sub.size => {
                        let topic = &mut log.topics[sub.topic];
                        for (field, flat) in topic.fields.iter_mut().zip(&sub.layout) {
                            if let Values::Numbers(values) = &mut field.values {
                                // In bounds: offset + size ≤ sub.size ≤ data.len().
                                values
                                    .push(flat.kind.read(&data[flat.offset..]).unwrap_or(f64::NAN));
                            }
                        }
                        if let Some(i) = sub.timestamp {
                            let us = sub.layout[i].kind.read(&data[sub.layout[i].offset..]);
                            topic.time_s.push(us.unwrap_or(f64::NAN) / 1e6);
                        }
                    }
                    Some(_) => short_data += 1,
                    None => {
                        let entry = unknown_data.entry(msg_id).or_insert((pos, 0));
                        entry.1 += 1;
                    }
                }
            }
            b'I' => {
                if let Some((key, value)) = key_value(payload) {
                    log.info.push((key.1, value_text(&key.0, value)));
                }
            }
            b'P' => {
                if let Some((key, value)) = key_value(payload) {
                    let number = split_array(&key.0)
                        .and_then(|(base, _)| primitive(base))
                        .and_then(|p| p.read(value));
                    if let Some(number) = number {
                        log.parameters.push((key.1, number));
                    }
                }
            }
            b'O' => {
                dropouts.0 += 1;
                dropouts.1 += u64::from(Bytes::new(payload).u16().unwrap_or(0));
            }
            _ => {}
        }
        pos += 3 + usize::from(size);
    }
    if dropouts.0 > 0 {
        log.dropped.push(format!(
            "the logger reported {} dropouts ({} ms of messages lost while flying)",
            dropouts.0, dropouts.1
        ));
    }
    if short_data > 0 {
        log.dropped.push(format!(
            "{short_data} data messages shorter than their format dropped"
        ));
    }
    let mut unknown: Vec<_> = unknown_data.into_iter().collect();
    unknown.sort();
    for (msg_id, (first, count)) in unknown {
        log.dropped.push(format!(
            "byte {first}: {count} data messages for message id {msg_id}, which no subscription defines, dropped"
        ));
    }
    Ok(log)
}

/// The offset of the next sync message at or after `from`.
fn find_sync(bytes: &[u8], from: usize) -> Option<usize> {
    let tail = bytes.get(from..)?;
    // A sync message: size 8, type 'S', then the magic.
    let pattern = [8u8, 0, b'S'];
    tail.windows(3 + SYNC.len())
        .position(|w| w[..3] == pattern && w[3..] == SYNC)
        .map(|i| from + i)
}

/// An `I`/`P` payload: `u8 key_len, "type name", value` → ((type, name), value).
fn key_value(payload: &[u8]) -> Option<((String, String), &[u8])> {
    let mut p = Bytes::new(payload);
    let len = usize::from(p.u8()?);
    let key = String::from_utf8_lossy(p.take(len)?).into_owned();
    let (kind, name) = key.split_once(' ')?;
    Some(((kind.to_string(), name.to_string()), p.rest()))
}

/// An information value as text: `char[n]` as the string, numbers as numbers.
fn value_text(kind: &str, value: &[u8]) -> String {
    match split_array(kind) {
        Some(("char", _)) => text(value),
        Some((base, None)) => primitive(base)
            .and_then(|p| p.read(value))
            .map_or_else(|| format!("{} bytes", value.len()), |v| v.to_string()),
        _ => format!("{} bytes", value.len()),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn message(kind: u8, payload: &[u8]) -> Vec<u8> {
        let mut m = (payload.len() as u16).to_le_bytes().to_vec();
        m.push(kind);
        m.extend_from_slice(payload);
        m
    }

    /// A small ULog: a nested format, an array, a padding field, two instances.
    pub(crate) fn small_ulog() -> Vec<u8> {
        let mut b = MAGIC.to_vec();
        b.push(1);
        b.extend_from_slice(&0u64.to_le_bytes());
        b.extend(message(b'F', b"inner:float a;uint8_t[2] b;"));
        b.extend(message(
            b'F',
            b"rates:uint64_t timestamp;float[2] xyz;inner in;uint8_t[3] _padding0;",
        ));
        b.extend(message(b'I', b"\x10char[3] sys_namePX4"));
        let mut sub = vec![0u8, 7, 0];
        sub.extend_from_slice(b"rates");
        b.extend(message(b'A', &sub));
        let mut sub = vec![1u8, 8, 0];
        sub.extend_from_slice(b"rates");
        b.extend(message(b'A', &sub));
        for (id, k) in [(7u16, 0u64), (8, 5), (7, 1)] {
            let mut d = id.to_le_bytes().to_vec();
            d.extend_from_slice(&(1_000_000 * (k + 1)).to_le_bytes());
            d.extend_from_slice(&(k as f32).to_le_bytes());
            d.extend_from_slice(&(-(k as f32)).to_le_bytes());
            d.extend_from_slice(&0.5f32.to_le_bytes());
            d.extend_from_slice(&[k as u8, 9, 0, 0, 0]);
            b.extend(message(b'D', &d));
        }
        b
    }

    #[test]
    fn reads_nested_arrays_instances_and_info() {
        let log = parse(&small_ulog(), "t.ulg").unwrap();
        assert!(log.dropped.is_empty(), "{:?}", log.dropped);
        assert_eq!(log.info, [("sys_name".to_string(), "PX4".to_string())]);
        let rates = log.topic("rates").unwrap();
        let names: Vec<&str> = rates.fields.iter().map(|f| f.name.as_str()).collect();
        assert_eq!(
            names,
            [
                "timestamp",
                "xyz[0]",
                "xyz[1]",
                "in.a",
                "in.b[0]",
                "in.b[1]"
            ]
        );
        assert_eq!(rates.time_s, [1.0, 2.0]);
        assert_eq!(rates.numbers("xyz[1]").unwrap(), [0.0, -1.0]);
        assert_eq!(rates.numbers("in.b[0]").unwrap(), [0.0, 1.0]);
        let second = log.topic_instance("rates", 1).unwrap();
        assert_eq!(second.label(), "rates[1]");
        assert_eq!(second.numbers("xyz[0]").unwrap(), [5.0]);
    }

    #[test]
    fn a_cut_off_file_keeps_the_whole_messages_and_says_what_was_dropped() {
        let bytes = small_ulog();
        let log = parse(&bytes[..bytes.len() - 4], "t.ulg").unwrap();
        assert_eq!(log.topic("rates").unwrap().len(), 1);
        assert_eq!(log.dropped.len(), 1);
        assert!(
            log.dropped[0].contains("cut off by the end of the file"),
            "{:?}",
            log.dropped
        );
    }

    #[test]
    fn circular_formats_are_refused_not_followed() {
        let mut formats = HashMap::new();
        formats.insert("a".to_string(), parse_format("a:b x;").unwrap().1);
        formats.insert("b".to_string(), parse_format("b:a y;").unwrap().1);
        let message = flatten(&formats, "a", "", 0, 0, &mut 0, &mut Vec::new()).unwrap_err();
        assert!(message.contains("nests deeper"), "{message}");
    }
}
