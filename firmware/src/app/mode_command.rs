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
        // The loops' own command of the tick before, kept only from one loop-test tick
        // to the next.
        let loops_last = self.loop_output.take();
        match self.mode {
            Mode::Disarmed => (SAFE_COMMAND, None, false),
            Mode::Pilot => {
                let (command, mode) = self.fly_loops(rc, &sensors, integrate, self.last_command);
                (command, Some(mode), false)
            }
            Mode::RcFailsafe => {
                let (command, mode) = self.fly_loops(None, &sensors, integrate, self.last_command);
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
                // A loop test keeps the loops flying through its excitation; the
                // sequencer adds the sweep to their command (`FlightController::
                // set_loop_command`) and is fed the pilot's sticks for its override check.
                let loop_test = self.fc.config().test.input.is_loop();
                let excitation = is_excitation(phase);
                // The tail's slew limit runs from the loops' own last command in a loop
                // test, not from the applied one: the sweep added after the loop must not
                // reach the loop's output other than through the aircraft.
                let last = match loops_last {
                    Some(own) if loop_test => own,
                    _ => self.last_command,
                };
                let loops = (loop_test || !excitation)
                    .then(|| self.fly_loops(rc, &sensors, integrate, last));
                if let Some((command, _)) = loops.filter(|_| loop_test) {
                    self.fc.set_loop_command(command);
                    self.loop_output = Some(command);
                }
                if excitation {
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
                    (
                        Controls::from_array(feed),
                        loops.map(|(_, mode)| mode),
                        test_switch,
                    )
                } else {
                    if matches!(phase, Phase::Armed | Phase::TrimCapture) {
                        if let Some(frame) = rc {
                            self.stick_reference.add(&frame.sticks);
                        }
                    }
                    let (command, mode) = loops.unwrap_or((self.last_command, StickMode::Rate));
                    (command, Some(mode), test_switch)
                }
            }
        }
    }

    /// One step of the pilot-mode loops: on the pilot's sticks (`rc`), or, without
    /// them, the receiver failsafe's demand (trim attitude, heading held, held
    /// collective). `last` is the command the tail's slew limit and a preload start
    /// from.
    fn fly_loops(
        &mut self,
        rc: Option<&RcInput>,
        sensors: &LoopSensors,
        integrate: bool,
        last: Controls,
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
            &last,
            integrate,
            self.preload,
        );
        self.preload = false;
        (command, mode)
    }
}
