//! The `mmic` binary end to end: encode → decode round trips for every command variant class
//! and every packet kind, a golden vector, every error path, and fresh review pages.

use mmic::command::{for_each_variant_class, Command, Reconfiguration};
use mmic::motion::State;
use mmic::units::{BoardNumber, HipAngle, PulseWidth};
use mmic::wire::command::CommandRepr;
use serde_json::{json, Value};
use std::process::{Command as Proc, Output};

fn mmic(args: &[&str]) -> Output {
    Proc::new(env!("CARGO_BIN_EXE_mmic"))
        .args(args)
        .output()
        .expect("run mmic")
}

fn ok(args: &[&str]) -> String {
    let o = mmic(args);
    assert!(
        o.status.success(),
        "{args:?}: {}",
        String::from_utf8_lossy(&o.stderr)
    );
    String::from_utf8(o.stdout).unwrap().trim().to_string()
}

fn fails(args: &[&str], code: i32, needle: &str) {
    let o = mmic(args);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(code), "{args:?}: {err}");
    assert!(
        err.contains(needle),
        "{args:?}: stderr {err:?} lacks {needle:?}"
    );
    assert!(o.stdout.is_empty());
}

fn round_trip(kind: &str, value: &Value) {
    let hex = ok(&["encode", kind, &value.to_string()]);
    let back: Value = serde_json::from_str(&ok(&["decode", kind, &hex])).unwrap();
    assert_eq!(&back, value, "{kind}: {hex}");
}

#[test]
fn every_command_variant_class_round_trips_through_the_binary() {
    let mut n = 0;
    for (pw, a) in [(500, 0), (2500, 35999), (1234, 9000)] {
        for_each_variant_class(
            PulseWidth::new(pw).unwrap(),
            HipAngle::new(a).unwrap(),
            |c| {
                let repr = CommandRepr {
                    board: BoardNumber::new(7).unwrap(),
                    command: c,
                };
                let v = serde_json::to_value(repr).unwrap();
                round_trip("command", &v);
                // The hex is exactly the library's emission.
                let hex = ok(&["encode", "command", &v.to_string()]);
                assert_eq!(
                    hex,
                    repr.to_bytes()
                        .iter()
                        .map(|b| format!("{b:02x}"))
                        .collect::<String>()
                );
                n += 1;
            },
        );
    }
    for initial in State::ALL {
        for target in State::MATCHED {
            if let Ok(r) = Reconfiguration::new(initial, target) {
                let repr = CommandRepr {
                    board: BoardNumber::ONE,
                    command: Command::Reconfigure(r),
                };
                round_trip("command", &serde_json::to_value(repr).unwrap());
                n += 1;
            }
        }
    }
    assert_eq!(n, 3 * 61 + 84);
}

fn electrical(base: u16) -> Value {
    json!({"v_bat": base, "i_bat": base + 1, "i_loc": base + 2, "i_grip": base + 3, "i_3v3": base + 4, "v_reg": base + 5, "i_bo": base + 6})
}

#[test]
fn other_kinds_round_trip_with_non_default_values() {
    let hb = json!({
        "board": 200, "hip_target": 9000, "hip_now": 8995,
        "arm_a_target": 500, "arm_a_now": 600, "arm_b_target": 2500, "arm_b_now": 2400,
        "gripper_a_target": 1000, "gripper_a_now": 1100, "gripper_b_target": 1200, "gripper_b_now": 1300,
        "electrical_a": electrical(11000), "electrical_b": electrical(10500),
        "target_state": "n", "command_complete": true, "active_bolter": 3, "bolter_attempt": 2,
        "faults": ["hip_mismatch", "low_battery"], "refusal": "not_allowed_in_mode", "mode": "safed"
    });
    round_trip("heartbeat", &hb);
    let ihb = json!({
        "arm_b_target": 700, "arm_b_now": 710, "gripper_b_target": 1800, "gripper_b_now": 1790,
        "electrical_b": electrical(12000),
        "bolter_aux": {"step": "rotate", "seq": 9, "pair": 2, "direction": "unbolt", "threshold_reached": true,
                       "locked": false, "timed_out": true, "at_home": false, "mux": {"a0": false, "a1": true}},
        "command_received": 255, "gravity": {"axis": "z", "sign": "-"},
        "arm_over_idle": true, "gripper_over_idle": false, "bolter_over_idle": true, "arm_overcurrent": false,
        "gripper_overcurrent": true, "bolter_overcurrent": false, "arm_contracted": true
    });
    round_trip("internal-heartbeat", &ihb);
    let bc = json!({
        "seq": 42, "power": {"regulator": true, "arm": true, "gripper": false, "bolter": true}, "stop": true,
        "arm_target": 1500, "gripper_target": 2100, "bolter": {"pair": 4, "direction": "bolt", "step": "descend_engage"}
    });
    round_trip("b-command", &bc);
    let bc_idle = json!({
        "seq": 0, "power": {"regulator": false, "arm": false, "gripper": false, "bolter": false}, "stop": false,
        "arm_target": 500, "gripper_target": 500, "bolter": null
    });
    round_trip("b-command", &bc_idle);
}

#[test]
fn golden_command_hex() {
    // "MICM", board 1, opcode 0x22 (arm A position), hip 0, arm A 1200 µs = 0x04b0 (b0 04),
    // arm B 0, CRC-16/CCITT-FALSE of the 12 bytes = 0xd44a (4a d4).
    let hex = ok(&[
        "encode",
        "command",
        r#"{"board":1,"command":{"arm":{"side":"a","target":{"position":1200}}}}"#,
    ]);
    assert_eq!(hex, "4d49434d01220000b00400004ad4");
    // Separators and 0x prefixes are accepted on decode.
    let v = ok(&[
        "decode",
        "command",
        "0x4d:49:43:4d 01 22 00 00 b0 04 00 00 4a d4",
    ]);
    assert_eq!(
        v,
        r#"{"board":1,"command":{"arm":{"side":"a","target":{"position":1200}}}}"#
    );
}

#[test]
fn every_error_path_is_reported_with_its_check() {
    let good = "4d49434d01220000b00400004ad4";
    fails(
        &["encode", "telemetry", "{}"],
        2,
        "unknown packet kind \"telemetry\"",
    );
    fails(&["decode", "telemetry", good], 2, "unknown packet kind");
    fails(
        &["encode", "command", "{not json"],
        2,
        "invalid command JSON",
    );
    fails(
        &[
            "encode",
            "command",
            r#"{"board":1,"command":"stop","extra":1}"#,
        ],
        2,
        "unknown field `extra`",
    );
    fails(
        &[
            "encode",
            "command",
            r#"{"board":1,"command":{"arm":{"side":"a","target":{"position":2501}}}}"#,
        ],
        2,
        "500..=2500, found 2501",
    );
    fails(
        &[
            "encode",
            "command",
            r#"{"board":1,"command":{"hip":{"angle":36000}}}"#,
        ],
        2,
        "found 36000",
    );
    fails(
        &["encode", "command", r#"{"board":0,"command":"stop"}"#],
        2,
        "found 0",
    );
    fails(&["decode", "command", "4d4"], 2, "odd number of hex digits");
    fails(
        &["decode", "command", "4d4z"],
        2,
        "character 3: not a hex digit",
    );
    fails(
        &["decode", "command", &good[..26]],
        1,
        "length check failed: command packet: length must be 14 bytes, found 13",
    );
    fails(
        &["decode", "heartbeat", good],
        1,
        "length must be 66 bytes, found 14",
    );
    let mut bad_header = good.to_string();
    bad_header.replace_range(0..2, "00");
    fails(
        &["decode", "command", &bad_header],
        1,
        "header check failed",
    );
    let mut bad_crc = good.to_string();
    bad_crc.replace_range(26..28, "00");
    fails(
        &["decode", "command", &bad_crc],
        1,
        "checksum check failed: command packet: checksum carried 0x004a, computed 0xd44a",
    );
    // A well-framed packet with an unknown opcode: seal it with the library's CRC.
    let mut b = [0u8; 14];
    b[..4].copy_from_slice(b"MICM");
    b[4] = 1;
    b[5] = 0xee;
    let crc = mmic::wire::checksum::crc16(&b[..12]).to_le_bytes();
    b[12..].copy_from_slice(&crc);
    let hex: String = b.iter().map(|x| format!("{x:02x}")).collect();
    fails(
        &["decode", "command", &hex],
        1,
        "command check failed: command packet: byte 5: unknown command id 0xee",
    );
    // A nonzero unused parameter byte names the byte.
    b[5] = 0x02; // stop: uses no parameter byte
    b[7] = 0x01;
    let crc = mmic::wire::checksum::crc16(&b[..12]).to_le_bytes();
    b[12..].copy_from_slice(&crc);
    let hex: String = b.iter().map(|x| format!("{x:02x}")).collect();
    fails(
        &["decode", "command", &hex],
        1,
        "byte 7: unused by command 0x02, must be 0, found 0x01",
    );
}

#[test]
fn review_pages_are_fresh() {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../spec/pages");
    let pages = mmic_host::pages::all();
    for (name, want) in &pages {
        let path = dir.join(name);
        let got = std::fs::read_to_string(&path).unwrap_or_default();
        assert!(
            &got == want,
            "{} is stale or missing; regenerate with: cargo run -p mmic-host -- spec --write spec/pages",
            path.display()
        );
    }
    let on_disk = std::fs::read_dir(&dir).unwrap().count();
    assert_eq!(
        on_disk,
        pages.len(),
        "spec/pages holds files that are not generated"
    );
}

#[test]
fn spec_prints_every_page() {
    let out = ok(&["spec"]);
    for (_, page) in mmic_host::pages::all() {
        assert!(out.contains(page.trim()));
    }
}

#[test]
fn plan_and_map_commands() {
    assert_eq!(
        ok(&["plan", "a", "m", "--json"]),
        r#"{"from":"a","to":"m","primitives":[4,1]}"#
    );
    let text = ok(&["plan", "a", "b"]);
    assert!(
        text.starts_with("a (Xneg match) -> b (Yneg match): 3 primitive(s)"),
        "{text}"
    );
    assert!(text.contains("4 backExtend"));
    assert_eq!(
        ok(&["plan", "c", "c", "--json"]),
        r#"{"from":"c","to":"c","primitives":[]}"#
    );
    fails(&["plan", "a", "z"], 2, "unknown state \"z\"");
    let map: Value = serde_json::from_str(&ok(&["map", "--json"])).unwrap();
    let moves = map["moves"].as_array().unwrap();
    assert_eq!(moves.len(), 72);
    assert_eq!(moves[0], json!({"from": "a", "to": "d", "primitive": 4}));
    // Every plan printed by the CLI follows the map's moves.
    for f in "abcdefghijklmno".chars() {
        for t in "abcdefghijklmno".chars() {
            let p: Value =
                serde_json::from_str(&ok(&["plan", &f.to_string(), &t.to_string(), "--json"]))
                    .unwrap();
            let n = p["primitives"].as_array().unwrap().len();
            assert!(n <= 3 && (n == 0) == (f == t), "{f}->{t}: {p}");
        }
    }
    let grid = ok(&["map"]);
    assert_eq!(grid.lines().count(), 16);
}
