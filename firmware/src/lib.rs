//! Flight logic of the sweephold flight controller (host-testable; `no_std` on the board).
#![cfg_attr(not(test), no_std)]
