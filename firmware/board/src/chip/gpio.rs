//! Pin muxing: a board map's pins ([`crate::chip::pins`]) switched to their alternate
//! functions or driven as outputs, through the PAC's GPIO register blocks.
//!
//! [`Gpio`] owns ports A, B and C (every pin of the supported boards' maps is on them).
//! The set-up (`output`, `alternate_function`: read-modify-writes of the mode, type,
//! speed, pull and AF registers) runs in thread mode at boot; afterwards only [`Gpio::set`]
//! is used (the IMU's chip select), a write of the port's set/reset register, atomic by
//! the hardware.

use embedded_hal::digital::{ErrorType, OutputPin};
use stm32f4::stm32f405 as pac;

use crate::chip::clocks::{ClockGate, ClockGates};
use crate::chip::pins::{Pin, Port};

/// Pull resistor of an input.
#[derive(Clone, Copy)]
pub enum Pull {
    /// Floating.
    None,
    /// Pull-up (idle-high UART line).
    Up,
}

/// GPIO ports A, B and C.
pub struct Gpio {
    a: pac::GPIOA,
    b: pac::GPIOB,
    c: pac::GPIOC,
}

/// Run `$body` with `$gpio` bound to the register block of `$port` (the PAC gives each
/// port family its own type; the field API is the same).
macro_rules! with_port {
    ($self:expr, $port:expr, |$gpio:ident| $body:expr) => {
        match $port {
            Port::A => {
                let $gpio = &$self.a;
                $body
            }
            Port::B => {
                let $gpio = &$self.b;
                $body
            }
            Port::C => {
                let $gpio = &$self.c;
                $body
            }
        }
    };
}

/// The clock gate of `port`.
fn gate(port: Port) -> ClockGate {
    match port {
        Port::A => ClockGate::GpioA,
        Port::B => ClockGate::GpioB,
        Port::C => ClockGate::GpioC,
    }
}

impl Gpio {
    /// The three ports, handed over by the PAC.
    pub fn new(a: pac::GPIOA, b: pac::GPIOB, c: pac::GPIOC) -> Self {
        Gpio { a, b, c }
    }

    /// Make `pin` a push-pull output driving `high` (level set before the mode, so the
    /// pin never glitches to the other level), output speed "fast".
    pub fn output(&self, gates: &ClockGates, pin: Pin, high: bool) {
        gates.enable(gate(pin.port));
        let n = pin.number;
        const MODE_OUTPUT: u8 = 0b01;
        const SPEED_HIGH: u8 = 0b10;
        self.set(pin, high);
        with_port!(self, pin.port, |gpio| {
            gpio.otyper().modify(|_, w| w.ot(n).push_pull());
            gpio.ospeedr().modify(|_, w| w.ospeedr(n).set(SPEED_HIGH));
            gpio.moder().modify(|_, w| w.moder(n).set(MODE_OUTPUT));
        });
    }

    /// Drive output `pin` high or low: one write of the port's set/reset register,
    /// atomic by the hardware.
    pub fn set(&self, pin: Pin, high: bool) {
        let n = pin.number;
        with_port!(self, pin.port, |gpio| gpio.bsrr().write(|w| if high {
            w.bs(n).set_bit()
        } else {
            w.br(n).set_bit()
        }));
    }

    /// Put `pin` in its alternate function (RM0090 §8.3.7, Table 9 of the STM32F405
    /// datasheet for the AF numbers), output speed 0b10 ("fast", 50 MHz); the port's
    /// clock is switched on first.
    pub fn alternate_function(&self, gates: &ClockGates, pin: Pin, pull: Pull) {
        gates.enable(gate(pin.port));
        let (n, af) = (pin.number, pin.af);
        const MODE_ALTERNATE: u8 = 0b10;
        const SPEED_HIGH: u8 = 0b10;
        with_port!(self, pin.port, |gpio| {
            gpio.moder().modify(|_, w| w.moder(n).set(MODE_ALTERNATE));
            gpio.ospeedr().modify(|_, w| w.ospeedr(n).set(SPEED_HIGH));
            gpio.pupdr().modify(|_, w| match pull {
                Pull::None => w.pupdr(n).floating(),
                Pull::Up => w.pupdr(n).pull_up(),
            });
            if n < 8 {
                gpio.afrl().modify(|_, w| w.afr(n).set(af));
            } else {
                gpio.afrh().modify(|_, w| w.afr(n - 8).set(af));
            }
        });
    }
}

/// One pin made an output by [`Gpio::output`], as an `embedded-hal` [`OutputPin`] (the
/// status LED's driver takes one). Each write is one set/reset register write.
pub struct GpioOutput {
    gpio: &'static Gpio,
    pin: Pin,
}

impl GpioOutput {
    /// Make `pin` a push-pull output driving `high` and hand it out.
    pub fn new(gpio: &'static Gpio, gates: &ClockGates, pin: Pin, high: bool) -> Self {
        gpio.output(gates, pin, high);
        GpioOutput { gpio, pin }
    }
}

impl ErrorType for GpioOutput {
    type Error = core::convert::Infallible;
}

impl OutputPin for GpioOutput {
    fn set_low(&mut self) -> Result<(), Self::Error> {
        self.gpio.set(self.pin, false);
        Ok(())
    }

    fn set_high(&mut self) -> Result<(), Self::Error> {
        self.gpio.set(self.pin, true);
        Ok(())
    }
}
