//! The `mmic` binary end to end: encode → decode round trips for every command variant class
//! and every packet kind, a golden vector, every error path, and fresh review pages.

use mmic::arbitrary::for_each_variant_class;
use mmic::command::{Command, Reconfiguration};
use mmic::motion::State;
use mmic::units::{BoardNumber, HipAngle, PulseWidth};
use mmic::wire::command::CommandRepr;
use serde_json::{json, Value};
use std::process::{Command as Proc, Output};

pub(crate) fn mmic(args: &[&str]) -> Output {
    Proc::new(env!("CARGO_BIN_EXE_mmic"))
        .args(args)
        .output()
        .expect("run mmic")
}

pub(crate) fn ok(args: &[&str]) -> String {
    let o = mmic(args);
    assert!(
        o.status.success(),
        "{args:?}: {}",
        String::from_utf8_lossy(&o.stderr)
    );
    String::from_utf8(o.stdout).unwrap().trim().to_string()
}

pub(crate) fn fails(args: &[&str], code: i32, needle: &str) {
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
    // Pulse widths within both servos' travels (arm 900..=2100, gripper 1000..=2000 µs).
    for (pw, a) in [(1000, 0), (2000, 35999), (1234, 9000)] {
        for_each_variant_class(
            PulseWidth::new(pw).unwrap(),
            HipAngle::new(a).unwrap(),
            |c| {
                let repr = CommandRepr {
                    board: BoardNumber::new(7).unwrap(),
                    command: c,
                    seq: 0,
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
                    seq: 0,
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
        "faults": ["hip_mismatch", "low_battery"], "refusal": "not_allowed_in_mode", "mode": "safed",
        "last_seq": 65535,
        "boot": {"cause": "watchdog", "count": 31}
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
        "seq": 42, "flags": {"regulator": true, "arm": true, "gripper": false, "bolter": true, "stop": true},
        "arm_target": 1500, "gripper_target": 2100, "bolter": {"pair": 4, "direction": "bolt", "step": "descend_engage"}
    });
    round_trip("b-command", &bc);
    // Byte 5 = regulator | arm | bolter | stop = 0b1_1011, byte 4 = 42.
    assert_eq!(
        &ok(&["encode", "b-command", &bc.to_string()])[8..12],
        "2a1b"
    );
    let bc_idle = json!({
        "seq": 0, "flags": {"regulator": false, "arm": false, "gripper": false, "bolter": false, "stop": false},
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
        r#"{"board":1,"command":{"arm":{"side":"a","target":{"position":1200}}},"seq":0}"#,
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
        r#"{"board":1,"command":{"arm":{"side":"a","target":{"position":1200}}},"seq":0}"#
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
        "invalid hex at character 3 (counting from 0): not a hex digit",
    );
    fails(
        &["decode", "command", "4d 4"],
        2,
        "invalid hex at character 3 (counting from 0): odd number of hex digits",
    );
    fails(
        &["decode", "command", "g0"],
        2,
        "invalid hex at character 0 (counting from 0): not a hex digit",
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
    // The right bytes under the wrong kind: the header names the kind they look like.
    fails(
        &["decode", "heartbeat", good],
        1,
        "length check failed: heartbeat packet: length must be 66 bytes, found 14; this looks like \
         a command packet (MICM): try `mmic decode command <hex>`",
    );
    let mut bad_crc = good.to_string();
    bad_crc.replace_range(26..28, "00");
    fails(
        &["decode", "command", &bad_crc],
        1,
        "checksum check failed: command packet: checksum carried 0x004a (bytes 4a 00), computed 0xd44a (bytes 4a d4)",
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
    // The conformance pages (pics-*.md, pus-tailoring.md) are tests/ccsds/pics.rs's, checked there.
    let on_disk = std::fs::read_dir(&dir)
        .unwrap()
        .filter(|e| {
            let name = e
                .as_ref()
                .unwrap()
                .file_name()
                .to_string_lossy()
                .into_owned();
            !(name.starts_with("pics-") || name == "pus-tailoring.md")
        })
        .count();
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
    assert_eq!(moves.len(), 60);
    assert_eq!(moves[0], json!({"from": "a", "to": "d", "primitive": 4}));
    let hipless = map["turns_without_hip"].as_array().unwrap();
    assert_eq!(hipless.len(), 12);
    assert!(hipless.contains(&json!({"from": "g", "to": "j", "primitive": 6})));
    assert!(!moves.iter().any(|m| hipless.contains(m)));
    // b -> c in three primitives the robot can make (the map had g -> j, a turn without the
    // hip, on the way before issue 24).
    assert_eq!(
        ok(&["plan", "b", "c"]),
        "b (Yneg match) -> c (Zneg match): 3 primitive(s)\n  \
         4 backExtend   -> h (Yneg Ypos stretch)\n  \
         6 fwdTurnCCW   -> k (Zneg Ypos turn)\n  \
         8 backTurnCCW  -> c (Zneg match)"
    );
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
    // The grid (a header and 15 rows, every row's cells under their column letters), then
    // the legend: every code the grid uses is explained, in the output and in --help.
    let out = ok(&["map"]);
    let (grid, legend) = out.split_once("\n\n").expect("grid, blank line, legend");
    assert_eq!(grid.lines().count(), 16);
    let header = grid.lines().next().unwrap();
    for row in grid.lines().skip(1) {
        for (i, c) in row.char_indices().skip(7) {
            if c.is_ascii_digit() || c == '.' || c == 'x' {
                // A primitive number sits one column left of its letter's column, `.` and `x`
                // under it.
                let col = if c.is_ascii_digit() { i + 1 } else { i };
                assert!(
                    header
                        .as_bytes()
                        .get(col)
                        .is_some_and(|b| b.is_ascii_lowercase()),
                    "cell {c:?} at column {i} of {row:?} is not under a state letter"
                );
            }
        }
    }
    assert_eq!(grid.matches(" x").count(), 12);
    for code in [
        "4i",
        "2F",
        "*",
        "x ",
        ".",
        "--",
        "primitives: 1 fwdContract",
    ] {
        assert!(legend.contains(code), "legend lacks {code:?}:\n{legend}");
    }
    let help = ok(&["map", "--help"]);
    assert!(
        help.contains(legend.trim_end()),
        "map --help lacks the legend:\n{help}"
    );
}

/// CRC-16/CCITT-FALSE bit by bit (poly 0x1021, init 0xffff, no reflection, no xor-out): an
/// implementation independent of the library's table-driven one, for the golden vectors.
fn crc16_bitwise(bytes: &[u8]) -> u16 {
    let mut c: u16 = 0xffff;
    for &b in bytes {
        c ^= u16::from(b) << 8;
        for _ in 0..8 {
            c = if c & 0x8000 != 0 {
                (c << 1) ^ 0x1021
            } else {
                c << 1
            };
        }
    }
    c
}

#[test]
fn golden_reconfiguration_hex() {
    // Table 2 by hand: "MICM" = 4d 49 43 4d; byte 4 board 1; byte 5 opcode 0x60 (reconfigure);
    // bytes 6-7 hip slot unused = 00 00; byte 8 final state 'm' = 0x6d; byte 9 initial state
    // 'a' = 0x61; bytes 10-11 arm B slot unused = 00 00; bytes 12-13 CRC-16/CCITT-FALSE of
    // bytes 0..=11 = 0x885b, low byte first: 5b 88.
    let body = [
        0x4d, 0x49, 0x43, 0x4d, 0x01, 0x60, 0x00, 0x00, 0x6d, 0x61, 0x00, 0x00,
    ];
    assert_eq!(crc16_bitwise(&body), 0x885b);
    let json = r#"{"board":1,"command":{"reconfigure":{"initial":"a","target":"m"}},"seq":0}"#;
    assert_eq!(
        ok(&["encode", "command", json]),
        "4d49434d016000006d6100005b88"
    );
    assert_eq!(
        ok(&["decode", "command", "4d49434d016000006d6100005b88"]),
        json
    );
    // The first golden vector's CRC, recomputed independently.
    assert_eq!(
        crc16_bitwise(&[0x4d, 0x49, 0x43, 0x4d, 0x01, 0x22, 0, 0, 0xb0, 0x04, 0, 0]),
        0xd44a
    );
}

/// A heartbeat with every field set, as JSON.
fn heartbeat() -> Value {
    json!({
        "board": 3, "hip_target": 4500, "hip_now": 4490,
        "arm_a_target": 1500, "arm_a_now": 1490, "arm_b_target": 1500, "arm_b_now": 1510,
        "gripper_a_target": 900, "gripper_a_now": 910, "gripper_b_target": 2000, "gripper_b_now": 1990,
        "electrical_a": electrical(7400), "electrical_b": electrical(7300),
        "target_state": "a", "command_complete": false, "active_bolter": null, "bolter_attempt": 0,
        "faults": [], "refusal": null, "mode": "operational"
    })
}

fn with(mut v: Value, path: &[&str], new: Value) -> String {
    let mut at = &mut v;
    for k in path {
        at = at
            .get_mut(*k)
            .unwrap_or_else(|| panic!("no {k} in {path:?}"));
    }
    *at = new;
    v.to_string()
}

#[test]
fn validated_values_are_refused_with_their_numbers() {
    let cmd = |c: Value| json!({"board": 1, "command": c}).to_string();
    let hb = heartbeat();
    let cases: Vec<(&str, String, &str)> = vec![
        ("command", cmd(json!({"primitive": {"primitive": 9, "target": "d"}})), "primitive (Table 6) must be in 1..=8, found 9"),
        // Out of the wire type's range too (negative, beyond u8/u16): still the field's own
        // range message, never serde's "expected u8".
        ("command", cmd(json!({"primitive": {"primitive": 900, "target": "d"}})), "primitive (Table 6) must be in 1..=8, found 900"),
        ("command", cmd(json!({"primitive": {"primitive": -1, "target": "d"}})), "primitive (Table 6) must be in 1..=8, found -1"),
        // A primitive names its final state; one it reaches from no state is refused.
        ("command", cmd(json!({"primitive": {"primitive": 4}})), "missing field `target`"),
        ("command", cmd(json!({"primitive": {"primitive": 3, "target": "a"}})), "primitive 3 fwdExtend takes no state to a (Xneg match) (Figure 9)"),
        (
            "command",
            cmd(json!({"arm": {"side": "a", "target": {"position": -5}}})),
            "servo pulse width (us) must be in 500..=2500, found -5",
        ),
        (
            "command",
            cmd(json!({"arm": {"side": "a", "target": {"position": 3000}}})),
            "servo pulse width (us) must be in 500..=2500, found 3000",
        ),
        (
            "command",
            cmd(json!({"arm": {"side": "a", "target": {"position": 70000}}})),
            "servo pulse width (us) must be in 500..=2500, found 70000",
        ),
        ("command", cmd(json!({"hip": {"angle": -1}})), "hip angle (0.01 deg) must be in 0..=35999, found -1"),
        ("command", cmd(json!({"hip": {"angle": 1.5}})), "invalid type: floating point `1.5`, expected an integer"),
        ("command", r#"{"board":300,"command":"stop"}"#.into(), "board number must be in 1..=255, found 300"),
        ("command", r#"{"board":0,"command":"stop"}"#.into(), "board number must be in 1..=255, found 0"),
        ("command", r#"{"board":-3,"command":"stop"}"#.into(), "board number must be in 1..=255, found -3"),
        ("command", r#"{"board":1,"command":"stop","seq":70000}"#.into(), "sequence number must be in 0..=65535, found 70000"),
        ("command", r#"{"board":1,"command":"stop","seq":-1}"#.into(), "sequence number must be in 0..=65535, found -1"),
        ("command", cmd(json!({"primitive": {"primitive": 0, "target": "d"}})), "found 0"),
        (
            "command",
            cmd(json!({"gripper": {"side": "b", "target": {"position": 499}}})),
            "500..=2500, found 499",
        ),
        // A servo pulse, but outside the module's travel (issue 24): the arm's and the
        // gripper's ranges are named.
        (
            "command",
            cmd(json!({"arm": {"side": "b", "target": {"position": 2101}}})),
            "arm target: pulse width 2101 us is outside the travel 900..=2100 us",
        ),
        (
            "command",
            cmd(json!({"arm": {"side": "a", "target": {"position": 899}}})),
            "arm target: pulse width 899 us is outside the travel 900..=2100 us",
        ),
        (
            "command",
            cmd(json!({"gripper": {"side": "a", "target": {"position": 2001}}})),
            "gripper target: pulse width 2001 us is outside the travel 1000..=2000 us",
        ),
        (
            "command",
            cmd(json!({"reconfigure": {"initial": "p", "target": "m"}})),
            "found 'p'",
        ),
        (
            "command",
            cmd(json!({"reconfigure": {"initial": "m", "target": "m"}})),
            "not a reconfiguration",
        ),
        (
            "command",
            cmd(json!({"bolter": {"bolt": {"pair": 5}}})),
            "bolter pair must be in 1..=4, found 5",
        ),
        (
            "command",
            cmd(json!({"arm": {"side": "c", "target": "contract"}})),
            "unknown variant `c`",
        ),
        ("command", cmd(json!("stopp")), "unknown variant `stopp`"),
        (
            "command",
            cmd(json!({"arm": {"side": "a", "target": "contract", "speed": 2}})),
            "unknown field `speed`",
        ),
        ("command", r#"{"board":256,"command":"stop"}"#.into(), "board number must be in 1..=255, found 256"),
        ("command", r#"{"board":1}"#.into(), "missing field `command`"),
        ("heartbeat", with(hb.clone(), &["bolter_attempt"], json!(4)), "bolter attempt must be in 0..=3, found 4"),
        ("heartbeat", with(hb.clone(), &["active_bolter"], json!(0)), "found 0"),
        ("heartbeat", with(hb.clone(), &["hip_now"], json!(36000)), "0..=35999, found 36000"),
        ("heartbeat", with(hb.clone(), &["arm_b_now"], json!(2501)), "500..=2500, found 2501"),
        ("heartbeat", with(hb.clone(), &["target_state"], json!("q")), "found 'q'"),
        ("heartbeat", with(hb.clone(), &["board"], json!(0)), "found 0"),
        (
            "heartbeat",
            with(hb.clone(), &["faults"], json!(["low_battery", "low_battery"])),
            "fault `low_battery` (bit 11) listed twice",
        ),
        ("heartbeat", with(hb.clone(), &["electrical_a", "v_bat"], json!(65536)), "voltage (mV) must be in 0..=65535, found 65536"),
        ("heartbeat", with(hb.clone(), &["electrical_b", "i_bo"], json!(-20)), "current (mA) must be in 0..=65535, found -20"),
        ("heartbeat", with(hb.clone(), &["electrical_b"], json!({"v_bat": 1})), "missing field `i_bat`"),
        ("heartbeat", with(hb.clone(), &["mode"], json!("off")), "unknown variant `off`"),
        (
            "internal-heartbeat",
            json!({"gravity": {"axis": "x", "sign": "+", "norm": 1}}).to_string(),
            "unknown field `norm`",
        ),
        (
            "b-command",
            json!({"seq": 1, "flags": {"regulator": true, "arm": true, "gripper": true, "bolter": true, "stop": false, "hold": true}}).to_string(),
            "unknown field `hold`",
        ),
        (
            "b-command",
            json!({"seq": 1, "power": {}}).to_string(),
            "unknown field `power`",
        ),
    ];
    for (kind, json, needle) in &cases {
        fails(&["encode", kind, json], 2, needle);
    }
}

/// Hex of `bytes` with the checksum recomputed, so that only the field check can fail.
fn sealed(mut bytes: Vec<u8>) -> String {
    let n = bytes.len();
    let crc = crc16_bitwise(&bytes[..n - 2]).to_le_bytes();
    bytes[n - 2..].copy_from_slice(&crc);
    bytes.iter().map(|b| format!("{b:02x}")).collect()
}

fn unhex(h: &str) -> Vec<u8> {
    (0..h.len())
        .step_by(2)
        .map(|i| u8::from_str_radix(&h[i..i + 2], 16).unwrap())
        .collect()
}

fn range_of(kind: mmic::wire::PacketKind, name: &str) -> std::ops::Range<usize> {
    kind.fields()
        .iter()
        .find(|f| f.name == name)
        .unwrap_or_else(|| panic!("{kind} has no field {name}"))
        .range
        .clone()
}

#[test]
fn field_check_failures_name_the_field_and_the_numbers() {
    use mmic::wire::PacketKind;
    let mut hb = unhex(&ok(&["encode", "heartbeat", &heartbeat().to_string()]));
    let r = range_of(PacketKind::Heartbeat, "arm_a_now");
    hb[r.start] = 0x10; // 16 µs
    hb[r.start + 1] = 0x00;
    let o = mmic(&["decode", "heartbeat", &sealed(hb)]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert!(err.contains("field check failed"), "{err}");
    assert!(
        err.contains("byte 11 (arm_a_now)") && err.contains("500..=2500") && err.contains("0x10"),
        "{err}"
    );

    let bc = json!({
        "seq": 0, "flags": {"regulator": false, "arm": false, "gripper": false, "bolter": false, "stop": false},
        "arm_target": 500, "gripper_target": 500, "bolter": null
    });
    let mut b = unhex(&ok(&["encode", "b-command", &bc.to_string()]));
    b[range_of(PacketKind::BCommand, "flags").start] = 0x20; // bit 5 is reserved
    let o = mmic(&["decode", "b-command", &sealed(b)]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert!(
        err.contains("field check failed: b-command packet: byte 5 (flags): expected bits 0..=4 only, found 0x20"),
        "{err}"
    );
}

#[test]
fn help_explains_units_exit_codes_and_gives_examples() {
    let top = ok(&["--help"]);
    for needle in [
        "µs",
        "0.01°",
        "mV",
        "mA",
        "Exit codes",
        "mmic encode command",
    ] {
        assert!(top.contains(needle), "mmic --help lacks {needle:?}:\n{top}");
    }
    let enc = ok(&["encode", "--help"]);
    for needle in [
        "500..=2500 µs",
        "0.01°",
        "\"primitive\":{\"primitive\":4,\"target\":\"d\"}",
        "\"reconfigure\"",
        "b-command",
    ] {
        assert!(
            enc.contains(needle),
            "encode --help lacks {needle:?}:\n{enc}"
        );
    }
    let dec = ok(&["decode", "--help"]);
    // Every example in `decode --help` decodes to the JSON printed under it.
    let lines: Vec<&str> = dec.lines().collect();
    let mut examples = 0;
    for w in lines.windows(2) {
        if let Some(rest) = w[0].trim().strip_prefix("mmic decode command ") {
            let hex = rest.trim_matches('\'');
            assert_eq!(ok(&["decode", "command", hex]), w[1].trim());
            examples += 1;
        }
    }
    assert_eq!(examples, 3, "{dec}");
    // And every `mmic encode` example in `encode --help` and `--help` is accepted.
    let mut encoded = 0;
    for line in enc.lines().chain(top.lines()) {
        if let Some(rest) = line.trim().strip_prefix("mmic encode ") {
            let (kind, json) = rest.split_once(' ').unwrap();
            let json = json.split("'   (").next().unwrap().trim_matches('\'');
            ok(&["encode", kind, json]);
            encoded += 1;
        }
    }
    assert!(encoded >= 8, "{encoded} examples");
}

#[test]
fn spec_write_writes_every_page_into_a_fresh_directory() {
    let dir = std::env::temp_dir().join(format!("mmic-spec-write-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    let o = mmic(&["spec", "--write", dir.to_str().unwrap()]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let pages = mmic_host::pages::all();
    for (name, want) in &pages {
        let got = std::fs::read_to_string(dir.join(name)).unwrap();
        assert_eq!(&got, want, "{name}");
        assert!(got.starts_with(mmic_host::pages::BANNER), "{name}");
    }
    for name in [
        "command.md",
        "heartbeat.md",
        "internal-heartbeat.md",
        "b-command.md",
        "commands.md",
    ] {
        assert!(pages.iter().any(|(n, _)| n == name), "{name}");
    }
    std::fs::remove_dir_all(&dir).unwrap();
    // A directory that cannot be created: exit 3 and the path in the message.
    let file = std::env::temp_dir().join(format!("mmic-spec-file-{}", std::process::id()));
    std::fs::write(&file, "x").unwrap();
    let target = file.join("sub");
    fails(
        &["spec", "--write", target.to_str().unwrap()],
        3,
        &format!("cannot write {}", target.display()),
    );
    std::fs::remove_file(&file).unwrap();
}
