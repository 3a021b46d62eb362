//! The device interrupts the image uses, and their dispatch.
//!
//! Without a PAC the vector table's 82 device entries all point at cortex-m-rt's
//! `DefaultHandler`, which receives the IRQ number (CMSIS IRQn): [`dispatch`] routes it.

use super::regs::nvic::{ICER, ISER};

/// Device interrupts of the STM32F405 the image enables (RM0090 Table 61, position).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(target_os = "none", derive(defmt::Format))]
pub enum Irq {
    /// TIM2 global interrupt: the loop tick.
    Tim2 = 28,
    /// USART1 global interrupt: receive, and transmit on silicon.
    Usart1 = 37,
}

impl Irq {
    fn from_number(number: i16) -> Option<Irq> {
        match number {
            28 => Some(Irq::Tim2),
            37 => Some(Irq::Usart1),
            _ => None,
        }
    }

    /// Register index and bit of this IRQ in ISER/ICER.
    fn slot(self) -> (usize, u32) {
        let n = self as usize;
        (n / 32, 1 << (n % 32))
    }
}

/// Unmask `irq` in the NVIC.
pub fn enable(irq: Irq) {
    let (index, bit) = irq.slot();
    if let Some(register) = ISER.get(index) {
        register.write(bit);
    }
}

/// Mask `irq` in the NVIC.
pub fn disable(irq: Irq) {
    let (index, bit) = irq.slot();
    if let Some(register) = ICER.get(index) {
        register.write(bit);
    }
}

/// Route a device interrupt (IRQ number ≥ 0) to its driver. Returns `false` for one the
/// image never enabled, which the caller treats as a fault.
pub fn dispatch(number: i16) -> bool {
    match Irq::from_number(number) {
        Some(Irq::Tim2) => super::ticker::on_interrupt(),
        Some(Irq::Usart1) => super::usart::on_interrupt(),
        None => return false,
    }
    true
}
