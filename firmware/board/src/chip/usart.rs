//! USART1: the telemetry and in-the-loop link, interrupt-driven, with byte rings.
//!
//! Pins: the board map's `link_tx` / `link_rx` (alternate function 7); 8N1 at [`BAUD`], no flow control.
//! The transmitter side is an [`embedded_io::Write`] ([`UsartTx`]) plus whole-frame
//! queuing: [`UsartTx::queue_frame`] (all or nothing) and
//! [`UsartTx::queue_frame_waiting`] (waits for room); the receiver side is an
//! [`embedded_io::Read`] + [`embedded_io::ReadReady`] ([`UsartRx`]).
//!
//! Transmit path: queuing a frame copies it into a ring and turns the TXE interrupt on;
//! the interrupt feeds the data register at the line rate, between and during ticks,
//! so no byte is sent from the tick itself. QEMU's USART model (7.2) writes each byte
//! out at once, always reads TXE as set and never raises the TXE interrupt: there the
//! loop empties the ring from thread mode after each timer tick ([`drain`]), outside
//! the control tick, as the interrupt does on silicon. (A full ring is the one case
//! where thread mode feeds the register inside a call: the waiting writers,
//! [`UsartTx::queue_frame_waiting`] and [`embedded_io::Write`], wait for room that way.)

use core::cell::RefCell;
use core::convert::Infallible;
use core::sync::atomic::{AtomicBool, AtomicU32, Ordering};

use sweephold_protocol::{encode, Frame, MAX_FRAME_LEN};

use cortex_m::interrupt::{self, CriticalSection, Mutex};
use stm32f4::stm32f405 as pac;

use crate::chip::boot::Boot;
use crate::chip::clocks::ClockGate;
use crate::chip::dividers::{self, DividerError};
use crate::chip::gpio::Pull;
use crate::chip::logport;
use crate::chip::nvic::{self, Irq};
use crate::chip::pins::Pin;
use crate::chip::shared::IrqShared;
use crate::ring::ByteRing;

/// USART1, once set up: reached inside a critical section by thread mode (queuing,
/// `flush`) and by the interrupt handler, so the one read-modify-write (CR1's TXEIE in
/// `pump`) never interleaves.
static USART1: IrqShared<pac::USART1> = IrqShared::new();

/// Line rate [Bd]. A 200 Hz loop in the loop with a host sends a Sample (~130 bytes on
/// the wire) and an ActuatorOut (~35) per tick: 33 kB/s, 72 % of the 46 kB/s that
/// 460 800 Bd 8N1 carries. 921 600 Bd would halve that but is 2 % off on the 16 MHz HSI
/// fallback; 460 800 Bd is within 0.8 % on both clock trees. (QEMU ignores the rate.)
pub const BAUD: u32 = 460_800;

/// Transmit ring [bytes]: several ticks' worth of frames (a tick queues a Sample, an
/// ActuatorOut and now and then a few Events, each at most `MAX_FRAME_LEN`).
pub const TX_CAPACITY: usize = 1024;

// Every frame fits the ring whole, so `queue_frame_waiting` always ends.
const _: () = assert!(MAX_FRAME_LEN <= TX_CAPACITY);

/// Receive ring [bytes]: in the loop the host sends one SensorIn (~80 bytes on the wire)
/// and waits for the answer, so a few frames' worth is plenty.
pub const RX_CAPACITY: usize = 256;

static TX: Mutex<RefCell<ByteRing<TX_CAPACITY>>> = Mutex::new(RefCell::new(ByteRing::new()));
static RX: Mutex<RefCell<ByteRing<RX_CAPACITY>>> = Mutex::new(RefCell::new(ByteRing::new()));
/// Received bytes lost: hardware overruns plus bytes that found the ring full.
static RX_LOST: AtomicU32 = AtomicU32::new(0);

/// Configure USART1 on the board's `tx` / `rx` pins (baud rate, interrupts); returns the
/// two halves of the link.
pub fn init(
    usart1: pac::USART1,
    (tx, rx): (Pin, Pin),
    boot: &mut Boot,
) -> Result<(UsartTx, UsartRx), DividerError> {
    let brr = dividers::usart_brr(boot.clocks.pclk2_hz, BAUD)?;
    boot.enable_clock(ClockGate::Usart1);
    boot.alternate_function(tx, Pull::None);
    boot.alternate_function(rx, Pull::Up);
    usart1.cr1().reset();
    // BRR is 16 bits wide (`usart_brr` checks the range): mantissa and fraction.
    usart1.brr().write(|w| {
        w.div_mantissa().set((brr >> 4) as u16);
        w.div_fraction().set((brr & 0xF) as u8)
    });
    usart1.cr2().reset(); // 1 stop bit
    usart1.cr3().reset(); // no flow control, no DMA
    usart1.cr1().write(|w| {
        w.ue()
            .set_bit()
            .te()
            .set_bit()
            .re()
            .set_bit()
            .rxneie()
            .set_bit()
    });
    interrupt::free(|cs| USART1.put(cs, usart1));
    boot.enable_interrupt(Irq::Usart1);
    Ok((
        UsartTx {
            dropped_frames: 0,
            brr,
        },
        UsartRx { _owned: () },
    ))
}

/// With `feed`, write bytes from the ring while the data register has room (TXE);
/// either way, keep the TXE interrupt on exactly while bytes are waiting. Thread mode
/// queues without `feed` (on silicon the interrupt, enabled here, sends the bytes as
/// soon as the critical section ends); the interrupt and [`drain`] feed. One function
/// for both (flash).
#[inline(never)]
fn pump(cs: &CriticalSection, feed: bool) {
    if CAPTURED.load(Ordering::Relaxed) {
        return;
    }
    let Some(usart1) = USART1.get(cs) else {
        return;
    };
    let mut ring = TX.borrow(cs).borrow_mut();
    while feed && usart1.sr().read().txe().bit_is_set() {
        match ring.pop() {
            Some(byte) => {
                usart1.dr().write(|w| w.dr().set(u16::from(byte)));
            }
            None => break,
        }
    }
    let waiting = !ring.is_empty();
    usart1.cr1().modify(|_, w| w.txeie().bit(waiting));
}

/// Send what the ring holds while TXE is set, from thread mode. Called by the loop
/// after each timer tick, outside the control tick: under QEMU, which never raises the
/// TXE interrupt, this is what sends the frames; on silicon the interrupt has sent them
/// already (or TXE reads clear) and this returns after a check.
pub fn drain() {
    interrupt::free(|cs| pump(cs, true));
}

/// Set when the frames leave through semihosting instead of the pin (QEMU only, see
/// `crate::image::semihosting`): the transmit ring then keeps what is queued until
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
    interrupt::free(|cs| {
        let Some(usart1) = USART1.get(cs) else {
            return;
        };
        // Reading SR then DR clears RXNE and the error flags (ORE, NE, FE).
        let status = usart1.sr().read();
        if status.rxne().bit_is_set() || status.ore().bit_is_set() {
            let byte = (usart1.dr().read().dr().bits() & 0xFF) as u8;
            if status.ore().bit_is_set() {
                RX_LOST.fetch_add(1, Ordering::Relaxed);
            }
            if !RX.borrow(cs).borrow_mut().push(byte) {
                RX_LOST.fetch_add(1, Ordering::Relaxed);
            }
        }
        pump(cs, true);
    });
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
        self.queue(frame, false)
    }

    /// Queue `frame` whole, waiting for room (at most the time the line needs to drain
    /// the ring, ~22 ms for 1 KiB at 460 800 Bd) instead of dropping it.
    pub fn queue_frame_waiting(&mut self, frame: &[u8]) {
        self.queue(frame, true);
    }

    /// Queue `frame` whole; with `wait`, feed the transmitter from thread mode until
    /// the ring has room (on silicon the interrupt makes it; QEMU needs the feed). A
    /// frame longer than the ring is dropped either way. `false` when dropped.
    fn queue(&mut self, frame: &[u8], wait: bool) -> bool {
        // Every frame the link carries also goes to the onboard log, whether or not the
        // link has room for it.
        logport::log_frame(frame);
        let wait = wait && frame.len() <= TX_CAPACITY;
        loop {
            let queued = interrupt::free(|cs| {
                let fits = {
                    let mut ring = TX.borrow(cs).borrow_mut();
                    let fits = ring.room() >= frame.len();
                    if fits {
                        ring.push_slice(frame);
                    }
                    fits
                };
                pump(cs, wait && !fits);
                fits
            });
            if queued {
                return true;
            }
            if !wait {
                self.dropped_frames = self.dropped_frames.wrapping_add(1);
                return false;
            }
        }
    }

    /// Queue `frame` without waiting: encoded in `scratch` with interrupts enabled,
    /// then copied into the ring whole if it fits ([`queue_frame`](Self::queue_frame)):
    /// the critical section holds only the copy, never the encoding. `false` when
    /// dropped (counted).
    pub fn queue_encoded(&mut self, frame: &Frame, scratch: &mut [u8; MAX_FRAME_LEN]) -> bool {
        match encode(frame, scratch) {
            Ok(len) => self.queue_frame(scratch.get(..len).unwrap_or(&[])),
            Err(_) => {
                self.dropped_frames = self.dropped_frames.wrapping_add(1);
                false
            }
        }
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
                // Full: on silicon the interrupt makes room; QEMU needs the feed.
                pump(cs, written == 0);
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
            let done = interrupt::free(|cs| {
                pump(cs, true);
                TX.borrow(cs).borrow().is_empty()
                    && USART1
                        .get(cs)
                        .is_some_and(|usart1| usart1.sr().read().tc().bit_is_set())
            });
            if done {
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
