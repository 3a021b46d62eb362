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
                // only writer of the port's mode, type, speed, pull and AF registers,
                // and `modify` is used from thread mode only (boot), so no write is
                // lost; pin levels change through BSRR, a write-only register whose
                // writes are atomic.
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

/// Make `pin` a push-pull output driving `high` (level set before the mode, so the pin
/// never glitches to the other level), output speed "fast".
pub fn output(pin: Pin, high: bool) {
    gate(pin.port).enable();
    let n = pin.number;
    const MODE_OUTPUT: u8 = 0b01;
    const SPEED_HIGH: u8 = 0b10;
    set(pin, high);
    with_port!(pin.port, |gpio| {
        gpio.otyper().modify(|_, w| w.ot(n).push_pull());
        gpio.ospeedr().modify(|_, w| w.ospeedr(n).set(SPEED_HIGH));
        gpio.moder().modify(|_, w| w.moder(n).set(MODE_OUTPUT));
    });
}

/// Drive output `pin` high or low: one write of the port's set/reset register, atomic
/// by the hardware, so any context may call it.
pub fn set(pin: Pin, high: bool) {
    let n = pin.number;
    with_port!(pin.port, |gpio| gpio.bsrr().write(|w| if high {
        w.bs(n).set_bit()
    } else {
        w.br(n).set_bit()
    }));
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
