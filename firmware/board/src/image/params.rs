//! The board's parameters (protocol 1.5): the table the board application flies, and
//! the host's `ParamRequest` frames from USART1, answered with `ParamReply` frames
//! through the flight logic's [`ParamLink`] and obeyed only while the board application
//! is disarmed (in the loop the host's simulation flies the servos, and the requests are
//! refused as armed).
//!
//! At boot the table is loaded from the parameter store ([`Store`], the chip's flash
//! sectors 10 and 11, `memory.x`): a valid set is
//! flown; a missing, corrupt, old-version or refused one gives the defaults of
//! [`DEFAULT_FRAME`], an Event says which ([`HostParams::store_event`]), and the
//! application refuses to arm (`params_invalid`) until a valid set is saved. A Set or
//! Reset accepted on the ground is flown from the next disarmed control tick on
//! ([`HostParams::take_changed`]: the runner rebuilds the board application from it);
//! armed, nothing changes. A `Save` writes the table to the flash (the loop stalls
//! while a sector is erased, up to 2 s: the runner stretches the watchdog around it);
//! a flash that does not keep what is programmed (QEMU's) refuses it `store_failed`.
//!
//! Bounded work: a `Get`, `Set` or `Reset` is answered at once with one frame; a `List`
//! is answered one reply per control tick (COUNT + 1 ticks for the values and Done), so
//! it never adds more than one frame to a tick's telemetry. A reply that finds the
//! transmit ring full is sent again on the next tick rather than dropped. A new `List`
//! restarts the walk; arming in the middle of one ends it with an `Armed` refusal.

use sweephold_firmware::params::link::ParamLink;
use sweephold_firmware::params::store::{LoadStatus, ParamStore};
use sweephold_firmware::params::{Params, ParamsError};
use sweephold_protocol::{
    Event, Frame, ParamName, ParamOp, ParamRefusal, ParamReply, ParamRequest,
};

use crate::boards::BOARD;
use crate::chip::flash::{F405Flash, Registers, STORE_REGION};
use crate::chip::usart::UsartTx;
use crate::image::config::DEFAULT_FRAME;
use crate::image::link::{self, FrameScratch};

/// The flash the store lives in: the chip's, sectors 10 and 11 ([`STORE_REGION`]).
pub type Store = F405Flash<Registers>;

/// The parameter table, its store, and the `List` being answered.
pub struct HostParams {
    link: ParamLink<Store>,
    /// Position of the next reply of the `List` in progress.
    listing: Option<usize>,
}

impl HostParams {
    /// The set the store in `flash` holds, or the defaults of [`DEFAULT_FRAME`] and
    /// why; nothing being listed.
    pub fn boot(flash: Store) -> Self {
        // The region is a constant the host tests build the same store on
        // (`chip::flash` tests): it is always usable.
        let store = match ParamStore::new(flash, STORE_REGION) {
            Ok(store) => store,
            Err(_) => defmt::panic!("parameter store region unusable"),
        };
        HostParams {
            link: ParamLink::boot(Some(store), DEFAULT_FRAME),
            listing: None,
        }
    }

    /// What the store held at boot (`Loaded` after a save).
    pub fn status(&self) -> LoadStatus {
        self.link.load_status()
    }

    /// The typed view of the table, its IMU mounting put after the board's own mounting
    /// of the chip ([`BoardMap::imu_mounting`](crate::chip::pins::BoardMap)): `IMU_ROT`
    /// is how the aircraft carries the board, as ArduPilot's `AHRS_ORIENTATION` and
    /// Betaflight's board alignment are, while the chip's place on the board comes with
    /// the board (its published definitions).
    pub fn params(&self) -> Result<Params, ParamsError> {
        let mut params = self.link.table().params()?;
        params.stack.orientation = params
            .imu_rotation
            .orientation()
            .after(BOARD.imu_mounting.orientation());
        Ok(params)
    }

    /// Whether a valid set is in use (the pre-arm check's flag).
    pub fn valid(&self) -> bool {
        self.link.params_valid()
    }

    /// The Event reporting what the store held at boot.
    pub fn store_event(&self, tick: u32) -> Event {
        self.link.store_event(tick)
    }

    /// Whether an accepted Set or Reset changed the table since the last call.
    pub fn take_changed(&mut self) -> bool {
        self.link.take_changed()
    }

    /// A request from the host; `disarmed`: it may be obeyed.
    pub fn on_request(
        &mut self,
        request: &ParamRequest,
        disarmed: bool,
        tx: &mut UsartTx,
        scratch: &mut FrameScratch,
    ) {
        if disarmed && matches!(request, ParamRequest::List) {
            self.listing = Some(0);
            return;
        }
        self.link.handle(request, disarmed, |reply| {
            link::send_waiting(tx, scratch, &Frame::ParamReply(reply));
        });
    }

    /// One control tick: the next reply of a `List` in progress, if any.
    pub fn on_control_tick(
        &mut self,
        disarmed: bool,
        tx: &mut UsartTx,
        scratch: &mut FrameScratch,
    ) {
        let Some(index) = self.listing else {
            return;
        };
        let reply = if disarmed {
            self.link.list_entry(index)
        } else {
            Some(ParamReply::Refused {
                op: ParamOp::List,
                name: ParamName::EMPTY,
                reason: ParamRefusal::Armed,
            })
        };
        let Some(reply) = reply else {
            self.listing = None;
            return;
        };
        if !link::send(tx, scratch, &Frame::ParamReply(reply)) {
            // Ring full: the same reply on the next tick.
            return;
        }
        self.listing = match reply {
            ParamReply::Value { .. } => Some(index.saturating_add(1)),
            ParamReply::Done { .. } | ParamReply::Refused { .. } => None,
        };
    }
}
