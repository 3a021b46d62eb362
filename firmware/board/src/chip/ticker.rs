//! The fixed-rate tick: TIM5 update interrupt at the loop rate.
//!
//! TIM5 is 32-bit, so it runs with prescaler 0 and an auto-reload computed from its
//! actual kernel clock ([`crate::chip::clocks::Clocks::apb1_timer_hz`]). The interrupt handler
//! only counts; the flight logic runs in thread mode and takes the count with
//! [`take_due`], so an overrun (a tick that took longer than the period) shows up as a
//! count above one instead of nested or lost interrupts.

use core::sync::atomic::{AtomicU32, Ordering};

use stm32f4::stm32f405 as pac;

use crate::chip::boot::Boot;
use crate::chip::clocks::ClockGate;
use crate::chip::dividers::{self, DividerError};
use crate::chip::nvic::Irq;
use crate::chip::shared::IrqShared;

/// Ticks signalled by the timer and not yet taken by the loop.
static DUE: AtomicU32 = AtomicU32::new(0);

/// TIM5, once started: after the set-up only the interrupt handler touches it.
static TIM5: IrqShared<pac::TIM5> = IrqShared::new();

/// The running tick timer.
pub struct Ticker {
    /// Update rate the reload value really gives [mHz].
    pub achieved_millihz: u64,
}

impl Ticker {
    /// Start TIM5 at `rate_hz` from its kernel clock and enable its interrupt.
    pub fn start(tim5: pac::TIM5, boot: &mut Boot, rate_hz: u32) -> Result<Ticker, DividerError> {
        let timer_hz = boot.clocks.apb1_timer_hz;
        let reload = dividers::tick_reload(timer_hz, rate_hz)?;
        boot.enable_clock(ClockGate::Tim5);
        // Out of reset PSC = 0 (also in the shadow register) and ARR preload is off, so
        // no update event (EGR.UG) is needed: the ARR write takes effect at once.
        // Written in this order for QEMU's TIM2..TIM5 model, which arms its alarm on the ARR
        // write and computes the period as ARR + the virtual time of the last PSC, CNT
        // or UG write (its `tick_offset`, ~0 from reset): writing none of those keeps
        // the emulated period at ARR counts (the silicon's is ARR + 1: 0.2 ppm apart).
        tim5.cr1().reset();
        tim5.sr().reset();
        tim5.dier().write(|w| w.uie().set_bit());
        // URS: only counter overflow raises the update interrupt.
        tim5.cr1().write(|w| w.urs().set_bit().cen().set_bit());
        tim5.arr().write(|w| w.arr().set(reload));
        cortex_m::interrupt::free(|cs| TIM5.put(cs, tim5));
        boot.enable_interrupt(Irq::Tim5);
        Ok(Ticker {
            achieved_millihz: dividers::achieved_rate_millihz(timer_hz, reload),
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
    cortex_m::interrupt::free(|cs| {
        let Some(tim5) = TIM5.get(cs) else {
            return;
        };
        if tim5.sr().read().uif().bit_is_set() {
            // rc_w0: the PAC writes 1 to the other flags (no effect) and 0 to UIF.
            tim5.sr().write(|w| w.uif().clear());
            DUE.fetch_add(1, Ordering::AcqRel);
        }
    });
}
