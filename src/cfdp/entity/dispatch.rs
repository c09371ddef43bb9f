//! The entity's three calls: a new file to send, a PDU received, the next PDU to send.

use super::{
    decode, header, Config, Entity, Filestore, HandleError, Put, PutError, Receiver, Sender,
    Transaction, TransactionId, DATA_BUF, NAK_SEGMENTS,
};
use crate::cfdp::directive::PduRepr;
use crate::cfdp::header::{Direction, PduHeader};
use crate::cfdp::MAX_PDU_LEN;

impl<const T: usize, const G: usize, const R: usize> Entity<T, G, R> {
    /// Starts sending `put`'s file to entity `dest` at `now`: the transaction. The file's size
    /// is read from `store` now.
    pub fn put<S: Filestore>(
        &mut self,
        now: u64,
        dest: u64,
        put: Put,
        store: &mut S,
    ) -> Result<TransactionId, PutError> {
        if self.tx.is_full() {
            return Err(PutError::Full { capacity: T });
        }
        let octets = self.cfg.lengths.seq;
        let limit = 1u64.checked_shl(u32::from(octets).saturating_mul(8));
        if limit.is_some_and(|l| self.next_seq >= l) {
            return Err(PutError::SeqExhausted { octets });
        }
        let size = store.size(&put.source)?;
        let id = TransactionId {
            source: self.cfg.local,
            seq: self.next_seq,
        };
        let tx = Transaction::Send(Sender::new(id, dest, put, size, now));
        self.tx
            .push(tx)
            .map_err(|_| PutError::Full { capacity: T })?;
        self.next_seq = self.next_seq.saturating_add(1);
        Ok(id)
    }

    /// Takes the PDU in `bytes`, received at `now`. A refused PDU changes nothing but a counter.
    pub fn handle<S: Filestore>(
        &mut self,
        now: u64,
        bytes: &[u8],
        store: &mut S,
    ) -> Result<(), HandleError> {
        let r = self.route(now, bytes, store);
        let c = &mut self.counters;
        let counter = match r {
            Ok(()) => return Ok(()),
            Err(HandleError::Pdu(_)) => &mut c.malformed,
            Err(HandleError::NotOurs { .. }) => &mut c.not_ours,
            Err(HandleError::Ended(_)) => &mut c.ended,
            Err(HandleError::Unknown(_)) => &mut c.unknown,
            Err(HandleError::Full { .. }) => &mut c.full,
        };
        *counter = counter.saturating_add(1);
        r
    }

    fn route<S: Filestore>(
        &mut self,
        now: u64,
        bytes: &[u8],
        store: &mut S,
    ) -> Result<(), HandleError> {
        let (h, repr) = decode(bytes)?;
        let id = TransactionId {
            source: h.source,
            seq: h.seq,
        };
        let local = self.cfg.local;
        let to_receiver = repr.direction() == Direction::TowardReceiver;
        let ours = if to_receiver { h.dest } else { h.source };
        if ours != local {
            return Err(HandleError::NotOurs { local, found: ours });
        }
        let cfg = self.cfg;
        let at = self.tx.iter().position(|t| match t {
            Transaction::Send(s) => !to_receiver && s.id() == id,
            Transaction::Receive(r) => to_receiver && r.id() == id,
        });
        let at = match at {
            Some(at) => at,
            None => self.open(now, &h, &repr, id)?,
        };
        if let Some(t) = self.tx.get_mut(at) {
            match t {
                Transaction::Send(s) => s.handle(now, &repr),
                Transaction::Receive(r) => r.handle(now, &cfg, &repr, store),
            }
        }
        self.collect();
        Ok(())
    }

    /// A new receiving transaction for the first PDU heard of `id`: its place.
    fn open(
        &mut self,
        now: u64,
        h: &PduHeader,
        repr: &PduRepr<'_>,
        id: TransactionId,
    ) -> Result<usize, HandleError> {
        if repr.direction() != Direction::TowardReceiver {
            return Err(HandleError::Unknown(id));
        }
        if self.ended.contains(&id) {
            return Err(HandleError::Ended(id));
        }
        self.tx
            .push(Transaction::Receive(Receiver::new(id, h.mode, now)))
            .map_err(|_| HandleError::Full { capacity: T })?;
        Ok(self.tx.len().saturating_sub(1))
    }

    /// The next PDU to send at `now`, written into `out`: its length. Runs every
    /// transaction's timers first, and takes the transactions in turn. `out` must hold
    /// [`MAX_PDU_LEN`] octets; a shorter one gets nothing and loses nothing.
    pub fn poll<S: Filestore>(&mut self, now: u64, store: &mut S, out: &mut [u8]) -> Option<usize> {
        if out.len() < MAX_PDU_LEN {
            return None;
        }
        let cfg = self.cfg;
        for t in self.tx.iter_mut() {
            match t {
                Transaction::Send(s) => s.tick(now, &cfg),
                Transaction::Receive(r) => r.tick(now, &cfg, store),
            }
        }
        self.collect();
        let n = self.tx.len();
        for k in 0..n {
            let at = self.turn.wrapping_add(k).checked_rem(n).unwrap_or(0);
            if let Some(len) = self.poll_one(at, now, store, out) {
                self.turn = at.wrapping_add(1);
                self.collect();
                return Some(len);
            }
        }
        self.collect();
        None
    }

    /// Transaction `at`'s next PDU, if any, written into `out`.
    fn poll_one<S: Filestore>(
        &mut self,
        at: usize,
        now: u64,
        store: &mut S,
        out: &mut [u8],
    ) -> Option<usize> {
        let cfg: Config = self.cfg;
        let mut data = [0u8; DATA_BUF];
        let mut segments = [(0u32, 0u32); NAK_SEGMENTS];
        let (repr, h) = match self.tx.get_mut(at)? {
            Transaction::Send(s) => {
                let h = header(&cfg, s.mode(), s.id(), s.dest());
                (s.poll(now, &cfg, store, &mut data)?, h)
            }
            Transaction::Receive(r) => {
                let h = header(&cfg, r.mode(), r.id(), cfg.local);
                (r.poll(now, &cfg, &mut segments)?, h)
            }
        };
        repr.emit(&h, out).ok()
    }

    /// Moves each transaction's end into the events, and forgets the transactions that owe
    /// nothing more (remembering their IDs).
    fn collect(&mut self) {
        for t in self.tx.iter_mut() {
            if self.events.is_full() {
                break;
            }
            let e = match t {
                Transaction::Send(s) => s.take_event(),
                Transaction::Receive(r) => r.take_event(),
            };
            if let Some(e) = e {
                let _ = self.events.push(e);
            }
        }
        let ended = &mut self.ended;
        self.tx.retain(|t| {
            let (done, id) = match t {
                Transaction::Send(s) => (s.is_ended(), s.id()),
                Transaction::Receive(r) => (r.is_ended(), r.id()),
            };
            if done {
                if ended.is_full() {
                    ended.remove(0);
                }
                let _ = ended.push(id);
            }
            !done
        });
    }
}
