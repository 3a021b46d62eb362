//! The control actuators' parameters: a second-order servo with a rate limit after a
//! transport delay ([`Sim`](super::Sim) steps it).

/// Control actuators: second-order servo with a rate limit, after a transport delay,
/// acting on the stick fractions (so their units are stick fractions).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ActuatorModel {
    /// Natural frequency ω_n [rad/s]; infinite (or ≤ 0) = the actuator follows instantly.
    pub natural_frequency_rad_s: f64,
    /// Damping ratio ζ.
    pub damping: f64,
    /// Rate limit [stick fraction per second].
    pub rate_limit_per_s: f64,
    /// Transport delay \[s\] (rounded to internal steps).
    pub transport_delay_s: f64,
}

impl ActuatorModel {
    /// The servos an aircraft file describes.
    pub fn from_aircraft(aircraft: &aircraft::Aircraft) -> ActuatorModel {
        let servos = &aircraft.servos;
        ActuatorModel {
            natural_frequency_rad_s: servos.natural_frequency.value,
            damping: servos.damping.value,
            rate_limit_per_s: servos.rate_limit.value,
            transport_delay_s: servos.transport_delay.value,
        }
    }

    /// Instant actuators, no delay.
    pub fn ideal() -> ActuatorModel {
        ActuatorModel {
            natural_frequency_rad_s: f64::INFINITY,
            damping: 1.0,
            rate_limit_per_s: f64::INFINITY,
            transport_delay_s: 0.0,
        }
    }

    pub(super) fn is_instant(&self) -> bool {
        !(self.natural_frequency_rad_s.is_finite() && self.natural_frequency_rad_s > 0.0)
    }
}

impl Default for ActuatorModel {
    /// ω_n = 60 rad/s, ζ = 0.7, full travel (2) in 0.5 s (4 per second), no delay.
    fn default() -> ActuatorModel {
        ActuatorModel {
            natural_frequency_rad_s: 60.0,
            damping: 0.7,
            rate_limit_per_s: 4.0,
            transport_delay_s: 0.0,
        }
    }
}
