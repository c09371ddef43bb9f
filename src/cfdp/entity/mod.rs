//! A CFDP entity (727.0-B-5 §4): up to `T` concurrent transactions, each sending or
//! receiving one file in class 1 or class 2, as a pure state machine. PDUs come in as bytes
//! with the time ([`Entity::handle`]); PDUs to send come out as bytes ([`Entity::poll`]), and
//! each transaction's end as an [`Event`]. Files live in a [`Filestore`] the shell provides.
//! A PDU refused (malformed, not for this entity, of a transaction that ended, or with no room
//! for a new one) changes nothing but a counter ([`Counters`]).
//!
//! ```
//! use mmic::cfdp::entity::{Config, Entity, Event, MemoryStore, Put};
//! use mmic::cfdp::header::Mode;
//!
//! let (mut ground, mut robot) = (
//!     Entity::<2, 8, 8>::new(Config::mission(0x15), 1),
//!     Entity::<2, 8, 8>::new(Config::mission(0x42), 1),
//! );
//! let (mut gs, mut rs) = (MemoryStore::<4, 2048>::new(), MemoryStore::<4, 2048>::new());
//! gs.put(b"plan.json", &[7u8; 1500]).unwrap();
//! let put = Put::new(b"plan.json", b"plans/next.json", Mode::Acknowledged).unwrap();
//! let id = ground.put(0, 0x42, put, &mut gs).unwrap();
//! let mut buf = [0u8; 512];
//! for now in 0..50u64 {
//!     while let Some(n) = ground.poll(now, &mut gs, &mut buf) {
//!         robot.handle(now, &buf[..n], &mut rs).unwrap();
//!     }
//!     while let Some(n) = robot.poll(now, &mut rs, &mut buf) {
//!         ground.handle(now, &buf[..n], &mut gs).unwrap();
//!     }
//! }
//! assert_eq!(rs.get(b"plans/next.json"), Some(&[7u8; 1500][..]));
//! assert!(matches!(ground.take_event(), Some(Event::Sent { id: i, .. }) if i == id));
//! ```

mod receiver;
mod sender;
mod store;

pub use receiver::{Receiver, NAK_SEGMENTS};
pub use sender::{Put, Sender};
pub use store::{Filestore, MemoryStore, StoreError, NAME_MAX};

use super::codes::{ChecksumType, ConditionCode, TransactionStatus};
use super::directive::PduRepr;
use super::header::{Direction, Lengths, Mode, PduHeader, PduType};
use super::{Pdu, PduError, MAX_PDU_LEN};
use heapless::Vec;

/// A transaction: its source entity and sequence number.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct TransactionId {
    /// The sending entity.
    pub source: u64,
    /// Its sequence number there.
    pub seq: u64,
}

/// An entity's choices (`spec/ccsds/cfdp.toml`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct Config {
    /// This entity's ID.
    pub local: u64,
    /// Octets of entity IDs and sequence numbers in the PDUs sent.
    pub lengths: Lengths,
    /// A CRC on each PDU sent.
    pub crc: bool,
    /// Octets of file data in one PDU at most.
    pub file_data: u16,
    /// The checksum of the files sent (modular or null).
    pub checksum: ChecksumType,
    /// Time to wait for the ACK of an EOF or Finished PDU, ms.
    pub ack_timeout_ms: u32,
    /// EOF or Finished PDUs sent before giving up (positive ACK limit).
    pub ack_limit: u8,
    /// Time to wait after a NAK before sending it again, ms (class 1: the check timer).
    pub nak_timeout_ms: u32,
    /// NAKs sent without progress before giving up.
    pub nak_limit: u8,
    /// Silence that ends a transaction, ms.
    pub inactivity_ms: u32,
    /// NAK a gap as soon as it appears, not only at EOF.
    pub immediate_nak: bool,
    /// What a fault found here does, per condition (727.0-B-5 §4.8).
    pub handlers: FaultHandlers,
}

impl Config {
    /// The mission's profile for entity `local` (`spec/ccsds/cfdp.toml`, decision
    /// `cfdp-timers`): YAMCS 5.12.8's acknowledgement timeouts (5 s, limit 5), NAK timeout
    /// (5 s) and immediate NAK; a NAK limit of 5; inactivity 30 s (YAMCS's default is 10 s:
    /// two NAKs or Finished PDUs lost in a row would end a transfer); 2- and 4-octet IDs, the
    /// modular checksum, no CRC (YAMCS sends none), 480 octets of file data a PDU (512-octet
    /// PDUs with the header, offset and room for a CRC).
    pub const fn mission(local: u64) -> Config {
        Config {
            local,
            lengths: Lengths::MISSION,
            crc: false,
            file_data: 480,
            checksum: ChecksumType::MODULAR,
            ack_timeout_ms: 5_000,
            ack_limit: 5,
            nak_timeout_ms: 5_000,
            nak_limit: 5,
            inactivity_ms: 30_000,
            immediate_nak: true,
            handlers: FaultHandlers::CANCEL,
        }
    }
}

/// What an entity does when it finds a fault (727.0-B-5 §4.8). Either way the fault is
/// reported once at this end ([`Event`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum FaultHandler {
    /// Notice of cancellation: the peer is told, by the sender's EOF or the receiver's
    /// Finished PDU carrying the condition (in class 2 until acknowledged or the positive ACK
    /// limit is reached), so that it ends at once rather than by its timers.
    Cancel,
    /// The transaction ends here with nothing more sent; the peer ends by its own timers.
    Abandon,
}

/// A [`FaultHandler`] per condition code: cancel, unless set to abandon. Suspend and ignore
/// are not offered (decision `cfdp-fault-handlers`).
///
/// ```
/// use mmic::cfdp::codes::ConditionCode;
/// use mmic::cfdp::entity::{FaultHandler, FaultHandlers};
///
/// let h = FaultHandlers::CANCEL.with(ConditionCode::InactivityDetected, FaultHandler::Abandon);
/// assert_eq!(h.handler(ConditionCode::InactivityDetected), FaultHandler::Abandon);
/// assert_eq!(h.handler(ConditionCode::NakLimitReached), FaultHandler::Cancel);
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub struct FaultHandlers {
    /// Bit `c` set: condition code `c` abandons.
    abandon: u16,
}

impl FaultHandlers {
    /// Cancel on every fault (the mission's: decision `cfdp-fault-handlers`).
    pub const CANCEL: FaultHandlers = FaultHandlers { abandon: 0 };

    /// These handlers with `condition` handled by `handler`.
    #[must_use]
    pub const fn with(self, condition: ConditionCode, handler: FaultHandler) -> FaultHandlers {
        let bit = 1u16 << (condition.code() & 0x0f);
        FaultHandlers {
            abandon: match handler {
                FaultHandler::Cancel => self.abandon & !bit,
                FaultHandler::Abandon => self.abandon | bit,
            },
        }
    }

    /// The handler of `condition`.
    pub const fn handler(&self, condition: ConditionCode) -> FaultHandler {
        if self.abandon & (1u16 << (condition.code() & 0x0f)) != 0 {
            FaultHandler::Abandon
        } else {
            FaultHandler::Cancel
        }
    }
}

/// A transaction's end, reported once.
#[derive(Debug, Clone, PartialEq, Eq, Hash)]
pub enum Event {
    /// A file this entity sent: `NoError` once the receiver said so (class 2, or class 1 with
    /// closure) or the EOF went out (class 1).
    Sent {
        /// The transaction.
        id: TransactionId,
        /// How it ended.
        condition: ConditionCode,
    },
    /// A file this entity received: `delivered` when it is in the store under `name`, whole and
    /// checked.
    Received {
        /// The transaction.
        id: TransactionId,
        /// How it ended.
        condition: ConditionCode,
        /// Whether the file was kept.
        delivered: bool,
        /// Its name at this entity (empty if the Metadata never came).
        name: Vec<u8, NAME_MAX>,
    },
}

/// A timer with a count of the times it was started (PDUs sent under it).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
struct Timer {
    deadline: Option<u64>,
    count: u8,
}

impl Timer {
    const IDLE: Timer = Timer {
        deadline: None,
        count: 0,
    };

    /// Running from `now` for `ms`, nothing counted.
    fn start(now: u64, ms: u32) -> Timer {
        Timer {
            deadline: Some(now.saturating_add(u64::from(ms))),
            count: 0,
        }
    }

    /// Running again from `now`, one more counted.
    fn restart(self, now: u64, ms: u32) -> Timer {
        Timer {
            deadline: Some(now.saturating_add(u64::from(ms))),
            count: self.count.saturating_add(1),
        }
    }

    fn expired(&self, now: u64) -> bool {
        self.deadline.is_some_and(|d| now >= d)
    }
}

/// The transaction status an ACK gives.
const fn status(active: bool) -> TransactionStatus {
    if active {
        TransactionStatus::Active
    } else {
        TransactionStatus::Terminated
    }
}

/// What the entity refused, by reason.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub struct Counters {
    /// Malformed PDUs (`PduError`).
    pub malformed: u32,
    /// PDUs for another entity.
    pub not_ours: u32,
    /// PDUs of transactions that ended here.
    pub ended: u32,
    /// PDUs toward a sender of a transaction this entity does not have.
    pub unknown: u32,
    /// New transactions refused for want of room.
    pub full: u32,
}

/// Why [`Entity::handle`] refused a PDU; nothing changed but [`Entity::counters`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, thiserror::Error)]
pub enum HandleError {
    /// Not a PDU of the profile.
    #[error(transparent)]
    Pdu(#[from] PduError),
    /// For entity `found`, not this one.
    #[error("a PDU for entity {found}, this is {local}")]
    NotOurs {
        /// This entity.
        local: u64,
        /// The entity the PDU is for.
        found: u64,
    },
    /// Of a transaction that ended here: it starts nothing new.
    #[error("a PDU of transaction {0:?}, which ended")]
    Ended(TransactionId),
    /// Toward the sender of a transaction this entity does not have.
    #[error("a PDU of transaction {0:?}, which this entity never sent")]
    Unknown(TransactionId),
    /// A new transaction with all `capacity` slots taken.
    #[error("a new transaction, and all {capacity} taken")]
    Full {
        /// Transactions at most.
        capacity: usize,
    },
}

/// Why [`Entity::put`] refused a file.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, thiserror::Error)]
pub enum PutError {
    /// The source file is not in the store.
    #[error("the file to send: {0}")]
    Store(#[from] StoreError),
    /// All `capacity` transactions taken.
    #[error("all {capacity} transactions taken")]
    Full {
        /// Transactions at most.
        capacity: usize,
    },
    /// The sequence numbers of the configured length are used up: they never repeat.
    #[error("transaction sequence numbers used up ({octets} octets)")]
    SeqExhausted {
        /// Octets of the sequence number.
        octets: u8,
    },
}

/// One transaction, either side.
#[derive(Debug, Clone, PartialEq, Eq, Hash)]
enum Transaction<const G: usize, const R: usize> {
    Send(Sender<R>),
    Receive(Receiver<G>),
}

/// Ended transactions remembered, so that their late PDUs start nothing.
pub const ENDED: usize = 16;

mod dispatch;

/// A CFDP entity of up to `T` transactions, each receiver keeping `G` ranges, each sender `R`
/// ranges to send again.
#[derive(Debug, Clone, PartialEq, Eq, Hash)]
pub struct Entity<const T: usize, const G: usize, const R: usize> {
    cfg: Config,
    next_seq: u64,
    tx: Vec<Transaction<G, R>, T>,
    ended: Vec<TransactionId, ENDED>,
    events: Vec<Event, T>,
    counters: Counters,
    turn: usize,
}

impl<const T: usize, const G: usize, const R: usize> Entity<T, G, R> {
    /// An entity whose next transaction takes sequence number `next_seq` (restored from
    /// durable storage: see [`Entity::next_seq`]).
    pub const fn new(cfg: Config, next_seq: u64) -> Self {
        Entity {
            cfg,
            next_seq,
            tx: Vec::new(),
            ended: Vec::new(),
            events: Vec::new(),
            counters: Counters {
                malformed: 0,
                not_ours: 0,
                ended: 0,
                unknown: 0,
                full: 0,
            },
            turn: 0,
        }
    }

    /// The sequence number the next [`Entity::put`] takes: the shell keeps it durable before
    /// the put's first PDU goes out, so that a restarted entity never repeats one.
    pub const fn next_seq(&self) -> u64 {
        self.next_seq
    }

    /// The configuration.
    pub const fn config(&self) -> &Config {
        &self.cfg
    }

    /// What was refused.
    pub const fn counters(&self) -> Counters {
        self.counters
    }

    /// Transactions running.
    pub fn active(&self) -> usize {
        self.tx.len()
    }

    /// The next transaction end, in order.
    pub fn take_event(&mut self) -> Option<Event> {
        (!self.events.is_empty()).then(|| self.events.remove(0))
    }
}

/// The header of a PDU of transaction `id` between `source` and `dest`.
fn header(cfg: &Config, mode: Mode, id: TransactionId, dest: u64) -> PduHeader {
    PduHeader {
        pdu_type: PduType::Directive,
        direction: Direction::TowardReceiver,
        mode,
        crc: cfg.crc,
        segmentation: false,
        lengths: cfg.lengths,
        data_len: 0,
        source: id.source,
        seq: id.seq,
        dest,
    }
}

/// The PDU in `bytes`, decoded.
fn decode(bytes: &[u8]) -> Result<(PduHeader, PduRepr<'_>), PduError> {
    let pdu = Pdu::parse(bytes)?;
    let repr = PduRepr::parse(&pdu)?;
    Ok((*pdu.header(), repr))
}

/// Octets of the buffer file data is read into.
const DATA_BUF: usize = MAX_PDU_LEN;
