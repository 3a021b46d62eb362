//! What every driver's set-up needs at boot, in one owned bundle: the clock frequencies,
//! the RCC's clock gates, the GPIO ports and the NVIC. [`crate::chip::devices`] makes it
//! from the peripherals it takes; each driver's `init` borrows it.

use crate::chip::clocks::{ClockGate, ClockGates, Clocks};
use crate::chip::gpio::{Gpio, Pull};
use crate::chip::nvic::{Irq, Nvic};
use crate::chip::pins::Pin;

/// The boot-time resources shared by the drivers' set-up.
pub struct Boot {
    /// The clock tree every divider is computed from.
    pub clocks: Clocks,
    /// The RCC's peripheral clock enables.
    pub gates: ClockGates,
    /// GPIO ports A..C: `'static` because the IMU's chip select keeps a reference.
    pub gpio: &'static Gpio,
    /// The NVIC.
    pub nvic: Nvic,
}

impl Boot {
    /// Switch `gate`'s clock on.
    pub fn enable_clock(&self, gate: ClockGate) {
        self.gates.enable(gate);
    }

    /// Put `pin` in its alternate function (its port's clock on first).
    pub fn alternate_function(&self, pin: Pin, pull: Pull) {
        self.gpio.alternate_function(&self.gates, pin, pull);
    }

    /// Make `pin` a push-pull output driving `high`.
    pub fn output(&self, pin: Pin, high: bool) {
        self.gpio.output(&self.gates, pin, high);
    }

    /// Set `irq`'s priority and unmask it.
    pub fn enable_interrupt(&mut self, irq: Irq) {
        self.nvic.enable(irq);
    }
}
