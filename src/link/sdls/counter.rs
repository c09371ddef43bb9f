//! Counters that survive restarts: the sender's next IV and the receiver's anti-replay window,
//! each bounded by a number the shell keeps in durable storage.
//!
//! A GCM IV must never be used twice under one key, and a receiver that forgets its last
//! counter when it restarts accepts a replay of anything it took before. Neither end writes
//! every counter to flash (a write per frame wears it and takes milliseconds); each keeps a
//! durable *reservation* a block of `K` counters ahead of where it is, asks for the next block
//! while half a block is left, and never goes past what was confirmed written:
//!
//! - the sender ([`TxCounter`]) uses an IV only below its durable reservation; after a
//!   restart it continues from the stored reservation, above every IV it may have used;
//! - the receiver ([`ReplayWindow`]) accepts an IV only up to its durable floor; after a
//!   restart it takes the stored floor as its last counter, so every frame it may have
//!   accepted before is now a replay.
//!
//! The shell keeps one number per SPI (a file, flash, memory that survives the simulator's
//! restart): it writes what [`TxCounter::due`] / [`ReplayWindow::due`] ask for and confirms
//! with `persisted` once the write is durable. Nothing is lost by restarting between the two:
//! an unconfirmed reservation is simply never used. The cost of a restart is at most two
//! blocks of counters skipped (the sender) or refused (the receiver: the frames the sender
//! sent below the stored floor; COP-1 sends them again under fresh IVs).
//!
//! ```
//! use mmic::link::sdls::{Iv, ReplayWindow, TxCounter};
//!
//! // A new sender reserves its first block before it sends anything.
//! let mut tx = TxCounter::boot(None, 16);
//! assert!(tx.take().is_err());
//! let block = tx.due().unwrap();
//! assert_eq!(block, 16);
//! tx.persisted(block); // the shell wrote 16 and confirms it
//! assert_eq!(tx.take(), Ok(Iv::ZERO));
//!
//! // After a restart with 16 stored, it continues from 16: IV 0 is never used again.
//! let mut tx = TxCounter::boot(Some(16), 16);
//! tx.persisted(tx.due().unwrap());
//! assert_eq!(tx.take(), Ok(Iv::new(16).unwrap()));
//! ```

use super::iv::{Iv, IV_SPACE};
use super::{SdlsError, SdlsRefusal};

/// Half the counter space: a counter less than this far ahead of the last is "ahead", one this
/// far or further is "behind" (a replay).
const HALF: u128 = IV_SPACE / 2;

/// The sending end's IV counter under a durable reservation.
#[derive(Debug, Clone, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct TxCounter {
    /// The IV the next frame gets (2^96 once every IV is spent).
    next: u128,
    /// Every IV below this may be used: it is written durably.
    reserved: u128,
    /// The reservation's step, K.
    block: u32,
}

impl TxCounter {
    /// The counter at start-up: `stored` is the reservation the shell kept (every IV used
    /// before the restart is below it), `None` for a new security association (it starts at
    /// 0). Nothing may be sent until the first block is reserved ([`TxCounter::due`]).
    pub fn boot(stored: Option<u128>, block: u32) -> TxCounter {
        let next = stored.unwrap_or(0).min(IV_SPACE);
        TxCounter {
            next,
            reserved: next,
            block: block.max(1),
        }
    }

    /// The IV the next frame gets.
    pub fn next(&self) -> u128 {
        self.next
    }

    /// The durable reservation: IVs below it may be used.
    pub fn reserved(&self) -> u128 {
        self.reserved
    }

    /// The reservation to write now, when half a block or less is left (and the counter
    /// space is not spent).
    pub fn due(&self) -> Option<u128> {
        // next <= reserved <= IV_SPACE = 2^96 always (boot, persisted and take keep it), so
        // neither saturating form below saturates in a u128.
        let left = self.reserved.saturating_sub(self.next);
        (left <= u128::from(self.block / 2) && self.reserved < IV_SPACE).then(|| {
            self.reserved
                .saturating_add(u128::from(self.block))
                .min(IV_SPACE)
        })
    }

    /// The shell wrote `value` durably: IVs below it may now be used. A value at or below
    /// the current reservation, or beyond the counter space, changes nothing (`false`).
    pub fn persisted(&mut self, value: u128) -> bool {
        let fresh = value > self.reserved && value <= IV_SPACE;
        if fresh {
            self.reserved = value;
        }
        fresh
    }

    /// The IV for the next frame, which it uses up.
    pub fn take(&mut self) -> Result<Iv, SdlsError> {
        if self.next >= IV_SPACE {
            return Err(SdlsError::CounterExhausted);
        }
        if self.next >= self.reserved {
            return Err(SdlsError::CounterNotReserved {
                next: self.next,
                reserved: self.reserved,
            });
        }
        let iv = Iv::wrapping(self.next);
        // Below IV_SPACE = 2^96 (checked above): far from u128's bound.
        self.next = self.next.saturating_add(1);
        Ok(iv)
    }
}

/// The receiving end's anti-replay window under a durable floor.
///
/// With `last` the last counter accepted and `d` = (IV − last) mod 2^96 (355.0-B-2 §3.3.3:
/// the window is the range of acceptable sequence numbers):
///
/// | d | verdict |
/// |---|---|
/// | 0, or 2^95 and above | [`SdlsRefusal::Replay`]: this counter or an older one |
/// | above the window W | [`SdlsRefusal::TooFarAhead`] |
/// | 1..=W, above the durable floor | [`SdlsRefusal::NotReserved`] (after the MAC is verified) |
/// | 1..=W, at or below the floor | accepted: `last` becomes the IV |
///
/// The arithmetic is modulo 2^96, like YAMCS's `IvSeqNum`, so a sender that wraps is
/// followed; ours never wraps ([`TxCounter`]).
#[derive(Debug, Clone, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct ReplayWindow {
    /// The last IV accepted (2^96 − 1 before the first: 0 is then one ahead).
    last: Iv,
    /// How far ahead of `last` the durable floor is.
    ahead: u128,
    /// How far ahead an authenticated frame wanted to be (a sender that restarted): the next
    /// reservation covers it.
    demand: u128,
    /// W.
    window: u32,
    /// The reservation's step, K.
    block: u32,
}

impl ReplayWindow {
    /// The window at start-up: `stored` is the floor the shell kept (every IV accepted before
    /// the restart is at or below it), `None` for a new security association. Nothing is
    /// accepted until the first block is reserved ([`ReplayWindow::due`]).
    pub fn boot(stored: Option<u128>, window: u32, block: u32) -> ReplayWindow {
        ReplayWindow {
            last: stored.map_or(Iv::MAX, Iv::wrapping),
            ahead: 0,
            demand: 0,
            window: window.max(1),
            block: block.max(1),
        }
    }

    /// The last IV accepted ([`Iv::MAX`] before the first, or the floor after a restart).
    pub fn last(&self) -> Iv {
        self.last
    }

    /// The durable floor: IVs up to it may be accepted.
    pub fn floor(&self) -> Iv {
        self.last.wrapping_add(self.ahead)
    }

    /// W.
    pub fn window(&self) -> u32 {
        self.window
    }

    /// The first check, before any cryptography: replays and counters beyond the window are
    /// refused for nothing.
    pub fn check(&self, iv: Iv) -> Result<(), SdlsRefusal> {
        let d = iv.ahead_of(self.last);
        if d == 0 || d >= HALF {
            return Err(SdlsRefusal::Replay {
                last: self.last.get(),
                found: iv.get(),
            });
        }
        if d > u128::from(self.window) {
            return Err(SdlsRefusal::TooFarAhead {
                last: self.last.get(),
                found: iv.get(),
                window: self.window,
            });
        }
        Ok(())
    }

    /// The last step, for a frame whose MAC verified: accepted if the floor covers it (`last`
    /// moves to it), else refused and the next reservation will cover it.
    pub fn admit(&mut self, iv: Iv) -> Result<(), SdlsRefusal> {
        self.check(iv)?;
        let d = iv.ahead_of(self.last);
        if d > self.ahead {
            self.demand = self.demand.max(d);
            return Err(SdlsRefusal::NotReserved {
                floor: self.floor().get(),
                found: iv.get(),
            });
        }
        self.last = iv;
        // d <= ahead here (checked above).
        self.ahead = self.ahead.saturating_sub(d);
        self.demand = self.demand.saturating_sub(d);
        Ok(())
    }

    /// Right after [`ReplayWindow::boot`], moves `last` back from the stored floor to `iv`,
    /// the last IV accepted before the restart as the shell kept it exactly (it wrote it
    /// before anything of that frame left the board): the IVs between it and the floor were
    /// never accepted, and the sender's next frames are taken at once instead of refused as
    /// replays. Only at or below the durable floor; false (nothing changes) otherwise.
    pub fn resume(&mut self, iv: Iv) -> bool {
        let back = self.floor().ahead_of(iv);
        if back >= HALF {
            return false;
        }
        self.last = iv;
        self.ahead = back;
        true
    }

    /// The floor to write now: when half a block or less is left above `last`, or an
    /// authenticated frame was beyond the floor.
    pub fn due(&self) -> Option<u128> {
        let short = self.ahead <= u128::from(self.block / 2) || self.demand > self.ahead;
        short.then(|| {
            // Both below 2^96 (distances modulo the IV space): the sum cannot saturate.
            let ahead = self
                .ahead
                .max(self.demand)
                .saturating_add(u128::from(self.block))
                .min(HALF - 1);
            self.last.wrapping_add(ahead).get()
        })
    }

    /// The shell wrote `floor` durably. A floor not further ahead than the current one, or
    /// half the counter space ahead or more, changes nothing (`false`).
    pub fn persisted(&mut self, floor: u128) -> bool {
        let Some(floor) = Iv::new(floor) else {
            return false;
        };
        let a = floor.ahead_of(self.last);
        let fresh = a > self.ahead && a < HALF;
        if fresh {
            self.ahead = a;
            if self.demand <= a {
                self.demand = 0;
            }
        }
        fresh
    }
}
