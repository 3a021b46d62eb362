//! The command of the application's current mode, and the pilot-mode loops that fly it.

use super::*;

impl BoardApp {
    /// The command of the current mode (for Test: the sequencer's pilot input), the
    /// loops' stick mode if they produced it, and the test switch the sequencer sees.
    pub(super) fn mode_command(
        &mut self,
        rc: Option<&RcInput>,
        imu: &ImuView,
        integrate: bool,
    ) -> (Controls, Option<StickMode>, bool) {
        let sensors = LoopSensors {
            rates: imu.rates,
            attitude: imu.attitude,
        };
        match self.mode {
            Mode::Disarmed => (SAFE_COMMAND, None, false),
            Mode::Pilot => {
                let (command, mode) = self.fly_loops(rc, &sensors, integrate);
                (command, Some(mode), false)
            }
            Mode::RcFailsafe => {
                let (command, mode) = self.fly_loops(None, &sensors, integrate);
                (command, Some(mode), false)
            }
            Mode::ImuFailsafe => {
                let usable = rc.filter(|_| self.loss.is_none());
                let collective = self
                    .held_collective()
                    .or(usable.map(|frame| frame.sticks.col))
                    .unwrap_or(self.last_command.col);
                let command = failsafe::imu_failsafe_command(
                    self.imu_trim,
                    usable.map(|frame| &frame.sticks),
                    self.config.failsafe.imu_direct_authority,
                    collective,
                );
                (command, None, false)
            }
            Mode::Test => {
                let phase = self.fc.phase();
                let test_switch = rc.is_some_and(|frame| frame.test_switch);
                if is_excitation(phase) {
                    let [t_lat, t_lon, t_ped, t_col] = self.fc.trim().sticks;
                    let trim = [t_lat, t_lon, t_ped, t_col];
                    let raw = rc.map_or(trim, |frame| frame.sticks.to_array());
                    let reference = self.stick_reference.mean().unwrap_or(raw);
                    let mut feed = [0.0; 4];
                    for (((feed, trim), raw), reference) in
                        feed.iter_mut().zip(trim).zip(raw).zip(reference)
                    {
                        *feed = clamp_finite(trim + (raw - reference), 1.0);
                    }
                    (Controls::from_array(feed), None, test_switch)
                } else {
                    if matches!(phase, Phase::Armed | Phase::TrimCapture) {
                        if let Some(frame) = rc {
                            self.stick_reference.add(&frame.sticks);
                        }
                    }
                    let (command, mode) = self.fly_loops(rc, &sensors, integrate);
                    (command, Some(mode), test_switch)
                }
            }
        }
    }

    /// One step of the pilot-mode loops: on the pilot's sticks (`rc`), or, without
    /// them, the receiver failsafe's demand (trim attitude, heading held, held
    /// collective).
    fn fly_loops(
        &mut self,
        rc: Option<&RcInput>,
        sensors: &LoopSensors,
        integrate: bool,
    ) -> (Controls, StickMode) {
        let gains = &self.config.pilot;
        let (demand, mode) = match rc {
            Some(frame) => {
                let switched = gains
                    .switch_modes
                    .get(frame.mode.index())
                    .copied()
                    .unwrap_or(StickMode::Rate);
                let mode = if sensors.attitude.is_some() {
                    switched
                } else {
                    StickMode::Rate
                };
                (Demand::from_sticks(&frame.sticks, mode, gains), mode)
            }
            None => {
                let (phi, theta) = self.trim.map_or((0.0, 0.0), |trim| (trim.phi, trim.theta));
                let collective = self.held_collective().unwrap_or(self.last_command.col);
                let (roll, pitch, mode) = if sensors.attitude.is_some() {
                    (
                        AxisDemand::Angle(phi),
                        AxisDemand::Angle(theta),
                        StickMode::Level,
                    )
                } else {
                    (
                        AxisDemand::Rate(0.0),
                        AxisDemand::Rate(0.0),
                        StickMode::Rate,
                    )
                };
                (
                    Demand {
                        roll,
                        pitch,
                        pedal: 0.0,
                        collective,
                    },
                    mode,
                )
            }
        };
        let command = self.loops.step(
            gains,
            &self.factors,
            &demand,
            sensors,
            &self.last_command,
            integrate,
            self.preload,
        );
        self.preload = false;
        (command, mode)
    }
}
