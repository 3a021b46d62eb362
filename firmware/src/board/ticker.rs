//! The fixed-rate tick: TIM5 update interrupt at the loop rate.
//!
//! TIM5 is 32-bit, so it runs with prescaler 0 and an auto-reload computed from its
//! actual kernel clock ([`super::clocks::Clocks::apb1_timer_hz`]). The interrupt handler
//! only counts; the flight logic runs in thread mode and takes the count with
//! [`take_due`], so an overrun (a tick that took longer than the period) shows up as a
//! count above one instead of nested or lost interrupts.

use core::sync::atomic::{AtomicU32, Ordering};

use super::clocks::{ClockGate, Clocks};
use super::dividers::{self, DividerError};
use super::nvic::{self, Irq};
use super::regs::TIM5;

/// Ticks signalled by the timer and not yet taken by the loop.
static DUE: AtomicU32 = AtomicU32::new(0);

const CR1_CEN: u32 = 1 << 0;
const CR1_URS: u32 = 1 << 2;
const DIER_UIE: u32 = 1 << 0;
const SR_UIF: u32 = 1 << 0;

/// The running tick timer.
pub struct Ticker {
    /// Update rate the reload value really gives [mHz].
    pub achieved_millihz: u64,
}

impl Ticker {
    /// Start TIM5 at `rate_hz` from its kernel clock and enable its interrupt.
    pub fn start(clocks: &Clocks, rate_hz: u32) -> Result<Ticker, DividerError> {
        let reload = dividers::tick_reload(clocks.apb1_timer_hz, rate_hz)?;
        ClockGate::TIM5.enable();
        // Out of reset PSC = 0 (also in the shadow register) and ARR preload is off, so
        // no update event (EGR.UG) is needed: the ARR write takes effect at once.
        // Written in this order for QEMU's TIM2..TIM5 model, which arms its alarm on the ARR
        // write and computes the period as ARR + the virtual time of the last PSC, CNT
        // or UG write (its `tick_offset`, ~0 from reset): writing none of those keeps
        // the emulated period at ARR counts (the silicon's is ARR + 1: 0.2 ppm apart).
        TIM5.cr1.write(0);
        TIM5.sr.write(0);
        TIM5.dier.write(DIER_UIE);
        // URS: only counter overflow raises the update interrupt.
        TIM5.cr1.write(CR1_URS | CR1_CEN);
        TIM5.arr.write(reload);
        nvic::enable(Irq::Tim5);
        Ok(Ticker {
            achieved_millihz: dividers::achieved_rate_millihz(clocks.apb1_timer_hz, reload),
        })
    }

    /// Ticks due since the last call (0 when none; more than 1 after an overrun).
    pub fn take_due(&self) -> u32 {
        DUE.swap(0, Ordering::AcqRel)
    }

    /// A tick is waiting to be taken.
    pub fn is_due(&self) -> bool {
        DUE.load(Ordering::Acquire) != 0
    }
}

/// TIM5 interrupt: acknowledge the update and count it.
pub fn on_interrupt() {
    if TIM5.sr.read() & SR_UIF != 0 {
        // rc_w0: writing 0 clears UIF, writing 1 elsewhere leaves the other flags alone.
        TIM5.sr.write(!SR_UIF);
        DUE.fetch_add(1, Ordering::AcqRel);
    }
}
