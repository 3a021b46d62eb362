//! The device interrupts the image uses: their priorities and their masks in the NVIC.
//! The handlers are the named vectors of `main.rs` (the PAC's vector table).
//!
//! Priorities (Cortex-M: a lower number preempts a higher one; the STM32F4 implements
//! the upper four bits) follow what must never wait: the IMU's data-ready and SPI
//! transfer first, then the control tick, then the receiver's UART, and last the
//! host link and the log, whose bytes can wait in their rings.

use cortex_m::peripheral::NVIC;
use stm32f4::stm32f405 as pac;

/// The device interrupts of the image, by the PAC's names.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Irq {
    /// TIM5 global interrupt: the loop tick.
    Tim5,
    /// USART1 global interrupt: the host link (receive, and transmit on silicon).
    Usart1,
    /// USART2 global interrupt: the SBUS receiver's bytes.
    Usart2,
    /// USART3 global interrupt: the onboard log's transmitter.
    Usart3,
}

// 0x00 is kept for the IMU's data-ready line and SPI transfer: the image reads the IMU
// from thread mode on the 1 kHz tick, so no interrupt of its own takes it yet.

/// Priority of the loop tick (the IMU sample and the control tick are counted by it).
pub const PRIORITY_TICK: u8 = 0x40;
/// Priority of the receiver's UART: an SBUS byte every 120 µs must not wait behind the
/// link or the log.
pub const PRIORITY_RECEIVER: u8 = 0x80;
/// Priority of the host link and the log.
pub const PRIORITY_LINK: u8 = 0xC0;

impl Irq {
    /// The PAC's interrupt number.
    fn interrupt(self) -> pac::Interrupt {
        match self {
            Irq::Tim5 => pac::Interrupt::TIM5,
            Irq::Usart1 => pac::Interrupt::USART1,
            Irq::Usart2 => pac::Interrupt::USART2,
            Irq::Usart3 => pac::Interrupt::USART3,
        }
    }

    /// The interrupt's priority (see the module documentation).
    pub fn priority(self) -> u8 {
        match self {
            Irq::Tim5 => PRIORITY_TICK,
            Irq::Usart2 => PRIORITY_RECEIVER,
            Irq::Usart1 | Irq::Usart3 => PRIORITY_LINK,
        }
    }
}

/// The NVIC, taken once with the core's peripherals: what unmasks the image's
/// interrupts at boot.
pub struct Nvic(NVIC);

impl Nvic {
    /// The core's NVIC, handed over by `cortex_m::Peripherals::take`.
    pub fn new(nvic: NVIC) -> Self {
        Nvic(nvic)
    }

    /// Set `irq`'s priority, then unmask it in the NVIC.
    pub fn enable(&mut self, irq: Irq) {
        // SAFETY: the image uses no priority-based critical sections (its critical
        // sections mask every interrupt), so a priority change cannot break one; the
        // NVIC's priority registers are written through this owned NVIC only, from
        // thread mode at boot.
        unsafe {
            self.0.set_priority(irq.interrupt(), irq.priority());
            // SAFETY: as above: unmasking cannot break a mask-based critical section,
            // and the handler of each unmasked interrupt exists (named vectors in
            // main.rs).
            NVIC::unmask(irq.interrupt());
        }
    }
}

/// Mask `irq` in the NVIC. Any context may: masking is one write of a write-1-to-clear
/// register (and `cortex_m` makes it safe).
pub fn disable(irq: Irq) {
    NVIC::mask(irq.interrupt());
}
