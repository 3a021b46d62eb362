//! Pin muxing: the pins the image uses, switched to their alternate functions.

use super::clocks::ClockGate;
use super::pins::{Pin, Port};
use super::regs::{GpioPort, GPIOA, GPIOB, GPIOC};

/// Pull resistor of an input.
#[derive(Clone, Copy)]
pub enum Pull {
    /// Floating.
    None,
    /// Pull-up (idle-high UART line).
    Up,
}

/// The registers and the clock gate of `port`.
fn port_of(port: Port) -> (GpioPort, ClockGate) {
    match port {
        Port::A => (GPIOA, ClockGate::GPIOA),
        Port::B => (GPIOB, ClockGate::GPIOB),
        Port::C => (GPIOC, ClockGate::GPIOC),
    }
}

/// Put `pin` (of the board's [`super::pins`] map) in its alternate function (RM0090
/// §8.3.7, Table 9 of the STM32F405 datasheet for the AF numbers), fast output speed;
/// the port's clock is switched on first.
pub fn alternate_function(pin: Pin, pull: Pull) {
    let (port, gate) = port_of(pin.port);
    gate.enable();
    let af = u32::from(pin.af);
    let pin = u32::from(pin.number);
    const MODE_ALTERNATE: u32 = 0b10;
    const SPEED_FAST: u32 = 0b10;
    port.moder.write_field(2 * pin, 2, MODE_ALTERNATE);
    port.ospeedr.write_field(2 * pin, 2, SPEED_FAST);
    let pull_bits = match pull {
        Pull::None => 0b00,
        Pull::Up => 0b01,
    };
    port.pupdr.write_field(2 * pin, 2, pull_bits);
    if pin < 8 {
        port.afrl.write_field(4 * pin, 4, af);
    } else {
        port.afrh.write_field(4 * (pin - 8), 4, af);
    }
}
