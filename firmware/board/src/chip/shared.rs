//! A peripheral that its driver and the driver's interrupt handler both use.
//!
//! The driver's `init` owns the PAC instance (taken once at boot), configures it, and
//! puts it here before it unmasks the interrupt; from then on thread mode and the handler
//! reach the registers inside a critical section, so a read-modify-write of one never
//! interleaves with the other's. No `unsafe`: the cell is `cortex_m`'s `Mutex` around
//! `core`'s `OnceCell`.

use core::cell::OnceCell;

use cortex_m::interrupt::{CriticalSection, Mutex};

/// A peripheral handed over once, then shared with an interrupt handler.
pub struct IrqShared<T>(Mutex<OnceCell<T>>);

impl<T> IrqShared<T> {
    /// Empty until [`put`](Self::put).
    pub const fn new() -> Self {
        IrqShared(Mutex::new(OnceCell::new()))
    }

    /// Hand the peripheral over (once: the PAC gives out each instance once, so a second
    /// one cannot exist).
    pub fn put(&self, cs: &CriticalSection, peripheral: T) {
        let _ = self.0.borrow(cs).set(peripheral);
    }

    /// The peripheral, once handed over.
    pub fn get<'cs>(&'cs self, cs: &'cs CriticalSection) -> Option<&'cs T> {
        self.0.borrow(cs).get()
    }
}
