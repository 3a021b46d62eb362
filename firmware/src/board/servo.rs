//! Servo outputs: four PWM channels of TIM3 behind `embedded_hal::pwm::SetDutyCycle`.
//!
//! | output | signal            | pin | TIM3 channel | AF |
//! |--------|-------------------|-----|--------------|----|
//! | 1      | swash servo 1     | PA6 | CH1          | 2  |
//! | 2      | swash servo 2     | PA7 | CH2          | 2  |
//! | 3      | swash servo 3     | PB0 | CH3          | 2  |
//! | 4      | tail servo        | PB1 | CH4          | 2  |
//!
//! TIM3 counts microseconds (prescaler from its actual kernel clock), so a channel's duty
//! value is the pulse width in µs and `max_duty_cycle()` is the frame period in µs.

use core::convert::Infallible;
use core::sync::atomic::{AtomicU16, Ordering};

use embedded_hal::pwm::{ErrorType, SetDutyCycle};

use super::clocks::{ClockGate, Clocks};
use super::dividers::{self, DividerError};
use super::gpio::{self, Pull};
use super::regs::{Reg, GPIOA, GPIOB, TIM3};

/// PWM frame rate [Hz]. 50 Hz is safe for every servo; digital swash servos of the
/// 700 class accept up to 333 Hz (then the frame is 3003 µs, still above the pulse).
pub const FRAME_HZ: u32 = 50;

/// Shortest pulse ever put on a pin [µs]; the flight logic's outputs are clamped here.
pub const MIN_PULSE_US: u16 = 900;
/// Longest pulse ever put on a pin [µs].
pub const MAX_PULSE_US: u16 = 2100;

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

/// One servo output (a TIM3 compare channel).
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

/// Start TIM3 with the failsafe pulses loaded before the outputs are enabled.
pub fn init(clocks: &Clocks) -> Result<Servos<ServoChannel>, DividerError> {
    // TIM3 shares TIM2's APB1 timer clock.
    let (prescaler, reload) = dividers::servo_dividers(clocks.apb1_timer_hz, FRAME_HZ)?;
    ClockGate::TIM3.enable();
    ClockGate::GPIOA.enable();
    ClockGate::GPIOB.enable();
    TIM3.cr1.write(0);
    TIM3.psc.write(u32::from(prescaler));
    TIM3.arr.write(u32::from(reload));
    force_failsafe();
    TIM3.ccmr1
        .write(CCMR_PWM1_PRELOAD | (CCMR_PWM1_PRELOAD << 8));
    TIM3.ccmr2
        .write(CCMR_PWM1_PRELOAD | (CCMR_PWM1_PRELOAD << 8));
    // Load prescaler, reload and compare preloads, then enable the four outputs.
    TIM3.egr.write(EGR_UG);
    TIM3.ccer.write((1 << 0) | (1 << 4) | (1 << 8) | (1 << 12));
    TIM3.cr1.write(CR1_ARPE | CR1_CEN);
    gpio::alternate_function(GPIOA, 6, 2, Pull::None);
    gpio::alternate_function(GPIOA, 7, 2, Pull::None);
    gpio::alternate_function(GPIOB, 0, 2, Pull::None);
    gpio::alternate_function(GPIOB, 1, 2, Pull::None);
    let period_us = reload.saturating_add(1);
    Ok(Servos {
        channels: TIM3.ccr.map(|compare| ServoChannel { compare, period_us }),
    })
}

/// Write the failsafe pulses straight into the compare registers. Needs no driver
/// state, so the panic and fault handlers can call it whatever the program was doing.
pub fn force_failsafe() {
    for (compare, pulse) in TIM3.ccr.iter().zip(&FAILSAFE_PULSE_US) {
        compare.write(u32::from(pulse.load(Ordering::Relaxed)));
    }
}
