//! Harnesses for the four packets (Tables 2–4 and the A→B command), written once and
//! instantiated per packet: `command::parse_never_panics`, `heartbeat::round_trip`, ...
//!
//! Each runs as a randomised test under `cargo test`, as a fuzz target under `cargo bolero
//! test`, and as a proof under `cargo kani --tests`. The unwind bound is the packet length
//! plus two, which covers the CRC loop over the body (see proofs/README.md); Kani needs it as a
//! literal, so each instantiation states it.

/// The arbitrary-length harness tries every length up to this many bytes.
const MAX_LEN: usize = 80;

macro_rules! packet_harnesses {
    ($(#[$doc:meta])* $module:ident: $repr:ty, $len:expr, unwind $unwind:literal) => {
        $(#[$doc])*
        mod $module {
            use mmic_proofs::{check_parse, check_round_trip, check_round_trip_near_valid};

            const LEN: usize = $len;

            /// `parse` of any LEN bytes returns, with the documented verdict (see
            /// `check_parse`).
            #[test]
            #[cfg_attr(kani, kani::proof, kani::unwind($unwind))]
            fn parse_never_panics() {
                bolero::check!()
                    .with_type::<[u8; LEN]>()
                    .for_each(|bytes| {
                        check_parse::<$repr>(bytes);
                    });
            }

            /// `parse` of any slice of up to `MAX_LEN` bytes returns, with the documented
            /// verdict: a length error naming both lengths unless the length is right, then
            /// header, checksum, fields.
            #[test]
            #[cfg_attr(kani, kani::proof, kani::unwind($unwind))]
            fn parse_never_panics_any_length() {
                bolero::check!()
                    .with_max_len(super::MAX_LEN)
                    .for_each(|bytes: &[u8]| {
                        check_parse::<$repr>(bytes);
                    });
            }

            /// Any body with the right header and a correct checksum is accepted canonically
            /// (`emit(parse(b)) == b`, `parse(emit(parse(b))) == parse(b)`) or refused by a
            /// field or command check, never by the length, header or checksum check.
            #[test]
            #[cfg_attr(kani, kani::proof, kani::unwind($unwind))]
            fn round_trip() {
                bolero::check!()
                    .with_type::<[u8; LEN]>()
                    .for_each(|body| {
                        check_round_trip::<$repr>(body);
                    });
            }

            /// A valid value built from any seed survives `parse(emit(x)) == x`; with up to two
            /// body bytes then overwritten and the checksum rewritten, the near miss is accepted
            /// canonically or refused by a field or command check (see
            /// `check_round_trip_near_valid`).
            #[test]
            #[cfg_attr(kani, kani::proof, kani::unwind($unwind))]
            fn round_trip_near_valid() {
                bolero::check!()
                    .with_type::<([u8; LEN], u8, [[u8; 2]; 2])>()
                    .for_each(|(seed, n, edits)| {
                        check_round_trip_near_valid::<$repr>(seed, &edits[..*n as usize % 3]);
                    });
            }
        }
    };
}

packet_harnesses! {
    /// The 14-byte command packet (Table 2).
    command: mmic::wire::command::CommandRepr, mmic::wire::command::COMMAND_LEN, unwind 16
}
packet_harnesses! {
    /// The 66-byte WiFi heartbeat (Table 3).
    heartbeat: mmic::wire::heartbeat::HeartbeatRepr, mmic::wire::heartbeat::HEARTBEAT_LEN, unwind 68
}
packet_harnesses! {
    /// The 47-byte internal heartbeat (Table 4).
    internal_heartbeat: mmic::wire::internal_heartbeat::InternalHeartbeatRepr,
        mmic::wire::internal_heartbeat::INTERNAL_HEARTBEAT_LEN, unwind 49
}
packet_harnesses! {
    /// The 15-byte A→B command.
    b_command: mmic::wire::b_command::BCommandRepr, mmic::wire::b_command::B_COMMAND_LEN, unwind 17
}
