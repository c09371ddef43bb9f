//! The review pages' rendering: the paper's 7-column grid, the field tables and the opcode
//! table, checked against the library they are rendered from.

use mmic::command::{for_each_variant_class, Command, HipTarget, ServoTarget};
use mmic::units::{HipAngle, PulseWidth, Side};
use mmic::wire::PacketKind;
use mmic_host::pages;

/// The Markdown tables of a page section: each a list of rows of cells.
fn tables(section: &str) -> Vec<Vec<Vec<String>>> {
    let mut out = Vec::new();
    let mut cur: Vec<Vec<String>> = Vec::new();
    for line in section.lines().chain(std::iter::once("")) {
        if let Some(inner) = line.strip_prefix('|').and_then(|l| l.strip_suffix('|')) {
            cur.push(inner.split('|').map(|c| c.trim().to_string()).collect());
        } else if !cur.is_empty() {
            out.push(std::mem::take(&mut cur));
        }
    }
    out
}

#[test]
fn every_grid_row_shows_seven_byte_indices_and_their_paper_labels() {
    for kind in PacketKind::ALL {
        let page = pages::packet(kind);
        assert!(page.starts_with(pages::BANNER));
        let (grid, fields) = page
            .split_once("## Fields")
            .expect("a grid section and a field section");
        let grid = tables(grid);
        assert_eq!(
            grid.len(),
            kind.len().div_ceil(7),
            "{kind}: one table per 7 bytes"
        );
        for (row, t) in grid.iter().enumerate() {
            let [index, rule, labels] = &t[..] else {
                panic!("{kind}: a grid table is header, rule, labels: {t:?}")
            };
            assert_eq!((index.len(), rule.len(), labels.len()), (7, 7, 7), "{kind}");
            for (col, ((index, rule), label)) in index.iter().zip(rule).zip(labels).enumerate() {
                let i = row * 7 + col;
                let f = kind.fields().iter().find(|f| f.range.contains(&i));
                let mut want = String::new();
                if let Some(f) = f {
                    f.cell(i, &mut want).unwrap();
                    assert_eq!(index, &i.to_string(), "{kind}: index cell");
                } else {
                    assert!(i >= kind.len(), "{kind}: byte {i} has no field");
                    assert_eq!(index, "");
                }
                assert_eq!(rule, "---");
                assert_eq!(label, &want, "{kind}: label of byte {i}");
            }
        }
        let ft = tables(fields);
        assert_eq!(ft.len(), 1);
        assert_eq!(ft[0][0], ["bytes", "name (JSON)", "unit", "paper label"]);
        assert_eq!(ft[0].len(), 2 + kind.fields().len());
        for (f, row) in kind.fields().iter().zip(&ft[0][2..]) {
            assert_eq!(row[1], format!("`{}`", f.name));
            assert_eq!(row[2], f.unit.name());
            assert_eq!(row[3], f.paper);
            let first = f.range.start.to_string();
            assert!(row[0] == first || row[0] == format!("{first}–{}", f.range.end - 1));
        }
    }
}

#[test]
fn opcode_table_has_one_row_per_variant_class() {
    let page = pages::commands();
    let t = &tables(&page)[0];
    assert_eq!(
        t[0],
        [
            "opcode",
            "Table 1 kind",
            "command (JSON)",
            "parameter bytes"
        ]
    );
    let mut rows = t[2..].iter();
    let mut n = 0;
    for_each_variant_class(PulseWidth::CENTER, HipAngle::new(9000).unwrap(), |c| {
        let row = rows.next().expect("a row per class");
        let (id, _) = c.encode();
        assert_eq!(row[0], format!("`{id:#04x}`"));
        assert_eq!(row[1], c.kind().name());
        let json = row[2].trim_matches('`');
        assert_eq!(serde_json::from_str::<Command>(json).unwrap(), c);
        n += 1;
    });
    assert!(rows.next().is_none());
    assert_eq!(n, 61);
}

#[test]
fn parameter_bytes_are_the_ones_the_decoder_reads_whatever_their_value() {
    let pw = |us| PulseWidth::new(us).unwrap();
    // 1536 µs = 0x0600: a zero low byte is still a used byte.
    let arm_a = Command::Arm {
        side: Side::A,
        target: ServoTarget::Position(pw(1536)),
    };
    assert_eq!(pages::param_bytes_used(arm_a), [8, 9]);
    // 1792 µs = 0x0700, within the grippers' travel.
    let grip_b = Command::Gripper {
        side: Side::B,
        target: ServoTarget::Position(pw(1792)),
    };
    assert_eq!(pages::param_bytes_used(grip_b), [10, 11]);
    // 0°: both bytes zero, both used.
    let hip = Command::Hip(HipTarget::Angle(HipAngle::ZERO));
    assert_eq!(pages::param_bytes_used(hip), [6, 7]);
    let contract = Command::Arm {
        side: Side::B,
        target: ServoTarget::Contract,
    };
    assert!(pages::param_bytes_used(contract).is_empty());
    // Over every class: the bytes a command uses are exactly the ones its encoding may set.
    // Pulse widths within both servos' travels (a command outside them decodes to no command).
    for (us, a) in [(1000, 0), (1536, 256), (2000, 35999)] {
        for_each_variant_class(pw(us), HipAngle::new(a).unwrap(), |c| {
            let (_, p) = c.encode();
            let used = pages::param_bytes_used(c);
            for (i, b) in p.iter().enumerate() {
                if *b != 0 {
                    assert!(
                        used.contains(&(i + 6)),
                        "{c:?}: byte {} set but unused",
                        i + 6
                    );
                }
            }
            // A u16 slot, or a primitive's final state alone (byte 8).
            let primitive = c.kind() == mmic::command::CommandKind::Primitive;
            assert!(
                used.is_empty() || used.len() == 2 || (primitive && used == [8]),
                "{c:?}: {used:?}"
            );
        });
    }
}
