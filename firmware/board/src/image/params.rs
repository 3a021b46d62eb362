//! Parameter requests on the host link (protocol 1.5): the image answers a host's
//! `ParamRequest` frames from USART1 with `ParamReply` frames through the flight logic's
//! [`ParamLink`], obeyed only while the board application is disarmed (in the loop the
//! host's simulation flies the servos, and the requests are refused as armed).
//!
//! The table lives in RAM, initialised from the defaults of the image's vehicle preset;
//! the board has no parameter store yet ([`NoFlash`]): a `Save` is refused with
//! `NoStore`, and the flight logic flies its build-time configuration whatever the
//! table holds.
//!
//! Bounded work: a `Get`, `Set` or `Reset` is answered at once with one frame; a `List`
//! is answered one reply per control tick (81 ticks for 80 values and Done), so it
//! never adds more than one frame to a tick's telemetry. A reply that finds the transmit
//! ring full is sent again on the next tick rather than dropped. A new `List` restarts
//! the walk; arming in the middle of one ends it with an `Armed` refusal.

use sweephold_firmware::params::link::ParamLink;
use sweephold_firmware::params::no_flash::NoFlash;
use sweephold_protocol::{
    Frame, ParamName, ParamOp, ParamRefusal, ParamReply, ParamRequest, VehicleId,
};

use crate::chip::usart::UsartTx;
use crate::image::link::{self, FrameScratch};

/// The parameter table in RAM and the `List` being answered.
pub struct HostParams {
    link: ParamLink<NoFlash>,
    /// Position of the next reply of the `List` in progress.
    listing: Option<usize>,
}

impl HostParams {
    /// The defaults of `vehicle`'s preset, nothing being listed.
    pub fn new(vehicle: VehicleId) -> Self {
        HostParams {
            link: ParamLink::boot(None, vehicle),
            listing: None,
        }
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
