//! COP-1 of the space data link (`mmic::link`): FARM-1 over any sequence of frames and
//! events, FOP-1 over any sequence of requests, CLCWs and timer expiries, and the CLCW's
//! parse/emit. Under `cargo test`: an exhaustive part over every short sequence from a
//! distinguished alphabet, then sampled inputs; `cargo bolero test`: fuzzing; `cargo kani
//! --tests`: proofs over all inputs of the fixed length (Kani not installed here: not run).

use mmic_proofs::link_cop::{check_clcw_word, check_farm_events, check_fop_inputs};

/// Events per sampled (and Kani) run.
const N: usize = 12;

/// The distinguished alphabet of the exhaustive part (17 events, window W = 20, V(R) from 0):
/// AD frames with N(S) 0, 1, 2, 3 (expected, ahead, behind), 11 (the positive window's edge
/// from V(R) 1 and 2) and 200 (the lockout area), each with and without a buffer; a BD frame;
/// Unlock; Set V(R) to 1; an invalid frame; a buffer release.
const ALPHABET: [(u8, u8, bool); 17] = [
    (0, 0, true),
    (0, 0, false),
    (0, 1, true),
    (0, 1, false),
    (0, 2, true),
    (0, 2, false),
    (0, 3, true),
    (0, 3, false),
    (0, 11, true),
    (0, 11, false),
    (0, 200, true),
    (0, 200, false),
    (4, 0, true),
    (5, 0, true),
    (5, 1, false),
    (6, 0, true),
    (7, 0, true),
];

/// FARM-1 takes each AD frame at most once and in order: every accepted AD frame has
/// N(S) = V(R) (then V(R) + 1), so the accepted N(S) run 0, 1, 2, … without gap or repeat
/// until a Set V(R) starts a new run at V*(R); V(R) moves only so; no AD frame is accepted in
/// Wait or Lockout; the CLCW reports the state (Lockout flag ⇔ S3, Wait flag in S2, Wait ⇒
/// Retransmit, report value V(R)).
///
/// Under `cargo test`: exhaustively, every sequence of 5 events of [`ALPHABET`] (17^5); then
/// sampled sequences of 12 events with any N(S) and V*(R), from any window.
// req: 232.1-B-2/FARM-3
#[test]
#[cfg_attr(kani, kani::proof, kani::unwind(14))]
fn farm_accepts_each_frame_once_in_order() {
    #[cfg(not(any(kani, fuzzing)))]
    {
        let name = "farm_accepts_each_frame_once_in_order";
        crate::ledger::exhaustive(
            name,
            17u64.pow(5),
            crate::ledger::seq::<_, 5>(0usize..17),
            |ks| {
                let evs: [(u8, u8, bool); 5] = core::array::from_fn(|i| ALPHABET[ks[i]]);
                check_farm_events(20, &evs);
            },
        );
        crate::ledger::sampled::<(u8, [(u8, u8, bool); N])>(name, 200_000, |(w, evs)| {
            check_farm_events(*w, evs)
        });
        return;
    }
    #[allow(unreachable_code)]
    bolero::check!()
        .with_type::<(u8, [(u8, u8, bool); N])>()
        .for_each(|(w, evs)| check_farm_events(*w, evs));
}

/// `Clcw::parse` of any four octets gives the verdict of the bit table (check by name, in
/// order); what it accepts emits back to the same octets, field by field where the table
/// puts them.
///
/// Under `cargo test`: exhaustively, every value of octets 0 and 2 (type, version, status,
/// COP; the flags, FARM-B counter and spare bits) with octets 1 and 3 each 0x00, 0xa5 and
/// 0xff; then sampled words.
// req: 232.1-B-2/CLCW-1
#[test]
#[cfg_attr(kani, kani::proof, kani::unwind(8))]
fn clcw_round_trip() {
    #[cfg(not(any(kani, fuzzing)))]
    {
        let name = "clcw_round_trip";
        crate::ledger::exhaustive(
            name,
            65_536 * 3,
            (bolero::produce::<u8>(), bolero::produce::<u8>(), 0usize..3),
            |&(o0, o2, k)| {
                let o13 = [0x00u32, 0xa5, 0xff][k];
                check_clcw_word(((o0 as u32) << 24) | (o13 << 16) | ((o2 as u32) << 8) | o13)
            },
        );
        crate::ledger::sampled::<u32>(name, 200_000, |w| check_clcw_word(*w));
        return;
    }
    #[allow(unreachable_code)]
    bolero::check!()
        .with_type::<u32>()
        .for_each(|w| check_clcw_word(*w));
}

/// FOP-1 keeps its books whatever arrives: at most K frames unacknowledged; V(S) − NN(R) is
/// the sent queue's length while the service runs; new AD frames go out numbered V(S) in
/// sequence; every AD frame transmitted lies in NN(R)..V(S); frames are confirmed in order
/// N(S) = NN(R), NN(R) + 1, … each once; an alert or a terminate leaves nothing outstanding;
/// T1 runs whenever frames are unacknowledged in Active or Retransmit without Wait.
///
/// Under `cargo test`: exhaustively, every sequence of 5 inputs of 20 (requests, CLCWs with
/// and without each flag at several N(R), T1's expiry, the initiate directives, terminate);
/// then sampled sequences of 12 of any inputs.
// req: 232.1-B-2/FOP-1, 232.1-B-2/FOP-2, 232.1-B-2/FOP-10
#[test]
#[cfg_attr(kani, kani::proof, kani::unwind(14))]
fn fop_keeps_its_window_and_confirms_in_order() {
    #[cfg(not(any(kani, fuzzing)))]
    {
        const A: [(u8, u8); 20] = [
            (0, 1),    // request
            (0, 2),    // request
            (2, 1),    // CLCW N(R) = NN(R)
            (2, 2),    // N(R) = NN(R) + 1
            (2, 3),    // N(R) = NN(R) + 2
            (2, 0),    // N(R) = NN(R) − 1
            (2, 0x11), // Retransmit, N(R) = NN(R)
            (2, 0x12), // Retransmit, N(R) = NN(R) + 1
            (2, 0x31), // Retransmit and Wait
            (2, 0x21), // Wait
            (2, 0xc1), // Lockout
            (6, 0),    // T1 expires
            (5, 200),  // 2 s later
            (7, 0),    // initiate without CLCW
            (7, 1),    // initiate with CLCW
            (7, 2),    // initiate with Unlock
            (7, 3),    // initiate with Set V(R) 3
            (7, 4),    // terminate
            (7, 5),    // resume
            (8, 9),    // BD frame
        ];
        let name = "fop_keeps_its_window_and_confirms_in_order";
        crate::ledger::exhaustive(
            name,
            20u64.pow(5),
            crate::ledger::seq::<_, 5>(0usize..20),
            |ks| {
                let inputs: [(u8, u8); 5] = core::array::from_fn(|i| A[ks[i]]);
                check_fop_inputs(0, &inputs);
            },
        );
        crate::ledger::sampled::<(u8, [(u8, u8); N])>(name, 200_000, |(t, inputs)| {
            check_fop_inputs(*t, inputs)
        });
        return;
    }
    #[allow(unreachable_code)]
    bolero::check!()
        .with_type::<(u8, [(u8, u8); N])>()
        .for_each(|(t, inputs)| check_fop_inputs(*t, inputs));
}
