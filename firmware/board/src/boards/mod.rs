//! The board list: one folder per flight controller, each with its pin map and crystal
//! (`mod.rs`, a [`BoardMap`]), and the choice of the board the image is built for. The
//! memory layout is the chip's, shared by every board: the workspace's `memory.x`.
//!
//! A board is selected by the cargo feature `board-<folder with dashes>`
//! (`cargo fw --features board-matek-f405-te`); without one, the image is for the
//! default board, the SpeedyBee F405 V4. Two board features at once stop the build.
//!
//! Adding a board: a folder here with `mod.rs`, its line in this list and
//! in `ALL`, and its feature in `Cargo.toml`. Nothing else changes as long as the board
//! is an STM32F405 with the host link on USART1, SBUS on USART2, the log on USART3 and
//! an ICM-42688-P on SPI1 (see [`BoardMap`]).
//!
//! **What it may import.** The chip layer's map types (`crate::chip::pins`) only.

pub use crate::chip::pins::BoardMap;

pub mod matek_f405_te;
pub mod speedybee_f405_v4;

/// The board the image is built for.
#[cfg(feature = "board-matek-f405-te")]
pub const BOARD: BoardMap = matek_f405_te::BOARD;

/// The board the image is built for (the default).
#[cfg(not(feature = "board-matek-f405-te"))]
pub const BOARD: BoardMap = speedybee_f405_v4::BOARD;

/// Every board of the list (for the tests of their maps).
#[cfg(test)]
pub const ALL: [BoardMap; 2] = [speedybee_f405_v4::BOARD, matek_f405_te::BOARD];

#[cfg(test)]
mod tests;
