//! Why the truth of a vehicle or a structure could not be computed.

use rotorsim::TrimError;
use sysid::fit::FitError;

/// What stops the truth mapping or the scoring against it.
#[derive(Debug, thiserror::Error)]
pub enum Error {
    /// The vehicle does not trim in hover, so there is no linearization to map.
    #[error("cannot trim {vehicle} at hover")]
    Trim {
        /// The vehicle's name.
        vehicle: String,
        /// Why its trim failed.
        source: TrimError,
    },
    /// A hybrid structure's flapping needs the simulator's flapping states.
    #[error("the linearization has no flapping states")]
    NoFlappingStates,
    /// The simulator's flapping block of A has no inverse (no quasi-static flapping).
    #[error("the flapping block of A is singular")]
    SingularFlappingBlock,
    /// The structure's own flap equations at the truth have no quasi-static solution.
    #[error("the structure's flapping block is singular at the truth")]
    SingularStructureFlappingBlock,
    /// The aircraft names a structure that is not shipped, or not one with a vehicle's
    /// constants to put in.
    #[error("identification.structure `{0}` is not a shipped 9-DOF hybrid structure")]
    UnknownStructure(String),
    /// The structure file with the vehicle's data in it does not parse.
    #[error(transparent)]
    Structure(#[from] sysid::fit::StructureError),
    /// The structure's model at the truth values, or the cost between two models, failed.
    #[error(transparent)]
    Fit(#[from] FitError),
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The error and its causes on one line, as the command-line tool prints them.
    fn chain(error: &dyn std::error::Error) -> String {
        let mut line = error.to_string();
        let mut cause = error.source();
        while let Some(next) = cause {
            line = format!("{line}: {next}");
            cause = next.source();
        }
        line
    }

    #[test]
    fn a_failed_trim_names_the_vehicle_then_the_cause() {
        let error = Error::Trim {
            vehicle: "trex700l".to_string(),
            source: TrimError::SingularJacobian,
        };
        assert_eq!(error.to_string(), "cannot trim trex700l at hover");
        assert_eq!(
            chain(&error),
            "cannot trim trex700l at hover: trim Jacobian is singular"
        );
        assert_eq!(
            chain(&Error::NoFlappingStates),
            "the linearization has no flapping states"
        );
    }
}
