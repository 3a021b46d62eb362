//! The host's parameter requests (protocol 1.5's [`ParamRequest`]): list, get, set,
//! save and reset the board's [`ParamTable`], answered with [`ParamReply`]s. Obeyed
//! only while the board application is disarmed; armed, every request is refused with
//! [`ParamRefusal::Armed`] and changes nothing, as the host link's other frames are
//! ([`BoardApp::host_link_allowed`](crate::app::BoardApp::host_link_allowed) is the
//! `disarmed` argument of [`ParamLink::handle`]).
//!
//! At boot [`ParamLink::boot`] loads the store; [`ParamLink::store_event`] is the
//! [`Event::ParamStore`] that reports what it found and [`ParamLink::params_valid`]
//! the flag the application's pre-arm check takes
//! ([`BoardApp::set_params_valid`](crate::app::BoardApp::set_params_valid)): the defaults
//! fly only on the ground until a valid set is saved. A `Set` changes the table in RAM;
//! the application flies the set it was built from until the board rebuilds it
//! ([`ParamLink::take_changed`] tells it to: the image does on its next disarmed
//! control tick). `Reset` restores the defaults of the airframe `FRAME` names.

use embedded_storage::nor_flash::NorFlash;
use sweephold_protocol::{
    Event, ParamName, ParamRefusal, ParamReply, ParamRequest, ParamStoreStatus, VehicleId,
};

use crate::params::store::{LoadStatus, ParamStore, SaveError};
use crate::params::{ParamId, ParamTable, SetError, COUNT, MAX_NAME_LEN};

/// The board's parameters in RAM, its store, and what the store held at boot.
pub struct ParamLink<F: NorFlash> {
    table: ParamTable,
    store: Option<ParamStore<F>>,
    status: LoadStatus,
    /// A Set or Reset changed the table since [`ParamLink::take_changed`] last looked.
    changed: bool,
}

/// A load status as it goes on the wire.
pub const fn store_status(status: LoadStatus) -> ParamStoreStatus {
    match status {
        LoadStatus::Loaded => ParamStoreStatus::Loaded,
        LoadStatus::Empty => ParamStoreStatus::Empty,
        LoadStatus::Corrupt => ParamStoreStatus::Corrupt,
        LoadStatus::OtherVersion => ParamStoreStatus::OtherVersion,
        LoadStatus::Invalid => ParamStoreStatus::Invalid,
        LoadStatus::FlashError => ParamStoreStatus::FlashError,
    }
}

/// A refused value as it goes on the wire.
pub const fn set_refusal(error: SetError) -> ParamRefusal {
    match error {
        SetError::UnknownName => ParamRefusal::UnknownName,
        SetError::NotFinite => ParamRefusal::NotFinite,
        SetError::OutOfRange => ParamRefusal::OutOfRange,
        SetError::NotAnInteger => ParamRefusal::NotAnInteger,
        SetError::NotAChoice => ParamRefusal::NotAChoice,
    }
}

impl<F: NorFlash> ParamLink<F> {
    /// Load `store` (the set it holds, or the defaults of `vehicle` and why); without a
    /// store the defaults are in use and count as valid (a board-less application).
    pub fn boot(store: Option<ParamStore<F>>, vehicle: VehicleId) -> Self {
        let mut store = store;
        let (table, status) = match store.as_mut() {
            Some(store) => {
                let loaded = store.load(vehicle);
                (loaded.table, loaded.status)
            }
            None => (ParamTable::defaults(vehicle), LoadStatus::Loaded),
        };
        ParamLink {
            table,
            store,
            status,
            changed: false,
        }
    }

    /// The parameters in RAM.
    pub const fn table(&self) -> &ParamTable {
        &self.table
    }

    /// What the store held at boot, or `Loaded` after a successful save.
    pub const fn load_status(&self) -> LoadStatus {
        self.status
    }

    /// Whether an accepted Set or Reset changed the table since the last call (the
    /// board rebuilds its configuration from it on the ground).
    pub fn take_changed(&mut self) -> bool {
        core::mem::take(&mut self.changed)
    }

    /// Whether a valid set is in use: the application refuses to arm otherwise.
    pub const fn params_valid(&self) -> bool {
        self.status.is_valid()
    }

    /// The Event reporting the store's status at `tick` (sent once, at boot).
    pub const fn store_event(&self, tick: u32) -> Event {
        Event::ParamStore {
            tick,
            status: store_status(self.status),
        }
    }

    /// The store back (tests, or a board handing the flash to something else).
    pub fn into_store(self) -> Option<ParamStore<F>> {
        self.store
    }

    /// Carry out `request` if `disarmed`, handing every reply to `reply` in order.
    pub fn handle(
        &mut self,
        request: &ParamRequest,
        disarmed: bool,
        mut reply: impl FnMut(ParamReply),
    ) {
        let op = request.op();
        let refuse =
            |name: ParamName, reason: ParamRefusal| ParamReply::Refused { op, name, reason };
        if !disarmed {
            let name = match request {
                ParamRequest::Get { name } | ParamRequest::Set { name, .. } => *name,
                _ => ParamName::EMPTY,
            };
            reply(refuse(name, ParamRefusal::Armed));
            return;
        }
        match *request {
            ParamRequest::List => {
                for index in 0..=COUNT {
                    if let Some(entry) = self.list_entry(index) {
                        reply(entry);
                    }
                }
            }
            ParamRequest::Get { name } => match lookup(&name) {
                Some(id) => reply(self.value(id)),
                None => reply(refuse(name, ParamRefusal::UnknownName)),
            },
            ParamRequest::Set { name, value } => match lookup(&name) {
                Some(id) => match self.table.set(id, value) {
                    Ok(()) => {
                        self.changed = true;
                        reply(self.value(id));
                    }
                    Err(error) => reply(refuse(name, set_refusal(error))),
                },
                None => reply(refuse(name, ParamRefusal::UnknownName)),
            },
            ParamRequest::Save => {
                let Some(store) = self.store.as_mut() else {
                    reply(refuse(ParamName::EMPTY, ParamRefusal::NoStore));
                    return;
                };
                match store.save(&self.table) {
                    Ok(()) => {
                        self.status = LoadStatus::Loaded;
                        reply(ParamReply::Done { op });
                    }
                    Err(SaveError::Inconsistent) => {
                        reply(refuse(ParamName::EMPTY, ParamRefusal::Inconsistent))
                    }
                    Err(SaveError::Flash) => {
                        reply(refuse(ParamName::EMPTY, ParamRefusal::StoreFailed))
                    }
                }
            }
            ParamRequest::Reset => {
                // The defaults of the airframe the table names (FRAME is kept).
                self.table = ParamTable::defaults(self.table.frame());
                self.changed = true;
                reply(ParamReply::Done { op });
            }
        }
    }

    /// The reply at position `index` of a `List`: the Value of the parameter at
    /// `index`, the closing Done at `COUNT`, nothing after. A board that answers a
    /// `List` one reply per tick (bounded work per tick) walks `index` from 0 itself;
    /// [`ParamLink::handle`] sends them all at once.
    pub fn list_entry(&self, index: usize) -> Option<ParamReply> {
        match ParamId::from_index(index) {
            Some(id) => Some(self.value(id)),
            None if index == COUNT => Some(ParamReply::Done {
                op: sweephold_protocol::ParamOp::List,
            }),
            None => None,
        }
    }

    /// The Value reply of `id`.
    fn value(&self, id: ParamId) -> ParamReply {
        let def = id.def();
        ParamReply::Value {
            index: id.index() as u16,
            count: COUNT as u16,
            name: ParamName::new(def.name).unwrap_or(ParamName::EMPTY),
            value: self.table.get(id),
        }
    }
}

/// The parameter a received name names.
fn lookup(name: &ParamName) -> Option<ParamId> {
    name.as_str().and_then(ParamId::from_name)
}

// Every table name (at most MAX_NAME_LEN, tested in params) fits the wire's field.
const _: () = assert!(MAX_NAME_LEN == sweephold_protocol::PARAM_NAME_LEN);

#[cfg(test)]
#[path = "link_tests.rs"]
mod tests;
