//! What more than one CLI test binary needs.

pub mod signals;
