//! The committed seed corpus is exactly what `mmic_fuzz::seeds()` generates, and each seed is
//! what its name says (valid packets parse; near misses fail the check they are named after).

use mmic::wire::PacketKind;
use mmic_fuzz::{parser_target, seeds, TARGETS};
use std::collections::BTreeSet;
use std::path::Path;

#[test]
fn committed_corpus_matches_the_generator() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/__fuzz__");
    let seeds = seeds();
    for target in TARGETS {
        let dir = root.join(target).join("corpus");
        let committed: BTreeSet<String> = std::fs::read_dir(&dir)
            .unwrap_or_else(|e| panic!("{}: {e}", dir.display()))
            .map(|e| e.unwrap().file_name().into_string().unwrap())
            .collect();
        let generated: BTreeSet<String> = seeds
            .iter()
            .filter(|s| s.target == target)
            .map(|s| s.name.clone())
            .collect();
        assert_eq!(
            committed, generated,
            "{target}: run `cargo run -p mmic-fuzz --bin mmic-fuzz-seeds`"
        );
        for s in seeds.iter().filter(|s| s.target == target) {
            assert_eq!(
                std::fs::read(dir.join(&s.name)).unwrap(),
                s.bytes,
                "{target}/{}",
                s.name
            );
        }
    }
}

#[test]
fn parser_seeds_are_what_their_names_say() {
    let mut n = 0;
    for kind in PacketKind::ALL {
        for s in seeds().iter().filter(|s| s.target == parser_target(kind)) {
            let accepted = mmic_proofs::check_parse_kind(kind, &s.bytes);
            let check = match kind {
                PacketKind::Command => mmic::wire::command::CommandRepr::parse(&s.bytes).err(),
                PacketKind::Heartbeat => {
                    mmic::wire::heartbeat::HeartbeatRepr::parse(&s.bytes).err()
                }
                PacketKind::InternalHeartbeat => {
                    mmic::wire::internal_heartbeat::InternalHeartbeatRepr::parse(&s.bytes).err()
                }
                PacketKind::BCommand => mmic::wire::b_command::BCommandRepr::parse(&s.bytes).err(),
            }
            .map(|e| e.check());
            let expected: &[&str] = if s.name.ends_with("-checksum-miss") {
                &["checksum"]
            } else if s.name.ends_with("-header-miss") {
                &["header"]
            } else if s.name.ends_with("-short") || s.name.ends_with("-long") {
                &["length"]
            } else if s.name.ends_with("-field-miss") {
                &["field", "command"]
            } else {
                &[]
            };
            match check {
                Some(c) => assert!(expected.contains(&c), "{}/{}: {c}", s.target, s.name),
                None => assert!(expected.is_empty(), "{}/{} accepted", s.target, s.name),
            }
            assert_eq!(accepted, check.is_none());
            n += 1;
        }
    }
    assert_eq!(n, 11 * 6);
}

#[test]
fn pus_seeds_are_what_their_names_say() {
    use mmic::ccsds::primary::PacketType;
    use mmic_fuzz::{pus_near_misses, pus_target, valid_pus_packets};
    let mut n = 0;
    for (kind, name, bytes) in valid_pus_packets() {
        let apids = [0x042];
        let accepted = mmic_proofs::ccsds::check_pus_parse_with(kind, &bytes, &apids);
        assert!(accepted, "{name} refused");
        for (suffix, check, b) in pus_near_misses(&bytes) {
            assert!(!mmic_proofs::ccsds::check_pus_parse_with(kind, &b, &apids));
            let e = match kind {
                PacketType::Tc => mmic::ccsds::tc::TcRepr::parse(&b, &apids).err(),
                PacketType::Tm => mmic::ccsds::tm::TmRepr::parse(&b, &apids).err(),
            };
            assert_eq!(e.map(|e| e.name()), Some(check), "{name}{suffix}");
            assert!(seeds().iter().any(|s| s.target == pus_target(kind)
                && s.name == format!("{name}{suffix}")
                && s.bytes == b));
            n += 1;
        }
    }
    assert_eq!(n, 4 * 8);
}

#[test]
fn tc_frame_seeds_are_what_their_names_say() {
    use mmic::link::tc_frame::TcFrame;
    let cfg = &mmic_proofs::link::CONFIGS[0];
    let seeds = mmic_fuzz::tc_frame_seeds();
    for (name, expected, bytes) in &seeds {
        let got = TcFrame::new_checked(&bytes[..], cfg)
            .and_then(|f| f.packets().try_for_each(|p| p.map(|_| ())))
            .err()
            .map(|e| e.name());
        assert_eq!(got, *expected, "{name}");
        mmic_proofs::link::check_tc_frame_parse(bytes);
    }
    // Every check has its near miss.
    for check in mmic::link::tc_frame::TcFrameError::NAMES {
        assert!(seeds.iter().any(|(_, e, _)| *e == Some(check)), "{check}");
    }
}

#[test]
fn sdls_seeds_are_what_their_names_say() {
    use mmic_proofs::sdls::{check_secured_tc_frame, check_secured_tm_frame};
    let seeds = mmic_fuzz::sdls_seed_frames();
    assert_eq!(seeds.len(), 14);
    for (target, name, expected, bytes) in &seeds {
        let got = if *target == "sdls_tc_verify" {
            let mut g = mmic_proofs::sdls::secured_gateway();
            let r = g.tc_frame(0, bytes);
            // The property holds, and a genuine frame's packet runs.
            let ran = check_secured_tc_frame(bytes);
            assert_eq!(
                ran,
                expected.is_none() && !name.starts_with("bc-"),
                "{name}"
            );
            r.verdict.err().map(|e| e.name())
        } else {
            let mut g = mmic_proofs::sdls::secured_ground();
            let r = g.tm_frame(0, bytes, &mut |_: &[u8]| {}, &mut |_: &[u8]| {});
            assert_eq!(check_secured_tm_frame(bytes), expected.is_none(), "{name}");
            r.err().map(|e| e.name())
        };
        assert_eq!(got, *expected, "{target}/{name}");
    }
}
