//! What more than one module of the CLI tests needs.

pub mod scratch;
#[cfg(unix)]
pub mod signals;

pub use scratch::Scratch;
