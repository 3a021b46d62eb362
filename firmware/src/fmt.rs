//! Logging shim (embassy style): the macros log through `defmt` on the flight controller
//! (`target_os = "none"`: the board image always logs) or with the `defmt` feature, and
//! compile to nothing otherwise, so host tests never need the defmt linker symbols. The arguments are still evaluated by reference in the silent build, which
//! keeps "unused variable" warnings identical in both configurations.
#![allow(unused_macros)]

/// Trace-level log line (defmt format string).
macro_rules! trace {
    ($s:literal $(, $x:expr)* $(,)?) => {{
        #[cfg(any(feature = "defmt", target_os = "none"))]
        ::defmt::trace!($s $(, $x)*);
        #[cfg(not(any(feature = "defmt", target_os = "none")))]
        let _ = ($( & $x ),*);
    }};
}

/// Debug-level log line (defmt format string).
macro_rules! debug {
    ($s:literal $(, $x:expr)* $(,)?) => {{
        #[cfg(any(feature = "defmt", target_os = "none"))]
        ::defmt::debug!($s $(, $x)*);
        #[cfg(not(any(feature = "defmt", target_os = "none")))]
        let _ = ($( & $x ),*);
    }};
}

/// Info-level log line (defmt format string).
macro_rules! info {
    ($s:literal $(, $x:expr)* $(,)?) => {{
        #[cfg(any(feature = "defmt", target_os = "none"))]
        ::defmt::info!($s $(, $x)*);
        #[cfg(not(any(feature = "defmt", target_os = "none")))]
        let _ = ($( & $x ),*);
    }};
}

/// Warning-level log line (defmt format string).
macro_rules! warn {
    ($s:literal $(, $x:expr)* $(,)?) => {{
        #[cfg(any(feature = "defmt", target_os = "none"))]
        ::defmt::warn!($s $(, $x)*);
        #[cfg(not(any(feature = "defmt", target_os = "none")))]
        let _ = ($( & $x ),*);
    }};
}

/// Error-level log line (defmt format string).
macro_rules! error {
    ($s:literal $(, $x:expr)* $(,)?) => {{
        #[cfg(any(feature = "defmt", target_os = "none"))]
        ::defmt::error!($s $(, $x)*);
        #[cfg(not(any(feature = "defmt", target_os = "none")))]
        let _ = ($( & $x ),*);
    }};
}
