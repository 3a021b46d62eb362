//! The image's defmt logger: RTT on a board, a semihosting file under QEMU.
//!
//! On a board the encoded defmt frames go to the RTT up channel "defmt" (1 KiB,
//! non-blocking: a full buffer drops, the loop never waits), which `probe-rs run`
//! decodes. In QEMU in the loop ([`semihosting`]) there is no probe: once the runner has
//! found the semihosting link it calls [`to_semihosting`], and from then on every frame
//! also goes, whole, in one SYS_WRITE to the host file `sweephold-log`, which the host
//! decodes against the ELF (`sweephold fly --fc qemu` writes `DIR/<record>.log`). Frames
//! logged before that (boot) wait in a small buffer and are sent first, unless the
//! runner says it is a board ([`to_rtt_only`]), which frees the buffer.
//!
//! Re-entrancy without a critical section across `acquire`…`release` (which would need
//! `unsafe` to restore the interrupt state): a nesting counter. The outermost
//! acquire/release pair owns the frame; a log call from an interrupt that lands inside
//! it finds the counter above one and is dropped whole, so frames never interleave.
//! Each write then takes a short critical section of its own for the shared state.
//!
//! Frames carry the loop's tick ([`set_tick`], the `tick` of the Sample being made) as
//! their timestamp, so a log line lines up with the telemetry.

use core::cell::RefCell;
use core::sync::atomic::{AtomicU32, AtomicU8, Ordering};

use cortex_m::interrupt::{self, Mutex};
use rtt_target::{rtt_init, ChannelMode, UpChannel};

use crate::image::semihosting;
use crate::ring::ByteRing;

/// Where frames go besides RTT.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Route {
    /// Not known yet (boot): keep frames for a possible semihosting file.
    Undecided,
    /// A board: RTT only.
    RttOnly,
    /// QEMU: also the semihosting file with this handle.
    Semihosting(usize),
}

/// Boot frames kept until the route is known [bytes].
const PENDING_CAPACITY: usize = 512;

/// Largest frame sent to the semihosting file; a longer one is dropped there (RTT still
/// gets it). Log frames are a few tens of bytes.
const FRAME_CAPACITY: usize = 256;

/// The logger's state shared by the acquire/write/release calls.
struct State {
    encoder: defmt::Encoder,
    out: Output,
}

/// Where encoded bytes go.
struct Output {
    rtt: Option<UpChannel>,
    route: Route,
    /// The frame being written, for the semihosting file.
    frame: [u8; FRAME_CAPACITY],
    frame_len: usize,
    frame_overflow: bool,
    /// Whole frames logged before the route was known.
    pending: ByteRing<PENDING_CAPACITY>,
}

static STATE: Mutex<RefCell<State>> = Mutex::new(RefCell::new(State {
    encoder: defmt::Encoder::new(),
    out: Output {
        rtt: None,
        route: Route::Undecided,
        frame: [0; FRAME_CAPACITY],
        frame_len: 0,
        frame_overflow: false,
        pending: ByteRing::new(),
    },
}));

/// acquire() calls not yet released: 1 inside a frame, more when an interrupt logs
/// during one (that frame is dropped).
static DEPTH: AtomicU8 = AtomicU8::new(0);

/// The loop tick frames are stamped with.
static TICK: AtomicU32 = AtomicU32::new(0);

/// Set up the RTT channel; call once, first thing in `main`, before any log.
pub fn init() {
    let channels = rtt_init! {
        up: {
            0: {
                size: 1024,
                mode: ChannelMode::NoBlockSkip,
                name: "defmt"
            }
        }
    };
    with_state(|_, out| out.rtt = Some(channels.up.0));
}

/// The loop tick the following log lines are stamped with.
pub fn set_tick(tick: u32) {
    TICK.store(tick, Ordering::Relaxed);
}

/// The timestamp of a log frame: the loop tick.
pub fn tick() -> u32 {
    TICK.load(Ordering::Relaxed)
}

/// A board: frames go to RTT only, the boot buffer is dropped.
pub fn to_rtt_only() {
    with_state(|_, out| {
        out.route = Route::RttOnly;
        out.pending = ByteRing::new();
    });
}

/// QEMU with semihosting: open the host's `sweephold-log`, send the boot frames kept so
/// far, and send every later frame there too. `false` when the host has no such file
/// (frames then go to RTT only).
pub fn to_semihosting() -> bool {
    let Some(handle) = semihosting::open(b"sweephold-log\0", true) else {
        to_rtt_only();
        return false;
    };
    with_state(|_, out| {
        let mut chunk = [0u8; 64];
        loop {
            let count = out.pending.pop_slice(&mut chunk);
            if count == 0 {
                break;
            }
            semihosting::write(handle, chunk.get(..count).unwrap_or(&[]));
        }
        out.route = Route::Semihosting(handle);
    });
    true
}

impl Output {
    /// Encoded bytes of the current frame: to RTT at once, and kept for the file.
    fn put(&mut self, bytes: &[u8]) {
        if let Some(rtt) = self.rtt.as_mut() {
            rtt.write(bytes);
        }
        if self.route == Route::RttOnly {
            return;
        }
        let end = self.frame_len + bytes.len();
        match self.frame.get_mut(self.frame_len..end) {
            Some(slot) => {
                slot.copy_from_slice(bytes);
                self.frame_len = end;
            }
            None => self.frame_overflow = true,
        }
    }

    /// The frame is complete: send or keep it for the file.
    fn finish(&mut self) {
        let frame = self.frame.get(..self.frame_len).unwrap_or(&[]);
        if !self.frame_overflow {
            match self.route {
                Route::Semihosting(handle) => {
                    semihosting::write(handle, frame);
                }
                Route::Undecided if self.pending.room() >= frame.len() => {
                    self.pending.push_slice(frame);
                }
                _ => {}
            }
        }
        self.frame_len = 0;
        self.frame_overflow = false;
    }
}

#[defmt::global_logger]
struct Logger;

// SAFETY (required by the trait, which is `unsafe`): `acquire`/`release` pairs and the
// writes between them come from one context at a time as far as the frame is concerned:
// a nested pair (an interrupt logging inside a frame) sees DEPTH > 1 and touches nothing,
// and every access to the shared state is inside a critical section.
unsafe impl defmt::Logger for Logger {
    fn acquire() {
        if DEPTH.fetch_add(1, Ordering::Acquire) == 0 {
            with_state(|encoder, out| encoder.start_frame(|bytes| out.put(bytes)));
        }
    }

    unsafe fn flush() {}

    unsafe fn release() {
        if DEPTH.load(Ordering::Relaxed) == 1 {
            with_state(|encoder, out| {
                encoder.end_frame(|bytes| out.put(bytes));
                out.finish();
            });
        }
        DEPTH.fetch_sub(1, Ordering::Release);
    }

    unsafe fn write(bytes: &[u8]) {
        if DEPTH.load(Ordering::Relaxed) == 1 {
            with_state(|encoder, out| encoder.write(bytes, |encoded| out.put(encoded)));
        }
    }
}

/// Run `f` on the encoder and the output inside a critical section (not at all if the
/// state is borrowed already, which only a logger bug could cause: better a lost line
/// than a panic in the logger).
fn with_state(f: impl FnOnce(&mut defmt::Encoder, &mut Output)) {
    interrupt::free(|cs| {
        if let Ok(mut state) = STATE.borrow(cs).try_borrow_mut() {
            let State { encoder, out } = &mut *state;
            f(encoder, out);
        }
    });
}
