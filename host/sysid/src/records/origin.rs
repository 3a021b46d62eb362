//! Where a dump's record came from, as its Header says: the vehicle, the protocol
//! version and the rate. Records of one frequency-response document must come from one
//! vehicle, flown by one kind of flight controller at one rate; dumps that differ in any
//! of these are refused together rather than joined into one response (a Bo-105 sweep
//! and a TREX 700L sweep describe two aircraft, not one).

use sweephold_protocol::{Header, ProtocolVersion, VehicleId};

use super::error::RecordError;

/// What a dump's Header says about the record's origin.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct DumpOrigin {
    /// The dump (file name), for messages.
    pub source: String,
    /// The vehicle the flight controller was configured for.
    pub vehicle: VehicleId,
    /// The protocol version the Header announces.
    pub protocol: ProtocolVersion,
    /// The control loop's rate \[Hz\].
    pub rate_hz: u16,
}

impl DumpOrigin {
    /// The origin `header` states for the dump `source`.
    pub fn of(source: &str, header: &Header) -> DumpOrigin {
        DumpOrigin {
            source: source.into(),
            vehicle: header.vehicle,
            protocol: header.protocol,
            rate_hz: header.rate_hz,
        }
    }

    /// What differs between `self` and `other`, if anything: the first of vehicle,
    /// protocol version and rate that does.
    fn difference(&self, other: &DumpOrigin) -> Option<String> {
        if self.vehicle != other.vehicle {
            Some(format!(
                "vehicle {} vs {}",
                self.vehicle.name(),
                other.vehicle.name()
            ))
        } else if self.protocol != other.protocol {
            Some(format!(
                "protocol version {} vs {}",
                self.protocol, other.protocol
            ))
        } else if self.rate_hz != other.rate_hz {
            Some(format!("rate {} Hz vs {} Hz", self.rate_hz, other.rate_hz))
        } else {
            None
        }
    }
}

/// Refuse dumps whose Headers name different vehicles, protocol versions or rates: the
/// first that differs from the first dump is named with it and what differs.
pub fn check_one_origin(origins: &[DumpOrigin]) -> Result<(), RecordError> {
    let Some(first) = origins.first() else {
        return Ok(());
    };
    for origin in &origins[1..] {
        if let Some(what) = first.difference(origin) {
            return Err(RecordError::MixedDumps {
                first: first.source.clone(),
                other: origin.source.clone(),
                what,
            });
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::frf::testing::{dump_bytes, DumpSpec};
    use crate::records::dump::load_dump_with_origin;

    fn origin(source: &str, vehicle: VehicleId, minor: u16, rate_hz: u16) -> DumpOrigin {
        DumpOrigin {
            source: source.into(),
            vehicle,
            protocol: ProtocolVersion { major: 1, minor },
            rate_hz,
        }
    }

    #[test]
    fn dumps_of_one_origin_pass() {
        let a = origin("a.bin", VehicleId::Bo105, 2, 100);
        let b = origin("b.bin", VehicleId::Bo105, 2, 100);
        assert!(check_one_origin(&[a.clone(), b, a]).is_ok());
        assert!(check_one_origin(&[]).is_ok());
    }

    #[test]
    fn dumps_of_two_vehicles_versions_or_rates_are_refused() {
        let bo105 = origin("bo105.bin", VehicleId::Bo105, 2, 100);
        let cases = [
            (
                origin("trex.bin", VehicleId::Trex700l, 2, 100),
                "bo105.bin and trex.bin cannot be joined: their Headers name vehicle bo105 vs trex700l",
            ),
            (
                origin("board.bin", VehicleId::Bo105, 4, 100),
                "bo105.bin and board.bin cannot be joined: their Headers name protocol version 1.2 vs 1.4",
            ),
            (
                origin("fast.bin", VehicleId::Bo105, 2, 400),
                "bo105.bin and fast.bin cannot be joined: their Headers name rate 100 Hz vs 400 Hz",
            ),
        ];
        for (other, message) in cases {
            let same = bo105.clone();
            let error = check_one_origin(&[bo105.clone(), same, other]).unwrap_err();
            assert_eq!(error.to_string(), message);
        }
    }

    #[test]
    fn the_origin_is_read_from_the_dump_header() {
        let dir = std::env::temp_dir().join(format!("sysid-origin-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("lat.bin");
        let spec = DumpSpec {
            rate_hz: 200,
            ..DumpSpec::default()
        };
        std::fs::write(&path, dump_bytes(&spec)).unwrap();
        let (record, origin) = load_dump_with_origin(&path).unwrap();
        std::fs::remove_dir_all(&dir).unwrap();
        assert_eq!(record.sample_rate_hz, 200.0);
        assert_eq!(origin.vehicle, VehicleId::Bo105);
        assert_eq!(origin.protocol, sweephold_protocol::PROTOCOL_VERSION);
        assert_eq!(origin.rate_hz, 200);
        assert_eq!(origin.source, path.display().to_string());
    }
}
