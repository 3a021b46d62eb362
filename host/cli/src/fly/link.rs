//! Flight-controller links: how the host reaches the firmware it flies in the loop.
//!
//! Every link runs the same lockstep protocol: each tick the host sends the simulated
//! sensors and pilot as a [`SensorIn`] and receives the flight controller's commands,
//! while the flight controller streams its telemetry (Header, Samples, Events) as it
//! would on the aircraft. The in-process link calls the firmware crate's tick directly —
//! the exact code the board image runs; the QEMU and serial links carry the same frames
//! over a byte stream.

use sweephold_firmware::{Config, FlightController};
use sweephold_protocol::{ActuatorOut, SensorIn};

/// A flight controller the host can fly in the loop.
pub trait FlightControllerLink {
    /// Short description for messages and `summary.json` (`in-process`, `qemu`, …).
    fn describe(&self) -> String;

    /// Prepare the flight controller for one record flown with `config`.
    fn begin_record(&mut self, config: &Config) -> anyhow::Result<()>;

    /// One lockstep tick: hand over `input`, return the commands. The telemetry bytes the
    /// flight controller streamed during this tick are appended to `telemetry`.
    fn exchange(
        &mut self,
        input: &SensorIn,
        telemetry: &mut Vec<u8>,
    ) -> anyhow::Result<ActuatorOut>;

    /// The controls the simulated rotor gets for the reply `out` of the last exchange:
    /// the command, or for a link that flies the servo pulses (`board-sim`) what the
    /// aircraft's servos make of them.
    fn controls_flown(&self, out: &ActuatorOut) -> [f64; 4] {
        out.command.to_array().map(f64::from)
    }

    /// The board application's mode after the last tick (`pilot`, `rc_failsafe`, …), for
    /// a link that runs one (`board-sim`). Default: none.
    fn board_mode(&self) -> Option<&'static str> {
        None
    }

    /// The record begun last is over (flown, aborted or failed); its dump is
    /// `dump_name` (e.g. `lat-1.bin`). A link that captures the flight controller's log
    /// writes it beside the dump here. Default: nothing.
    fn end_record(&mut self, dump_name: &str) -> anyhow::Result<()> {
        let _ = dump_name;
        Ok(())
    }

    /// No more records on this link: a link that keeps a log of the board's whole
    /// power-up (`board-sim` with one power-up for many records) writes it here.
    /// Default: nothing.
    fn end_flight(&mut self) -> anyhow::Result<()> {
        Ok(())
    }
}

/// The firmware's flight logic called in-process.
#[derive(Default)]
pub struct InProcessLink {
    controller: Option<FlightController>,
}

impl InProcessLink {
    /// A link with no record started yet.
    pub fn new() -> Self {
        Self::default()
    }
}

impl FlightControllerLink for InProcessLink {
    fn describe(&self) -> String {
        "in-process".to_string()
    }

    fn begin_record(&mut self, config: &Config) -> anyhow::Result<()> {
        let controller = FlightController::new(*config)
            .map_err(|e| anyhow::anyhow!("firmware refused the configuration: {e:?}"))?;
        self.controller = Some(controller);
        Ok(())
    }

    fn exchange(
        &mut self,
        input: &SensorIn,
        telemetry: &mut Vec<u8>,
    ) -> anyhow::Result<ActuatorOut> {
        let controller = self
            .controller
            .as_mut()
            .ok_or_else(|| anyhow::anyhow!("no record started on the in-process link"))?;
        let output = controller.step(input, telemetry);
        // `tick()` is already the next tick; the reply carries the one just stepped,
        // as the board image's does (the tick of this step's Sample).
        Ok(output.actuator_out(controller.tick().wrapping_sub(1), input.seq))
    }
}
