//! USART2 RX: the SBUS receiver's bytes, into a ring the control tick empties.
//!
//! Pin: the board map's `sbus_rx` (PA3, AF7), behind the board's inverter. SBUS is 100 000 Bd, 8 data
//! bits, even parity, 2 stop bits: the USART runs with 9-bit words (M = 1) of which the
//! ninth is the parity (PCE = 1, PS = 0), and STOP = 0b10.
//!
//! The receive interrupt (priority [`crate::chip::nvic::PRIORITY_RECEIVER`]) moves each byte into
//! a [`RX_CAPACITY`]-byte ring; a byte with a parity, framing or noise error is dropped
//! and counted, since SBUS carries no checksum of its own and a frame with a damaged byte
//! must not be decoded (the decoder resynchronises on the next frame). The control tick
//! takes the bytes with [`SbusRx::take`] and hands them to the flight logic's SBUS
//! decoder, which judges frames, failsafe flags and the link timeout.
//!
//! Under QEMU USART2 is the machine's second `-serial`: a host test feeds SBUS frames
//! there (QEMU ignores rate, parity and stop bits).

use core::cell::RefCell;
use core::sync::atomic::{AtomicU32, Ordering};

use cortex_m::interrupt::{self, Mutex};
use stm32f4::stm32f405 as pac;

use crate::chip::boot::Boot;
use crate::chip::clocks::ClockGate;
use crate::chip::dividers::{self, DividerError};
use crate::chip::gpio::Pull;
use crate::chip::nvic::{self, Irq};
use crate::chip::pins::Pin;
use crate::chip::shared::IrqShared;
use crate::ring::ByteRing;

/// SBUS line rate [Bd].
pub const BAUD: u32 = 100_000;

/// Receive ring [bytes]: SBUS brings about 42 bytes per 5 ms control tick (25-byte
/// frames every 7–14 ms at 8 333 bytes/s at most); 256 holds six ticks' worth.
pub const RX_CAPACITY: usize = 256;

static RX: Mutex<RefCell<ByteRing<RX_CAPACITY>>> = Mutex::new(RefCell::new(ByteRing::new()));
/// Bytes dropped: parity, framing and noise errors.
static LINE_ERRORS: AtomicU32 = AtomicU32::new(0);
/// Bytes lost: hardware overruns and a full ring.
static LOST: AtomicU32 = AtomicU32::new(0);

/// USART2, once set up: after the set-up only the interrupt handler reads it.
static USART2: IrqShared<pac::USART2> = IrqShared::new();

/// Configure the `rx` pin, 100 000 Bd 8E2 (from PCLK1: USART2 is on APB1) and the
/// receive interrupt.
pub fn init(usart2: pac::USART2, rx: Pin, boot: &mut Boot) -> Result<SbusRx, DividerError> {
    let brr = dividers::usart_brr(boot.clocks.pclk1_hz, BAUD)?;
    boot.enable_clock(ClockGate::Usart2);
    boot.alternate_function(rx, Pull::None);
    usart2.cr1().reset();
    usart2.brr().write(|w| {
        w.div_mantissa().set((brr >> 4) as u16);
        w.div_fraction().set((brr & 0xF) as u8)
    });
    usart2.cr2().write(|w| w.stop().stop2());
    usart2.cr3().reset();
    usart2.cr1().write(|w| {
        w.m().m9();
        w.pce().enabled();
        w.ps().even();
        w.re().set_bit();
        w.rxneie().set_bit();
        w.ue().set_bit()
    });
    interrupt::free(|cs| USART2.put(cs, usart2));
    boot.enable_interrupt(Irq::Usart2);
    Ok(SbusRx { _owned: () })
}

/// USART2 interrupt: move the received byte into the ring, or count why not.
pub fn on_interrupt() {
    interrupt::free(|cs| {
        let Some(usart2) = USART2.get(cs) else {
            return;
        };
        // Reading SR then DR clears RXNE and the error flags (ORE, NE, FE, PE).
        let status = usart2.sr().read();
        if status.rxne().bit_is_clear() && status.ore().bit_is_clear() {
            return;
        }
        let byte = (usart2.dr().read().dr().bits() & 0xFF) as u8;
        if status.ore().bit_is_set() {
            LOST.fetch_add(1, Ordering::Relaxed);
        }
        if status.pe().bit_is_set() || status.fe().bit_is_set() || status.nf().bit_is_set() {
            LINE_ERRORS.fetch_add(1, Ordering::Relaxed);
            return;
        }
        if !RX.borrow(cs).borrow_mut().push(byte) {
            LOST.fetch_add(1, Ordering::Relaxed);
        }
    });
}

/// The receiver's byte stream.
pub struct SbusRx {
    _owned: (),
}

impl SbusRx {
    /// Move the bytes received so far (at most `buf.len()`) into `buf`; returns how many.
    pub fn take(&mut self, buf: &mut [u8]) -> usize {
        interrupt::free(|cs| RX.borrow(cs).borrow_mut().pop_slice(buf))
    }
}

/// Bytes dropped for line errors so far.
pub fn line_errors() -> u32 {
    LINE_ERRORS.load(Ordering::Relaxed)
}

/// Bytes lost to overruns or a full ring so far.
pub fn lost() -> u32 {
    LOST.load(Ordering::Relaxed)
}

/// Stop the receiver's interrupt (panic path).
pub fn silence() {
    nvic::disable(Irq::Usart2);
}
