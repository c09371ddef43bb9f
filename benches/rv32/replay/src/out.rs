//! What each call gave back: one output record per trace record, made of named fields, so
//! that two runs can be compared field by field and the first difference named.
//!
//! ```text
//! record  tag:u8 t_ms:u32 len:u16 fields      (tag and t of the trace record it answers)
//! field   id:u8 len:u16 bytes                 (ids: [`Field`]; a field may repeat)
//! ```
//!
//! Numbers are little-endian; texts (events, refusals, errors) are their `Debug` form, which
//! the library derives and which does not depend on the target.
//!
//! ```
//! use mmic_replay::out::{first_difference, Field, RecordWriter};
//! let mut w = RecordWriter::new();
//! let (mut a, mut b) = (Vec::new(), Vec::new());
//! w.begin(1, 10);
//! w.u16(Field::Arm, 1500);
//! w.end(&mut a);
//! w.begin(1, 10);
//! w.u16(Field::Arm, 1501);
//! w.end(&mut b);
//! let d = first_difference(&a, &b).unwrap();
//! assert_eq!((d.index, d.t, d.field), (0, 10, Some(Field::Arm)));
//! ```

use crate::Sink;
use core::fmt::{self, Write};

/// The largest output record, bytes (a gateway loop's reports, or the frame gateway's TM
/// frames: its framer holds 4 KiB of packets, 17 frames of 256 octets; a longer one is cut and
/// says so in [`Field::Truncated`]).
pub const RECORD_MAX: usize = 8192;

macro_rules! fields {
    ($($name:ident = $id:literal, $text:literal;)*) => {
        /// The fields of an output record.
        #[derive(Debug, Clone, Copy, PartialEq, Eq)]
        #[allow(missing_docs)]
        pub enum Field { $($name = $id,)* }

        impl Field {
            /// The field of an id.
            pub const fn from_id(id: u8) -> Option<Field> {
                match id { $($id => Some(Field::$name),)* _ => None }
            }
            /// The field's name in a difference report.
            pub const fn name(self) -> &'static str {
                match self { $(Field::$name => $text,)* }
            }
        }
    };
}

fields! {
    Command = 1, "command taken from the hand-off queue";
    FromB = 2, "internal heartbeat taken from the serial line";
    Hip = 3, "hip pulse (µs, 0: unpowered)";
    Arm = 4, "arm pulse (µs, 0: unpowered)";
    Gripper = 5, "gripper pulse (µs, 0: unpowered)";
    Regulator = 6, "7.4 V regulator";
    Bolter = 7, "bolter drive";
    Mux = 8, "bolter multiplexer lines";
    ToB = 9, "B command sent";
    Heartbeat = 10, "heartbeat made";
    Events = 11, "events";
    EventsLost = 12, "events lost";
    Mode = 13, "mode";
    Faults = 14, "latched faults";
    State = 15, "state";
    InMotion = 16, "in motion";
    HandoffFull = 17, "heartbeat refused by the full hand-off queue";
    InternalHeartbeat = 18, "internal heartbeat made";
    LinkLost = 19, "link to A lost";
    Rejected = 20, "packet refused";
    Queued = 21, "packets queued";
    Sent = 22, "packet written";
    Discarded = 23, "packets discarded";
    Accepted = 24, "server: command accepted";
    Visit = 25, "server: visit (board, command)";
    Report = 26, "server: telemetry packet";
    Refused = 27, "server: packet refused";
    Deadline = 28, "server: next deadline";
    Overflow = 29, "server: reports overflowed";
    Error = 30, "replay error";
    Truncated = 31, "output record cut";
    TcFrame = 32, "server: TC frame (robot, verdict, packets accepted, refused)";
    TmFrame = 33, "server: TM frame";
}

/// Builds one output record at a time (the buffer lives here, not on the stack of the tick
/// being measured).
pub struct RecordWriter {
    buf: [u8; RECORD_MAX],
    len: usize,
    cut: bool,
}

impl Default for RecordWriter {
    fn default() -> Self {
        Self::new()
    }
}

impl RecordWriter {
    /// Empty.
    pub const fn new() -> RecordWriter {
        RecordWriter {
            buf: [0; RECORD_MAX],
            len: 0,
            cut: false,
        }
    }

    /// Starts the record answering trace record `tag` at `t` ms.
    pub fn begin(&mut self, tag: u8, t: u32) {
        self.len = 0;
        self.cut = false;
        self.raw(&[tag]);
        self.raw(&t.to_le_bytes());
        self.raw(&[0, 0]);
    }

    fn raw(&mut self, b: &[u8]) {
        match self.buf.get_mut(self.len..self.len + b.len()) {
            Some(d) => {
                d.copy_from_slice(b);
                self.len += b.len();
            }
            None => self.cut = true,
        }
    }

    /// A field of bytes.
    pub fn bytes(&mut self, f: Field, b: &[u8]) {
        let n = u16::try_from(b.len()).unwrap_or(u16::MAX);
        if self.len + 3 + usize::from(n) > RECORD_MAX - 4 {
            self.cut = true;
            return;
        }
        self.raw(&[f as u8]);
        self.raw(&n.to_le_bytes());
        self.raw(b);
    }

    /// A one-byte field.
    pub fn u8(&mut self, f: Field, v: u8) {
        self.bytes(f, &[v]);
    }

    /// A two-byte field.
    pub fn u16(&mut self, f: Field, v: u16) {
        self.bytes(f, &v.to_le_bytes());
    }

    /// A four-byte field.
    pub fn u32(&mut self, f: Field, v: u32) {
        self.bytes(f, &v.to_le_bytes());
    }

    /// A field holding `v`'s `Debug` text, written in place (the record is cut if it does
    /// not fit).
    pub fn debug(&mut self, f: Field, v: &dyn fmt::Debug) {
        let start = self.len;
        self.raw(&[f as u8, 0, 0]);
        if self.cut {
            return;
        }
        let mut t = Text {
            buf: self
                .buf
                .get_mut(start + 3..RECORD_MAX - 4)
                .unwrap_or(&mut []),
            len: 0,
            full: false,
        };
        let _ = write!(t, "{v:?}");
        let (n, full) = (t.len, t.full);
        self.cut |= full;
        self.len += n;
        let n = u16::try_from(n).unwrap_or(u16::MAX);
        if let Some(l) = self.buf.get_mut(start + 1..start + 3) {
            l.copy_from_slice(&n.to_le_bytes());
        }
    }

    /// Ends the record and writes it to `out`.
    pub fn end(&mut self, out: &mut impl Sink) {
        if self.cut {
            self.cut = false;
            let keep = self.len.min(RECORD_MAX - 4);
            self.len = keep;
            self.raw(&[Field::Truncated as u8, 1, 0, 1]);
        }
        let n = u16::try_from(self.len - 7).unwrap_or(u16::MAX);
        if let Some(l) = self.buf.get_mut(5..7) {
            l.copy_from_slice(&n.to_le_bytes());
        }
        out.put(self.buf.get(..self.len).unwrap_or(&[]));
    }
}

/// Text written into the rest of the record's buffer.
struct Text<'b> {
    buf: &'b mut [u8],
    len: usize,
    full: bool,
}

impl Write for Text<'_> {
    fn write_str(&mut self, s: &str) -> fmt::Result {
        let b = s.as_bytes();
        match self.buf.get_mut(self.len..self.len + b.len()) {
            Some(d) => {
                d.copy_from_slice(b);
                self.len += b.len();
                Ok(())
            }
            None => {
                self.full = true;
                Err(fmt::Error)
            }
        }
    }
}

/// One output record, read back.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct OutRecord<'a> {
    /// The trace record's tag.
    pub tag: u8,
    /// Its time, ms.
    pub t: u32,
    /// The fields' bytes.
    pub fields: &'a [u8],
}

/// The output records of a stream; stops at a record cut short.
pub fn records(mut b: &[u8]) -> impl Iterator<Item = OutRecord<'_>> {
    core::iter::from_fn(move || {
        let (&tag, rest) = b.split_first()?;
        let t = u32::from_le_bytes(rest.get(..4)?.try_into().ok()?);
        let n = u16::from_le_bytes(rest.get(4..6)?.try_into().ok()?);
        let fields = rest.get(6..6 + usize::from(n))?;
        b = rest.get(6 + usize::from(n)..)?;
        Some(OutRecord { tag, t, fields })
    })
}

/// The fields of a record: (id, bytes).
pub fn fields(mut b: &[u8]) -> impl Iterator<Item = (u8, &[u8])> {
    core::iter::from_fn(move || {
        let (&id, rest) = b.split_first()?;
        let n = u16::from_le_bytes(rest.get(..2)?.try_into().ok()?);
        let v = rest.get(2..2 + usize::from(n))?;
        b = rest.get(2 + usize::from(n)..)?;
        Some((id, v))
    })
}

/// Where two output streams first differ.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Difference<'a> {
    /// The record's index (0: the first).
    pub index: usize,
    /// The trace record's tag (of the left stream, or the right one's if the left ended).
    pub tag: u8,
    /// Its time, ms.
    pub t: u32,
    /// The first field that differs (none: the records' shapes differ, or a stream ended).
    pub field: Option<Field>,
    /// The left and right values of that field (empty: absent).
    pub left: &'a [u8],
    /// See `left`.
    pub right: &'a [u8],
}

/// The first difference between two output streams, if any.
pub fn first_difference<'a>(left: &'a [u8], right: &'a [u8]) -> Option<Difference<'a>> {
    let (mut l, mut r) = (records(left), records(right));
    let mut index = 0;
    loop {
        match (l.next(), r.next()) {
            (None, None) => return None,
            (Some(a), Some(b)) if a == b => {}
            (Some(a), Some(b)) if (a.tag, a.t) != (b.tag, b.t) => {
                return Some(Difference {
                    index,
                    tag: a.tag,
                    t: a.t,
                    field: None,
                    left: &[],
                    right: &[],
                })
            }
            (Some(a), Some(b)) => {
                let (mut fa, mut fb) = (fields(a.fields), fields(b.fields));
                loop {
                    match (fa.next(), fb.next()) {
                        (Some(x), Some(y)) if x == y => continue,
                        (x, y) => {
                            let id = x.or(y).map(|(id, _)| id).unwrap_or(0);
                            return Some(Difference {
                                index,
                                tag: a.tag,
                                t: a.t,
                                field: Field::from_id(id),
                                left: x.map(|(_, v)| v).unwrap_or(&[]),
                                right: y.map(|(_, v)| v).unwrap_or(&[]),
                            });
                        }
                    }
                }
            }
            (a, b) => {
                let o = a.or(b);
                return Some(Difference {
                    index,
                    tag: o.map(|o| o.tag).unwrap_or(0),
                    t: o.map(|o| o.t).unwrap_or(0),
                    field: None,
                    left: &[],
                    right: &[],
                });
            }
        }
        index += 1;
    }
}
