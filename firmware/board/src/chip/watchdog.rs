//! The independent watchdog (IWDG): a reset unless a fresh sensor sample keeps being
//! processed.
//!
//! The IWDG runs from the 32 kHz LSI, independent of the main clock tree, and once
//! started nothing but a reset stops it. It is started by the first fresh sample the
//! loop processes and fed by every fresh sample after that ([`Watchdog::fed_by_fresh_sample`]):
//! a loop that stops processing fresh samples (stuck in a handler, a lock-up, a host
//! in the loop gone silent) resets the MCU, and the boot path starts Disarmed with the
//! servos at their failsafe pulses and the ESC at the throttle cut. In the board
//! application the fresh sample is an IMU sample through the filters and the estimator;
//! in the loop, the host's SensorIn. An image whose IMU never answered never starts it.
//!
//! One exception: while the board application flies its IMU failsafe (an IMU fault it
//! detected and handles: trim plus reduced direct pilot inputs), each control tick feeds
//! the watchdog ([`Watchdog::fed_by_failsafe_tick`]). The loop is demonstrably running
//! then, and a reset would put an airborne helicopter into Disarmed with the throttle cut;
//! a loop that hangs in the failsafe still stops feeding it.
//!
//! Timeout: LSI / 64 with a reload of 1000, nominally 2 s (LSI 32 kHz), 1.36 s at the
//! LSI's fastest (47 kHz, datasheet): always longer than the link timeout, so a host
//! that falls silent first gets the stale-sensor abort, logged, then the reset.
//!
//! QEMU's `netduinoplus2` does not emulate the IWDG (its registers read zero and ignore
//! writes): there the watchdog is a no-op by construction and the emulated runs are
//! unchanged.

use stm32f4::stm32f405 as pac;

/// IWDG reload value (12 bits): 1000 counts of LSI / 64.
const RELOAD: u16 = 1000;

/// The watchdog: not started until the first fresh sample. Owns the IWDG (thread mode
/// only).
pub struct Watchdog {
    iwdg: pac::IWDG,
    started: bool,
}

impl Watchdog {
    /// A watchdog that has not started.
    pub fn new(iwdg: pac::IWDG) -> Self {
        Watchdog {
            iwdg,
            started: false,
        }
    }

    /// A fresh sample was processed: start the watchdog (the first time) or feed it.
    pub fn fed_by_fresh_sample(&mut self) {
        let iwdg = &self.iwdg;
        if !self.started {
            self.started = true;
            // Start first (the LSI comes up with it), then unlock and set the prescaler
            // and reload (RM0090 §21.3.2); the values take effect at the next feed.
            iwdg.kr().write(|w| w.key().start());
            iwdg.kr().write(|w| w.key().unlock());
            iwdg.pr().write(|w| w.pr().divide_by64());
            iwdg.rlr().write(|w| w.rl().set(RELOAD));
            defmt::info!("watchdog started: fed by every fresh sample");
        }
        iwdg.kr().write(|w| w.key().feed());
    }

    /// A control tick of the IMU failsafe ran: feed the watchdog if it is running (never
    /// start it: only a fresh sample does).
    pub fn fed_by_failsafe_tick(&mut self) {
        if self.started {
            self.iwdg.kr().write(|w| w.key().feed());
        }
    }
}
