//! The board application's configuration ([`AppConfig`]): the sequencer's, the pilot
//! mode's, the failsafes', the throttle's, the airborne rule's and the test list, with
//! the presets and the checks a configuration must pass.

use super::*;

/// Everything the board application needs.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AppConfig {
    /// The sequencer's configuration (rate, test, hold gains, abort limits, mixer).
    pub flight: Config,
    /// Stabilised pilot mode.
    pub pilot: PilotModeGains,
    /// Throttle channel.
    pub throttle: ThrottleSettings,
    /// Failsafes.
    pub failsafe: FailsafeSettings,
    /// The airborne and landed rule.
    pub airborne: AirborneSettings,
    /// The test list the selector channel chooses from (unused without one).
    pub tests: TestList,
}

impl AppConfig {
    /// TREX 700L: [`Config::trex700l_default`], [`PilotModeGains::trex700l`], standard
    /// throttle and failsafe settings, [`AirborneSettings::trex700l`], the preset's
    /// campaign as the test list ([`TestList::campaign`]).
    pub const fn trex700l(primary: Axis) -> Self {
        AppConfig {
            flight: Config::trex700l_default(primary),
            pilot: PilotModeGains::trex700l(),
            throttle: ThrottleSettings::standard(),
            failsafe: FailsafeSettings::standard(),
            airborne: AirborneSettings::trex700l(),
            tests: TestList::campaign(VehicleId::Trex700l),
        }
    }

    /// The preset of `vehicle` ([`AppConfig::bo105`], [`AppConfig::trex700l`]).
    pub const fn preset(vehicle: VehicleId, primary: Axis) -> Self {
        match vehicle {
            VehicleId::Bo105 => AppConfig::bo105(primary),
            VehicleId::Trex700l => AppConfig::trex700l(primary),
        }
    }

    /// Bo-105 (simulator): [`Config::bo105_default`], [`PilotModeGains::bo105`],
    /// standard throttle and failsafe settings, [`AirborneSettings::bo105`], the
    /// preset's campaign as the test list.
    pub const fn bo105(primary: Axis) -> Self {
        AppConfig {
            flight: Config::bo105_default(primary),
            pilot: PilotModeGains::bo105(),
            throttle: ThrottleSettings::standard(),
            failsafe: FailsafeSettings::standard(),
            airborne: AirborneSettings::bo105(),
            tests: TestList::campaign(VehicleId::Bo105),
        }
    }

    /// Check the application's own settings (the sequencer's are checked by
    /// [`FlightController::new`]).
    pub fn validate(&self) -> Result<(), AppConfigError> {
        if !self.pilot.is_valid() {
            return Err(AppConfigError::PilotGainsInvalid);
        }
        if !self.throttle.is_valid() {
            return Err(AppConfigError::ThrottleInvalid);
        }
        if !self.failsafe.is_valid() {
            return Err(AppConfigError::FailsafeInvalid);
        }
        if !self.airborne.is_valid() {
            return Err(AppConfigError::AirborneInvalid);
        }
        // The entries are checked as tests of this configuration: it must be valid first.
        self.flight.validate().map_err(AppConfigError::Flight)?;
        self.tests
            .validate(&self.flight)
            .map_err(AppConfigError::TestList)
    }
}

/// Why a configuration was refused.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum AppConfigError {
    /// The sequencer refused its configuration.
    Flight(ConfigError),
    /// A pilot-mode gain or limit is out of range.
    PilotGainsInvalid,
    /// A throttle setting is out of range.
    ThrottleInvalid,
    /// A failsafe setting is out of range.
    FailsafeInvalid,
    /// An airborne-rule setting is out of range.
    AirborneInvalid,
    /// The test list's slices are out of range or an entry makes a refused test.
    TestList(TestListError),
}

impl AppConfigError {
    /// Human-readable explanation.
    pub const fn message(self) -> &'static str {
        match self {
            AppConfigError::Flight(error) => error.message(),
            AppConfigError::PilotGainsInvalid => "pilot-mode gains or limits invalid",
            AppConfigError::ThrottleInvalid => "throttle settings invalid",
            AppConfigError::FailsafeInvalid => "failsafe settings invalid",
            AppConfigError::AirborneInvalid => "airborne settings invalid",
            AppConfigError::TestList(error) => error.message(),
        }
    }
}

impl core::fmt::Display for AppConfigError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.write_str(self.message())
    }
}

#[cfg(any(test, feature = "std"))]
impl std::error::Error for AppConfigError {}
