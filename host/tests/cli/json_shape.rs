//! The JSON of every packet kind follows spec/: its key paths are the `name`s of the packet's
//! field table (`PacketKind::fields()`, checked against spec/packets/*.toml by spec/check/tests/wire/spec.rs),
//! a dotted name being a nested object.

use mmic::wire::PacketKind;
use mmic_host::codec;
use serde_json::{json, Value};
use std::collections::BTreeSet;

/// Field-table names that have no JSON key of their own, and why.
fn not_in_json(kind: PacketKind, name: &str) -> bool {
    // Framing: fixed or computed, never chosen by an operator.
    matches!(name, "header" | "checksum")
        // Table 2's parameter slots: their meaning depends on the opcode, so they live inside
        // `command` (e.g. `{"arm":{"side":"a","target":{"position":1200}}}` fills arm_a).
        || (kind == PacketKind::Command && matches!(name, "hip" | "arm_a" | "arm_b"))
}

/// JSON keys that are no field-table name, and why.
fn json_only(kind: PacketKind, key: &str) -> bool {
    // The exactly-once sequence number rides in whichever parameter slot the opcode leaves
    // free (`mmic::wire::opcode::seq_slot`), so like the other slot contents it has no byte range
    // of its own.
    kind == PacketKind::Command && key == "seq"
        // The heartbeat's boot byte (59) is two bit fields: the reset cause and the count.
        || (kind == PacketKind::Heartbeat && matches!(key, "boot.cause" | "boot.count"))
}

/// Every key path (intermediate objects included) and the leaf paths.
fn paths(v: &Value, prefix: &str, all: &mut BTreeSet<String>, leaves: &mut BTreeSet<String>) {
    match v {
        Value::Object(m) => {
            for (k, v) in m {
                let p = if prefix.is_empty() {
                    k.clone()
                } else {
                    format!("{prefix}.{k}")
                };
                all.insert(p.clone());
                paths(v, &p, all, leaves);
            }
        }
        _ => {
            leaves.insert(prefix.to_string());
        }
    }
}

/// A packet of each kind with every optional field present, as JSON.
fn sample(kind: PacketKind) -> Value {
    let el = json!({"v_bat": 7400, "i_bat": 1, "i_loc": 2, "i_grip": 3, "i_3v3": 4, "v_reg": 5000, "i_bo": 6});
    match kind {
        PacketKind::Command => {
            json!({"board": 2, "command": {"hip": {"angle": 4500}}, "seq": 513})
        }
        PacketKind::Heartbeat => json!({
            "board": 1, "hip_target": 9000, "hip_now": 9000, "arm_a_target": 1500, "arm_a_now": 1500,
            "arm_b_target": 1500, "arm_b_now": 1500, "gripper_a_target": 1500, "gripper_a_now": 1500,
            "gripper_b_target": 1500, "gripper_b_now": 1500, "electrical_a": el, "electrical_b": el,
            "target_state": "c", "command_complete": true, "active_bolter": 1, "bolter_attempt": 1,
            "faults": ["low_battery"], "refusal": "not_allowed_in_mode", "mode": "standby",
            "last_seq": 513, "boot": {"cause": "brown_out", "count": 2}
        }),
        PacketKind::InternalHeartbeat => json!({
            "arm_b_target": 1500, "arm_b_now": 1500, "gripper_b_target": 1500, "gripper_b_now": 1500,
            "electrical_b": el,
            "bolter_aux": {"step": "rotate", "seq": 1, "pair": 1, "direction": "bolt", "threshold_reached": false,
                           "locked": false, "timed_out": false, "at_home": false, "mux": {"a0": false, "a1": false}},
            "command_received": 1, "gravity": {"axis": "y", "sign": "+"},
            "arm_over_idle": false, "gripper_over_idle": false, "bolter_over_idle": false,
            "arm_overcurrent": false, "gripper_overcurrent": false, "bolter_overcurrent": false,
            "arm_contracted": false
        }),
        PacketKind::BCommand => json!({
            "seq": 1, "flags": {"regulator": true, "arm": false, "gripper": false, "bolter": false, "stop": false},
            "arm_target": 1500, "gripper_target": 1500,
            "bolter": {"pair": 2, "direction": "unbolt", "step": "rotate"}
        }),
    }
}

#[test]
fn json_key_paths_are_the_field_table_names() {
    for kind in PacketKind::ALL {
        let bytes = codec::encode(kind, &sample(kind).to_string()).unwrap();
        let printed: Value = serde_json::from_str(&codec::decode(kind, &bytes).unwrap()).unwrap();
        assert_eq!(
            printed,
            sample(kind),
            "{kind}: decode(encode(json)) == json"
        );
        let (mut all, mut leaves) = (BTreeSet::new(), BTreeSet::new());
        paths(&printed, "", &mut all, &mut leaves);
        let names: Vec<&str> = kind
            .fields()
            .iter()
            .map(|f| f.name)
            .filter(|n| !not_in_json(kind, n))
            .collect();
        // Every field of the table is in the JSON ...
        for n in &names {
            assert!(all.contains(*n), "{kind}: field {n} missing from {printed}");
        }
        // ... and every JSON value belongs to a field of the table.
        for leaf in &leaves {
            assert!(
                json_only(kind, leaf)
                    || names
                        .iter()
                        .any(|n| leaf == n || leaf.starts_with(&format!("{n}."))),
                "{kind}: JSON key {leaf} is no field of the table"
            );
        }
        // The excluded names do exist in the table (the exclusions are not stale).
        for f in kind.fields() {
            if not_in_json(kind, f.name) {
                assert!(!all.contains(f.name), "{kind}: {} is in the JSON", f.name);
            }
        }
    }
}

#[test]
fn decode_prints_every_field_even_when_empty() {
    // Optional fields print as null rather than disappearing, so the output has one shape.
    let bc = r#"{"seq":0,"flags":{"regulator":false,"arm":false,"gripper":false,"bolter":false,"stop":false},"arm_target":500,"gripper_target":500,"bolter":null}"#;
    let bytes = codec::encode(PacketKind::BCommand, bc).unwrap();
    assert_eq!(codec::decode(PacketKind::BCommand, &bytes).unwrap(), bc);
    let hb = sample(PacketKind::Heartbeat);
    let mut empty = hb.clone();
    empty["active_bolter"] = Value::Null;
    empty["refusal"] = Value::Null;
    empty["faults"] = json!([]);
    let bytes = codec::encode(PacketKind::Heartbeat, &empty.to_string()).unwrap();
    let printed: Value =
        serde_json::from_str(&codec::decode(PacketKind::Heartbeat, &bytes).unwrap()).unwrap();
    assert_eq!(printed, empty);
    assert_eq!(
        printed.as_object().unwrap().len(),
        hb.as_object().unwrap().len()
    );
}
