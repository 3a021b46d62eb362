//! The channel map: which SBUS channel drives which function, and how raw channel
//! values become stick fractions, a throttle fraction and switch positions.
//!
//! # Default map (flybarless helicopter)
//!
//! | channel | function                          | output                         | kind      |
//! |---------|-----------------------------------|--------------------------------|-----------|
//! | ch1     | lateral cyclic (aileron)          | `sticks.lat` in [−1, 1]        | stick     |
//! | ch2     | longitudinal cyclic (elevator)    | `sticks.lon` in [−1, 1]        | stick     |
//! | ch3     | throttle                          | `throttle` in [0, 1]           | unipolar  |
//! | ch4     | pedal (rudder)                    | `sticks.ped` in [−1, 1]        | stick     |
//! | ch5     | arm switch                        | `arm`                          | 2-position|
//! | ch6     | collective (pitch)                | `sticks.col` in [−1, 1]        | stick     |
//! | ch7     | test switch                       | `test_switch`                  | 2-position|
//! | ch8     | mode switch                       | `mode`: Low / Middle / High    | 3-position|
//! | none    | test selector (knob or switch)    | `selector` in [−1, 1] or None  | stick     |
//!
//! The test selector ([`ChannelMap::selector`], parameter `TEST_SEL_CH`) has no channel
//! by default (channel 0): `selector` is then `None` and the test switch engages the
//! single configured test. With a channel it reads like a stick; the board application
//! cuts its travel into slices that select an entry of the test list
//! ([`crate::app::test_list`]).
//!
//! Each function has its own channel (1 … 16, distinct) and a `reversed` flag;
//! [`ChannelMap::validate`] checks both. Positive stick outputs follow the sign
//! convention of [`Controls`]: lat rolls right, lon pitches nose up, ped yaws nose right,
//! col raises the collective. Radios differ in which way a channel moves for a given
//! stick: set `reversed` so that the table's positive direction raises the mapped value,
//! and check each function on the bench.
//!
//! # Raw values
//!
//! SBUS carries 11-bit values. Radios and receivers scale their ±100 % travel to
//! 172 … 1811 with centre 992 (the common 10-bit-scaled range: ±100 % ↔ 992 ± 819.2,
//! 0.625 µs per count around 1500 µs, i.e. 988 … 2012 µs), which is [`RawRange::SBUS`].
//! The two halves of that range differ by one count (820 below the centre, 819 above),
//! so the stick mapping scales each half by its own span, which gives the endpoints and
//! the centre exactly:
//!
//! ```text
//! stick(r)    = (r − c)/(c − min)   for r < c,   (r − c)/(max − c)   for r ≥ c,
//!               clamped to [−1, 1];                    reversed: −stick(r)
//! throttle(r) = (r − min)/(max − min), clamped to [0, 1];   reversed: 1 − throttle(r)
//! ```
//!
//! so 172 ↦ −1, 992 ↦ 0, 1811 ↦ +1 and 172 ↦ 0, 1811 ↦ 1 for the throttle. Values
//! beyond the range (radios with extended limits give 0 … 2047) clamp. All arithmetic
//! starts from integers, so no output can be NaN; a range whose spans are not positive
//! (an unvalidated map) yields 0 rather than a division by zero.
//!
//! # Switches
//!
//! A switch channel is first mapped like a stick, `s = stick(r)` (reversal included),
//! then compared with the threshold `τ` ([`ChannelMap::switch_threshold`], default ½):
//!
//! ```text
//! two-position:   on  ⇔ s > τ                       (everything else off)
//! three-position: Low ⇔ s < −τ,   High ⇔ s > τ,     Middle otherwise
//! ```
//!
//! The decision depends on the present value only — no hysteresis, no memory — and the
//! nominal switch positions (−1, 0, +1) sit a clear band of 1 − τ = ½ (410 counts) away
//! from any threshold, so servo-style jitter of a few counts never flips a switch. A
//! two-position switch reads *on* only in its upper band: a value at or below the
//! threshold, including one exactly at it, is *off* (disarmed, no test).

use super::sbus::{SbusFrame, CHANNELS};
use sweephold_protocol::{Controls, PilotInput};

/// The raw-value calibration: the values of full negative travel, centre and full
/// positive travel.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct RawRange {
    /// Raw value at −100 % (throttle 0).
    pub min: u16,
    /// Raw value at the centre.
    pub centre: u16,
    /// Raw value at +100 % (throttle 1).
    pub max: u16,
}

impl RawRange {
    /// 172 … 992 … 1811, the common SBUS scaling of ±100 % travel.
    pub const SBUS: RawRange = RawRange {
        min: 172,
        centre: 992,
        max: 1811,
    };

    /// Whether min < centre < max ≤ 2047.
    pub const fn is_valid(&self) -> bool {
        self.min < self.centre && self.centre < self.max && self.max <= super::sbus::CHANNEL_MAX
    }

    /// `raw` as a stick fraction in [−1, 1] (see the module doc); 0 for an invalid
    /// range.
    pub fn stick(&self, raw: u16) -> f32 {
        let offset = i32::from(raw) - i32::from(self.centre);
        let span = if offset < 0 {
            i32::from(self.centre) - i32::from(self.min)
        } else {
            i32::from(self.max) - i32::from(self.centre)
        };
        if span <= 0 {
            return 0.0;
        }
        (offset as f32 / span as f32).clamp(-1.0, 1.0)
    }

    /// `raw` as a fraction in [0, 1] from min to max; 0 for an invalid range.
    pub fn unipolar(&self, raw: u16) -> f32 {
        let span = i32::from(self.max) - i32::from(self.min);
        if span <= 0 {
            return 0.0;
        }
        let offset = i32::from(raw) - i32::from(self.min);
        (offset as f32 / span as f32).clamp(0.0, 1.0)
    }
}

/// Where one function reads from.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct ChannelSource {
    /// The channel number as on the radio, 1 … 16 (channel 1 is `channels[0]`).
    pub channel: u8,
    /// Invert the direction (stick: −s; throttle: 1 − t; switch: the stick value is
    /// inverted before the thresholds).
    pub reversed: bool,
}

impl ChannelSource {
    /// Channel `channel` (1-based), not reversed.
    pub const fn normal(channel: u8) -> Self {
        ChannelSource {
            channel,
            reversed: false,
        }
    }

    /// The raw value of this channel in `frame`; `None` for a channel outside 1 … 16.
    fn raw(&self, frame: &SbusFrame) -> Option<u16> {
        let index = usize::from(self.channel).checked_sub(1)?;
        frame.channels.get(index).copied()
    }
}

/// A three-position switch.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum ModeSwitch {
    /// Below −τ (toward the minimum raw value, after reversal).
    Low,
    /// Between −τ and +τ (also what a missing channel reads as).
    #[default]
    Middle,
    /// Above +τ.
    High,
}

impl ModeSwitch {
    /// Position number 0 (low), 1 (middle) or 2 (high).
    pub const fn index(self) -> usize {
        match self {
            ModeSwitch::Low => 0,
            ModeSwitch::Middle => 1,
            ModeSwitch::High => 2,
        }
    }
}

/// The pilot's inputs, mapped.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct RcInput {
    /// Cyclic, pedal and collective sticks, fractions of full travel in [−1, 1].
    pub sticks: Controls,
    /// Throttle in [0, 1].
    pub throttle: f32,
    /// The arm switch is in its on position.
    pub arm: bool,
    /// The test switch is in its on position.
    pub test_switch: bool,
    /// The mode switch position.
    pub mode: ModeSwitch,
    /// The test selector's position in [−1, 1]; `None` without a selector channel.
    pub selector: Option<f32>,
}

impl RcInput {
    /// Sticks centred, collective mid, throttle 0, both switches off, mode switch low.
    pub const NEUTRAL: RcInput = RcInput {
        sticks: Controls {
            lat: 0.0,
            lon: 0.0,
            ped: 0.0,
            col: 0.0,
        },
        throttle: 0.0,
        arm: false,
        test_switch: false,
        mode: ModeSwitch::Low,
        selector: None,
    };

    /// The part of the input the flight logic's sensor frame carries.
    pub const fn pilot_input(&self) -> PilotInput {
        PilotInput {
            sticks: self.sticks,
            test_switch: self.test_switch,
        }
    }
}

/// Why a channel map is refused.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum ChannelMapError {
    /// A channel number outside 1 … 16.
    ChannelOutOfRange,
    /// Two functions read the same channel.
    DuplicateChannel,
    /// The raw range is not min < centre < max ≤ 2047.
    RangeInvalid,
    /// The switch threshold is not in (0, 1).
    ThresholdInvalid,
}

impl core::fmt::Display for ChannelMapError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.write_str(match self {
            ChannelMapError::ChannelOutOfRange => "channel number outside 1-16",
            ChannelMapError::DuplicateChannel => "two functions share a channel",
            ChannelMapError::RangeInvalid => "raw range must satisfy min < centre < max <= 2047",
            ChannelMapError::ThresholdInvalid => "switch threshold outside (0, 1)",
        })
    }
}

/// Function → channel assignment plus the raw calibration (see the module doc).
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct ChannelMap {
    /// Lateral cyclic (aileron).
    pub lateral: ChannelSource,
    /// Longitudinal cyclic (elevator).
    pub longitudinal: ChannelSource,
    /// Throttle.
    pub throttle: ChannelSource,
    /// Pedal (rudder).
    pub pedal: ChannelSource,
    /// Arm switch (two positions).
    pub arm: ChannelSource,
    /// Collective pitch.
    pub collective: ChannelSource,
    /// Test switch (two positions).
    pub test: ChannelSource,
    /// Mode switch (three positions).
    pub mode: ChannelSource,
    /// Test selector (a knob or a multi-position switch): channel 0 for none.
    pub selector: ChannelSource,
    /// Raw calibration shared by all channels.
    pub range: RawRange,
    /// Switch threshold τ as a fraction of half travel.
    pub switch_threshold: f32,
}

impl Default for ChannelMap {
    fn default() -> Self {
        ChannelMap::flybarless_default()
    }
}

impl ChannelMap {
    /// The default flybarless-helicopter map of the module doc's table: nothing
    /// reversed, [`RawRange::SBUS`], τ = ½.
    pub const fn flybarless_default() -> Self {
        ChannelMap {
            lateral: ChannelSource::normal(1),
            longitudinal: ChannelSource::normal(2),
            throttle: ChannelSource::normal(3),
            pedal: ChannelSource::normal(4),
            arm: ChannelSource::normal(5),
            collective: ChannelSource::normal(6),
            test: ChannelSource::normal(7),
            mode: ChannelSource::normal(8),
            selector: ChannelSource::normal(0),
            range: RawRange::SBUS,
            switch_threshold: 0.5,
        }
    }

    /// The eight sources in table order.
    const fn sources(&self) -> [ChannelSource; 8] {
        [
            self.lateral,
            self.longitudinal,
            self.throttle,
            self.pedal,
            self.arm,
            self.collective,
            self.test,
            self.mode,
        ]
    }

    /// Check channel numbers (1 … 16, all distinct; the selector's 0 or one of the
    /// others' not), the raw range and the threshold.
    pub fn validate(&self) -> Result<(), ChannelMapError> {
        let sources = self.sources();
        let mut seen: u32 = 0;
        for source in sources.iter() {
            if !(1..=CHANNELS).contains(&usize::from(source.channel)) {
                return Err(ChannelMapError::ChannelOutOfRange);
            }
            let bit = 1u32 << source.channel;
            if seen & bit != 0 {
                return Err(ChannelMapError::DuplicateChannel);
            }
            seen |= bit;
        }
        let selector = self.selector.channel;
        if selector != 0 {
            if usize::from(selector) > CHANNELS {
                return Err(ChannelMapError::ChannelOutOfRange);
            }
            if seen & (1u32 << selector) != 0 {
                return Err(ChannelMapError::DuplicateChannel);
            }
        }
        if !self.range.is_valid() {
            return Err(ChannelMapError::RangeInvalid);
        }
        let tau = self.switch_threshold;
        if !(tau.is_finite() && tau > 0.0 && tau < 1.0) {
            return Err(ChannelMapError::ThresholdInvalid);
        }
        Ok(())
    }

    /// Map a frame. Defined for any map: a channel outside 1 … 16 reads as neutral
    /// (stick 0, throttle 0, switch off, mode Middle), a NaN threshold leaves the
    /// switches off and the mode Middle.
    pub fn map(&self, frame: &SbusFrame) -> RcInput {
        RcInput {
            sticks: Controls {
                lat: self.stick(&self.lateral, frame),
                lon: self.stick(&self.longitudinal, frame),
                ped: self.stick(&self.pedal, frame),
                col: self.stick(&self.collective, frame),
            },
            throttle: self.unipolar(&self.throttle, frame),
            arm: self.two_position(&self.arm, frame),
            test_switch: self.two_position(&self.test, frame),
            mode: self.three_position(&self.mode, frame),
            selector: self
                .selector
                .raw(frame)
                .map(|_| self.stick(&self.selector, frame)),
        }
    }

    /// The transmitter's side of [`map`](Self::map): the frame a radio sends for
    /// `input` (a transmitter model for the host and the tests). Sticks, throttle and
    /// switches are written to their channels, reversal included: a stick `s` becomes
    /// `centre + round(s·span)` with the span of its half, the throttle
    /// `min + round(t·(max − min))`, a two-position switch full travel on (+1) or off
    /// (−1), the mode switch −1, 0 or +1. Non-finite values write the centre (throttle:
    /// the minimum); other channels stay at the centre; no flag is set. For a valid map,
    /// `map(encode(x))` returns `x` with each stick and the throttle rounded to the
    /// nearest raw count.
    pub fn encode(&self, input: &RcInput) -> SbusFrame {
        let range = self.range;
        let mut frame = SbusFrame {
            channels: [range.centre; CHANNELS],
            ..SbusFrame::default()
        };
        let stick_raw = |source: &ChannelSource, value: f32| -> u16 {
            let s = if value.is_finite() {
                value.clamp(-1.0, 1.0)
            } else {
                0.0
            };
            let s = if source.reversed { -s } else { s };
            let centre = f32::from(range.centre);
            let span = if s < 0.0 {
                centre - f32::from(range.min)
            } else {
                f32::from(range.max) - centre
            };
            libm::roundf(centre + s * span).clamp(0.0, f32::from(super::sbus::CHANNEL_MAX)) as u16
        };
        let throttle_raw = |source: &ChannelSource, value: f32| -> u16 {
            let t = if value.is_finite() {
                value.clamp(0.0, 1.0)
            } else {
                0.0
            };
            let t = if source.reversed { 1.0 - t } else { t };
            let min = f32::from(range.min);
            libm::roundf(min + t * (f32::from(range.max) - min))
                .clamp(0.0, f32::from(super::sbus::CHANNEL_MAX)) as u16
        };
        let switch = |on: bool| if on { 1.0 } else { -1.0 };
        let mode = match input.mode {
            ModeSwitch::Low => -1.0,
            ModeSwitch::Middle => 0.0,
            ModeSwitch::High => 1.0,
        };
        let writes = [
            (self.lateral, stick_raw(&self.lateral, input.sticks.lat)),
            (
                self.longitudinal,
                stick_raw(&self.longitudinal, input.sticks.lon),
            ),
            (self.throttle, throttle_raw(&self.throttle, input.throttle)),
            (self.pedal, stick_raw(&self.pedal, input.sticks.ped)),
            (self.arm, stick_raw(&self.arm, switch(input.arm))),
            (
                self.collective,
                stick_raw(&self.collective, input.sticks.col),
            ),
            (self.test, stick_raw(&self.test, switch(input.test_switch))),
            (self.mode, stick_raw(&self.mode, mode)),
            (
                self.selector,
                stick_raw(&self.selector, input.selector.unwrap_or(0.0)),
            ),
        ];
        for (source, raw) in writes {
            let slot = usize::from(source.channel)
                .checked_sub(1)
                .and_then(|index| frame.channels.get_mut(index));
            if let Some(slot) = slot {
                *slot = raw;
            }
        }
        frame
    }

    fn stick(&self, source: &ChannelSource, frame: &SbusFrame) -> f32 {
        match source.raw(frame) {
            Some(raw) => {
                let s = self.range.stick(raw);
                if source.reversed {
                    -s
                } else {
                    s
                }
            }
            None => 0.0,
        }
    }

    fn unipolar(&self, source: &ChannelSource, frame: &SbusFrame) -> f32 {
        match source.raw(frame) {
            Some(raw) => {
                let t = self.range.unipolar(raw);
                if source.reversed {
                    1.0 - t
                } else {
                    t
                }
            }
            None => 0.0,
        }
    }

    fn two_position(&self, source: &ChannelSource, frame: &SbusFrame) -> bool {
        source.raw(frame).is_some() && self.stick(source, frame) > self.switch_threshold
    }

    fn three_position(&self, source: &ChannelSource, frame: &SbusFrame) -> ModeSwitch {
        if source.raw(frame).is_none() {
            return ModeSwitch::Middle;
        }
        let s = self.stick(source, frame);
        if s > self.switch_threshold {
            ModeSwitch::High
        } else if s < -self.switch_threshold {
            ModeSwitch::Low
        } else {
            ModeSwitch::Middle
        }
    }
}
