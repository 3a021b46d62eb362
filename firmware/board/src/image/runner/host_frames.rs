//! What the runner does with a frame from the host: which frames an armed board ignores,
//! entering the loop, the in-the-loop configuration, the bench servo test, and the
//! parameter requests.

use super::*;

impl Runner {
    /// Whether a host frame may be obeyed: always in the loop, and in the board
    /// application only while it is disarmed. An ignored frame is counted, and the first
    /// of an armed period reported.
    pub(super) fn host_frame_allowed(&mut self, frame: HostFrame) -> bool {
        if self.mode != Mode::BoardApplication || self.stack.app().host_link_allowed() {
            return true;
        }
        self.stats.ignored_frames = self.stats.ignored_frames.wrapping_add(1);
        if !self.host_ignored_reported {
            self.host_ignored_reported = true;
            defmt::warn!("host {=str} ignored: armed", frame.name());
            let event = Event::HostLinkIgnored {
                tick: self.stack.app().flight_controller().tick(),
                frame,
            };
            link::send(&mut self.tx, &mut self.scratch, &Frame::Event(event));
        }
        false
    }

    /// Whether the host's parameter requests are obeyed: in the board application while
    /// it is disarmed (in the loop the host's simulation flies the servos: refused as
    /// armed).
    pub(super) fn params_allowed(&self) -> bool {
        self.mode == Mode::BoardApplication && self.stack.app().host_link_allowed()
    }

    /// Leave the board application for the loop: the ESC to the cut, the link timer's
    /// silence count from zero.
    pub(super) fn enter_the_loop(&mut self) {
        // The host's simulation flies the servos from now on.
        self.servo_test.stop();
        if self.mode == Mode::BoardApplication {
            let _ = self.esc.set_duty_cycle(ESC_CUT_US);
            defmt::info!("host in the loop: the board application stops");
        }
        self.mode = Mode::InTheLoop { silent_ticks: 0 };
    }

    /// A Configure frame: restart the in-the-loop flight logic on the requested
    /// configuration, or keep the running one if the flight logic refuses it, and answer.
    pub(super) fn configure(&mut self, request: &LinkConfig) {
        if !self.host_frame_allowed(HostFrame::Configure) {
            return;
        }
        self.enter_the_loop();
        let result = match FlightController::new(link_config(request)) {
            Ok(fc) => {
                self.fc = fc;
                // A new test starts at tick 0: so do its log lines.
                log::set_tick(self.fc.tick());
                let neutral =
                    sweephold_firmware::mix(&self.fc.config().mixer, &Controls::default());
                servo::set_failsafe(neutral);
                self.stats.reconfigured = self.stats.reconfigured.wrapping_add(1);
                defmt::info!(
                    "configured by the host: {=str}, {=u16} Hz",
                    request.vehicle.name(),
                    request.rate_hz
                );
                self.announce();
                ConfigureResult {
                    accepted: true,
                    refusal: 0,
                }
            }
            Err(error) => {
                self.stats.refused = self.stats.refused.wrapping_add(1);
                defmt::warn!("configuration refused: {=str}", error.message());
                ConfigureResult {
                    accepted: false,
                    // The variant's position: the host names it with the same library.
                    refusal: error as u8,
                }
            }
        };
        link::send_waiting(
            &mut self.tx,
            &mut self.scratch,
            &Frame::ConfigureResult(result),
        );
    }

    /// A bench servo test request: refused in the loop, armed, or without a valid
    /// parameter set; answered at once.
    pub(super) fn servo_test_request(&mut self, request: &ServoTest) {
        let app = self.stack.app();
        let refused = if self.mode != Mode::BoardApplication {
            Some(ServoTestRefusal::InTheLoop)
        } else if !app.host_link_allowed() {
            Some(ServoTestRefusal::Armed)
        } else if !self.params.valid() {
            Some(ServoTestRefusal::ParamsInvalid)
        } else {
            None
        };
        let flight = &self.stack.config().app.flight;
        let reply = self
            .servo_test
            .request(request, refused, &flight.mixer, flight.rate_hz);
        link::send_waiting(
            &mut self.tx,
            &mut self.scratch,
            &Frame::ServoTestReply(reply),
        );
    }

    /// A frame (or a decoding error) from the host.
    pub(super) fn on_frame(&mut self, frame: Result<Frame, FrameError>) {
        match frame {
            Ok(Frame::SensorIn(input)) => {
                if !self.host_frame_allowed(HostFrame::SensorIn) {
                    return;
                }
                if self.mode == Mode::BoardApplication {
                    defmt::info!("SensorIn from the host: in-the-loop mode");
                    self.enter_the_loop();
                    self.announce();
                }
                self.mode = Mode::InTheLoop { silent_ticks: 0 };
                self.input = input;
                self.step(Some(input.seq));
                // The host's SensorIn is the fresh sample of the loop.
                self.watchdog.fed_by_fresh_sample();
            }
            Ok(Frame::Configure(request)) => self.configure(&request),
            Ok(Frame::ServoTest(request)) => self.servo_test_request(&request),
            Ok(Frame::ParamRequest(request)) => {
                let disarmed = self.params_allowed();
                // A save may erase a flash sector: the loop stalls up to 2 s (disarmed
                // only; the link refuses a save armed before touching the flash).
                let saving = disarmed && matches!(request, ParamRequest::Save);
                if saving {
                    self.watchdog.stretch_for_flash();
                }
                self.params
                    .on_request(&request, disarmed, &mut self.tx, &mut self.scratch);
                if saving {
                    self.watchdog.restore_after_save();
                }
            }
            Ok(_) => self.stats.ignored_frames = self.stats.ignored_frames.wrapping_add(1),
            // The decoder has resynchronised on the next delimiter already.
            Err(_) => self.stats.bad_frames = self.stats.bad_frames.wrapping_add(1),
        }
    }
}
