//! The excitation phases' tick (fade-in, sweep, fade-out): the sweep or pulse on the
//! primary axis, the off-axis noise, and on each held axis the conditional attitude
//! hold's logic and controller; in a loop test ([`InputKind::LoopSweep`]) the sweep
//! added to the pilot-mode loops' command instead.
//!
//! # Loop test
//!
//! The board application closes its pilot-mode loops through the whole test and hands
//! their command c to [`FlightController::set_loop_command`] before each step. In the
//! excitation phases the command is then u = c + d on the primary axis (d the sweep,
//! scaled as every excitation is) and c on the others: no trim, no hold, no noise, the
//! configured command slew limit as in every test. The safety checks are the same as in
//! every test; the pilot-override check compares the sticks the board application
//! feeds (the captured trim plus the pilot's displacement from the capture's mean) with
//! the trim, so it still sees the pilot's hands, not the loops' moving command. When a
//! test ends (Done, an abort) the tick's command is c, the loops' command. Without a
//! loop command (a flight controller without the board application) the pilot's sticks
//! stand for it.

use super::*;

impl FlightController {
    /// The pilot-mode loops' command of the coming tick, in a loop test: the command the
    /// step passes through and, in the excitation phases, adds the sweep to. Used by the
    /// next [`step`](Self::step) only (a step without one uses the pilot's sticks);
    /// ignored in other tests. Non-finite values count as the last finite pilot stick.
    pub fn set_loop_command(&mut self, command: Controls) {
        self.loop_command = Some(command.to_array());
    }

    /// The command the tick starts from: the loops' command in a loop test if one was
    /// set for this tick (each non-finite value replaced by the pilot's), else `pilot`.
    pub(super) fn loop_or_pilot(&mut self, pilot: [f32; 4]) -> [f32; 4] {
        let command = self.loop_command.take();
        match command.filter(|_| self.config.test.input.is_loop()) {
            Some(mut command) => {
                for (value, stick) in command.iter_mut().zip(pilot) {
                    if !value.is_finite() {
                        *value = stick;
                    }
                }
                command
            }
            None => pilot,
        }
    }

    /// One excitation tick of a loop test: the sweep `sweep` (already scaled) added to
    /// the loops' command `loops` on the primary axis (see the module documentation).
    fn loop_parts(&self, sweep: f32, omega: f32, loops: [f32; 4]) -> TickParts {
        let primary = self.config.test.primary.index();
        let sweeps: [f32; 4] = core::array::from_fn(|k| if k == primary { sweep } else { 0.0 });
        let mut command = [0.0; 4];
        for (((command, &c), (&d, last)), step) in command
            .iter_mut()
            .zip(&loops)
            .zip(sweeps.iter().zip(self.last_command))
            .zip(self.slew_steps)
        {
            *command = clamp_unit(slew::limit(last, clamp_unit(c + d), step));
        }
        TickParts {
            command,
            sweep: sweeps,
            noise: [0.0; 4],
            sweep_omega: omega,
        }
    }

    /// One tick of the excitation phases.
    pub(super) fn excite(
        &mut self,
        meas: &Measurements,
        pilot: [f32; 4],
        tick: u32,
        sink: &mut impl FrameSink,
    ) -> TickParts {
        // Tick n of the excitation, t = n / rate: an integer count, no accumulated
        // rounding over a long record.
        let mut sample = self.excitation.sample(self.excitation_tick);
        let Some(phase) = sample.segment.phase() else {
            self.release_all(tick, sink);
            self.set_phase(Phase::Done, tick, sink);
            return TickParts::pass_through(pilot);
        };
        self.set_phase(phase, tick, sink);
        self.excitation_tick = self.excitation_tick.saturating_add(1);

        // The vehicle's share of the test's amplitudes on each axis, applied before the
        // adaptive shaping so that its stick-travel and servo-rate bounds see what is flown.
        let scale = self.config.excitation_scale;
        sample.value *= scale.of(self.config.test.primary);
        if self.config.test.input.is_loop() {
            return self.loop_parts(sample.value, sample.omega, pilot);
        }
        let trim = self.trim;
        let [_, _, _, pilot_col] = pilot;
        let [noise_lat, noise_lon, noise_ped] = self.noise.next_sample();
        let [noise_lat, noise_lon, noise_ped] = [
            noise_lat * scale.of(Axis::Lat),
            noise_lon * scale.of(Axis::Lon),
            noise_ped * scale.of(Axis::Ped),
        ];
        let gains = &self.config.gains;
        // lat ↔ φ (damped by p), lon ↔ θ (q), ped ↔ heading error ψ − ψ_trim wrapped to
        // ±π (r); all as deviations from the captured trim.
        // The hold thresholds apply to φ and θ themselves (paper) or to their deviations
        // from trim; the controller always regulates to the trim attitude.
        let (phi_ref, theta_ref) = match self.config.hold_reference {
            HoldReference::Level => (0.0, 0.0),
            HoldReference::Trim => (trim.phi, trim.theta),
        };
        let [decay_lat, decay_lon, decay_ped] = self.decays;
        let inputs = [
            AxisInput {
                axis: Axis::Lat,
                gains: gains.lat,
                decay: decay_lat,
                hold_angle: meas.phi - phi_ref,
                deviation: meas.phi - trim.phi,
                rate: meas.p,
                noise: noise_lat,
            },
            AxisInput {
                axis: Axis::Lon,
                gains: gains.lon,
                decay: decay_lon,
                hold_angle: meas.theta - theta_ref,
                deviation: meas.theta - trim.theta,
                rate: meas.q,
                noise: noise_lon,
            },
            AxisInput {
                axis: Axis::Ped,
                gains: gains.ped,
                decay: decay_ped,
                hold_angle: wrap_pi(meas.psi - trim.psi),
                deviation: wrap_pi(meas.psi - trim.psi),
                rate: meas.r,
                noise: noise_ped,
            },
        ];

        let primary = self.config.test.primary;
        if let Some(shaper) = &mut self.shaper {
            let envelopes = inputs.map(|input| AxisEnvelope {
                deviation: input.deviation,
                rate: input.rate,
            });
            let trim_stick = trim.sticks.get(primary.index()).copied().unwrap_or(0.0);
            let quadrature = self.excitation.quadrature();
            sample.value = shaper.shape(
                sample.value,
                quadrature,
                sample.omega,
                trim_stick,
                &envelopes,
            );
        }
        let mode = self.config.test.mode;
        let mut parts = TickParts {
            command: [0.0; 4],
            sweep: [0.0; 4],
            noise: [0.0; 4],
            sweep_omega: sample.omega,
        };
        let held_parts = parts
            .command
            .iter_mut()
            .zip(parts.sweep.iter_mut())
            .zip(parts.noise.iter_mut())
            .zip(trim.sticks.iter().zip(self.last_command))
            .zip(self.slew_steps);
        for (
            ((((command, sweep_part), noise_part), (&trim_stick, last)), max_step),
            ((held, input), hold_step),
        ) in held_parts.zip(self.axes.iter_mut().zip(inputs).zip(self.hold_slew_steps))
        {
            let step = step_axis(
                held,
                &input,
                &sample,
                primary,
                mode,
                &self.thresholds,
                self.dt_s,
            );
            let perturbation = if hold_step.is_finite() {
                let hold = slew::limit(
                    held.last_hold,
                    step.perturbation - step.sweep - step.noise,
                    hold_step,
                );
                held.last_hold = hold;
                step.sweep + step.noise + hold
            } else {
                step.perturbation
            };
            *command = clamp_unit(slew::limit(
                last,
                clamp_unit(trim_stick + perturbation),
                max_step,
            ));
            held.last_perturbation = *command - trim_stick;
            *sweep_part = step.sweep;
            *noise_part = step.noise;
            if step.previous != held.state {
                let axis = input.axis;
                match held.state {
                    HoldState::Engaged => {
                        debug!("tick {=u32}: hold engaged on {}", tick, axis);
                        emit(sink, &Frame::Event(Event::HoldEngaged { tick, axis }));
                    }
                    HoldState::Released => {
                        debug!("tick {=u32}: hold released on {}", tick, axis);
                        emit(sink, &Frame::Event(Event::HoldReleased { tick, axis }));
                    }
                    HoldState::Frozen => {}
                }
            }
        }

        // The collective is never held and never gets noise: trim (or the pilot's stick,
        // `CollectiveSource::Pilot`), plus the excitation when it is the primary axis.
        let collective_sweep = if primary == Axis::Col {
            sample.value
        } else {
            0.0
        };
        let [lat, lon, ped, _] = parts.command;
        let [sweep_lat, sweep_lon, sweep_ped, _] = parts.sweep;
        let trim_col = match self.config.collective {
            CollectiveSource::Trim => trim.sticks[3],
            CollectiveSource::Pilot => pilot_col,
        };
        let [_, _, _, last_col] = self.last_command;
        let [_, _, _, col_step] = self.slew_steps;
        let col = slew::limit(last_col, clamp_unit(trim_col + collective_sweep), col_step);
        parts.command = [lat, lon, ped, clamp_unit(col)];
        parts.sweep = [sweep_lat, sweep_lon, sweep_ped, collective_sweep];
        parts
    }
}

/// Result of one held axis' tick.
struct AxisStep {
    previous: HoldState,
    perturbation: f32,
    sweep: f32,
    noise: f32,
}

/// Hold logic and controller of one held axis for one tick; updates `held.state` and
/// the controller, returns the perturbation and its sweep and noise parts.
fn step_axis(
    held: &mut HeldAxis,
    input: &AxisInput,
    sample: &ExcitationSample,
    primary: Axis,
    mode: ExcitationMode,
    thresholds: &HoldThresholds,
    dt_s: f32,
) -> AxisStep {
    let is_primary = input.axis == primary;
    let with_noise = matches!(
        mode,
        ExcitationMode::ConditionalAttitudeHold | ExcitationMode::OffAxisNoise
    );
    let sweep = if is_primary { sample.value } else { 0.0 };
    let noise = if !is_primary && with_noise {
        input.noise * sample.envelope
    } else {
        0.0
    };
    let previous = held.state;
    let (state, perturbation, sweep, noise) = match mode {
        ExcitationMode::ConditionalAttitudeHold => {
            match next_hold_state(previous, input.hold_angle, thresholds) {
                HoldState::Released => {
                    if previous != HoldState::Released {
                        held.controller.reset();
                        // Bumpless release: the controller was holding the aircraft
                        // against moments (sideslip, speed) that do not vanish at 4°;
                        // dropping its output in one tick kicks the aircraft straight
                        // back through 6° and injects a broadband step into every held
                        // axis at once, i.e. cross-control coherence.
                        held.release_carry = held.last_perturbation - sweep - noise;
                    }
                    held.release_carry *= input.decay.release;
                    let carry = held.release_carry;
                    (HoldState::Released, sweep + noise + carry, sweep, noise)
                }
                HoldState::Engaged => {
                    let output = controller_output(held, input, previous, dt_s);
                    (HoldState::Engaged, output, 0.0, 0.0)
                }
                HoldState::Frozen => (HoldState::Frozen, held.last_perturbation, 0.0, 0.0),
            }
        }
        // Standard and off-axis-noise methods: the controller always drives the axis and
        // the excitation is added on top.
        ExcitationMode::Standard | ExcitationMode::OffAxisNoise => {
            let output = controller_output(held, input, previous, dt_s);
            (HoldState::Engaged, output + sweep + noise, sweep, noise)
        }
    };
    held.state = state;
    AxisStep {
        previous,
        perturbation,
        sweep,
        noise,
    }
}

/// The attitude-hold controller's output this tick. A controller that was not driving the
/// axis the tick before is engaged first, bumplessly from the last command.
fn controller_output(
    held: &mut HeldAxis,
    input: &AxisInput,
    previous: HoldState,
    dt_s: f32,
) -> f32 {
    let gains = &input.gains;
    if previous != HoldState::Engaged {
        let last = held.last_perturbation;
        held.controller
            .engage(gains, input.deviation, input.rate, last);
    }
    held.controller.update_with_decay(
        gains,
        input.deviation,
        input.rate,
        dt_s,
        input.decay.transfer,
    )
}
