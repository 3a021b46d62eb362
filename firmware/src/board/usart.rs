//! USART1: the telemetry and in-the-loop link, interrupt-driven, with byte rings.
//!
//! Pins PA9 (TX) / PA10 (RX), alternate function 7; 8N1 at [`BAUD`], no flow control.
//! The transmitter side is an [`embedded_io::Write`] ([`UsartTx`]) plus an
//! all-or-nothing [`UsartTx::queue_frame`] for whole frames; the receiver side is an
//! [`embedded_io::Read`] + [`embedded_io::ReadReady`] ([`UsartRx`]).
//!
//! Transmit path: bytes go into a ring; the data register is fed whenever TXE is set,
//! both right after queuing (from thread mode) and from the TXE interrupt. Feeding from
//! thread mode matters in QEMU: its USART model writes each byte out at once, always
//! reads TXE as set and never raises the TXE interrupt, so there the ring drains while
//! it is being filled; on silicon the TXE interrupt drains it at the line rate.

use core::cell::RefCell;
use core::convert::Infallible;
use core::sync::atomic::{AtomicBool, AtomicU32, Ordering};

use sweephold_protocol::{encode, Frame, MAX_FRAME_LEN};

use super::ring::ByteRing;
use cortex_m::interrupt::{self, CriticalSection, Mutex};

use super::clocks::{ClockGate, Clocks};
use super::dividers::{self, DividerError};
use super::gpio::{self, Pull};
use super::nvic::{self, Irq};
use super::pins;
use super::regs::usart1;

/// Line rate [Bd]. A 200 Hz loop in the loop with a host sends a Sample (~130 bytes on
/// the wire) and an ActuatorOut (~35) per tick: 33 kB/s, 72 % of the 46 kB/s that
/// 460 800 Bd 8N1 carries. 921 600 Bd would halve that but is 2 % off on the 16 MHz HSI
/// fallback; 460 800 Bd is within 0.8 % on both clock trees. (QEMU ignores the rate.)
pub const BAUD: u32 = 460_800;

/// Transmit ring [bytes]: several ticks' worth of frames (a tick queues a Sample, an
/// ActuatorOut and now and then a few Events, each at most `MAX_FRAME_LEN`).
pub const TX_CAPACITY: usize = 1024;

/// Receive ring [bytes]: in the loop the host sends one SensorIn (~80 bytes on the wire)
/// and waits for the answer, so a few frames' worth is plenty.
pub const RX_CAPACITY: usize = 256;

const SR_ORE: u32 = 1 << 3;
const SR_RXNE: u32 = 1 << 5;
const SR_TC: u32 = 1 << 6;
const SR_TXE: u32 = 1 << 7;
const CR1_RE: u32 = 1 << 2;
const CR1_TE: u32 = 1 << 3;
const CR1_RXNEIE: u32 = 1 << 5;
const CR1_TXEIE: u32 = 1 << 7;
const CR1_UE: u32 = 1 << 13;

static TX: Mutex<RefCell<ByteRing<TX_CAPACITY>>> = Mutex::new(RefCell::new(ByteRing::new()));
static RX: Mutex<RefCell<ByteRing<RX_CAPACITY>>> = Mutex::new(RefCell::new(ByteRing::new()));
/// Received bytes lost: hardware overruns plus bytes that found the ring full.
static RX_LOST: AtomicU32 = AtomicU32::new(0);

/// Configure pins, baud rate and interrupts; returns the two halves of the link.
pub fn init(clocks: &Clocks) -> Result<(UsartTx, UsartRx), DividerError> {
    let brr = dividers::usart_brr(clocks.pclk2_hz, BAUD)?;
    ClockGate::USART1.enable();
    gpio::alternate_function(pins::LINK_TX, Pull::None);
    gpio::alternate_function(pins::LINK_RX, Pull::Up);
    usart1::CR1.write(0);
    usart1::BRR.write(brr);
    usart1::CR2.write(0); // 1 stop bit
    usart1::CR3.write(0); // no flow control, no DMA
    usart1::CR1.write(CR1_UE | CR1_TE | CR1_RE | CR1_RXNEIE);
    nvic::enable(Irq::Usart1);
    Ok((
        UsartTx {
            dropped_frames: 0,
            brr,
        },
        UsartRx { _owned: () },
    ))
}

/// Feed the data register from the ring while it has room, and keep the TXE interrupt
/// on exactly while bytes are waiting.
fn pump(cs: &CriticalSection) {
    if CAPTURED.load(Ordering::Relaxed) {
        return;
    }
    let mut ring = TX.borrow(cs).borrow_mut();
    while usart1::SR.read() & SR_TXE != 0 {
        match ring.pop() {
            Some(byte) => usart1::DR.write(u32::from(byte)),
            None => break,
        }
    }
    if ring.is_empty() {
        usart1::CR1.clear_bits(CR1_TXEIE);
    } else {
        usart1::CR1.set_bits(CR1_TXEIE);
    }
}

/// Set when the frames leave through semihosting instead of the pin (QEMU only, see
/// `board::semihosting`): the transmit ring then keeps what is queued until
/// [`take_captured`] empties it.
static CAPTURED: AtomicBool = AtomicBool::new(false);

/// From now on keep queued frames in the ring for [`take_captured`].
pub fn capture() {
    CAPTURED.store(true, Ordering::Relaxed);
}

/// Move queued bytes (at most `buf.len()`) into `buf`; returns how many.
pub fn take_captured(buf: &mut [u8]) -> usize {
    interrupt::free(|cs| TX.borrow(cs).borrow_mut().pop_slice(buf))
}

/// USART1 interrupt: move a received byte into the ring, feed the transmitter.
pub fn on_interrupt() {
    // Reading SR then DR clears RXNE and the error flags (ORE, NE, FE).
    let status = usart1::SR.read();
    if status & (SR_RXNE | SR_ORE) != 0 {
        let byte = (usart1::DR.read() & 0xFF) as u8;
        if status & SR_ORE != 0 {
            RX_LOST.fetch_add(1, Ordering::Relaxed);
        }
        let pushed = interrupt::free(|cs| RX.borrow(cs).borrow_mut().push(byte));
        if !pushed {
            RX_LOST.fetch_add(1, Ordering::Relaxed);
        }
    }
    interrupt::free(pump);
}

/// Received bytes lost so far (overruns and ring overflows).
pub fn rx_lost() -> u32 {
    RX_LOST.load(Ordering::Relaxed)
}

/// Transmit half of USART1.
pub struct UsartTx {
    dropped_frames: u32,
    brr: u32,
}

impl UsartTx {
    /// Queue `frame` whole, or drop it whole when the ring lacks room (a partial frame
    /// would only cost the host a corrupt frame too). Returns `false` when dropped.
    pub fn queue_frame(&mut self, frame: &[u8]) -> bool {
        let queued = interrupt::free(|cs| {
            let fits = {
                let mut ring = TX.borrow(cs).borrow_mut();
                let fits = ring.room() >= frame.len();
                if fits {
                    ring.push_slice(frame);
                }
                fits
            };
            pump(cs);
            fits
        });
        if !queued {
            self.dropped_frames = self.dropped_frames.wrapping_add(1);
        }
        queued
    }

    /// Encode `frame` straight into the ring when a frame's worth of room is free there
    /// in one piece (no copy; the usual case: the ring starts over at its beginning
    /// whenever it drains). `None` when that room is not there (nothing done), else
    /// whether the frame was encoded (it always is, for the protocol's types).
    pub fn encode_in_place(&mut self, frame: &Frame) -> Option<bool> {
        let mut encoded = false;
        let in_place = interrupt::free(|cs| {
            let in_place = TX
                .borrow(cs)
                .borrow_mut()
                .fill_contiguous(MAX_FRAME_LEN, |space| {
                    let written = encode(frame, space).ok();
                    encoded = written.is_some();
                    written
                });
            if in_place {
                pump(cs);
            }
            in_place
        });
        in_place.then_some(encoded)
    }

    /// Queue `frame` without waiting: encoded in place ([`encode_in_place`]) or, when
    /// the room for that is missing, in `scratch` and queued whole if it fits
    /// ([`queue_frame`](Self::queue_frame)). `false` when dropped (counted).
    ///
    /// [`encode_in_place`]: Self::encode_in_place
    pub fn queue_encoded(&mut self, frame: &Frame, scratch: &mut [u8; MAX_FRAME_LEN]) -> bool {
        let queued = match self.encode_in_place(frame) {
            Some(encoded) => encoded,
            None => match encode(frame, scratch) {
                Ok(len) => return self.queue_frame(scratch.get(..len).unwrap_or(&[])),
                Err(_) => false,
            },
        };
        if !queued {
            self.dropped_frames = self.dropped_frames.wrapping_add(1);
        }
        queued
    }

    /// Frames dropped so far because the ring was full.
    pub fn dropped_frames(&self) -> u32 {
        self.dropped_frames
    }

    /// The programmed baud-rate register.
    pub fn brr(&self) -> u32 {
        self.brr
    }
}

impl embedded_io::ErrorType for UsartTx {
    type Error = Infallible;
}

impl embedded_io::Write for UsartTx {
    /// Queue as many bytes as fit, waiting for room when the ring is full.
    fn write(&mut self, buf: &[u8]) -> Result<usize, Infallible> {
        if buf.is_empty() {
            return Ok(0);
        }
        loop {
            let written = interrupt::free(|cs| {
                let written = { TX.borrow(cs).borrow_mut().push_slice(buf) };
                pump(cs);
                written
            });
            if written > 0 {
                return Ok(written);
            }
        }
    }

    /// Wait until the ring is empty and the last stop bit has left the pin.
    fn flush(&mut self) -> Result<(), Infallible> {
        loop {
            let empty = interrupt::free(|cs| {
                pump(cs);
                TX.borrow(cs).borrow().is_empty()
            });
            if empty && usart1::SR.read() & SR_TC != 0 {
                return Ok(());
            }
        }
    }
}

/// Receive half of USART1.
pub struct UsartRx {
    _owned: (),
}

impl UsartRx {
    /// Move the bytes received so far into `buf`; returns how many.
    pub fn read_available(&mut self, buf: &mut [u8]) -> usize {
        interrupt::free(|cs| RX.borrow(cs).borrow_mut().pop_slice(buf))
    }

    /// Bytes are waiting.
    pub fn has_data(&self) -> bool {
        interrupt::free(|cs| !RX.borrow(cs).borrow().is_empty())
    }
}

impl embedded_io::ErrorType for UsartRx {
    type Error = Infallible;
}

impl embedded_io::ReadReady for UsartRx {
    fn read_ready(&mut self) -> Result<bool, Infallible> {
        Ok(self.has_data())
    }
}

impl embedded_io::Read for UsartRx {
    /// Wait for at least one byte, then return what has arrived (up to `buf.len()`).
    fn read(&mut self, buf: &mut [u8]) -> Result<usize, Infallible> {
        if buf.is_empty() {
            return Ok(0);
        }
        loop {
            let count = self.read_available(buf);
            if count > 0 {
                return Ok(count);
            }
            // Sleep with interrupts masked: a byte that arrives between the check and
            // the WFI still wakes it (WFI wakes on a pending interrupt even when masked).
            interrupt::free(|cs| {
                if RX.borrow(cs).borrow().is_empty() {
                    cortex_m::asm::wfi();
                }
            });
        }
    }
}

/// Stop interrupts of the link (panic path): the rings are left as they are.
pub fn silence() {
    nvic::disable(Irq::Usart1);
}
