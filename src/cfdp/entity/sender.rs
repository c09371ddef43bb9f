//! The sending side of one transaction (727.0-B-5 §4.6, class 1 and class 2): the Metadata,
//! the file in file data PDUs of at most the configured size, read from the store as they go
//! (the checksum summed on the way), the EOF; in class 2 the EOF repeated until acknowledged
//! or the positive ACK limit is reached, the octets (and the Metadata) a NAK asks for sent
//! again, and the Finished PDU acknowledged. Silence for the inactivity timeout while waiting
//! for the Finished PDU ends the transaction with that fault.

use super::{Config, Event, FaultHandler, Filestore, Timer, TransactionId, NAME_MAX};
use crate::cfdp::checksum::Modular;
use crate::cfdp::codes::{ConditionCode, DirectiveCode};
use crate::cfdp::directive::{AckRepr, EofRepr, FileDataRepr, MetadataRepr, PduRepr};
use crate::cfdp::header::Mode;
use crate::cfdp::tlv::Tlvs;
use heapless::Vec;

/// Where the sender stands.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
enum Phase {
    /// Sending the Metadata and the file's first pass.
    Sending,
    /// EOF sent (class 2: waiting for its ACK, then for the Finished PDU; class 1 with closure:
    /// for the Finished PDU).
    Waiting,
    /// A fault found here, its handler cancel: the EOF with the fault's condition sent (in
    /// class 2 until acknowledged or the positive ACK limit is reached).
    Cancelling,
    /// Done: nothing more to send.
    Ended,
}

/// A file to send.
#[derive(Debug, Clone, PartialEq, Eq, Hash)]
pub struct Put {
    /// Its name in the sender's store.
    pub source: Vec<u8, NAME_MAX>,
    /// Its name at the receiver.
    pub dest: Vec<u8, NAME_MAX>,
    /// Class 2 (acknowledged) or class 1.
    pub mode: Mode,
    /// Class 1: ask the receiver for a Finished PDU.
    pub closure: bool,
}

impl Put {
    /// A file `source` to send as `dest` in `mode` (no closure asked in class 1); none if a
    /// name is longer than [`NAME_MAX`].
    pub fn new(source: &[u8], dest: &[u8], mode: Mode) -> Option<Put> {
        Some(Put {
            source: Vec::from_slice(source).ok()?,
            dest: Vec::from_slice(dest).ok()?,
            mode,
            closure: false,
        })
    }
}

/// One transaction's sending side, keeping at most `R` ranges a NAK asked for.
#[derive(Debug, Clone, PartialEq, Eq, Hash)]
pub struct Sender<const R: usize> {
    id: TransactionId,
    dest: u64,
    put: Put,
    size: u32,
    sent: u32,
    sum: Modular,
    metadata: bool,
    resend: Vec<(u32, u32), R>,
    eof: bool,
    eof_acked: bool,
    ack_finished: bool,
    phase: Phase,
    condition: ConditionCode,
    heard: u64,
    timer: Timer,
    event: Option<Event>,
}

impl<const R: usize> Sender<R> {
    /// A transaction sending a file of `size` octets to entity `dest`, begun at `now`.
    pub fn new(id: TransactionId, dest: u64, put: Put, size: u32, now: u64) -> Self {
        Sender {
            id,
            dest,
            put,
            size,
            sent: 0,
            sum: Modular::new(),
            metadata: true,
            resend: Vec::new(),
            eof: false,
            eof_acked: false,
            ack_finished: false,
            phase: Phase::Sending,
            condition: ConditionCode::NoError,
            heard: now,
            timer: Timer::IDLE,
            event: None,
        }
    }

    /// The transaction.
    pub const fn id(&self) -> TransactionId {
        self.id
    }

    /// The receiving entity.
    pub const fn dest(&self) -> u64 {
        self.dest
    }

    /// The transmission mode.
    pub const fn mode(&self) -> Mode {
        self.put.mode
    }

    /// Whether it has ended and owes nothing more.
    pub fn is_ended(&self) -> bool {
        self.phase == Phase::Ended && self.event.is_none() && !self.ack_finished
    }

    /// Takes a PDU of this transaction (toward the sender) received at `now`.
    pub fn handle(&mut self, now: u64, repr: &PduRepr<'_>) {
        self.heard = now;
        match repr {
            PduRepr::Ack(a) if a.of == DirectiveCode::Eof && self.eof && !self.eof_acked => {
                self.eof_acked = true;
                self.timer = Timer::IDLE;
                if self.phase == Phase::Cancelling {
                    self.phase = Phase::Ended;
                }
            }
            PduRepr::Nak(n)
                if matches!(self.phase, Phase::Sending | Phase::Waiting)
                    && self.put.mode == Mode::Acknowledged =>
            {
                for (start, end) in n.segments.iter() {
                    self.ask(start, end);
                }
            }
            PduRepr::Finished(_) if self.phase == Phase::Cancelling => {
                // The receiver ended too: acknowledged, the fault already reported.
                self.ack_finished = self.put.mode == Mode::Acknowledged;
                self.phase = Phase::Ended;
            }
            PduRepr::Finished(f) if self.phase != Phase::Ended => {
                self.ack_finished = self.put.mode == Mode::Acknowledged;
                self.end(f.condition);
            }
            PduRepr::Finished(_) => {
                // Our ACK was lost: acknowledge again.
                self.ack_finished = self.put.mode == Mode::Acknowledged;
            }
            _ => {}
        }
    }

    /// Queues octets `start..end` to send again (`0`–`0`: the Metadata); a request beyond
    /// the file is cut to it, one the queue cannot hold waits for the next NAK.
    fn ask(&mut self, start: u32, end: u32) {
        if (start, end) == (0, 0) {
            self.metadata = true;
            return;
        }
        let end = end.min(self.size);
        if start < end && !self.resend.contains(&(start, end)) {
            let _ = self.resend.push((start, end));
        }
    }

    fn end(&mut self, condition: ConditionCode) {
        self.condition = condition;
        self.phase = Phase::Ended;
        self.resend.clear();
        self.timer = Timer::IDLE;
        self.event = Some(Event::Sent {
            id: self.id,
            condition,
        });
    }

    /// A fault found here: reported at once, then the transaction ends as its handler says
    /// (`Config::handlers`): cancel, the receiver told by an EOF with the condition; abandon,
    /// nothing more sent.
    fn fault(&mut self, condition: ConditionCode, cfg: &Config) {
        self.end(condition);
        if cfg.handlers.handler(condition) == FaultHandler::Cancel {
            self.phase = Phase::Cancelling;
            self.eof = false;
            self.eof_acked = false;
            self.metadata = false;
        }
    }

    /// The timers at `now`: the EOF's ACK timer, and inactivity while waiting.
    pub fn tick(&mut self, now: u64, cfg: &Config) {
        let waiting = self.phase == Phase::Waiting;
        if !waiting && self.phase != Phase::Cancelling {
            return;
        }
        if self.timer.expired(now) && !self.eof_acked {
            if self.timer.count < cfg.ack_limit {
                self.eof = false;
                self.timer.deadline = None;
            } else if waiting {
                return self.fault(ConditionCode::PositiveAckLimitReached, cfg);
            } else {
                // A notice of cancellation unacknowledged: abandoned.
                self.phase = Phase::Ended;
            }
        }
        if waiting && now >= self.heard.saturating_add(u64::from(cfg.inactivity_ms)) {
            self.fault(ConditionCode::InactivityDetected, cfg);
        }
    }

    /// The event this transaction reports, once.
    pub fn take_event(&mut self) -> Option<Event> {
        self.event.take()
    }

    /// The next PDU to send at `now`, if any; file data is read into `buf` (at most
    /// `cfg.file_data` octets a PDU). A store that fails ends the transaction.
    pub fn poll<'b, S: Filestore>(
        &mut self,
        now: u64,
        cfg: &Config,
        store: &mut S,
        buf: &'b mut [u8],
    ) -> Option<PduRepr<'b>> {
        if core::mem::take(&mut self.ack_finished) {
            return Some(PduRepr::Ack(AckRepr {
                of: DirectiveCode::Finished,
                condition: self.condition,
                status: super::status(false),
            }));
        }
        match self.phase {
            Phase::Ended => return None,
            Phase::Cancelling => return self.cancel_eof(now, cfg),
            Phase::Sending | Phase::Waiting => {}
        }
        if core::mem::take(&mut self.metadata) {
            // The names copied into `buf`, which the PDU borrows.
            let (source, rest) = buf.split_at_mut_checked(self.put.source.len())?;
            source.copy_from_slice(&self.put.source);
            let dest = rest.get_mut(..self.put.dest.len())?;
            dest.copy_from_slice(&self.put.dest);
            return Some(PduRepr::Metadata(MetadataRepr {
                closure_requested: self.put.closure,
                checksum: cfg.checksum,
                file_size: self.size,
                source,
                dest,
                options: Tlvs::EMPTY,
            }));
        }
        let chunk = buf.len().min(usize::from(cfg.file_data));
        if let Some(&(start, end)) = self.resend.first() {
            return self.data(start, end, chunk, (cfg, store), buf, false);
        }
        if self.sent < self.size {
            return self.data(self.sent, self.size, chunk, (cfg, store), buf, true);
        }
        if !self.eof && self.phase != Phase::Ended {
            self.eof = true;
            self.timer = self.timer.restart(now, cfg.ack_timeout_ms);
            self.phase = Phase::Waiting;
            let eof = PduRepr::Eof(EofRepr {
                condition: ConditionCode::NoError,
                checksum: self.checksum(cfg),
                file_size: self.size,
                fault_location: None,
            });
            if self.put.mode == Mode::Unacknowledged && !self.put.closure {
                self.end(ConditionCode::NoError);
            }
            return Some(eof);
        }
        None
    }

    /// The notice of cancellation: an EOF with the fault's condition, the checksum and size
    /// of what was sent, and this entity as the fault location; once, and in class 2 again
    /// each ACK timeout up to the positive ACK limit ([`Sender::tick`]).
    fn cancel_eof<'b>(&mut self, now: u64, cfg: &Config) -> Option<PduRepr<'b>> {
        if self.eof {
            return None;
        }
        self.eof = true;
        self.timer = self.timer.restart(now, cfg.ack_timeout_ms);
        if self.put.mode == Mode::Unacknowledged {
            self.phase = Phase::Ended;
        }
        Some(PduRepr::Eof(EofRepr {
            condition: self.condition,
            checksum: self.checksum(cfg),
            file_size: self.sent,
            fault_location: Some(cfg.local),
        }))
    }

    /// The checksum an EOF carries: of the octets sent so far (0 with the null checksum).
    fn checksum(&self, cfg: &Config) -> u32 {
        if cfg.checksum == crate::cfdp::codes::ChecksumType::NULL {
            0
        } else {
            self.sum.value()
        }
    }

    /// File data from `start` (before `end`), at most `chunk` octets read into `buf`; on the
    /// first pass the checksum takes them.
    fn data<'b, S: Filestore>(
        &mut self,
        start: u32,
        end: u32,
        chunk: usize,
        (cfg, store): (&Config, &mut S),
        buf: &'b mut [u8],
        first: bool,
    ) -> Option<PduRepr<'b>> {
        let want = usize::try_from(end.saturating_sub(start)).map_or(chunk, |w| w.min(chunk));
        let dst = buf.get_mut(..want)?;
        let n = match store.read(&self.put.source, start, dst) {
            Ok(n) if n > 0 => n,
            _ => {
                self.fault(ConditionCode::FilestoreRejection, cfg);
                return None;
            }
        };
        let data = buf.get(..n)?;
        let next = start.saturating_add(u32::try_from(n).unwrap_or(u32::MAX));
        if first {
            self.sum.add(u64::from(start), data);
            self.sent = next;
        } else if let Some(r) = self.resend.first_mut() {
            if next >= r.1 {
                self.resend.remove(0);
            } else {
                r.0 = next;
            }
        }
        Some(PduRepr::FileData(FileDataRepr {
            offset: start,
            data,
        }))
    }
}
