//! Servo and ESC outputs: PWM compare channels behind `embedded_hal::pwm::SetDutyCycle`.
//!
//! Which pad, timer and channel drives what is the board's pin map ([`super::pins`]):
//! swash servos 1–3 on TIM4 CH1/CH2 and TIM3 CH3, the tail servo on TIM8 CH3, the ESC on
//! TIM2 CH3. Each timer counts microseconds (prescaler from its actual kernel clock) at
//! the frame rate of its group ([`super::pins::OutputTimer::frame_hz`]), so a channel's
//! duty value is the pulse width in µs and `max_duty_cycle()` is the frame period in µs.
//!
//! From boot the servos hold their failsafe pulses and the ESC the throttle cut
//! ([`ESC_CUT_US`]): the pins carry them before any other driver starts.

use core::convert::Infallible;
use core::sync::atomic::{AtomicU16, Ordering};

use embedded_hal::pwm::{ErrorType, SetDutyCycle};

use super::clocks::{ClockGate, Clocks};
use super::dividers::{self, DividerError};
use super::gpio::{self, Pull};
use super::pins::{self, Output, OutputTimer};
use super::regs::{GeneralTimer, Reg, TIM2, TIM3, TIM4, TIM8};

pub use super::pins::{MAX_PULSE_US, MIN_PULSE_US};

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

const CCMR_PWM1_PRELOAD: u32 = (0b110 << 4) | (1 << 3); // OCxM = PWM mode 1, OCxPE
const CR1_CEN: u32 = 1 << 0;
const CR1_ARPE: u32 = 1 << 7;
const EGR_UG: u32 = 1 << 0;
const BDTR_MOE: u32 = 1 << 15;

/// The registers, clock gate and kernel clock of an output timer.
fn timer_of(timer: OutputTimer, clocks: &Clocks) -> (GeneralTimer, ClockGate, u32) {
    match timer {
        OutputTimer::Tim2 => (TIM2, ClockGate::TIM2, clocks.apb1_timer_hz),
        OutputTimer::Tim3 => (TIM3, ClockGate::TIM3, clocks.apb1_timer_hz),
        OutputTimer::Tim4 => (TIM4, ClockGate::TIM4, clocks.apb1_timer_hz),
        OutputTimer::Tim8 => (TIM8, ClockGate::TIM8, clocks.apb2_timer_hz),
    }
}

/// The registers of an output timer (no clock needed).
const fn registers(timer: OutputTimer) -> GeneralTimer {
    match timer {
        OutputTimer::Tim2 => TIM2,
        OutputTimer::Tim3 => TIM3,
        OutputTimer::Tim4 => TIM4,
        OutputTimer::Tim8 => TIM8,
    }
}

/// The compare register of `output`.
fn compare(output: &Output) -> Reg {
    let ccr = registers(output.timer).ccr;
    ccr[usize::from(output.channel.clamp(1, 4) - 1)]
}

/// One servo output (a timer compare channel).
pub struct ServoChannel {
    compare: Reg,
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
        self.compare.write(u32::from(duty.min(self.period_us)));
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
/// and the throttle cut (ESC) loaded before the outputs are enabled.
pub fn init(clocks: &Clocks) -> Result<Servos<ServoChannel>, DividerError> {
    for timer in OutputTimer::ALL {
        let (regs, gate, timer_hz) = timer_of(timer, clocks);
        let (prescaler, reload) = dividers::servo_dividers(timer_hz, timer.frame_hz())?;
        gate.enable();
        regs.cr1.write(0);
        regs.psc.write(u32::from(prescaler));
        regs.arr.write(u32::from(reload));
    }
    force_failsafe();
    let outputs = pins::SERVOS.iter().chain([&pins::ESC]);
    for output in outputs.clone() {
        let regs = registers(output.timer);
        let (ccmr, shift) = match output.channel {
            1 => (regs.ccmr1, 0),
            2 => (regs.ccmr1, 8),
            3 => (regs.ccmr2, 0),
            _ => (regs.ccmr2, 8),
        };
        ccmr.write_field(shift, 8, CCMR_PWM1_PRELOAD);
        regs.ccer
            .set_bits(1 << (4 * u32::from(output.channel.clamp(1, 4) - 1)));
    }
    // Load prescaler, reload and compare preloads, then start the counters; the advanced
    // timer's outputs also need their main output enable.
    for timer in OutputTimer::ALL {
        let regs = registers(timer);
        regs.egr.write(EGR_UG);
        if timer == OutputTimer::Tim8 {
            regs.bdtr.write(BDTR_MOE);
        }
        regs.cr1.write(CR1_ARPE | CR1_CEN);
    }
    for output in outputs {
        gpio::alternate_function(output.pin, Pull::None);
    }
    Ok(Servos {
        channels: pins::SERVOS.map(|output| {
            let frame_us = dividers::SERVO_COUNTER_HZ / output.timer.frame_hz();
            ServoChannel {
                compare: compare(&output),
                period_us: u16::try_from(frame_us).unwrap_or(u16::MAX),
            }
        }),
    })
}

/// Write the failsafe pulses and the throttle cut straight into the compare registers.
/// Needs no driver state, so the panic and fault handlers can call it whatever the
/// program was doing.
pub fn force_failsafe() {
    for (output, pulse) in pins::SERVOS.iter().zip(&FAILSAFE_PULSE_US) {
        compare(output).write(u32::from(pulse.load(Ordering::Relaxed)));
    }
    compare(&pins::ESC).write(u32::from(ESC_CUT_US));
}
