//! The onboard log: every frame the image sends to the host also goes, as the same COBS
//! bytes, to an OpenLog-style serial logger on USART3 TX (the board map's `log_tx`), whose file
//! `sweephold decode` then reads as it reads a dump.
//!
//! The log never blocks the loop: a frame is copied into a 4 KiB ring (a short critical
//! section: the copy, never the encoding) that the TXE interrupt drains at the line rate
//! (under QEMU, which never raises it, the loop's [`drain`] after each timer tick does,
//! as for the link: see [`crate::chip::usart`]).
//! When the logger falls behind, the oldest frames make room for the newest
//! ([`ByteRing::push_frame_dropping_oldest`]); the drops are counted ([`dropped`]) and
//! the file then lacks those frames (a frame that was being sent leaves one cut frame,
//! which the decoder skips).
//!
//! Line rate [`BAUD`] (8N1): a 200 Hz tick's Sample and ActuatorOut are about 33 kB/s,
//! which needs a logger that takes 460 800 Bd (OpenLog Artemis class); a slower logger
//! records what its rate allows, newest frames first. Under QEMU USART3 is the third
//! `-serial` (none given: its bytes go nowhere).

use core::cell::RefCell;
use core::sync::atomic::{AtomicU32, Ordering};

use cortex_m::interrupt::{self, CriticalSection, Mutex};
use stm32f4::stm32f405 as pac;

use crate::chip::boot::Boot;
use crate::chip::clocks::ClockGate;
use crate::chip::dividers::{self, DividerError};
use crate::chip::gpio::Pull;
use crate::chip::nvic::{self, Irq};
use crate::chip::pins::Pin;
use crate::chip::shared::IrqShared;
use crate::ring::ByteRing;

/// Line rate of the logger [Bd].
pub const BAUD: u32 = 460_800;

/// Log ring [bytes]: a few ticks' frames; what does not fit drops the oldest.
pub const CAPACITY: usize = 4096;

static RING: Mutex<RefCell<ByteRing<CAPACITY>>> = Mutex::new(RefCell::new(ByteRing::new()));
/// Frames dropped so far to make room (or too long for the ring).
static DROPPED: AtomicU32 = AtomicU32::new(0);

/// USART3, once set up: reached inside a critical section only (its one
/// read-modify-write, CR1's TXEIE in `pump`, never interleaves).
static USART3: IrqShared<pac::USART3> = IrqShared::new();

/// Configure the `tx` pin, the baud rate (from PCLK1: USART3 is on APB1) and the
/// interrupt.
pub fn init(usart3: pac::USART3, tx: Pin, boot: &mut Boot) -> Result<(), DividerError> {
    let brr = dividers::usart_brr(boot.clocks.pclk1_hz, BAUD)?;
    boot.enable_clock(ClockGate::Usart3);
    boot.alternate_function(tx, Pull::None);
    usart3.cr1().reset();
    usart3.brr().write(|w| {
        w.div_mantissa().set((brr >> 4) as u16);
        w.div_fraction().set((brr & 0xF) as u8)
    });
    usart3.cr2().reset();
    usart3.cr3().reset();
    usart3.cr1().write(|w| w.ue().set_bit().te().set_bit());
    interrupt::free(|cs| USART3.put(cs, usart3));
    boot.enable_interrupt(Irq::Usart3);
    Ok(())
}

/// Log one whole encoded frame (delimiter included).
pub fn log_frame(bytes: &[u8]) {
    let dropped = interrupt::free(|cs| {
        let dropped = RING
            .borrow(cs)
            .borrow_mut()
            .push_frame_dropping_oldest(bytes);
        pump(cs, false);
        dropped
    });
    if dropped > 0 {
        DROPPED.fetch_add(dropped, Ordering::Relaxed);
    }
}

/// Frames dropped from the log so far.
pub fn dropped() -> u32 {
    DROPPED.load(Ordering::Relaxed)
}

/// With `feed`, write bytes from the ring while the data register has room (TXE);
/// either way, keep the TXE interrupt on exactly while bytes are waiting (on silicon
/// it fires once the critical section ends and sends them). One function for
/// [`log_frame`] and [`drain`] (flash).
#[inline(never)]
fn pump(cs: &CriticalSection, feed: bool) {
    let Some(usart3) = USART3.get(cs) else {
        return;
    };
    let mut ring = RING.borrow(cs).borrow_mut();
    while feed && usart3.sr().read().txe().bit_is_set() {
        match ring.pop() {
            Some(byte) => {
                usart3.dr().write(|w| w.dr().set(u16::from(byte)));
            }
            None => break,
        }
    }
    let waiting = !ring.is_empty();
    usart3.cr1().modify(|_, w| w.txeie().bit(waiting));
}

/// Send what the ring holds while TXE is set, from thread mode, outside the control
/// tick: what sends the log under QEMU (no TXE interrupt there); on silicon a check.
/// The same work as the interrupt's.
#[inline(never)]
pub fn drain() {
    interrupt::free(|cs| pump(cs, true));
}

/// USART3 interrupt: room in the transmitter.
pub fn on_interrupt() {
    drain();
}

/// Stop the log's interrupt (panic path).
pub fn silence() {
    nvic::disable(Irq::Usart3);
}
