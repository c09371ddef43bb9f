//! Property harnesses for `mmic`, in the bolero pattern of the project's brief: each `#[test]`
//! in `tests/` is a randomised unit test under `cargo test`, a coverage-guided fuzz target under
//! `cargo bolero test`, and a bounded proof under `cargo kani --tests` (where Kani is installed;
//! it is not on the development machines, so no Kani result is claimed anywhere in this crate).
//!
//! This library holds what the harnesses (and the fuzz targets of `mmic-fuzz`) share: an
//! *oracle* for the framing checks written from the definitions, independently of the library
//! (a bitwise CRC-16/CCITT-FALSE, not the `crc` crate's table), and the properties themselves as
//! plain functions that panic when a property fails. Keeping the properties here means the
//! test, the fuzz target and the proof check the very same statement.
//!
//! ```
//! use mmic::wire::command::CommandRepr;
//! use mmic::wire::Repr;
//! use mmic_proofs::{check_parse, crc16_bitwise};
//!
//! assert_eq!(crc16_bitwise(b"123456789"), 0x29b1); // the CRC-16/CCITT-FALSE check value
//!
//! // Checks every documented verdict; returns whether the bytes were accepted.
//! assert!(!check_parse::<CommandRepr>(&[0; 3])); // refused by the length check
//! assert!(!check_parse::<CommandRepr>(b"MICM\x01\x02\0\0\0\0\0\0\0\0")); // checksum
//! let stop = mmic::wire::command::CommandRepr {
//!     board: mmic::units::BoardNumber::ONE,
//!     command: mmic::command::Command::Stop,
//!     seq: 0,
//! };
//! assert!(check_parse::<CommandRepr>(&Repr::to_bytes(&stop))); // accepted, canonical
//! ```
#![no_std]
#![forbid(unsafe_code)]
#![deny(missing_docs)]

pub mod ccsds;
pub mod cfdp;
pub mod link;
pub mod link_cop;
pub mod link_tm;
pub mod pus;
pub mod sdls;
pub mod store;

use core::fmt::Debug;
use mmic::arbitrary::for_each_variant_class;
use mmic::bolter::{BolterDirection, BolterStep, MuxLines};
use mmic::command::{BolterPair, Command, PrimitiveMove, ServoTarget};
use mmic::control::interp::Travel;
use mmic::faults::Faults;
use mmic::mode::Mode;
use mmic::motion::State;
use mmic::refusal::Refusal;
use mmic::units::{Axis, BoardNumber, Electrical, Gravity, HipAngle, PulseWidth, Sign};
use mmic::wire::b_command::{BCommandRepr, BPower, BolterOrder};
use mmic::wire::command::CommandRepr;
use mmic::wire::deframer::{Deframed, Deframer, Frame};
use mmic::wire::heartbeat::BolterAttempt;
use mmic::wire::heartbeat::HeartbeatRepr;
use mmic::wire::internal_heartbeat::BolterAux;
use mmic::wire::internal_heartbeat::InternalHeartbeatRepr;
pub use mmic::wire::Repr;
use mmic::wire::{PacketKind, WireError, CHECKSUM_LEN, HEADER_LEN, MAX_PACKET_LEN};

/// CRC-16/CCITT-FALSE (poly 0x1021, init 0xFFFF, no reflection, no final xor), one bit at a
/// time straight from the definition: the independent oracle for the library's table-driven CRC.
///
/// Each bit: the register shifts left, and the polynomial is xored in when the bit shifted out
/// was set (`0u16.wrapping_sub(crc >> 15)` is all ones then, zero otherwise). Written without a
/// branch or an inner loop, so that CI's instrumented run counts each octet once rather than
/// each bit's branch: the `if` form spent half of the TM harnesses' time in coverage counters
/// (issue 40), for the same values.
pub fn crc16_bitwise(bytes: &[u8]) -> u16 {
    macro_rules! bit {
        ($crc:ident) => {
            $crc = ($crc << 1) ^ (0x1021 & 0u16.wrapping_sub($crc >> 15))
        };
    }
    let mut crc: u16 = 0xffff;
    for &b in bytes {
        crc ^= (b as u16) << 8;
        bit!(crc);
        bit!(crc);
        bit!(crc);
        bit!(crc);
        bit!(crc);
        bit!(crc);
        bit!(crc);
        bit!(crc);
    }
    crc
}

/// Writes `kind`'s header into the first four bytes and the checksum of the rest into the last
/// two, computed with [`crc16_bitwise`]. `packet` must be `kind.len()` bytes long.
pub fn seal(kind: PacketKind, packet: &mut [u8]) {
    assert_eq!(packet.len(), kind.len(), "seal: wrong length");
    let n = packet.len();
    packet[..HEADER_LEN].copy_from_slice(&kind.header());
    let crc = crc16_bitwise(&packet[..n - CHECKSUM_LEN]);
    packet[n - CHECKSUM_LEN..].copy_from_slice(&crc.to_le_bytes());
}

/// What the framing checks must report for some bytes, worked out by the oracle in the
/// documented order: length, then header, then checksum.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Framing {
    /// Wrong length.
    Length {
        /// Bytes given.
        found: usize,
    },
    /// Right length, wrong header.
    Header {
        /// Bytes 0–3.
        found: [u8; HEADER_LEN],
    },
    /// Right length and header, checksum disagrees.
    Checksum {
        /// Last two bytes, little-endian.
        carried: u16,
        /// [`crc16_bitwise`] of the others.
        computed: u16,
    },
    /// Length, header and checksum hold: only the field checks remain.
    Sound,
}

/// The oracle's verdict on `bytes` as a `kind` packet.
pub fn framing(kind: PacketKind, bytes: &[u8]) -> Framing {
    if bytes.len() != kind.len() {
        return Framing::Length { found: bytes.len() };
    }
    let mut found = [0u8; HEADER_LEN];
    found.copy_from_slice(&bytes[..HEADER_LEN]);
    if found != kind.header() {
        return Framing::Header { found };
    }
    let (body, crc) = bytes.split_at(bytes.len() - CHECKSUM_LEN);
    let carried = u16::from_le_bytes([crc[0], crc[1]]);
    let computed = crc16_bitwise(body);
    if carried != computed {
        return Framing::Checksum { carried, computed };
    }
    Framing::Sound
}

/// A valid value of any packet, built from arbitrary bytes (see [`Seed`]): the one thing the
/// harnesses need beyond the library's [`Repr`], so that each property is written once.
pub trait Sample: Repr {
    /// A valid value built from arbitrary bytes.
    fn sample(seed: &mut Seed<'_>) -> Self;
}

macro_rules! sample {
    ($($t:ty => $sample:ident;)*) => {$(
        impl Sample for $t {
            fn sample(seed: &mut Seed<'_>) -> Self {
                $sample(seed)
            }
        }
    )*};
}

sample! {
    CommandRepr => sample_command;
    HeartbeatRepr => sample_heartbeat;
    InternalHeartbeatRepr => sample_internal_heartbeat;
    BCommandRepr => sample_b_command;
}

/// Arbitrary bytes read as the choices that build a valid value: every byte is folded into
/// its field's domain (a pulse width is `500 + raw % 2001`, an optional pair is none for
/// `raw % 5 == 0`, …), and reading past the end yields zeros. Bolero's byte-level engines
/// rarely produce whole valid packets by chance (none in 200,000 random bodies of any packet
/// type, measured), so the harnesses that need valid packets build them from a `Seed`; every
/// valid value is reachable, which keeps the harnesses complete under Kani.
#[derive(Debug, Clone)]
pub struct Seed<'a> {
    bytes: &'a [u8],
    at: usize,
}

impl<'a> Seed<'a> {
    /// Choices read from `bytes`.
    pub fn new(bytes: &'a [u8]) -> Self {
        Seed { bytes, at: 0 }
    }

    /// Next byte (0 when exhausted).
    pub fn u8(&mut self) -> u8 {
        let b = self.bytes.get(self.at).copied().unwrap_or(0);
        self.at += 1;
        b
    }

    /// Next two bytes, little-endian.
    pub fn u16(&mut self) -> u16 {
        u16::from_le_bytes([self.u8(), self.u8()])
    }

    /// Next bit of choice.
    pub fn bool(&mut self) -> bool {
        self.u8() & 1 != 0
    }

    /// One of `all`.
    pub fn pick<T: Copy>(&mut self, all: &[T]) -> T {
        all[self.u8() as usize % all.len()]
    }

    /// A pulse width in 500..=2500 µs.
    pub fn pulse(&mut self) -> PulseWidth {
        let span = PulseWidth::MAX_US - PulseWidth::MIN_US + 1;
        PulseWidth::new(PulseWidth::MIN_US + self.u16() % span).expect("in range")
    }

    /// A hip angle in 0..36000 centidegrees.
    pub fn angle(&mut self) -> HipAngle {
        HipAngle::new(self.u16() % HipAngle::TURN).expect("in range")
    }

    /// Any voltages and currents.
    pub fn electrical(&mut self) -> Electrical {
        Electrical {
            v_bat: self.u16(),
            i_bat: self.u16(),
            i_loc: self.u16(),
            i_grip: self.u16(),
            i_3v3: self.u16(),
            v_reg: self.u16(),
            i_bo: self.u16(),
        }
    }

    /// No pair (one choice in five) or a pair.
    pub fn pair(&mut self) -> Option<BolterPair> {
        BolterPair::from_number(self.u8() % 5)
    }

    /// Any command: one of the 61 opcode classes, with sampled parameters (a primitive's final
    /// state among those it reaches).
    pub fn command(&mut self) -> Command {
        let class = self.u8() as usize % 61;
        let (pw, angle) = (self.pulse(), self.angle());
        let (initial, target) = (self.pick(&State::ALL), self.pick(&State::MATCHED));
        let mut chosen = Command::Heartbeat;
        let mut i = 0;
        for_each_variant_class(pw, angle, |c| {
            if i == class {
                chosen = c;
            }
            i += 1;
        });
        // An arm or gripper position within its module's travel (the commands refuse others):
        // the sampled pulse folded into it.
        let fit = |travel: Travel| {
            let (min, max) = (travel.min().micros(), travel.max().micros());
            let off = (pw.micros() - PulseWidth::MIN_US) % (max - min + 1);
            ServoTarget::Position(PulseWidth::new(min + off).expect("within the travel"))
        };
        match chosen {
            Command::Arm {
                side,
                target: ServoTarget::Position(_),
            } => {
                chosen = Command::Arm {
                    side,
                    target: fit(Travel::ARM),
                }
            }
            Command::Gripper {
                side,
                target: ServoTarget::Position(_),
            } => {
                chosen = Command::Gripper {
                    side,
                    target: fit(Travel::GRIPPER),
                }
            }
            _ => {}
        }
        if let Command::Primitive(m) = chosen {
            // Any final state the primitive reaches (3 for primitives 1-4, 12 for 5-8).
            let of_p = || PrimitiveMove::all().filter(move |o| o.primitive() == m.primitive());
            let i = self.u8() as usize % of_p().count().max(1);
            chosen = Command::Primitive(of_p().nth(i).unwrap_or(m));
        }
        if let Command::Reconfigure(_) = chosen {
            // Any matched target other than the initial state.
            let target = if target == initial {
                State::MATCHED[(target.index() + 1) % State::MATCHED.len()]
            } else {
                target
            };
            chosen = Command::reconfigure(initial, target).expect("valid reconfiguration");
        }
        chosen
    }
}

fn sample_command(s: &mut Seed<'_>) -> CommandRepr {
    CommandRepr {
        board: BoardNumber::new(1 + s.u8() % 255).expect("1..=255"),
        command: s.command(),
        seq: s.u16(),
    }
}

fn sample_heartbeat(s: &mut Seed<'_>) -> HeartbeatRepr {
    HeartbeatRepr {
        board: BoardNumber::new(1 + s.u8() % 255).expect("1..=255"),
        hip_target: s.angle(),
        hip_now: s.angle(),
        arm_a_target: s.pulse(),
        arm_a_now: s.pulse(),
        arm_b_target: s.pulse(),
        arm_b_now: s.pulse(),
        gripper_a_target: s.pulse(),
        gripper_a_now: s.pulse(),
        gripper_b_target: s.pulse(),
        gripper_b_now: s.pulse(),
        electrical_a: s.electrical(),
        electrical_b: s.electrical(),
        target_state: State::from_index(s.u8() as usize % 16),
        command_complete: s.bool(),
        active_bolter: s.pair(),
        bolter_attempt: BolterAttempt::new(s.u8() % 4).expect("0..=3"),
        faults: {
            let raw = s.u16() as u32 & Faults::DEFINED;
            Faults::from_wire([raw as u8, (raw >> 8) as u8]).expect("defined bits")
        },
        // 0 (accepted) or any refusal code.
        refusal: Refusal::from_wire(s.u8() % (Refusal::ALL.len() as u8 + 1)),
        mode: s.pick(&Mode::ALL),
        last_seq: s.u16(),
        boot: mmic::restart::Boot::from_wire(s.u8()),
    }
}

fn sample_internal_heartbeat(s: &mut Seed<'_>) -> InternalHeartbeatRepr {
    InternalHeartbeatRepr {
        arm_b_target: s.pulse(),
        arm_b_now: s.pulse(),
        gripper_b_target: s.pulse(),
        gripper_b_now: s.pulse(),
        electrical_b: s.electrical(),
        bolter_aux: BolterAux {
            step: BolterStep::from_wire(s.u8() % 9),
            seq: s.u8(),
            pair: s.pair(),
            direction: BolterDirection::from_wire(s.u8() % 3),
            threshold_reached: s.bool(),
            locked: s.bool(),
            timed_out: s.bool(),
            at_home: s.bool(),
            mux: MuxLines::from_wire(s.u8() & 0b11).expect("two lines"),
        },
        command_received: s.u8(),
        gravity: match s.u8() % 7 {
            0 => None,
            k => Some(Gravity {
                axis: Axis::ALL[(k as usize - 1) % 3],
                sign: if k <= 3 {
                    Sign::Positive
                } else {
                    Sign::Negative
                },
            }),
        },
        arm_over_idle: s.bool(),
        gripper_over_idle: s.bool(),
        bolter_over_idle: s.bool(),
        arm_overcurrent: s.bool(),
        gripper_overcurrent: s.bool(),
        bolter_overcurrent: s.bool(),
        arm_contracted: s.bool(),
    }
}

fn sample_b_command(s: &mut Seed<'_>) -> BCommandRepr {
    BCommandRepr {
        seq: s.u8(),
        power: BPower {
            regulator: s.bool(),
            arm: s.bool(),
            gripper: s.bool(),
            bolter: s.bool(),
        },
        stop: s.bool(),
        arm_target: s.pulse(),
        gripper_target: s.pulse(),
        bolter: match s.bool() {
            false => None,
            true => Some(BolterOrder {
                pair: s.pick(&BolterPair::ALL),
                direction: s.pick(&[BolterDirection::Bolt, BolterDirection::Unbolt]),
                step: s.pick(&BolterStep::ALL),
            }),
        },
    }
}

/// Property of every parser, for any bytes: `parse` returns (never panics) and
///
/// * refuses exactly as the oracle says when length, header or checksum is wrong, with the
///   documented numbers (expected and found length, header, carried and computed checksum),
///   checking in the order length → header → checksum;
/// * otherwise either refuses with a field or command error, or accepts, and then the value is
///   canonical: `emit(parse(b)) == b` and `parse(emit(parse(b))) == parse(b)`.
///
/// Returns whether `bytes` were accepted.
pub fn check_parse<R: Repr>(bytes: &[u8]) -> bool {
    let kind = R::KIND;
    let got = R::parse(bytes);
    match framing(kind, bytes) {
        Framing::Length { found } => assert_eq!(
            got,
            Err(WireError::Length {
                kind,
                expected: R::LEN,
                found
            })
        ),
        Framing::Header { found } => assert_eq!(
            got,
            Err(WireError::Header {
                kind,
                expected: kind.header(),
                found
            })
        ),
        Framing::Checksum { carried, computed } => assert_eq!(
            got,
            Err(WireError::Checksum {
                kind,
                carried,
                computed
            })
        ),
        Framing::Sound => match got {
            Ok(repr) => {
                let again = repr.to_bytes();
                assert_eq!(again.as_ref(), bytes, "emit(parse(b)) != b for {repr:?}");
                assert_eq!(R::parse(again.as_ref()), Ok(repr));
                return true;
            }
            Err(e) => assert!(
                matches!(e, WireError::Field { .. } | WireError::Command(_)),
                "sound framing refused by the {} check: {e:?}",
                e.check()
            ),
        },
    }
    false
}

/// Property of every parser, for any body: `body` (its first `R::LEN` bytes, zero-padded) with
/// the right header and a correct checksum written over it is sound framing, so `parse` either
/// accepts it canonically or refuses it on a field or command check — never on length, header
/// or checksum. Returns whether it was accepted.
pub fn check_round_trip<R: Repr>(body: &[u8]) -> bool {
    let mut buf = [0u8; MAX_PACKET_LEN];
    let n = body.len().min(R::LEN);
    buf[..n].copy_from_slice(&body[..n]);
    let packet = &mut buf[..R::LEN];
    seal(R::KIND, packet);
    assert_eq!(framing(R::KIND, packet), Framing::Sound);
    check_parse::<R>(packet)
}

/// Property of every `Repr`, for any seed and edits: the value `R::sample(seed)` survives
/// `parse(emit(x)) == x` (and its bytes pass [`check_parse`] as accepted); then each
/// `(position, value)` pair of `edits` overwrites one body byte (header and checksum excluded),
/// the checksum is rewritten, and the near miss must pass [`check_parse`]: accepted
/// canonically, or refused by a field or command check. Returns whether the edited packet was
/// accepted.
pub fn check_round_trip_near_valid<R: Sample>(seed: &[u8], edits: &[[u8; 2]]) -> bool {
    let repr = R::sample(&mut Seed::new(seed));
    let bytes = repr.to_bytes();
    assert_eq!(R::parse(bytes.as_ref()), Ok(repr), "parse(emit(x)) != x");
    assert!(check_parse::<R>(bytes.as_ref()));
    let mut buf = [0u8; MAX_PACKET_LEN];
    buf[..R::LEN].copy_from_slice(bytes.as_ref());
    let body = R::LEN - HEADER_LEN - CHECKSUM_LEN;
    for [at, value] in edits {
        buf[HEADER_LEN + *at as usize % body] = *value;
    }
    check_round_trip::<R>(&buf[..R::LEN])
}

/// [`check_parse`] for the packet type `kind`.
pub fn check_parse_kind(kind: PacketKind, bytes: &[u8]) -> bool {
    match kind {
        PacketKind::Command => check_parse::<CommandRepr>(bytes),
        PacketKind::Heartbeat => check_parse::<HeartbeatRepr>(bytes),
        PacketKind::InternalHeartbeat => check_parse::<InternalHeartbeatRepr>(bytes),
        PacketKind::BCommand => check_parse::<BCommandRepr>(bytes),
    }
}

/// What a deframer run saw.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct DeframerRun {
    /// Bytes pushed (the whole stream).
    pub pushed: usize,
    /// Bytes reported in `Discarded` events.
    pub discarded: usize,
    /// Frames delivered.
    pub frames: usize,
    /// Bytes in delivered frames.
    pub frame_bytes: usize,
}

/// Size of the `i`-th chunk under chunk plan `plan`: 1..=70 bytes (more than the smallest legal
/// buffer, so that `push` also takes partial chunks); the whole stream when `plan` is empty.
pub fn chunk_len(plan: &[u8], i: usize, rest: usize) -> usize {
    match plan.len() {
        0 => rest,
        n => 1 + plan[i % n] as usize % 70,
    }
}

/// Feeds `stream` to a `Deframer<N>` in the chunks `plan` gives, polls after every push, then
/// calls `resync` until it returns `None`, and checks on the way:
///
/// * conservation after every call: bytes pushed = bytes discarded + bytes in frames + bytes
///   buffered; `Discarded` events add up to `discarded_total()`, frames to `frames_total()`;
/// * every `Discarded(n)` has `n > 0`;
/// * every frame is what the stream holds at its offset (the bytes consumed before it),
///   byte for byte, and passes the oracle's framing checks for its kind;
/// * no packet is lost: every offset at which the stream holds a packet with sound framing
///   (a header, then that packet's length of bytes whose checksum holds) is either delivered
///   as a frame or lies inside a frame delivered before it;
/// * at the end nothing is buffered: every byte was discarded or delivered.
///
/// `on_frame(offset, frame)` sees each frame with its stream offset.
pub fn run_deframer<const N: usize>(
    stream: &[u8],
    plan: &[u8],
    mut on_frame: impl FnMut(usize, &Frame),
) -> DeframerRun {
    let mut d = Deframer::<N>::new();
    let mut run = DeframerRun::default();
    // Stream offsets before this one are delivered or checked to hold no packet.
    let mut covered = 0;
    let mut event = |e: Deframed, d: &Deframer<N>, run: &mut DeframerRun| {
        match e {
            Deframed::Discarded(n) => {
                assert!(n > 0, "empty discard");
                run.discarded += n;
            }
            Deframed::Frame(f) => {
                let offset = run.discarded + run.frame_bytes;
                let bytes = f.as_bytes();
                assert_eq!(bytes.len(), f.kind().len());
                assert_eq!(framing(f.kind(), bytes), Framing::Sound);
                assert_eq!(Some(bytes), stream.get(offset..offset + bytes.len()));
                assert_no_packet_in(stream, covered..offset);
                covered = offset + bytes.len();
                on_frame(offset, &f);
                run.frames += 1;
                run.frame_bytes += bytes.len();
            }
        }
        assert_eq!(d.discarded_total(), run.discarded as u64);
        assert_eq!(d.frames_total(), run.frames as u64);
        assert_eq!(run.pushed, run.discarded + run.frame_bytes + d.buffered());
    };
    let mut rest = stream;
    let mut i = 0;
    while !rest.is_empty() {
        let want = chunk_len(plan, i, rest.len()).min(rest.len());
        i += 1;
        let mut chunk = &rest[..want];
        rest = &rest[want..];
        while !chunk.is_empty() {
            let free = d.free();
            let took = d.push(chunk);
            assert_eq!(took, chunk.len().min(free));
            run.pushed += took;
            chunk = &chunk[took..];
            assert_eq!(run.pushed, run.discarded + run.frame_bytes + d.buffered());
            while let Some(e) = d.poll() {
                event(e, &d, &mut run);
            }
            // A full buffer always resolves: the longest packet fits.
            assert!(d.free() > 0);
        }
    }
    while let Some(e) = d.resync() {
        event(e, &d, &mut run);
    }
    assert_eq!(d.buffered(), 0, "bytes left after resync");
    assert_no_packet_in(stream, covered..stream.len());
    assert_eq!(run.pushed, stream.len());
    run
}

/// Asserts that no packet with sound framing starts at an offset in `range` of `stream`: the
/// deframer dropped those bytes, so it must not have dropped a packet.
fn assert_no_packet_in(stream: &[u8], range: core::ops::Range<usize>) {
    for q in range {
        let Some(kind) = stream
            .get(q..q + HEADER_LEN)
            .and_then(PacketKind::from_header)
        else {
            continue;
        };
        if let Some(packet) = stream.get(q..q + kind.len()) {
            assert_ne!(
                framing(kind, packet),
                Framing::Sound,
                "a {kind} packet at offset {q} was dropped"
            );
        }
    }
}

/// Property: after any `garbage`, a packet with sound framing (`kind`, `body` sealed as in
/// [`check_round_trip`]) fed in the chunks `plan` gives and flushed with `resync` is delivered
/// exactly once, byte-identical, at offset `garbage.len()` — unless the garbage itself starts a
/// frame with sound framing that overlaps the packet (then the deframer rightly delivered that
/// frame first; [`run_deframer`] has checked it is one). Returns whether the packet was delivered.
pub fn check_packet_after_garbage<const N: usize, const S: usize>(
    garbage: &[u8],
    kind: PacketKind,
    body: &[u8],
    plan: &[u8],
) -> bool {
    let mut stream = [0u8; S];
    let g = garbage.len();
    let len = kind.len();
    assert!(g + len <= S, "stream buffer too small");
    stream[..g].copy_from_slice(garbage);
    let n = body.len().min(len);
    stream[g..g + n].copy_from_slice(&body[..n]);
    seal(kind, &mut stream[g..g + len]);
    let stream = &stream[..g + len];
    let mut delivered = 0;
    let mut overlapped = false;
    run_deframer::<N>(stream, plan, |offset, f| {
        if offset == g {
            assert_eq!(f.as_bytes(), &stream[g..]);
            delivered += 1;
        } else if offset < g && offset + f.as_bytes().len() > g {
            overlapped = true;
        }
    });
    assert!(delivered <= 1);
    assert!(
        delivered == 1 || overlapped,
        "packet after {g} bytes of garbage was lost"
    );
    delivered == 1
}

/// Builds a byte stream from fuzzer input, rich in what a deframer must sort out: each step
/// reads a tag byte; a tag below 0x80 copies the next `tag + 1` input bytes verbatim (so every
/// stream can be built), a tag of 0x80 or more writes a packet of kind `ALL[tag & 3]` with sound
/// framing whose middle bytes come from the input, and if bit 6 is set, flips the bit of it
/// that the next input byte selects (a near miss). Stops when `out` is full; returns the length.
pub fn build_stream(input: &[u8], out: &mut [u8]) -> usize {
    let (mut i, mut n) = (0, 0);
    while let Some(&tag) = input.get(i) {
        i += 1;
        if tag < 0x80 {
            let k = (tag as usize + 1).min(input.len() - i).min(out.len() - n);
            out[n..n + k].copy_from_slice(&input[i..i + k]);
            i += k;
            n += k;
        } else {
            let kind = PacketKind::ALL[(tag & 3) as usize];
            let len = kind.len();
            if n + len > out.len() {
                break;
            }
            let packet = &mut out[n..n + len];
            packet.fill(0);
            let mid = len - HEADER_LEN - CHECKSUM_LEN;
            let k = mid.min(input.len() - i);
            packet[HEADER_LEN..HEADER_LEN + k].copy_from_slice(&input[i..i + k]);
            i += k;
            seal(kind, packet);
            if tag & 0x40 != 0 {
                let bit = input.get(i).map_or(0, |&b| b as usize) % (len * 8);
                i += 1;
                packet[bit / 8] ^= 1 << (bit % 8);
            }
            n += len;
        }
        if n == out.len() {
            break;
        }
    }
    n
}
