//! The routing of device interrupts to their drivers.
//!
//! Without a PAC the vector table's 82 device entries all point at cortex-m-rt's
//! `DefaultHandler`, which receives the IRQ number (CMSIS IRQn): [`dispatch`] routes it.
//! The drivers unmask their own interrupt ([`super::nvic`]); this module is the one
//! place that knows which driver answers which.

use super::nvic::Irq;

/// Route a device interrupt (IRQ number ≥ 0) to its driver. Returns `false` for one the
/// image never enabled, which the caller treats as a fault.
pub fn dispatch(number: i16) -> bool {
    match Irq::from_number(number) {
        Some(Irq::Tim5) => super::ticker::on_interrupt(),
        Some(Irq::Usart1) => super::usart::on_interrupt(),
        None => return false,
    }
    true
}
