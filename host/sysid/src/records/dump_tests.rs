//! The tests of a telemetry dump: a logger writes one file per power-up (or records are
//! concatenated into one), and every test in it starts at a Header. This module splits a
//! decoded frame stream at its Headers and says how each test ended; [`super::dump`]
//! builds the records from the tests, and `sweephold decode` lists them with the same
//! [`TestProgress`] rule while it streams.
//!
//! **How a test ended** ([`TestEnd`]), from its Samples' phases in stream order:
//! * `aborted`: an abort Event, a phase change to aborted, or a Sample in the aborted
//!   phase (the pilot or a limit stopped it; the firmware may pass through the aborted
//!   phase within one tick, so no Sample need show it);
//! * `completed`: excitation (fade-in, sweep, fade-out) followed by a Sample out of it
//!   (the firmware's done phase, which lasts until the test switch is released);
//! * `partial`: the test's last Sample is in the excitation (the file ends, or the next
//!   Header comes, during it: a logger's power cut, a lost link);
//! * `not started`: no excitation Sample at all (switched off during trim capture).

use sweephold_protocol::{Decoder, Event, Frame, FrameError, Header, Phase, Sample};

use super::error::RecordError;
use super::record::Record;

/// How a test ended; see the module documentation.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TestEnd {
    /// Excitation, then a Sample out of it.
    Completed,
    /// An abort Event, a change to the aborted phase, or a Sample in it.
    Aborted,
    /// The last Sample is in the excitation.
    Partial,
    /// No excitation Sample.
    NotStarted,
}

impl TestEnd {
    /// `completed`, `aborted`, `partial`, `not started`.
    pub fn name(self) -> &'static str {
        match self {
            TestEnd::Completed => "completed",
            TestEnd::Aborted => "aborted",
            TestEnd::Partial => "partial",
            TestEnd::NotStarted => "not started",
        }
    }
}

/// Whether a phase is part of the excitation.
pub(crate) fn is_excitation(phase: Phase) -> bool {
    matches!(phase, Phase::FadeIn | Phase::Sweep | Phase::FadeOut)
}

/// What the phases seen so far say about how a test ends: fed one Sample phase at a
/// time, in stream order.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct TestProgress {
    excited: bool,
    left_excitation: bool,
    aborted: bool,
}

impl TestProgress {
    /// Take the next Sample's phase into account.
    pub fn see(&mut self, phase: Phase) {
        if is_excitation(phase) {
            self.excited = true;
            self.left_excitation = false;
        } else if phase == Phase::Aborted {
            self.aborted = true;
        } else if self.excited {
            self.left_excitation = true;
        }
    }

    /// Take an Event of the test into account: an abort, or a change to the aborted phase.
    pub fn see_event(&mut self, event: &Event) {
        if matches!(
            event,
            Event::Abort { .. }
                | Event::PhaseChange {
                    to: Phase::Aborted,
                    ..
                }
        ) {
            self.aborted = true;
        }
    }

    /// How the test ended, given the phases seen.
    pub fn end(&self) -> TestEnd {
        if self.aborted {
            TestEnd::Aborted
        } else if !self.excited {
            TestEnd::NotStarted
        } else if self.left_excitation {
            TestEnd::Completed
        } else {
            TestEnd::Partial
        }
    }
}

/// One test of a dump: its Header and the Samples up to the next Header.
#[derive(Clone, Debug, PartialEq)]
pub struct DumpTest {
    /// 1-based, in file order.
    pub number: usize,
    /// The Header that started it.
    pub header: Header,
    /// Its Samples, in stream order.
    pub samples: Vec<Sample>,
    /// Samples of the dump before this test's first (for messages).
    pub offset: usize,
    /// Its Samples' phases and its Events, seen.
    pub progress: TestProgress,
    /// The filter its IMU outputs went through, when the flight controller announced one
    /// (a board application, after the Header).
    pub measurement_filter: Option<sweephold_protocol::MeasurementFilter>,
}

impl DumpTest {
    /// How it ended.
    pub fn end(&self) -> TestEnd {
        self.progress.end()
    }

    /// Seconds its Samples span at the Header's rate (0 for a rate of 0).
    pub fn duration_s(&self) -> f64 {
        match self.header.rate_hz {
            0 => 0.0,
            rate => self.samples.len() as f64 / f64::from(rate),
        }
    }

    /// One line for listings ([`test_line`]).
    pub fn describe(&self) -> String {
        test_line(self.number, &self.header, self.samples.len(), self.end())
    }
}

/// One line for listings: `test 2: lon Sweep, ConditionalAttitudeHold, 91.0 s, completed`
/// (input and mode as `decode --format jsonl` names them in the Header; the duration is
/// `samples` at the Header's rate).
pub fn test_line(number: usize, header: &Header, samples: usize, end: TestEnd) -> String {
    let test = &header.test;
    let seconds = match header.rate_hz {
        0 => 0.0,
        rate => samples as f64 / f64::from(rate),
    };
    format!(
        "test {number}: {} {:?}, {:?}, {seconds:.1} s, {}",
        test.primary.name(),
        test.input,
        test.mode,
        end.name()
    )
}

/// One test of a dump file and its sweep record, or why it gives none (not a sweep, no
/// excitation, ticks that step back…).
#[derive(Debug)]
pub struct TestRecord {
    /// The test (Header, Samples, how it ended).
    pub test: DumpTest,
    /// Its excitation record, named `FILE` when the file holds one test and `FILE test N`
    /// when it holds several.
    pub record: Result<Record, RecordError>,
}

/// A dump split at its Headers.
#[derive(Clone, Debug, PartialEq)]
pub struct SplitDump {
    /// Its tests, in file order.
    pub tests: Vec<DumpTest>,
    /// Samples before the first Header (no test to put them in).
    pub samples_before_header: usize,
    /// Frames decoded whole.
    pub good_frames: u64,
}

impl SplitDump {
    /// Why a dump gives no record at all: no valid frame, no Header, or no excitation.
    pub(crate) fn no_record_error(&self, source: &str) -> RecordError {
        if self.good_frames == 0 {
            RecordError::NoSweep {
                path: source.into(),
                detail: "no valid frame".into(),
            }
        } else if self.tests.is_empty() {
            RecordError::NoHeader {
                path: source.into(),
            }
        } else {
            RecordError::NoSweep {
                path: source.into(),
                detail: "no Sample in the fade-in, sweep or fade-out phases".into(),
            }
        }
    }
}

/// Split the dump `bytes` at its Headers; `source` names it in messages. Damaged frames
/// are skipped (the decoder counts them); a Header of another protocol major version is
/// an error.
pub fn split_tests(bytes: &[u8], source: &str) -> Result<SplitDump, RecordError> {
    let mut decoder = Decoder::new();
    let mut tests: Vec<DumpTest> = Vec::new();
    let mut samples_before_header = 0;
    let mut seen = 0;
    for result in decoder.feed(bytes) {
        match result {
            Ok(Frame::Header(header)) => tests.push(DumpTest {
                number: tests.len() + 1,
                header,
                samples: Vec::new(),
                offset: seen,
                progress: TestProgress::default(),
                measurement_filter: None,
            }),
            Ok(Frame::MeasurementFilter(filter)) => {
                if let Some(test) = tests.last_mut() {
                    test.measurement_filter = Some(filter);
                }
            }
            Ok(Frame::Sample(sample)) => {
                seen += 1;
                match tests.last_mut() {
                    Some(test) => {
                        test.progress.see(sample.phase);
                        test.samples.push(sample);
                    }
                    None => samples_before_header += 1,
                }
            }
            Ok(Frame::Event(event)) => {
                if let Some(test) = tests.last_mut() {
                    test.progress.see_event(&event);
                }
            }
            Ok(_) => {}
            Err(mismatch @ FrameError::VersionMismatch { .. }) => {
                return Err(RecordError::Protocol {
                    path: source.into(),
                    message: mismatch.to_string(),
                })
            }
            Err(_) => {} // counted by the decoder; a damaged frame is skipped
        }
    }
    Ok(SplitDump {
        tests,
        samples_before_header,
        good_frames: decoder.stats().good_frames,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::frf::testing::{dump_bytes, DumpSpec};
    use sweephold_protocol::{encode, MAX_FRAME_LEN};

    /// The Header and a Sample of a [`dump_bytes`] dump, to copy from.
    fn header_and_sample() -> (Header, Sample) {
        let bytes = dump_bytes(&DumpSpec::default());
        let split = split_tests(&bytes, "spec").unwrap();
        (split.tests[0].header, split.tests[0].samples[0])
    }

    fn encoded(frames: &[Frame]) -> Vec<u8> {
        let mut out = Vec::new();
        for frame in frames {
            let mut buf = [0u8; MAX_FRAME_LEN];
            let n = encode(frame, &mut buf).unwrap();
            out.extend_from_slice(&buf[..n]);
        }
        out
    }

    /// One Sample per phase of `phases`, ticks from `first_tick`, after a Header if
    /// `header`.
    fn test_bytes(header: bool, phases: &[Phase], first_tick: u32) -> Vec<u8> {
        let (h, sample) = header_and_sample();
        let mut frames: Vec<Frame> = header.then_some(Frame::Header(h)).into_iter().collect();
        for (i, &phase) in phases.iter().enumerate() {
            frames.push(Frame::Sample(Sample {
                tick: first_tick + i as u32,
                phase,
                ..sample
            }));
        }
        encoded(&frames)
    }

    #[test]
    fn how_a_test_ended() {
        use Phase::*;
        let end = |phases: &[Phase]| {
            let mut progress = TestProgress::default();
            phases.iter().for_each(|&p| progress.see(p));
            progress.end()
        };
        assert_eq!(
            end(&[TrimCapture, FadeIn, Sweep, FadeOut, Done]),
            TestEnd::Completed
        );
        assert_eq!(
            end(&[TrimCapture, FadeIn, Sweep, Aborted]),
            TestEnd::Aborted
        );
        assert_eq!(end(&[TrimCapture, FadeIn, Sweep]), TestEnd::Partial);
        assert_eq!(end(&[Idle, Armed, TrimCapture, Done]), TestEnd::NotStarted);
        assert_eq!(end(&[]), TestEnd::NotStarted);
        // Through the aborted phase within one tick: only the Events say so.
        let mut progress = TestProgress::default();
        [TrimCapture, Sweep, Idle]
            .iter()
            .for_each(|&p| progress.see(p));
        assert_eq!(progress.end(), TestEnd::Completed);
        progress.see_event(&Event::PhaseChange {
            tick: 9,
            from: Sweep,
            to: Aborted,
        });
        assert_eq!(progress.end(), TestEnd::Aborted);
    }

    #[test]
    fn splits_at_every_header() {
        use Phase::*;
        // One Sample before any Header, then three tests.
        let mut bytes = test_bytes(false, &[Idle], 0);
        bytes.extend(test_bytes(true, &[TrimCapture, Sweep, Done], 1));
        bytes.extend(test_bytes(true, &[TrimCapture, Sweep, Aborted, Aborted], 4));
        bytes.extend(test_bytes(true, &[Idle], 8));
        let split = split_tests(&bytes, "two.bin").unwrap();
        assert_eq!(split.samples_before_header, 1);
        let summary: Vec<(usize, usize, usize, TestEnd)> = split
            .tests
            .iter()
            .map(|t| (t.number, t.samples.len(), t.offset, t.end()))
            .collect();
        assert_eq!(
            summary,
            [
                (1, 3, 1, TestEnd::Completed),
                (2, 4, 4, TestEnd::Aborted),
                (3, 1, 8, TestEnd::NotStarted)
            ]
        );
        let line = split.tests[0].describe();
        assert!(line.starts_with("test 1: "), "{line}");
        assert!(line.ends_with(", completed"), "{line}");
    }

    #[test]
    fn a_measurement_filter_after_a_header_belongs_to_its_test() {
        use sweephold_protocol::MeasurementFilter;
        let filter = MeasurementFilter {
            sample_rate_hz: 1000.0,
            sections: [
                [0.5, 0.5, 0.0, 0.0, 0.0],
                [1.0, 0.0, 0.0, 0.0, 0.0],
                [1.0, 0.0, 0.0, 0.0, 0.0],
                [1.0, 0.0, 0.0, 0.0, 0.0],
            ],
        };
        let (h, _) = header_and_sample();
        let mut bytes = test_bytes(true, &[Phase::Sweep], 10);
        bytes.extend(encoded(&[
            Frame::Header(h),
            Frame::MeasurementFilter(filter),
        ]));
        bytes.extend(test_bytes(false, &[Phase::Sweep], 20));
        let split = split_tests(&bytes, "spec").unwrap();
        assert_eq!(split.tests.len(), 2);
        assert_eq!(split.tests[0].measurement_filter, None);
        assert_eq!(split.tests[1].measurement_filter, Some(filter));
    }
}
