//! The host's end of the parameter frames (protocol 1.5): one request out, its replies
//! in, over any [`ByteWire`] a flight-controller link offers (QEMU's USART, a serial
//! port). The telemetry the board streams meanwhile (Samples, Events) is read past.

use std::time::Duration;

use anyhow::{anyhow, bail};
use sweephold_protocol::{Frame, ParamName, ParamOp, ParamReply, ParamRequest};

use crate::fly::frame_channel::{ByteWire, FrameChannel};

/// How long one reply may take. A board answers a List one value per control tick
/// (5 ms); QEMU's USART model takes the request in at about one byte per main-loop turn.
pub const REPLY_TIMEOUT: Duration = Duration::from_secs(10);

/// A parameter as the board reports it.
#[derive(Clone, Debug, PartialEq)]
pub struct BoardValue {
    /// Its name.
    pub name: String,
    /// Its value in the board's RAM.
    pub value: f32,
}

/// Why the board did not carry out a request: refused (the board's reason), or the
/// link failed.
#[derive(Debug)]
pub enum ParamError {
    /// The board answered with a refusal.
    Refused {
        /// The refused operation.
        op: ParamOp,
        /// The refusal's snake_case name (`armed`, `out_of_range`, …).
        reason: &'static str,
    },
    /// No answer, or not one that fits the request.
    Link(anyhow::Error),
}

impl std::fmt::Display for ParamError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            ParamError::Refused { op, reason } => {
                write!(f, "the flight controller refused {op:?}: {reason}")?;
                if *reason == "armed" {
                    write!(f, " (parameters change on the ground only: arm switch off)")?;
                }
                Ok(())
            }
            ParamError::Link(error) => write!(f, "{error:#}"),
        }
    }
}

impl std::error::Error for ParamError {}

/// What a push needs of a board: its list, and setting one value.
pub trait ParamBoard {
    /// Every parameter, in the board's order.
    fn list(&mut self) -> Result<Vec<BoardValue>, ParamError>;
    /// Set `name` to `value`; the value the board now holds.
    fn set(&mut self, name: &str, value: f32) -> Result<f32, ParamError>;
}

/// Parameter requests over a frame channel.
pub struct ParamClient<W> {
    channel: FrameChannel<W>,
    /// The telemetry read past while waiting for replies (at most [`PASSED_KEEP`] bytes,
    /// the first ones), for a caller that shows it (`fc watch`).
    passed: Vec<u8>,
}

/// How many bytes of telemetry read past a client keeps.
pub const PASSED_KEEP: usize = 1 << 20;

impl<W: ByteWire> ParamClient<W> {
    /// A client on `channel` (its boot frame already read, if the link has one).
    pub fn new(channel: FrameChannel<W>) -> Self {
        ParamClient {
            channel,
            passed: Vec::new(),
        }
    }

    /// The channel back (to read the telemetry on), and the telemetry's bytes read past
    /// so far (whole frames with their delimiters).
    pub fn into_channel(self) -> (FrameChannel<W>, Vec<u8>) {
        (self.channel, self.passed)
    }

    /// Send `request` and return its next reply.
    fn ask(&mut self, request: ParamRequest) -> Result<ParamReply, ParamError> {
        self.channel
            .send(&Frame::ParamRequest(request))
            .map_err(ParamError::Link)?;
        self.next_reply()
    }

    /// The next ParamReply, telemetry read past.
    fn next_reply(&mut self) -> Result<ParamReply, ParamError> {
        let mut telemetry = Vec::new();
        let frame = self
            .channel
            .read_until(
                REPLY_TIMEOUT,
                "ParamReply (firmware older than protocol 1.5? rebuild it with `cargo fw`)",
                |frame| Some(matches!(frame, Frame::ParamReply(_))),
                &mut telemetry,
            )
            .map_err(ParamError::Link)?;
        let room = PASSED_KEEP.saturating_sub(self.passed.len());
        // Whole frames only: cut at the last delimiter that fits.
        let kept = telemetry
            .get(..room.min(telemetry.len()))
            .and_then(|part| part.iter().rposition(|&b| b == 0))
            .map_or(0, |end| end + 1);
        self.passed
            .extend_from_slice(telemetry.get(..kept).unwrap_or(&[]));
        match frame {
            Frame::ParamReply(reply) => Ok(reply),
            other => Err(ParamError::Link(anyhow!("unexpected frame {other:?}"))),
        }
    }

    /// One parameter's value.
    pub fn get(&mut self, name: &str) -> Result<f32, ParamError> {
        let wire_name = wire_name(name)?;
        let reply = self.ask(ParamRequest::Get { name: wire_name })?;
        value_of(reply, name)
    }

    /// Save the set in RAM to the board's flash.
    pub fn save(&mut self) -> Result<(), ParamError> {
        let reply = self.ask(ParamRequest::Save)?;
        done(reply, ParamOp::Save)
    }

    /// Put the defaults in the board's RAM.
    pub fn reset(&mut self) -> Result<(), ParamError> {
        let reply = self.ask(ParamRequest::Reset)?;
        done(reply, ParamOp::Reset)
    }
}

impl<W: ByteWire> ParamBoard for ParamClient<W> {
    fn list(&mut self) -> Result<Vec<BoardValue>, ParamError> {
        let mut values = Vec::new();
        let mut reply = self.ask(ParamRequest::List)?;
        loop {
            match reply {
                ParamReply::Value {
                    index, count, name, ..
                } => {
                    if usize::from(index) != values.len() || index >= count {
                        return Err(ParamError::Link(anyhow!(
                            "the List reply came out of order (value {index} of {count} after {} values)",
                            values.len()
                        )));
                    }
                    let name = name_of(&name)?;
                    values.push(BoardValue {
                        value: value_of(reply, &name)?,
                        name,
                    });
                }
                ParamReply::Done { op: ParamOp::List } => return Ok(values),
                other => return Err(unexpected(other, ParamOp::List)),
            }
            reply = self.next_reply()?;
        }
    }

    fn set(&mut self, name: &str, value: f32) -> Result<f32, ParamError> {
        let wire_name = wire_name(name)?;
        let reply = self.ask(ParamRequest::Set {
            name: wire_name,
            value,
        })?;
        value_of(reply, name)
    }
}

/// `name` as it goes on the wire; a name that cannot be one is unknown to every board.
fn wire_name(name: &str) -> Result<ParamName, ParamError> {
    ParamName::new(name).ok_or_else(|| {
        ParamError::Link(anyhow!(
            "`{name}` cannot be a parameter name (1-16 printable ASCII characters)"
        ))
    })
}

fn name_of(name: &ParamName) -> Result<String, ParamError> {
    name.as_str()
        .map(str::to_string)
        .ok_or_else(|| ParamError::Link(anyhow!("the board sent a name that is not ASCII")))
}

/// The value a Value reply for `name` carries.
fn value_of(reply: ParamReply, name: &str) -> Result<f32, ParamError> {
    match reply {
        ParamReply::Value {
            name: got, value, ..
        } if got.as_str() == Some(name) => Ok(value),
        ParamReply::Value { name: got, .. } => Err(ParamError::Link(anyhow!(
            "asked for {name}, the board answered {}",
            got.as_str().unwrap_or("a non-ASCII name")
        ))),
        ParamReply::Refused { op, reason, .. } => Err(ParamError::Refused {
            op,
            reason: reason.name(),
        }),
        other => Err(ParamError::Link(anyhow!(
            "unexpected answer for {name}: {other:?}"
        ))),
    }
}

fn done(reply: ParamReply, op: ParamOp) -> Result<(), ParamError> {
    match reply {
        ParamReply::Done { op: got } if got == op => Ok(()),
        other => Err(unexpected(other, op)),
    }
}

fn unexpected(reply: ParamReply, op: ParamOp) -> ParamError {
    match reply {
        ParamReply::Refused { op, reason, .. } => ParamError::Refused {
            op,
            reason: reason.name(),
        },
        other => ParamError::Link(anyhow!("unexpected answer to {op:?}: {other:?}")),
    }
}

/// Fail unless `board` is the host's table: same names, same order.
pub fn check_same_table(board: &[BoardValue]) -> anyhow::Result<()> {
    let defs = sweephold_firmware::params::DEFS;
    if board.len() != defs.len() || board.iter().zip(defs.iter()).any(|(b, d)| b.name != d.name) {
        bail!(
            "the flight controller's parameter table ({} parameters) is not this host's ({}): \
             update sweephold or the image",
            board.len(),
            defs.len()
        );
    }
    Ok(())
}
