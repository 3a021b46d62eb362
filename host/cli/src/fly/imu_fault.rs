//! `--imu-fault KIND@AT_S`: the IMU faults board-sim injects into the emulated chip.

use sweephold_firmware::imu::emulator::Fault;

/// An IMU fault injected into the emulator.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ImuFaultKind {
    /// Data registers frozen.
    Stuck,
    /// Every axis at positive full scale.
    Saturate,
    /// No chip on the bus.
    Missing,
}

impl ImuFaultKind {
    /// The emulator's fault.
    pub(crate) fn fault(self) -> Fault {
        match self {
            ImuFaultKind::Stuck => Fault::Stuck,
            ImuFaultKind::Saturate => Fault::Saturate,
            ImuFaultKind::Missing => Fault::Missing,
        }
    }

    /// Name on the command line.
    pub fn name(self) -> &'static str {
        match self {
            ImuFaultKind::Stuck => "stuck",
            ImuFaultKind::Saturate => "saturate",
            ImuFaultKind::Missing => "missing",
        }
    }
}

/// `--imu-fault KIND@AT_S` (or `missing`: from power-on).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ImuFaultPlan {
    /// Which fault.
    pub kind: ImuFaultKind,
    /// Record time it starts \[s\]; `None`: from power-on.
    pub at_s: Option<f64>,
}

impl ImuFaultPlan {
    /// Parse `stuck@T`, `saturate@T`, `missing@T` or `missing`.
    pub fn parse(text: &str) -> Result<ImuFaultPlan, ImuFaultPlanError> {
        let (kind, at) = match text.split_once('@') {
            Some((kind, at)) => (kind, Some(at)),
            None => (text, None),
        };
        let kind = match kind {
            "stuck" => ImuFaultKind::Stuck,
            "saturate" => ImuFaultKind::Saturate,
            "missing" => ImuFaultKind::Missing,
            _ => return Err(ImuFaultPlanError::UnknownKind(kind.to_string())),
        };
        let at_s = match at {
            None if kind == ImuFaultKind::Missing => None,
            None => return Err(ImuFaultPlanError::NoTime(kind)),
            Some(at) => match at.trim().parse::<f64>() {
                Ok(t) if t.is_finite() && t >= 0.0 => Some(t),
                _ => return Err(ImuFaultPlanError::NotATime(at.to_string())),
            },
        };
        Ok(ImuFaultPlan { kind, at_s })
    }
}

/// Why an `--imu-fault` value names no fault.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum ImuFaultPlanError {
    /// Not one of the faults.
    #[error(
        "unknown IMU fault `{0}` (expected stuck@AT_S, saturate@AT_S, missing@AT_S or missing)"
    )]
    UnknownKind(String),
    /// A fault that starts at a time, given none.
    #[error("`{name}` needs a time: {name}@AT_S (seconds of record time)", name = .0.name())]
    NoTime(ImuFaultKind),
    /// The part after `@` is not a time.
    #[error("`{0}` is not a time: expected seconds of record time >= 0")]
    NotATime(String),
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn imu_fault_specs_parse_and_bad_ones_are_refused() {
        assert_eq!(
            ImuFaultPlan::parse("stuck@15"),
            Ok(ImuFaultPlan {
                kind: ImuFaultKind::Stuck,
                at_s: Some(15.0)
            })
        );
        assert_eq!(
            ImuFaultPlan::parse("missing"),
            Ok(ImuFaultPlan {
                kind: ImuFaultKind::Missing,
                at_s: None
            })
        );
        assert_eq!(
            ImuFaultPlan::parse("saturate@0.5").map(|p| p.at_s),
            Ok(Some(0.5))
        );
        for bad in ["stuck", "stuck@", "stuck@-1", "stuck@nan", "hot@3", ""] {
            assert!(ImuFaultPlan::parse(bad).is_err(), "{bad}");
        }
    }
}
