//! Pin muxing: the pins of the board's map ([`crate::pins`]) switched to their alternate
//! functions, through the PAC's GPIO register blocks.

use stm32f4::stm32f405 as pac;

use crate::clocks::ClockGate;
use crate::pins::{Pin, Port};

/// Pull resistor of an input.
#[derive(Clone, Copy)]
pub enum Pull {
    /// Floating.
    None,
    /// Pull-up (idle-high UART line).
    Up,
}

/// Run `$body` with `$gpio` bound to the register block of `$port` (the PAC gives each
/// port family its own type; the field API is the same).
macro_rules! with_port {
    ($port:expr, |$gpio:ident| $body:expr) => {
        match $port {
            Port::A => {
                // SAFETY: GPIOA's register block is always mapped; this module is the
                // only writer of the port's mode, speed, pull and AF registers, and
                // `modify` is used from thread mode only (boot), so no write is lost.
                let $gpio = unsafe { &*pac::GPIOA::ptr() };
                $body
            }
            Port::B => {
                // SAFETY: as for GPIOA.
                let $gpio = unsafe { &*pac::GPIOB::ptr() };
                $body
            }
            Port::C => {
                // SAFETY: as for GPIOA.
                let $gpio = unsafe { &*pac::GPIOC::ptr() };
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

/// Put `pin` in its alternate function (RM0090 §8.3.7, Table 9 of the STM32F405
/// datasheet for the AF numbers), output speed 0b10 ("fast", 50 MHz); the port's clock is switched on
/// first.
pub fn alternate_function(pin: Pin, pull: Pull) {
    gate(pin.port).enable();
    let (n, af) = (pin.number, pin.af);
    const MODE_ALTERNATE: u8 = 0b10;
    const SPEED_HIGH: u8 = 0b10;
    with_port!(pin.port, |gpio| {
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
