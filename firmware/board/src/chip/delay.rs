//! A busy-wait `embedded_hal::delay::DelayNs` from the core clock: what the IMU driver's
//! start-up waits (soft reset, gyro start-up) run on, once, at boot.
//!
//! Counts core cycles with `cortex_m::asm::delay` (at least the requested number of
//! cycles on an M4), so a delay is never shorter than asked. Under QEMU the cycles pass
//! at the emulator's speed: longer or shorter in wall time, which the boot does not mind.

use embedded_hal::delay::DelayNs;

/// Busy-wait delay at a known core clock.
#[derive(Clone, Copy, Debug)]
pub struct BusyDelay {
    hclk_hz: u32,
}

impl BusyDelay {
    /// A delay for a core running at `hclk_hz`.
    pub const fn new(hclk_hz: u32) -> Self {
        BusyDelay { hclk_hz }
    }
}

impl DelayNs for BusyDelay {
    fn delay_ns(&mut self, ns: u32) {
        // cycles = ns · f / 1e9, rounded up; at 168 MHz and u32::MAX ns: 7.2e8 cycles,
        // which fits u32.
        let cycles = (u64::from(ns) * u64::from(self.hclk_hz)).div_ceil(1_000_000_000);
        cortex_m::asm::delay(u32::try_from(cycles).unwrap_or(u32::MAX));
    }
}
