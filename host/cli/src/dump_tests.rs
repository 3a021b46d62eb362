//! Which tests of a telemetry dump `frf` analyses: a dump (a logger's file per power-up,
//! or records concatenated) holds one test per Header (split by
//! [`sysid::records::load_dump_tests`]); every completed sweep is used, and every test is
//! listed with how it ended and what became of it. `verify` and `identify` take every
//! test with an excitation of any kind ([`excitation_records`]). A loop test (the sweep
//! added to the closed pilot-mode loops) is listed and left out by all three: its broken
//! loop is `margins --measured`'s.

use std::path::Path;

use anyhow::anyhow;
use sysid::records::{load_dump_tests, DumpOrigin, Excitation, Record, TestEnd, TestRecord};

/// What `frf` takes from one dump.
pub struct DumpSweeps {
    /// The sweep records used, each with the origin its Header gives.
    pub records: Vec<(Record, DumpOrigin)>,
    /// One line per test: what it is, how it ended, used or why not.
    pub lines: Vec<String>,
}

/// The sweep records of the dump `path` that `frf` analyses, each with its origin, and one
/// line per test for stderr. Aborted and partial tests are left out unless
/// `include_aborted`; tests that are not sweeps, or never started, are left out. A test
/// that would be used but gives no record (ticks that step back, too many missing) is an
/// error, and so is a dump none of whose tests is used (the first test's reason: its
/// record's error when it has one, else why it was left out).
pub fn sweep_records(path: &Path, include_aborted: bool) -> anyhow::Result<DumpSweeps> {
    let tests = chosen_tests(
        path,
        Excitation::Sweep,
        include_aborted,
        include_aborted,
        false,
    )?;
    Ok(DumpSweeps {
        lines: tests.listing.iter().map(TestListing::line).collect(),
        records: tests
            .used
            .into_iter()
            .map(|test| (test.record, test.origin))
            .collect(),
    })
}

/// One test of a dump that [`excitation_records`] uses.
pub struct UsedTest {
    /// Its number in the file (1-based, at its Header).
    pub number: usize,
    /// Its record (any excitation), named `FILE` or `FILE test N`.
    pub record: Record,
    /// Where its Header says it was flown.
    pub origin: DumpOrigin,
    /// Whether it is a frequency sweep (else a doublet, 3-2-1-1…: a verification record).
    pub is_sweep: bool,
}

/// One test of a dump as listed: the file, its line (`test N: axis Input, Mode, s, end`)
/// and what became of it.
#[derive(Clone, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub struct TestListing {
    /// The dump file, as given.
    pub file: String,
    /// The test's line ([`sysid::records::test_line`]).
    pub test: String,
    /// `used`, or why it was left out.
    pub verdict: String,
}

/// What [`excitation_records`] takes from one dump.
pub struct DumpTests {
    /// The tests used, in file order.
    pub used: Vec<UsedTest>,
    /// Every test with what became of it.
    pub listing: Vec<TestListing>,
    /// The loop tests among them (listed, never used: their broken loops are measured
    /// by `margins --measured` and `identify`'s margins stage).
    pub loop_tests: usize,
}

/// Every test of the dump `path` with an excitation of any kind (sweep, doublet,
/// 3-2-1-1), for the verbs that replay records in time (`verify`) or take both sweeps
/// and verification records from one log (`identify`). Aborted tests are left out unless
/// `include_aborted`, partial ones (cut off by the end of the file) unless
/// `include_partial` or `include_aborted`, tests that never started always; a test that
/// would be used but gives no record is an error, and so is a dump none of whose tests is
/// used.
pub fn excitation_records(
    path: &Path,
    include_aborted: bool,
    include_partial: bool,
) -> anyhow::Result<DumpTests> {
    chosen_tests(
        path,
        Excitation::Any,
        include_aborted,
        include_partial,
        false,
    )
}

/// [`excitation_records`] for `identify`, which also measures the loop tests: a dump
/// whose tests are all loop tests is taken (nothing used, its loop tests counted).
pub fn identify_records(path: &Path, include_aborted: bool) -> anyhow::Result<DumpTests> {
    chosen_tests(
        path,
        Excitation::Any,
        include_aborted,
        include_aborted,
        true,
    )
}

/// The tests of the dump `path` whose records of `excitation` are used, and every test
/// with what became of it (the rules of [`sweep_records`] and [`excitation_records`]);
/// with `loop_only_ok` a dump of loop tests alone is no error ([`identify_records`]).
fn chosen_tests(
    path: &Path,
    excitation: Excitation,
    include_aborted: bool,
    include_partial: bool,
    loop_only_ok: bool,
) -> anyhow::Result<DumpTests> {
    let (tests, _) = load_dump_tests(path, excitation)?;
    let file = path.display().to_string();
    let mut used = Vec::new();
    let mut listing = Vec::new();
    let mut refusal: Option<String> = None;
    let mut loop_tests = 0;
    for TestRecord { test, record } in tests {
        let end = test.end();
        let is_sweep = test.header.test.input.is_sweep();
        let verdict = match (end, record) {
            (TestEnd::NotStarted, record) => {
                if let Err(error) = record {
                    refusal.get_or_insert(error.to_string());
                }
                "left out: no excitation".to_string()
            }
            // A loop test's command is the closed loops' own answer plus the sweep: the
            // airframe's response to it is not an open-loop record, and what it measures
            // is the broken loop (`margins --measured`).
            (_, _) if test.header.test.input.is_loop() => {
                loop_tests += 1;
                refusal.get_or_insert(format!(
                    "{file}: test {}: a loop test: `sweephold margins --measured` reads it",
                    test.number
                ));
                "left out: a loop test (`margins --measured` and `identify` measure its broken loop)".to_string()
            }
            (_, Err(error)) if excitation == Excitation::Sweep && !is_sweep => {
                refusal.get_or_insert(error.to_string());
                "left out: not a sweep".to_string()
            }
            (TestEnd::Aborted | TestEnd::Partial, record)
                if !include_aborted && (end == TestEnd::Aborted || !include_partial) =>
            {
                // A record that cannot be read says more than its test's end.
                let why = match record {
                    Err(error) => error.to_string(),
                    Ok(_) => format!(
                        "{file}: test {} {}: left out (--include-aborted uses it)",
                        test.number,
                        end.name()
                    ),
                };
                refusal.get_or_insert(why);
                "left out (--include-aborted uses it)".to_string()
            }
            (_, Err(error)) => return Err(anyhow!("{error}")),
            (_, Ok(record)) => {
                let origin = DumpOrigin::of(&record.source, &test.header);
                used.push(UsedTest {
                    number: test.number,
                    record,
                    origin,
                    is_sweep,
                });
                "used".to_string()
            }
        };
        listing.push(TestListing {
            file: file.clone(),
            test: test.describe(),
            verdict,
        });
    }
    if used.is_empty() && !(loop_only_ok && loop_tests > 0) {
        let what = match excitation {
            Excitation::Sweep => "a sweep",
            Excitation::Any => "an excitation",
        };
        return Err(anyhow!(
            "{}",
            refusal.unwrap_or_else(|| format!("{file}: no test with {what}"))
        ));
    }
    Ok(DumpTests {
        used,
        listing,
        loop_tests,
    })
}

impl TestListing {
    /// `FILE: test N: …: verdict`, as `frf` lists its tests.
    pub fn line(&self) -> String {
        format!("{}: {}: {}", self.file, self.test, self.verdict)
    }
}
