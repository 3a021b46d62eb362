//! `params push`: a params file onto the board, all or nothing. The board's list is read
//! first and every name and value of the file checked against it and against the host's
//! copy of the firmware's table (range and kind) before anything is written; then only
//! the values that differ are set, and if a set fails mid-way the values already changed
//! are set back to what the board held before.

use anyhow::bail;
use sweephold_firmware::params::ParamId;

use super::client::{check_same_table, BoardValue, ParamBoard, ParamError};

/// What a push did.
#[derive(Debug, PartialEq)]
pub struct Pushed {
    /// Values changed on the board.
    pub changed: usize,
    /// Values the board held already.
    pub unchanged: usize,
}

/// The changes `file` asks of a board holding `board`: `(name, old, new)` for each value
/// that differs, in the board's order, or why the file cannot be pushed (nothing written).
pub fn plan(board: &[BoardValue], file: &[BoardValue]) -> anyhow::Result<Vec<(String, f32, f32)>> {
    check_same_table(board)?;
    let mut changes = Vec::new();
    for entry in file {
        let Some(current) = board.iter().find(|b| b.name == entry.name) else {
            bail!(
                "{} is not a parameter of the flight controller: nothing was written",
                entry.name
            );
        };
        // The board's table is the host's (checked above): its ranges apply.
        if let Some(id) = ParamId::from_name(&entry.name) {
            if let Err(error) = id.def().check(entry.value) {
                let def = id.def();
                bail!(
                    "{} = {}: {} ({} … {} {}): nothing was written",
                    entry.name,
                    entry.value,
                    error.message(),
                    def.min,
                    def.max,
                    def.unit
                );
            }
        }
        if current.value.to_bits() != entry.value.to_bits() {
            changes.push((entry.name.clone(), current.value, entry.value));
        }
    }
    // Set in the board's order, whatever the file's.
    changes.sort_by_key(|(name, _, _)| board.iter().position(|b| &b.name == name));
    Ok(changes)
}

/// Push `file` onto `board`, all or nothing.
pub fn push(board: &mut impl ParamBoard, file: &[BoardValue]) -> anyhow::Result<Pushed> {
    let before = board.list()?;
    let changes = plan(&before, file)?;
    for (done, (name, _, new)) in changes.iter().enumerate() {
        let failure = match board.set(name, *new) {
            Ok(held) if held.to_bits() == new.to_bits() => continue,
            Ok(held) => ParamError::Link(anyhow::anyhow!(
                "the board holds {held} for {name}, not {new}"
            )),
            Err(error) => error,
        };
        // Put back what was changed, last first; the failed one too (it may have landed).
        let mut not_restored = Vec::new();
        for (name, old, _) in changes.get(..=done).unwrap_or(&[]).iter().rev() {
            if board.set(name, *old).is_err() {
                not_restored.push(name.as_str());
            }
        }
        if not_restored.is_empty() {
            bail!(
                "setting {name} failed ({failure}): the {done} values set before it were \
                 restored, the board holds what it held before the push"
            );
        }
        bail!(
            "setting {name} failed ({failure}) and restoring failed too for {}: the board \
             holds a mix; pull its values before flying",
            not_restored.join(", ")
        );
    }
    Ok(Pushed {
        changed: changes.len(),
        unchanged: file.len() - changes.len(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use sweephold_firmware::params::ParamTable;
    use sweephold_protocol::{ParamOp, VehicleId};

    /// A board holding a parameter table in memory; the `fail_at`-th set is refused.
    struct FakeBoard {
        table: ParamTable,
        sets: usize,
        fail_at: Option<usize>,
    }

    impl ParamBoard for FakeBoard {
        fn list(&mut self) -> Result<Vec<BoardValue>, ParamError> {
            Ok(ParamId::ALL
                .iter()
                .map(|id| BoardValue {
                    name: id.def().name.to_string(),
                    value: self.table.get(*id),
                })
                .collect())
        }

        fn set(&mut self, name: &str, value: f32) -> Result<f32, ParamError> {
            self.sets += 1;
            if Some(self.sets) == self.fail_at {
                return Err(ParamError::Refused {
                    op: ParamOp::Set,
                    reason: "armed",
                });
            }
            self.table
                .set_by_name(name, value)
                .map_err(|e| ParamError::Refused {
                    op: ParamOp::Set,
                    reason: e.message(),
                })?;
            Ok(self.table.get_by_name(name).unwrap_or(f32::NAN))
        }
    }

    fn board(fail_at: Option<usize>) -> FakeBoard {
        FakeBoard {
            table: ParamTable::defaults(VehicleId::Trex700l),
            sets: 0,
            fail_at,
        }
    }

    fn entry(name: &str, value: f32) -> BoardValue {
        BoardValue {
            name: name.to_string(),
            value,
        }
    }

    #[test]
    fn a_push_sets_only_what_differs() {
        let mut fake = board(None);
        let phase = fake.table.get_by_name("SWASH_PHASE").unwrap();
        let file = [entry("SWASH_PHASE", phase), entry("SWASH_TYPE", 140.0)];
        let pushed = push(&mut fake, &file).unwrap();
        assert_eq!(
            pushed,
            Pushed {
                changed: 1,
                unchanged: 1
            }
        );
        assert_eq!(fake.table.get_by_name("SWASH_TYPE"), Ok(140.0));
        assert_eq!(fake.sets, 1);
    }

    #[test]
    fn unknown_names_and_out_of_range_values_are_refused_before_any_write() {
        for (file, expected) in [
            (
                vec![entry("SWASH_TYPE", 140.0), entry("NO_SUCH", 1.0)],
                "NO_SUCH is not a parameter",
            ),
            (
                vec![entry("SWASH_TYPE", 140.0), entry("SWASH_PHASE", 400.0)],
                "outside the parameter's range",
            ),
            (
                vec![entry("SWASH_TYPE", 121.0)],
                "not one of the parameter's choices",
            ),
        ] {
            let mut fake = board(None);
            let error = push(&mut fake, &file).expect_err("refused").to_string();
            assert!(
                error.contains(expected) && error.contains("nothing was written"),
                "{error}"
            );
            assert_eq!(fake.sets, 0);
            assert_eq!(fake.table, ParamTable::defaults(VehicleId::Trex700l));
        }
    }

    #[test]
    fn a_set_failing_mid_way_restores_the_values_set_before() {
        let mut fake = board(Some(3));
        let file = [
            entry("SWASH_TYPE", 140.0),
            entry("SWASH_PHASE", 12.5),
            entry("SWASH_LEAD", 2.0),
        ];
        let error = push(&mut fake, &file)
            .expect_err("the third set fails")
            .to_string();
        assert!(
            error.contains("setting SWASH_LEAD failed") && error.contains("restored"),
            "{error}"
        );
        assert_eq!(fake.table, ParamTable::defaults(VehicleId::Trex700l));
    }
}
