//! The test list: the tests a flight can fly, chosen in the air by a transmitter
//! channel (the selector) when the test switch engages.
//!
//! Each entry names what differs between the tests of an identification campaign: the
//! axis, the input, the sweep band (or the pulse width), the record length and the
//! amplitude. Everything else (excitation mode, fades, noise, seed, hold and abort
//! settings) stays the sequencer's one configuration: a campaign flies every record with
//! the same ones. An entry with no axis or a zero record length is empty.
//!
//! # Each test of a flight its own noise
//!
//! The off-axis noise of the n-th test engaged since power-up is seeded with
//! [`engagement_seed`]`(TEST_SEED, n)`: the stored seed for the first test, another seed for
//! each later one. With one seed for all, every test of a flight would put the same noise
//! sequence on its off-axes, and a noise-driven error would repeat in every record the
//! identification combines instead of averaging out. The Header records the seed each
//! test flew with; a flight of one test per power-up flies exactly as before.
//!
//! # Why [`TEST_LIST_LEN`] = 12
//!
//! The campaign the host flies for each aircraft preset (`sweephold campaign`) is two
//! sweeps per axis (the two bands) on four axes and one held-out doublet per axis: 12
//! tests. Twelve entries hold all of them, so one flight flies the whole campaign. More
//! would cost flash for entries no campaign uses (7 parameters each) and make a knob's
//! slices narrower: twelve slices of the selector channel's travel are 1/12 of it each,
//! about 136 SBUS counts, far wider than a knob's jitter.
//!
//! # The selector
//!
//! With a selector channel (`TEST_SEL_CH` ≠ 0) its travel is cut into
//! [`TestList::slices`] equal slices (`TEST_SEL_N`), slice 1 at the low end: position
//! p ∈ [−1, 1] selects entry `min(⌊(p + 1)/2 · n⌋, n − 1) + 1`. A knob sweeps them all;
//! a 3-position switch (−1, 0, +1) with n = 3 selects entries 1, 2, 3, a 6-position
//! switch (−1, −0.6, −0.2, 0.2, 0.6, 1) with n = 6 entries 1 … 6. Without one
//! (`TEST_SEL_CH` = 0) the test switch engages the single test of the `TEST_*`
//! parameters, entry 0 in the Header, as before the list existed.

use sweephold_protocol::{Axis, InputKind, TestConfig, VehicleId};

use crate::config::{Config, ConfigError};

/// Entries in the test list (see the module documentation for the choice).
pub const TEST_LIST_LEN: usize = 12;

/// The off-axis noise seed of the `engagement`-th test since power-up (1-based): `seed`
/// for the first (and for 0, no engagement), then `seed` plus (n − 1) times the 32-bit
/// golden-ratio constant 0x9E37_79B9 (a Weyl sequence: no two engagements below 2³² share
/// a seed). The noise generator (PCG32) mixes its seed, so neighbouring seeds give
/// unrelated sequences.
pub const fn engagement_seed(seed: u32, engagement: u16) -> u32 {
    let later = engagement.saturating_sub(1) as u32;
    seed.wrapping_add(later.wrapping_mul(0x9E37_79B9))
}

/// One entry of the list.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct TestEntry {
    /// The excited axis; `None`: the entry is empty.
    pub axis: Option<Axis>,
    /// The excitation signal.
    pub input: InputKind,
    /// Sweep start frequency \[rad/s\].
    pub omega_min: f32,
    /// Sweep end frequency \[rad/s\].
    pub omega_max: f32,
    /// Doublet / 3-2-1-1 unit pulse width \[s\].
    pub pulse_width_s: f32,
    /// Record length \[s\]; 0: the entry is empty.
    pub t_rec_s: f32,
    /// Sweep or pulse amplitude, fraction of stick travel.
    pub amplitude: f32,
}

impl TestEntry {
    /// An empty entry (its other fields valid values, so that a table of them loads).
    pub const EMPTY: TestEntry = TestEntry {
        axis: None,
        input: InputKind::Sweep,
        omega_min: 0.2,
        omega_max: 31.4,
        pulse_width_s: 1.0,
        t_rec_s: 0.0,
        amplitude: 0.05,
    };

    /// Whether the entry holds no test (no axis or no record length).
    pub fn is_empty(&self) -> bool {
        self.axis.is_none() || self.t_rec_s <= 0.0
    }

    /// The entry of `test`: its axis, input, band, pulse width, record length and sweep
    /// amplitude (the inverse of [`TestEntry::apply`] where sweep and pulse amplitudes
    /// agree).
    pub const fn of(test: &TestConfig) -> TestEntry {
        TestEntry {
            axis: Some(test.primary),
            input: test.input,
            omega_min: test.sweep.omega_min,
            omega_max: test.sweep.omega_max,
            pulse_width_s: test.pulse.width_s,
            t_rec_s: test.sweep.t_rec_s,
            amplitude: test.sweep.amplitude,
        }
    }

    /// `base` with this entry's axis, input, band, pulse width, record length and
    /// amplitude (sweep and pulse); `base` itself for an empty entry.
    pub fn apply(&self, base: &TestConfig) -> TestConfig {
        let mut test = *base;
        let Some(axis) = self.axis.filter(|_| !self.is_empty()) else {
            return test;
        };
        test.primary = axis;
        test.input = self.input;
        test.sweep.omega_min = self.omega_min;
        test.sweep.omega_max = self.omega_max;
        test.sweep.t_rec_s = self.t_rec_s;
        test.sweep.amplitude = self.amplitude;
        test.pulse.width_s = self.pulse_width_s;
        test.pulse.amplitude = self.amplitude;
        test
    }
}

/// Why a test list was refused.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum TestListError {
    /// `slices` is not 1 … [`TEST_LIST_LEN`].
    SlicesOutOfRange,
    /// Entry `entry` (1-based) makes a test the sequencer refuses.
    Entry {
        /// The entry's number.
        entry: u8,
        /// Why the sequencer refuses it.
        error: ConfigError,
    },
}

impl TestListError {
    /// Human-readable explanation.
    pub const fn message(self) -> &'static str {
        match self {
            TestListError::SlicesOutOfRange => "test selector slices must be 1 to 12",
            TestListError::Entry { error, .. } => error.message(),
        }
    }
}

/// The list and how the selector channel is cut.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct TestList {
    /// Entries 1 … [`TEST_LIST_LEN`], in order.
    pub entries: [TestEntry; TEST_LIST_LEN],
    /// Equal slices of the selector channel's travel, mapped onto entries 1 … `slices`.
    pub slices: u8,
}

/// The first band of every preset's campaign (the paper's Fig. 8 band; the TREX 700L's
/// reaches 62.8 rad/s, past its coupled rotor–body modes) and the second (Fig. 9).
const BO105_BANDS: [(f32, f32); 2] = [(0.2, 31.4), (0.01, 18.85)];
const TREX700L_BANDS: [(f32, f32); 2] = [(0.2, 62.8), (0.01, 18.85)];

/// Top of a loop test's band \[rad/s\]: above the phase crossovers of the presets' loops
/// (predicted 18–45 rad/s on the identified models; the Bo-105's heading loop at 42 rad/s,
/// past its campaign band's 31.4, where a loop test on that band measured no gain margin).
pub const LOOP_TEST_OMEGA_MAX: f32 = 62.8;

/// A campaign entry: 90 s at 5 % of stick travel.
const fn entry(
    axis: Axis,
    input: InputKind,
    (omega_min, omega_max): (f32, f32),
    pulse_width_s: f32,
) -> TestEntry {
    TestEntry {
        axis: Some(axis),
        input,
        omega_min,
        omega_max,
        pulse_width_s,
        t_rec_s: 90.0,
        amplitude: 0.05,
    }
}

impl TestList {
    /// The campaign of `vehicle`'s preset, as `sweephold campaign` flies it: for each
    /// axis (lat, lon, ped, col) its two sweep bands (entries 1 … 8), then one doublet
    /// per axis on the first band (entries 9 … 12, the verification records); 90 s
    /// records at 5 % of stick travel, the preset's pulse width (Bo-105 1 s, TREX 700L
    /// 0.3 s). Twelve slices.
    pub const fn campaign(vehicle: VehicleId) -> TestList {
        let (bands, pulse_width_s) = match vehicle {
            VehicleId::Bo105 => (BO105_BANDS, 1.0),
            VehicleId::Trex700l => (TREX700L_BANDS, 0.3),
        };
        let [first, second] = bands;
        let w = pulse_width_s;
        let entries = [
            entry(Axis::Lat, InputKind::Sweep, first, w),
            entry(Axis::Lat, InputKind::Sweep, second, w),
            entry(Axis::Lon, InputKind::Sweep, first, w),
            entry(Axis::Lon, InputKind::Sweep, second, w),
            entry(Axis::Ped, InputKind::Sweep, first, w),
            entry(Axis::Ped, InputKind::Sweep, second, w),
            entry(Axis::Col, InputKind::Sweep, first, w),
            entry(Axis::Col, InputKind::Sweep, second, w),
            entry(Axis::Lat, InputKind::Doublet, first, w),
            entry(Axis::Lon, InputKind::Doublet, first, w),
            entry(Axis::Ped, InputKind::Doublet, first, w),
            entry(Axis::Col, InputKind::Doublet, first, w),
        ];
        TestList {
            entries,
            slices: TEST_LIST_LEN as u8,
        }
    }

    /// The loop tests of `vehicle`'s preset ([`InputKind::LoopSweep`]): the roll (lat),
    /// pitch (lon) and yaw/heading (ped) loops broken at their actuator input, in
    /// entries 1, 2, 3, each a 90 s sweep at 5 % of stick travel from the campaign's
    /// first band's ω_min to [`LOOP_TEST_OMEGA_MAX`]. Three slices.
    pub const fn loop_tests(vehicle: VehicleId) -> TestList {
        let (bands, pulse_width_s) = match vehicle {
            VehicleId::Bo105 => (BO105_BANDS, 1.0),
            VehicleId::Trex700l => (TREX700L_BANDS, 0.3),
        };
        let [(omega_min, _), _] = bands;
        let first = (omega_min, LOOP_TEST_OMEGA_MAX);
        let w = pulse_width_s;
        let mut entries = [TestEntry::EMPTY; TEST_LIST_LEN];
        entries[0] = entry(Axis::Lat, InputKind::LoopSweep, first, w);
        entries[1] = entry(Axis::Lon, InputKind::LoopSweep, first, w);
        entries[2] = entry(Axis::Ped, InputKind::LoopSweep, first, w);
        TestList { entries, slices: 3 }
    }

    /// The entry (1 … `slices`) the selector at position `position` ∈ [−1, 1] selects;
    /// a non-finite position selects nothing.
    pub fn entry_at(&self, position: f32) -> Option<u8> {
        if !position.is_finite() {
            return None;
        }
        let n = self.slices.clamp(1, TEST_LIST_LEN as u8);
        let u = (position.clamp(-1.0, 1.0) + 1.0) * 0.5;
        let slice = libm::floorf(u * f32::from(n)) as u8;
        Some(slice.min(n - 1) + 1)
    }

    /// Entry `entry` (1-based), if it exists and is not empty.
    pub fn get(&self, entry: u8) -> Option<&TestEntry> {
        let index = usize::from(entry).checked_sub(1)?;
        self.entries.get(index).filter(|e| !e.is_empty())
    }

    /// Check the slices and that every non-empty entry makes a test `base` accepts.
    pub fn validate(&self, base: &Config) -> Result<(), TestListError> {
        if !(1..=TEST_LIST_LEN as u8).contains(&self.slices) {
            return Err(TestListError::SlicesOutOfRange);
        }
        for (i, entry) in self.entries.iter().enumerate() {
            if entry.is_empty() {
                continue;
            }
            let config = Config {
                test: entry.apply(&base.test),
                ..*base
            };
            config.validate().map_err(|error| TestListError::Entry {
                entry: i as u8 + 1,
                error,
            })?;
        }
        Ok(())
    }
}
