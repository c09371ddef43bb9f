//! The receiving side of one transaction (727.0-B-5 §4.6, class 1 and class 2): file data
//! written into the transaction's incoming file as it comes, its gaps asked for again by NAK
//! (at once when a gap appears, with `immediate_nak`, at EOF, and again each NAK timeout up to
//! the NAK limit), the EOF acknowledged, the file checked whole against the EOF's size and
//! checksum (read back from the store) and only then given its name, and the Finished PDU
//! repeated until acknowledged or the positive ACK limit is reached. Silence for the
//! inactivity timeout before the EOF ends the transaction with that fault; after the EOF the
//! NAK limit bounds the wait.

use super::{Config, Event, FaultHandler, Filestore, Timer, TransactionId, NAME_MAX};
use crate::cfdp::checksum::Modular;
use crate::cfdp::codes::{ChecksumType, ConditionCode, DirectiveCode, FileStatus};
use crate::cfdp::directive::{
    AckRepr, EofRepr, FinishedRepr, MetadataRepr, NakRepr, PduRepr, PromptFor, Segments,
};
use crate::cfdp::header::Mode;
use crate::cfdp::received::{Received, ReceivedError};
use crate::cfdp::tlv::Tlvs;
use heapless::Vec;

/// Where the receiver stands.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
enum Phase {
    /// Taking file data.
    Receiving,
    /// Its Finished PDU sent, waiting for the ACK.
    Finishing,
    /// Done: nothing more to send.
    Ended,
}

/// What the Metadata PDU said.
#[derive(Debug, Clone, PartialEq, Eq, Hash)]
struct Meta {
    size: u32,
    checksum: ChecksumType,
    closure: bool,
    name: Vec<u8, NAME_MAX>,
}

/// PDUs owed to the sender.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
struct Owed {
    ack_eof: bool,
    finished: bool,
    nak: bool,
    keep_alive: bool,
}

/// Most segment requests a NAK carries.
pub const NAK_SEGMENTS: usize = 16;

/// One transaction's receiving side, keeping at most `G` received ranges.
#[derive(Debug, Clone, PartialEq, Eq, Hash)]
pub struct Receiver<const G: usize> {
    id: TransactionId,
    mode: Mode,
    meta: Option<Meta>,
    got: Received<G>,
    highest: u32,
    eof: Option<(u32, u32)>,
    phase: Phase,
    condition: ConditionCode,
    delivered: bool,
    heard: u64,
    nak: Timer,
    fin: Timer,
    owed: Owed,
    event: Option<Event>,
}

impl<const G: usize> Receiver<G> {
    /// A transaction first heard of at `now`.
    pub fn new(id: TransactionId, mode: Mode, now: u64) -> Self {
        Receiver {
            id,
            mode,
            meta: None,
            got: Received::new(),
            highest: 0,
            eof: None,
            phase: Phase::Receiving,
            condition: ConditionCode::NoError,
            delivered: false,
            heard: now,
            nak: Timer::IDLE,
            fin: Timer::IDLE,
            owed: Owed::default(),
            event: None,
        }
    }

    /// The transaction.
    pub const fn id(&self) -> TransactionId {
        self.id
    }

    /// The transmission mode.
    pub const fn mode(&self) -> Mode {
        self.mode
    }

    /// Whether it has ended and owes nothing more.
    pub fn is_ended(&self) -> bool {
        self.phase == Phase::Ended && self.event.is_none() && self.owed == Owed::default()
    }

    /// Takes a PDU of this transaction (toward the receiver) received at `now`.
    pub fn handle<S: Filestore>(
        &mut self,
        now: u64,
        cfg: &Config,
        repr: &PduRepr<'_>,
        store: &mut S,
    ) {
        self.heard = now;
        match repr {
            PduRepr::Metadata(m) if self.phase == Phase::Receiving => self.metadata(m, cfg, store),
            PduRepr::FileData(f) if self.phase == Phase::Receiving => {
                self.file_data(f.offset, f.data, cfg, store);
            }
            PduRepr::Eof(e) => self.eof(now, e, cfg, store),
            PduRepr::Prompt(PromptFor::Nak) if self.class2() => self.owed.nak = true,
            PduRepr::Prompt(PromptFor::KeepAlive) if self.class2() => {
                self.owed.keep_alive = true;
            }
            PduRepr::Ack(a)
                if a.of == DirectiveCode::Finished && self.phase == Phase::Finishing =>
            {
                self.phase = Phase::Ended;
            }
            _ => {}
        }
    }

    fn class2(&self) -> bool {
        self.mode == Mode::Acknowledged
    }

    fn metadata<S: Filestore>(&mut self, m: &MetadataRepr<'_>, cfg: &Config, store: &mut S) {
        if self.meta.is_some() {
            return;
        }
        if !(m.checksum == ChecksumType::MODULAR || m.checksum == ChecksumType::NULL) {
            return self.fault(ConditionCode::UnsupportedChecksumType, cfg, store);
        }
        let Ok(name) = Vec::from_slice(m.dest) else {
            return self.fault(ConditionCode::FilestoreRejection, cfg, store);
        };
        if self.highest > m.file_size {
            return self.fault(ConditionCode::FileSizeError, cfg, store);
        }
        self.meta = Some(Meta {
            size: m.file_size,
            checksum: m.checksum,
            closure: m.closure_requested,
            name,
        });
        self.evaluate(cfg, store);
    }

    fn file_data<S: Filestore>(&mut self, offset: u32, data: &[u8], cfg: &Config, store: &mut S) {
        let len = u32::try_from(data.len()).unwrap_or(u32::MAX);
        let Some(end) = offset.checked_add(len) else {
            return self.fault(ConditionCode::FileSizeError, cfg, store);
        };
        if self.size().is_some_and(|size| end > size) {
            return self.fault(ConditionCode::FileSizeError, cfg, store);
        }
        if store.write_incoming(self.id, offset, data).is_err() {
            return self.fault(ConditionCode::FilestoreRejection, cfg, store);
        }
        match self.got.add(offset, len) {
            // New octets: the NAK limit counts NAKs without progress.
            Ok(new) if new > 0 => self.nak.count = 0,
            Ok(_) | Err(ReceivedError::Full { .. }) => {}
            Err(ReceivedError::Overflow { .. }) => {
                return self.fault(ConditionCode::FileSizeError, cfg, store);
            }
        }
        // A gap opened, or the first file data came without the Metadata: ask at once.
        let first_without_metadata = self.meta.is_none() && self.highest == 0;
        if (offset > self.highest || first_without_metadata) && self.class2() && cfg.immediate_nak {
            self.owed.nak = true;
        }
        self.highest = self.highest.max(end);
        self.evaluate(cfg, store);
    }

    fn eof<S: Filestore>(&mut self, now: u64, e: &EofRepr, cfg: &Config, store: &mut S) {
        if self.class2() {
            self.owed.ack_eof = true;
        }
        if self.phase != Phase::Receiving || self.eof.is_some() {
            return;
        }
        if e.condition != ConditionCode::NoError {
            return self.finish(e.condition, store);
        }
        if self.highest > e.file_size || self.meta.as_ref().is_some_and(|m| m.size != e.file_size) {
            return self.fault(ConditionCode::FileSizeError, cfg, store);
        }
        self.eof = Some((e.checksum, e.file_size));
        self.nak = Timer::start(now, cfg.nak_timeout_ms);
        if self.class2() {
            self.owed.nak = true;
        }
        self.evaluate(cfg, store);
    }

    /// The file's size, once the Metadata or the EOF said it.
    fn size(&self) -> Option<u32> {
        self.meta
            .as_ref()
            .map(|m| m.size)
            .or(self.eof.map(|(_, s)| s))
    }

    /// Once the EOF and the Metadata are in and every octet is here: the file checked and
    /// named, or refused.
    fn evaluate<S: Filestore>(&mut self, cfg: &Config, store: &mut S) {
        let (Some((checksum, size)), Some(meta)) = (self.eof, self.meta.as_ref()) else {
            return;
        };
        if self.phase != Phase::Receiving || !self.got.is_complete(size) {
            return;
        }
        let ok = meta.checksum == ChecksumType::NULL
            || matches!(stored_checksum(store, self.id, size), Some(c) if c == checksum);
        if !ok {
            return self.fault(ConditionCode::FileChecksumFailure, cfg, store);
        }
        let name = meta.name.clone();
        if store.commit(self.id, &name).is_err() {
            return self.fault(ConditionCode::FilestoreRejection, cfg, store);
        }
        self.delivered = true;
        self.finish(ConditionCode::NoError, store);
    }

    /// A fault found here ends the transaction as its handler says (`Config::handlers`):
    /// cancel, the sender told by the Finished PDU (in class 2, or with closure); abandon,
    /// nothing more sent.
    fn fault<S: Filestore>(&mut self, condition: ConditionCode, cfg: &Config, store: &mut S) {
        self.finish(condition, store);
        if cfg.handlers.handler(condition) == FaultHandler::Abandon {
            self.owed.finished = false;
            self.phase = Phase::Ended;
        }
    }

    /// Ends the transaction with `condition`: the incoming file discarded unless delivered,
    /// the Finished PDU owed in class 2 (and in class 1 when closure was requested).
    fn finish<S: Filestore>(&mut self, condition: ConditionCode, store: &mut S) {
        if !self.delivered {
            store.discard(self.id);
        }
        self.condition = condition;
        self.owed.nak = false;
        self.owed.keep_alive = false;
        let closure = self.meta.as_ref().is_some_and(|m| m.closure);
        if self.class2() || closure {
            self.owed.finished = true;
            self.phase = Phase::Finishing;
        } else {
            self.phase = Phase::Ended;
        }
        self.event = Some(Event::Received {
            id: self.id,
            condition,
            delivered: self.delivered,
            name: self
                .meta
                .as_ref()
                .map(|m| m.name.clone())
                .unwrap_or_default(),
        });
    }

    /// The timers at `now`: inactivity, the NAK (or, in class 1, check) timer, the Finished
    /// PDU's ACK timer.
    pub fn tick<S: Filestore>(&mut self, now: u64, cfg: &Config, store: &mut S) {
        match self.phase {
            Phase::Receiving => {
                // Before the EOF, silence is the sender's; after it the receiver asks, and
                // the NAK limit bounds how long.
                let silent = now >= self.heard.saturating_add(u64::from(cfg.inactivity_ms));
                if silent && self.eof.is_none() {
                    return self.fault(ConditionCode::InactivityDetected, cfg, store);
                }
                if self.nak.expired(now) {
                    if !self.class2() {
                        return self.fault(ConditionCode::CheckLimitReached, cfg, store);
                    }
                    if self.nak.count >= cfg.nak_limit {
                        return self.fault(ConditionCode::NakLimitReached, cfg, store);
                    }
                    self.owed.nak = true;
                    self.nak.deadline = None;
                }
            }
            Phase::Finishing => {
                if self.fin.expired(now) {
                    if self.fin.count >= cfg.ack_limit || !self.class2() {
                        self.phase = Phase::Ended;
                        self.owed.finished = false;
                        return;
                    }
                    self.owed.finished = true;
                    self.fin.deadline = None;
                }
            }
            Phase::Ended => {}
        }
    }

    /// The event this transaction reports, once.
    pub fn take_event(&mut self) -> Option<Event> {
        self.event.take()
    }

    /// The next PDU owed to the sender at `now`, if any (the timers it starts started).
    pub fn poll<'s>(
        &mut self,
        now: u64,
        cfg: &Config,
        segments: &'s mut [(u32, u32)],
    ) -> Option<PduRepr<'s>> {
        if core::mem::take(&mut self.owed.ack_eof) {
            return Some(PduRepr::Ack(AckRepr {
                of: DirectiveCode::Eof,
                condition: self.condition_of_eof(),
                status: super::status(self.phase != Phase::Ended),
            }));
        }
        if core::mem::take(&mut self.owed.finished) {
            self.fin = self.fin.restart(now, cfg.ack_timeout_ms);
            return Some(PduRepr::Finished(FinishedRepr {
                condition: self.condition,
                data_complete: self.delivered,
                status: if self.delivered {
                    FileStatus::Retained
                } else {
                    FileStatus::DiscardedDeliberately
                },
                responses: Tlvs::EMPTY,
                fault_location: (self.condition != ConditionCode::NoError).then_some(cfg.local),
            }));
        }
        if core::mem::take(&mut self.owed.nak) {
            self.nak = self.nak.restart(now, cfg.nak_timeout_ms);
            return Some(PduRepr::Nak(self.nak_repr(segments)));
        }
        if core::mem::take(&mut self.owed.keep_alive) {
            return Some(PduRepr::KeepAlive {
                progress: self.got.progress(),
            });
        }
        None
    }

    /// The condition an ACK of EOF echoes: the EOF's (no error unless it canceled).
    fn condition_of_eof(&self) -> ConditionCode {
        match self.eof {
            Some(_) => ConditionCode::NoError,
            None => self.condition,
        }
    }

    /// A NAK of what is missing below the EOF's size (or the highest offset heard), the
    /// Metadata first (`0`–`0`) if it is missing, at most `segments.len()` requests.
    fn nak_repr<'s>(&self, segments: &'s mut [(u32, u32)]) -> NakRepr<'s> {
        let end = self.eof.map_or(self.highest, |(_, size)| size);
        let meta = self.meta.is_none().then_some((0, 0));
        let n = segments
            .iter_mut()
            .zip(meta.into_iter().chain(self.got.gaps(end)))
            .map(|(slot, gap)| *slot = gap)
            .count();
        NakRepr {
            start: 0,
            end,
            segments: Segments::Pairs(segments.get(..n).unwrap_or(&[])),
        }
    }
}

/// The modular checksum of `id`'s incoming file of `size` octets, read back from the store;
/// none if the store has fewer octets.
fn stored_checksum<S: Filestore>(store: &mut S, id: TransactionId, size: u32) -> Option<u32> {
    let mut sum = Modular::new();
    let mut at = 0u32;
    let mut buf = [0u8; 64];
    while at < size {
        let n = store.read_incoming(id, at, &mut buf).ok()?;
        let want = usize::try_from(size.saturating_sub(at)).unwrap_or(usize::MAX);
        let chunk = buf.get(..n.min(want))?;
        if chunk.is_empty() {
            return None;
        }
        sum.add(u64::from(at), chunk);
        at = at.saturating_add(u32::try_from(chunk.len()).unwrap_or(u32::MAX));
    }
    Some(sum.value())
}
