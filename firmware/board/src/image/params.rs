//! The board's parameters (protocol 1.5): the table the board application flies, and
//! the host's `ParamRequest` frames from USART1, answered with `ParamReply` frames
//! through the flight logic's [`ParamLink`] and obeyed only while the board application
//! is disarmed (in the loop the host's simulation flies the servos, and the requests are
//! refused as armed).
//!
//! At boot the table is loaded from the parameter store ([`Store`]): a valid set is
//! flown; a missing, corrupt, old-version or refused one gives the defaults of
//! [`DEFAULT_FRAME`], an Event says which ([`HostParams::store_event`]), and the
//! application refuses to arm (`params_invalid`) until a valid set is saved. A Set or
//! Reset accepted on the ground is flown from the next disarmed control tick on
//! ([`HostParams::take_changed`]: the runner rebuilds the board application from it);
//! armed, nothing changes.
//!
//! Bounded work: a `Get`, `Set` or `Reset` is answered at once with one frame; a `List`
//! is answered one reply per control tick (COUNT + 1 ticks for the values and Done), so
//! it never adds more than one frame to a tick's telemetry. A reply that finds the
//! transmit ring full is sent again on the next tick rather than dropped. A new `List`
//! restarts the walk; arming in the middle of one ends it with an `Armed` refusal.

use sweephold_firmware::params::link::ParamLink;
use sweephold_firmware::params::store::ParamStore;
use sweephold_firmware::params::{Params, ParamsError};
use sweephold_protocol::{
    Event, Frame, ParamName, ParamOp, ParamRefusal, ParamReply, ParamRequest,
};

use crate::chip::usart::UsartTx;
use crate::image::config::DEFAULT_FRAME;
use crate::image::link::{self, FrameScratch};

pub use sweephold_firmware::params::no_flash::NoFlash as Store;

/// The parameter table, its store, and the `List` being answered.
pub struct HostParams {
    link: ParamLink<Store>,
    /// Position of the next reply of the `List` in progress.
    listing: Option<usize>,
}

impl HostParams {
    /// The set `store` holds, or the defaults of [`DEFAULT_FRAME`]; nothing being
    /// listed.
    pub fn boot(store: Option<ParamStore<Store>>) -> Self {
        HostParams {
            link: ParamLink::boot(store, DEFAULT_FRAME),
            listing: None,
        }
    }

    /// The typed view of the table.
    pub fn params(&self) -> Result<Params, ParamsError> {
        self.link.table().params()
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
