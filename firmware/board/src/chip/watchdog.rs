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
//! **Flash saves.** Erasing a 128 KiB sector of the parameter store stalls every flash
//! fetch for up to 2 s (datasheet, x32), so the loop stops; a save may erase one sector
//! (or, repairing an interrupted one, both). Around a save, which the image runs only
//! while disarmed, [`Watchdog::stretch_for_flash`] sets the longest timeout the IWDG
//! has (LSI / 256, reload 4095: 32.8 s nominal, 22.3 s at the LSI's fastest) and
//! [`Watchdog::restore_after_save`] the normal one; RM0090 §21.3 allows changing the
//! prescaler and reload while the watchdog runs (unlock, write, wait for PVU and RVU to
//! clear, then a feed loads them). A watchdog not started yet is left alone.
//!
//! QEMU's `netduinoplus2` does not emulate the IWDG (its registers read zero and ignore
//! writes): there the watchdog is a no-op by construction and the emulated runs are
//! unchanged.

use stm32f4::stm32f405 as pac;

/// IWDG reload value (12 bits): 1000 counts of LSI / 64.
const RELOAD: u16 = 1000;
/// The longest reload (12 bits), with LSI / 256, around a flash save.
const SAVE_RELOAD: u16 = 4095;

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

    /// Before a parameter save: the longest timeout, so a sector erase (up to 2 s, the
    /// loop stalled) cannot reset the board. Nothing if the watchdog has not started.
    pub fn stretch_for_flash(&mut self) {
        if self.started {
            self.set_timeout(true);
        }
    }

    /// After a parameter save: the normal timeout again, fed.
    pub fn restore_after_save(&mut self) {
        if self.started {
            self.set_timeout(false);
        }
    }

    /// Feed, then load LSI / 256 with [`SAVE_RELOAD`] (`long`) or LSI / 64 with
    /// [`RELOAD`], and feed again so the new values count from now.
    fn set_timeout(&mut self, long: bool) {
        let iwdg = &self.iwdg;
        let updating = || {
            let sr = iwdg.sr().read();
            sr.pvu().bit_is_set() || sr.rvu().bit_is_set()
        };
        iwdg.kr().write(|w| w.key().feed());
        // A previous update must have reached the LSI domain before the next write
        // (at most 5 LSI periods, ~160 µs); QEMU reads zero here.
        while updating() {}
        iwdg.kr().write(|w| w.key().unlock());
        if long {
            iwdg.pr().write(|w| w.pr().divide_by256());
            iwdg.rlr().write(|w| w.rl().set(SAVE_RELOAD));
        } else {
            iwdg.pr().write(|w| w.pr().divide_by64());
            iwdg.rlr().write(|w| w.rl().set(RELOAD));
        }
        while updating() {}
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
