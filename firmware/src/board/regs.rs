//! Memory-mapped registers of the STM32F405 that the board drivers touch: the only
//! `unsafe` code of the image.
//!
//! There is no PAC: each register is a [`Reg`] constant of the register map below, taken
//! from RM0090 (STM32F405/415 reference manual) §2.3 "Memory map" and the register maps
//! at the end of each peripheral chapter. A [`Reg`] can only be made in this module, so
//! every volatile access in the image goes to one of these addresses.

/// One 32-bit memory-mapped peripheral register.
#[derive(Clone, Copy, PartialEq, Eq)]
pub struct Reg {
    address: usize,
}

impl Reg {
    /// The register at `base + offset`; private so that only the map below makes them.
    const fn at(base: usize, offset: usize) -> Reg {
        Reg {
            address: base + offset,
        }
    }

    /// Read the register.
    #[inline(always)]
    pub fn read(self) -> u32 {
        // SAFETY: `self.address` is one of the constants of this module: a word-aligned
        // 32-bit register of an STM32F405 peripheral (RM0090 memory map), which is always
        // mapped and readable. It is device memory, not memory the Rust program owns, so
        // a volatile read cannot alias or invalidate any Rust object.
        unsafe { core::ptr::read_volatile(self.address as *const u32) }
    }

    /// Write the register.
    #[inline(always)]
    pub fn write(self, value: u32) {
        // SAFETY: as in `read`: an aligned, always-mapped peripheral register outside
        // Rust-owned memory. What a write *does* to the hardware is the caller's
        // concern; it cannot break Rust's memory safety.
        unsafe { core::ptr::write_volatile(self.address as *mut u32, value) }
    }

    /// Read-modify-write: `reg = f(reg)`. Not atomic against interrupts: callers that
    /// share a register with an interrupt handler do it inside a critical section.
    #[inline(always)]
    pub fn modify(self, f: impl FnOnce(u32) -> u32) {
        self.write(f(self.read()));
    }

    /// Set the bits of `mask`.
    #[inline(always)]
    pub fn set_bits(self, mask: u32) {
        self.modify(|v| v | mask);
    }

    /// Clear the bits of `mask`.
    #[inline(always)]
    pub fn clear_bits(self, mask: u32) {
        self.modify(|v| v & !mask);
    }

    /// Write `value` into the `width`-bit field starting at bit `shift`.
    #[inline(always)]
    pub fn write_field(self, shift: u32, width: u32, value: u32) {
        let mask = ((1u32 << width) - 1) << shift;
        self.modify(|v| (v & !mask) | ((value << shift) & mask));
    }
}

/// Reset and clock control (RM0090 §7.3).
pub mod rcc {
    use super::Reg;
    const BASE: usize = 0x4002_3800;
    /// Clock control: oscillator enables and ready flags.
    pub const CR: Reg = Reg::at(BASE, 0x00);
    /// PLL configuration.
    pub const PLLCFGR: Reg = Reg::at(BASE, 0x04);
    /// Clock configuration: system clock switch and bus prescalers.
    pub const CFGR: Reg = Reg::at(BASE, 0x08);
    /// AHB1 peripheral clock enable (GPIO ports).
    pub const AHB1ENR: Reg = Reg::at(BASE, 0x30);
    /// APB1 peripheral clock enable (TIM2..TIM5).
    pub const APB1ENR: Reg = Reg::at(BASE, 0x40);
    /// APB2 peripheral clock enable (USART1).
    pub const APB2ENR: Reg = Reg::at(BASE, 0x44);
}

/// Flash interface (RM0090 §3.9).
pub mod flash {
    use super::Reg;
    /// Access control: wait states, prefetch and caches.
    pub const ACR: Reg = Reg::at(0x4002_3C00, 0x00);
}

/// A GPIO port's registers (RM0090 §8.4).
#[derive(Clone, Copy)]
pub struct GpioPort {
    /// Mode (input, output, alternate function, analog), 2 bits per pin.
    pub moder: Reg,
    /// Output speed, 2 bits per pin.
    pub ospeedr: Reg,
    /// Pull-up / pull-down, 2 bits per pin.
    pub pupdr: Reg,
    /// Alternate function of pins 0..=7, 4 bits per pin.
    pub afrl: Reg,
    /// Alternate function of pins 8..=15, 4 bits per pin.
    pub afrh: Reg,
}

const fn gpio_port(base: usize) -> GpioPort {
    GpioPort {
        moder: Reg::at(base, 0x00),
        ospeedr: Reg::at(base, 0x08),
        pupdr: Reg::at(base, 0x0C),
        afrl: Reg::at(base, 0x20),
        afrh: Reg::at(base, 0x24),
    }
}

/// GPIO port A.
pub const GPIOA: GpioPort = gpio_port(0x4002_0000);
/// GPIO port B.
pub const GPIOB: GpioPort = gpio_port(0x4002_0400);
/// GPIO port C.
pub const GPIOC: GpioPort = gpio_port(0x4002_0800);

/// USART1 (RM0090 §30.6).
pub mod usart1 {
    use super::Reg;
    const BASE: usize = 0x4001_1000;
    /// Status: TXE, TC, RXNE, error flags.
    pub const SR: Reg = Reg::at(BASE, 0x00);
    /// Data (one byte in, one byte out).
    pub const DR: Reg = Reg::at(BASE, 0x04);
    /// Baud rate divider.
    pub const BRR: Reg = Reg::at(BASE, 0x08);
    /// Control 1: enable, transmitter, receiver, interrupt enables.
    pub const CR1: Reg = Reg::at(BASE, 0x0C);
    /// Control 2: stop bits.
    pub const CR2: Reg = Reg::at(BASE, 0x10);
    /// Control 3: flow control, DMA.
    pub const CR3: Reg = Reg::at(BASE, 0x14);
}

/// A timer's registers (TIM2..TIM5 RM0090 §18.4; TIM8 §17.4 shares the offsets).
#[derive(Clone, Copy)]
pub struct GeneralTimer {
    /// Control 1: enable, direction, auto-reload preload.
    pub cr1: Reg,
    /// DMA / interrupt enable.
    pub dier: Reg,
    /// Status: update and capture/compare flags (write 0 to clear).
    pub sr: Reg,
    /// Event generation (UG reloads prescaler and counter).
    pub egr: Reg,
    /// Capture/compare mode of channels 1 and 2.
    pub ccmr1: Reg,
    /// Capture/compare mode of channels 3 and 4.
    pub ccmr2: Reg,
    /// Capture/compare output enables.
    pub ccer: Reg,
    /// Prescaler: counter clock = timer clock / (PSC + 1).
    pub psc: Reg,
    /// Auto-reload: the counter period is ARR + 1 counts.
    pub arr: Reg,
    /// Compare values of channels 1..=4.
    pub ccr: [Reg; 4],
    /// Break and dead time (advanced timers TIM1/TIM8 only: MOE gates their outputs).
    pub bdtr: Reg,
}

const fn general_timer(base: usize) -> GeneralTimer {
    GeneralTimer {
        cr1: Reg::at(base, 0x00),
        dier: Reg::at(base, 0x0C),
        sr: Reg::at(base, 0x10),
        egr: Reg::at(base, 0x14),
        ccmr1: Reg::at(base, 0x18),
        ccmr2: Reg::at(base, 0x1C),
        ccer: Reg::at(base, 0x20),
        psc: Reg::at(base, 0x28),
        arr: Reg::at(base, 0x2C),
        ccr: [
            Reg::at(base, 0x34),
            Reg::at(base, 0x38),
            Reg::at(base, 0x3C),
            Reg::at(base, 0x40),
        ],
        bdtr: Reg::at(base, 0x44),
    }
}

/// TIM2: 32-bit, the ESC output.
pub const TIM2: GeneralTimer = general_timer(0x4000_0000);
/// TIM3: 16-bit, swash servo 3.
pub const TIM3: GeneralTimer = general_timer(0x4000_0400);
/// TIM4: 16-bit, swash servos 1 and 2.
pub const TIM4: GeneralTimer = general_timer(0x4000_0800);
/// TIM5: 32-bit, the control-loop tick.
pub const TIM5: GeneralTimer = general_timer(0x4000_0C00);
/// TIM8: advanced 16-bit timer (same layout for what the image uses, plus BDTR), the
/// tail servo (RM0090 §17.4).
pub const TIM8: GeneralTimer = general_timer(0x4001_0400);

/// Nested vectored interrupt controller (ARMv7-M ARM §B3.4).
pub mod nvic {
    use super::Reg;
    /// Interrupt set-enable registers 0..=2 (IRQ 0..=95), one bit per IRQ.
    pub const ISER: [Reg; 3] = [
        Reg::at(0xE000_E100, 0x0),
        Reg::at(0xE000_E100, 0x4),
        Reg::at(0xE000_E100, 0x8),
    ];
    /// Interrupt clear-enable registers 0..=2.
    pub const ICER: [Reg; 3] = [
        Reg::at(0xE000_E180, 0x0),
        Reg::at(0xE000_E180, 0x4),
        Reg::at(0xE000_E180, 0x8),
    ];
}
