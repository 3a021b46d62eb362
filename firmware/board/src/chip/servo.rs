//! Servo and ESC outputs: PWM compare channels behind `embedded_hal::pwm::SetDutyCycle`.
//!
//! Which pad, timer and channel drives what is the board's map ([`BoardMap`]: the four
//! servos, the ESC, and each output timer's frame rate). Each timer counts microseconds
//! (prescaler from its actual kernel clock) at the frame rate of its group, so a
//! channel's duty value is the pulse width in µs and `max_duty_cycle()` is the frame
//! period in µs.
//!
//! The output timers (TIM1..TIM4, TIM8) are owned by one [`OutputTimers`], moved to a
//! `'static` place at boot and shared by the channels (each writes only its own compare
//! register, a single store). The panic and fault path is the one place that steals them
//! ([`force_failsafe_anywhere`]).
//!
//! From boot the servos hold their failsafe pulses and the ESC the throttle cut
//! ([`ESC_CUT_US`]): the pins carry them before any other driver starts.

use core::convert::Infallible;
use core::sync::atomic::{AtomicU16, Ordering};

use embedded_hal::pwm::{ErrorType, SetDutyCycle};

use stm32f4::stm32f405 as pac;

use crate::chip::boot::Boot;
use crate::chip::clocks::{ClockGate, Clocks};
use crate::chip::dividers::{self, DividerError};
use crate::chip::gpio::Pull;
use crate::chip::pins::{BoardMap, Output, OutputTimer};

pub use crate::chip::pins::{MAX_PULSE_US, MIN_PULSE_US};

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

/// The timers that may drive outputs, owned.
pub struct OutputTimers {
    tim1: pac::TIM1,
    tim2: pac::TIM2,
    tim3: pac::TIM3,
    tim4: pac::TIM4,
    tim8: pac::TIM8,
}

impl OutputTimers {
    /// The five timers, handed over by the PAC.
    pub fn new(
        tim1: pac::TIM1,
        tim2: pac::TIM2,
        tim3: pac::TIM3,
        tim4: pac::TIM4,
        tim8: pac::TIM8,
    ) -> Self {
        OutputTimers {
            tim1,
            tim2,
            tim3,
            tim4,
            tim8,
        }
    }
}

/// Run `$body` with `$tim` bound to the register block of `$timer` in `$timers` (the PAC
/// gives the 32-bit, the 16-bit general-purpose and the advanced timers their own types;
/// the field API the image uses is the same).
macro_rules! with_timer {
    ($timers:expr, $timer:expr, |$tim:ident| $body:expr) => {
        match $timer {
            OutputTimer::Tim1 => {
                let $tim = &$timers.tim1;
                $body
            }
            OutputTimer::Tim2 => {
                let $tim = &$timers.tim2;
                $body
            }
            OutputTimer::Tim3 => {
                let $tim = &$timers.tim3;
                $body
            }
            OutputTimer::Tim4 => {
                let $tim = &$timers.tim4;
                $body
            }
            OutputTimer::Tim8 => {
                let $tim = &$timers.tim8;
                $body
            }
        }
    };
}

/// The kernel clock and the clock gate of an output timer.
fn clock_of(timer: OutputTimer, clocks: &Clocks) -> (ClockGate, u32) {
    match timer {
        OutputTimer::Tim1 => (ClockGate::Tim1, clocks.apb2_timer_hz),
        OutputTimer::Tim2 => (ClockGate::Tim2, clocks.apb1_timer_hz),
        OutputTimer::Tim3 => (ClockGate::Tim3, clocks.apb1_timer_hz),
        OutputTimer::Tim4 => (ClockGate::Tim4, clocks.apb1_timer_hz),
        OutputTimer::Tim8 => (ClockGate::Tim8, clocks.apb2_timer_hz),
    }
}

/// Write `pulse_us` into the compare register of `output` (a single store).
// One body serves the 32-bit TIM2 (u32 fields) and the 16-bit timers (u16 fields).
#[allow(clippy::useless_conversion)]
fn write_compare(timers: &OutputTimers, output: &Output, pulse_us: u16) {
    let index = usize::from(output.channel.clamp(1, 4) - 1);
    with_timer!(timers, output.timer, |tim| tim
        .ccr(index)
        .write(|w| w.ccr().set(pulse_us.into())));
}

/// One servo output (a timer compare channel).
pub struct ServoChannel {
    timers: &'static OutputTimers,
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
        write_compare(self.timers, &self.output, duty.min(self.period_us));
        Ok(())
    }
}

/// The four outputs, in wire order (`ActuatorOut::servo_us`).
pub struct Servos<P: SetDutyCycle> {
    channels: [P; 4],
}

impl Servos<ServoChannel> {
    /// Frames at `swash_hz` on the swash servos' timers and `tail_hz` on the tail's (the
    /// parameters `SERVO_RATE`, `TAIL_RATE`); the ESC's timer keeps its rate. The board
    /// maps give the tail and the ESC timers of their own (`boards` tests), so each rate
    /// reaches its outputs only. The new reload is preloaded (ARPE): it starts with the
    /// next frame, never cutting one short. Every control tick writes every compare
    /// register, so at 333 Hz (3 ms frames, 5 ms ticks) each command reaches its servo.
    // One body serves the 32-bit TIM2 (u32 fields) and the 16-bit timers (u16 fields).
    #[allow(clippy::useless_conversion)]
    pub fn set_frame_rates(
        &mut self,
        clocks: &Clocks,
        swash_hz: u32,
        tail_hz: u32,
    ) -> Result<(), DividerError> {
        let rates = [swash_hz, swash_hz, swash_hz, tail_hz];
        let mut periods = [0u16; 4];
        // Every divider first: a rate refused leaves every timer as it was.
        for ((channel, rate), period) in self.channels.iter().zip(rates).zip(&mut periods) {
            let (_, timer_hz) = clock_of(channel.output.timer, clocks);
            let (_, reload) = dividers::servo_dividers(timer_hz, rate)?;
            *period = reload.saturating_add(1);
        }
        for (channel, period) in self.channels.iter_mut().zip(periods) {
            let reload = period.saturating_sub(1);
            with_timer!(channel.timers, channel.output.timer, |tim| tim
                .arr()
                .write(|w| w.arr().set(reload.into())));
            channel.period_us = period;
        }
        Ok(())
    }
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

/// Start every output timer of `map` at its group's frame rate with the failsafe pulses
/// (servos) and the throttle cut (ESC) loaded before the outputs are enabled. Returns
/// the four servos and the ESC's channel (its duty value is the throttle pulse in µs).
// One body serves the 32-bit TIM2 (u32 fields) and the 16-bit timers (u16 fields).
#[allow(clippy::useless_conversion)]
pub fn init(
    timers: &'static OutputTimers,
    map: &BoardMap,
    boot: &Boot,
) -> Result<(Servos<ServoChannel>, ServoChannel), DividerError> {
    for rate in map.output_timers {
        let (gate, timer_hz) = clock_of(rate.timer, &boot.clocks);
        let (prescaler, reload) = dividers::servo_dividers(timer_hz, rate.frame_hz)?;
        boot.enable_clock(gate);
        with_timer!(timers, rate.timer, |tim| {
            tim.cr1().reset();
            tim.psc().write(|w| w.psc().set(prescaler));
            tim.arr().write(|w| w.arr().set(reload.into()));
        });
    }
    force_failsafe(timers, map);
    let outputs = map.outputs();
    for output in &outputs {
        // PWM mode 1 with the compare preload on; channels 1, 2 in CCMR1, 3, 4 in CCMR2.
        let index = output.channel.clamp(1, 4) - 1;
        let within = index % 2;
        with_timer!(timers, output.timer, |tim| {
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
    // timers' outputs also need their main output enable.
    for rate in map.output_timers {
        with_timer!(timers, rate.timer, |tim| {
            tim.egr().write(|w| w.ug().set_bit());
            tim.cr1().write(|w| w.arpe().set_bit().cen().set_bit());
        });
    }
    for rate in map.output_timers {
        match rate.timer {
            OutputTimer::Tim1 => {
                timers.tim1.bdtr().modify(|_, w| w.moe().set_bit());
            }
            OutputTimer::Tim8 => {
                timers.tim8.bdtr().modify(|_, w| w.moe().set_bit());
            }
            OutputTimer::Tim2 | OutputTimer::Tim3 | OutputTimer::Tim4 => {}
        }
    }
    for output in &outputs {
        boot.alternate_function(output.pin, Pull::None);
    }
    let channel = |output: Output| {
        let frame_us = dividers::SERVO_COUNTER_HZ / map.frame_hz(output.timer);
        ServoChannel {
            timers,
            output,
            period_us: u16::try_from(frame_us).unwrap_or(u16::MAX),
        }
    };
    Ok((
        Servos {
            channels: map.servos.map(channel),
        },
        channel(map.esc),
    ))
}

/// Write the failsafe pulses and the throttle cut into the compare registers of `map`'s
/// outputs.
fn force_failsafe(timers: &OutputTimers, map: &BoardMap) {
    for (output, pulse) in map.servos.iter().zip(&FAILSAFE_PULSE_US) {
        write_compare(timers, output, pulse.load(Ordering::Relaxed));
    }
    write_compare(timers, &map.esc, ESC_CUT_US);
}

/// [`force_failsafe`] from the panic and fault handlers, whatever the program was doing:
/// needs no driver state and takes the timers regardless of their owner.
pub fn force_failsafe_anywhere(map: &BoardMap) {
    // SAFETY: called only on the way to a reset (panic, fault, unexpected interrupt) with
    // interrupts disabled: the owner of the timers never runs again, so these stolen
    // instances cannot race with it. Each write is a whole compare register (a single
    // store), valid whatever state the timer is in.
    let p = unsafe { pac::Peripherals::steal() };
    let timers = OutputTimers::new(p.TIM1, p.TIM2, p.TIM3, p.TIM4, p.TIM8);
    force_failsafe(&timers, map);
}
