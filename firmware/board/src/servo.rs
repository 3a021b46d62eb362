//! Servo and ESC outputs: PWM compare channels behind `embedded_hal::pwm::SetDutyCycle`.
//!
//! Which pad, timer and channel drives what is the board's pin map ([`crate::pins`]):
//! swash servos 1–3 on TIM4 CH1/CH2 and TIM3 CH3, the tail servo on TIM8 CH3, the ESC on
//! TIM2 CH3. Each timer counts microseconds (prescaler from its actual kernel clock) at
//! the frame rate of its group ([`crate::pins::OutputTimer::frame_hz`]), so a channel's
//! duty value is the pulse width in µs and `max_duty_cycle()` is the frame period in µs.
//!
//! From boot the servos hold their failsafe pulses and the ESC the throttle cut
//! ([`ESC_CUT_US`]): the pins carry them before any other driver starts.

use core::convert::Infallible;
use core::sync::atomic::{AtomicU16, Ordering};

use embedded_hal::pwm::{ErrorType, SetDutyCycle};

use stm32f4::stm32f405 as pac;

use crate::clocks::{ClockGate, Clocks};
use crate::dividers::{self, DividerError};
use crate::gpio::{self, Pull};
use crate::pins::{self, Output, OutputTimer};

pub use crate::pins::{MAX_PULSE_US, MIN_PULSE_US};

/// The ESC's pulse while the motor must not run [µs]: the throttle cut of the board
/// application's standard ESC range (`ThrottleSettings::standard().esc_min_us`).
pub const ESC_CUT_US: u16 = 1000;

/// Pulses of the safe state until the flight logic's mixer is known [µs]: the servo
/// centre of the standard RC convention.
pub const DEFAULT_FAILSAFE_PULSE_US: u16 = 1500;

/// Pulses of the safe state [µs], put on the pins at boot, on a panic and on a fault:
/// [`set_failsafe`] replaces the default with the mixer's output for centred sticks
/// (swash level at mid collective, tail at neutral pitch: the pilot pass-through of a
/// centred transmitter). Atomics, so the panic handler reads them without a lock.
static FAILSAFE_PULSE_US: [AtomicU16; 4] = [
    AtomicU16::new(DEFAULT_FAILSAFE_PULSE_US),
    AtomicU16::new(DEFAULT_FAILSAFE_PULSE_US),
    AtomicU16::new(DEFAULT_FAILSAFE_PULSE_US),
    AtomicU16::new(DEFAULT_FAILSAFE_PULSE_US),
];

/// Set the safe-state pulses (clamped to [`MIN_PULSE_US`, `MAX_PULSE_US`]).
pub fn set_failsafe(pulse_us: [u16; 4]) {
    for (slot, pulse) in FAILSAFE_PULSE_US.iter().zip(pulse_us) {
        slot.store(pulse.clamp(MIN_PULSE_US, MAX_PULSE_US), Ordering::Relaxed);
    }
}

/// Run `$body` with `$tim` bound to the register block of `$timer` (the PAC gives the
/// 32-bit, the 16-bit general-purpose and the advanced timers their own types; the
/// field API the image uses is the same).
macro_rules! with_timer {
    ($timer:expr, |$tim:ident| $body:expr) => {
        match $timer {
            OutputTimer::Tim2 => {
                // SAFETY: TIM2's register block is always mapped. This module is its only
                // user; its read-modify-writes run in thread mode at boot, before any
                // interrupt exists that could touch it, and afterwards only whole
                // compare registers are written (single volatile stores).
                let $tim = unsafe { &*pac::TIM2::ptr() };
                $body
            }
            OutputTimer::Tim3 => {
                // SAFETY: as for TIM2.
                let $tim = unsafe { &*pac::TIM3::ptr() };
                $body
            }
            OutputTimer::Tim4 => {
                // SAFETY: as for TIM2.
                let $tim = unsafe { &*pac::TIM4::ptr() };
                $body
            }
            OutputTimer::Tim8 => {
                // SAFETY: as for TIM2.
                let $tim = unsafe { &*pac::TIM8::ptr() };
                $body
            }
        }
    };
}

/// The kernel clock and the clock gate of an output timer.
fn clock_of(timer: OutputTimer, clocks: &Clocks) -> (ClockGate, u32) {
    match timer {
        OutputTimer::Tim2 => (ClockGate::Tim2, clocks.apb1_timer_hz),
        OutputTimer::Tim3 => (ClockGate::Tim3, clocks.apb1_timer_hz),
        OutputTimer::Tim4 => (ClockGate::Tim4, clocks.apb1_timer_hz),
        OutputTimer::Tim8 => (ClockGate::Tim8, clocks.apb2_timer_hz),
    }
}

/// Write `pulse_us` into the compare register of `output` (a single store).
// One body serves the 32-bit TIM2 (u32 fields) and the 16-bit timers (u16 fields).
#[allow(clippy::useless_conversion)]
fn write_compare(output: &Output, pulse_us: u16) {
    let index = usize::from(output.channel.clamp(1, 4) - 1);
    with_timer!(output.timer, |tim| tim
        .ccr(index)
        .write(|w| w.ccr().set(pulse_us.into())));
}

/// One servo output (a timer compare channel).
pub struct ServoChannel {
    output: Output,
    period_us: u16,
}

impl ErrorType for ServoChannel {
    type Error = Infallible;
}

impl SetDutyCycle for ServoChannel {
    fn max_duty_cycle(&self) -> u16 {
        self.period_us
    }

    fn set_duty_cycle(&mut self, duty: u16) -> Result<(), Infallible> {
        write_compare(&self.output, duty.min(self.period_us));
        Ok(())
    }
}

/// The four outputs, in wire order (`ActuatorOut::servo_us`).
pub struct Servos<P: SetDutyCycle> {
    channels: [P; 4],
}

impl<P: SetDutyCycle> Servos<P> {
    /// Put the pulses `pulse_us` (clamped to [`MIN_PULSE_US`, `MAX_PULSE_US`]) on the
    /// outputs. The duty value of a channel counting µs is the pulse width itself.
    pub fn apply(&mut self, pulse_us: [u16; 4]) -> Result<(), P::Error> {
        for (channel, pulse) in self.channels.iter_mut().zip(pulse_us) {
            channel.set_duty_cycle(pulse.clamp(MIN_PULSE_US, MAX_PULSE_US))?;
        }
        Ok(())
    }
}

/// Start every output timer at its group's frame rate with the failsafe pulses (servos)
/// and the throttle cut (ESC) loaded before the outputs are enabled. Returns the four
/// servos and the ESC's channel (its duty value is the throttle pulse in µs).
// One body serves the 32-bit TIM2 (u32 fields) and the 16-bit timers (u16 fields).
#[allow(clippy::useless_conversion)]
pub fn init(clocks: &Clocks) -> Result<(Servos<ServoChannel>, ServoChannel), DividerError> {
    for timer in OutputTimer::ALL {
        let (gate, timer_hz) = clock_of(timer, clocks);
        let (prescaler, reload) = dividers::servo_dividers(timer_hz, timer.frame_hz())?;
        gate.enable();
        with_timer!(timer, |tim| {
            tim.cr1().reset();
            tim.psc().write(|w| w.psc().set(prescaler));
            tim.arr().write(|w| w.arr().set(reload.into()));
        });
    }
    force_failsafe();
    let outputs = pins::SERVOS.iter().chain([&pins::ESC]);
    for output in outputs.clone() {
        // PWM mode 1 with the compare preload on; channels 1, 2 in CCMR1, 3, 4 in CCMR2.
        let index = output.channel.clamp(1, 4) - 1;
        let within = index % 2;
        with_timer!(output.timer, |tim| {
            if index < 2 {
                tim.ccmr1_output().modify(|_, w| {
                    w.ocm(within).pwm_mode1();
                    w.ocpe(within).set_bit()
                });
            } else {
                tim.ccmr2_output().modify(|_, w| {
                    w.ocm(within).pwm_mode1();
                    w.ocpe(within).set_bit()
                });
            }
            tim.ccer().modify(|_, w| w.cce(index).set_bit());
        });
    }
    // Load prescaler, reload and compare preloads, then start the counters; the advanced
    // timer's outputs also need their main output enable.
    for timer in OutputTimer::ALL {
        with_timer!(timer, |tim| {
            tim.egr().write(|w| w.ug().set_bit());
            tim.cr1().write(|w| w.arpe().set_bit().cen().set_bit());
        });
    }
    // SAFETY: as in `with_timer!`: TIM8 is this module's, written at boot only.
    let tim8 = unsafe { &*pac::TIM8::ptr() };
    tim8.bdtr().modify(|_, w| w.moe().set_bit());
    for output in outputs {
        gpio::alternate_function(output.pin, Pull::None);
    }
    let channel = |output: Output| {
        let frame_us = dividers::SERVO_COUNTER_HZ / output.timer.frame_hz();
        ServoChannel {
            output,
            period_us: u16::try_from(frame_us).unwrap_or(u16::MAX),
        }
    };
    Ok((
        Servos {
            channels: pins::SERVOS.map(channel),
        },
        channel(pins::ESC),
    ))
}

/// Write the failsafe pulses and the throttle cut straight into the compare registers.
/// Needs no driver state, so the panic and fault handlers can call it whatever the
/// program was doing.
pub fn force_failsafe() {
    for (output, pulse) in pins::SERVOS.iter().zip(&FAILSAFE_PULSE_US) {
        write_compare(output, pulse.load(Ordering::Relaxed));
    }
    write_compare(&pins::ESC, ESC_CUT_US);
}
