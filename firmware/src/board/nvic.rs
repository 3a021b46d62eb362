//! The device interrupts the image uses, and their masks in the NVIC. Which driver
//! handles each is [`super::interrupts`]'s routing.

use super::regs::nvic::{ICER, ISER};

/// Device interrupts of the STM32F405 the image enables (RM0090 Table 61, position).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(target_os = "none", derive(defmt::Format))]
pub enum Irq {
    /// TIM5 global interrupt: the loop tick.
    Tim5 = 50,
    /// USART1 global interrupt: receive, and transmit on silicon.
    Usart1 = 37,
}

impl Irq {
    /// The interrupt of IRQ number `number` (CMSIS IRQn), if the image uses it.
    pub fn from_number(number: i16) -> Option<Irq> {
        match number {
            50 => Some(Irq::Tim5),
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
