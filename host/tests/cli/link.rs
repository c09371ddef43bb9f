//! `mmic encode|decode tc-frame|tm-frame|clcw` end to end: the golden frames of
//! tests/ccsds/tc_frame.rs and tm_frame.rs both ways, decode → encode round trips, the TM
//! frame's padding, every refusal by its check's name and exit code. (Every `tc-frame` and
//! `tm-frame` row of spec/ccsds/bad-inputs.toml is refused by name in `pus.rs`'s walk.)

use serde_json::{json, Value};

use crate::cli::{fails as refused, ok};

/// The TC(17,1) ping of APID 0x042 (spec/ccsds/bad-inputs.toml's reference packet).
const PING: &str = "1842c00700062f1101000012d0";
/// The ping in an AD frame of spacecraft 0x101, VC 0, N(S) 0, MAP 0 (tests/ccsds/tc_frame.rs).
const AD_PING: &str = "0101001400c01842c00700062f1101000012d06a5a";
const BC_UNLOCK: &str = "3101000700004bfd";
const BC_SET_VR_5: &str = "310100090082000525b3";
/// The TM(17,2) of bad-inputs.toml, the first packet of the reference TM frame.
const TM_17_2: &str = "0842c009000e201102000300000000005a8000ef0f";

/// The reference TM frame of spec/ccsds/bad-inputs.toml (hand-checked in
/// tests/ccsds/tm_frame.rs): spacecraft 0x142, VC 0, counts 0x12/0x34, first header pointer 0,
/// the TM(17,2) then a 223-octet idle packet, CLCW 01000000.
fn reference_tm_frame() -> String {
    let mut s = String::from("142112341800");
    s += TM_17_2;
    s += "07ffc00000d8";
    s += &"55".repeat(223 - 6);
    s += "01000000";
    s += "1746";
    assert_eq!(s.len(), 512);
    s
}

fn decode(args: &[&str]) -> Value {
    serde_json::from_str(&ok(args)).unwrap()
}

/// The decoded form encodes back to the same bytes.
fn round_trips(kind: &str, hex: &str, extra: &[&str]) -> Value {
    let mut args = vec!["decode", kind, hex];
    args.extend_from_slice(extra);
    let text = ok(&args);
    assert_eq!(ok(&["encode", kind, &text]), hex, "{kind} {text}");
    serde_json::from_str(&text).unwrap()
}

#[test]
fn the_golden_tc_frames_decode_field_by_field() {
    let d = round_trips("tc-frame", AD_PING, &["--apid", "0x42"]);
    let want = json!({
        "kind": "ad", "version": 0, "bypass": false, "control_command": false, "spare": 0,
        "spacecraft_id": 0x101, "vcid": 0, "length": 20, "seq": 0,
        "sequence_flags": 3, "map_id": 0, "data_field": format!("c0{PING}"), "data": PING,
        "control": null, "fecf": "6a5a", "len": 21,
    });
    for (k, v) in want.as_object().unwrap() {
        assert_eq!(&d[k], v, "{k}");
    }
    let packets = d["packets"].as_array().unwrap();
    assert_eq!(packets.len(), 1);
    assert_eq!(packets[0]["hex"], PING);
    // The packet as `decode pus-tc` prints it.
    let tc = decode(&["decode", "pus-tc", PING, "--apid", "0x42"]);
    assert_eq!(packets[0]["pus_tc"], tc);
    assert_eq!(packets[0]["pus_tc"]["request"], "are_you_alive");
    assert_eq!(packets[0]["pus_tc_refused"], Value::Null);
    // Without --apid, 0x042 is no robot's: the frame decodes, the packet is refused by name.
    let d = decode(&["decode", "tc-frame", AD_PING]);
    assert_eq!(d["packets"][0]["pus_tc"], Value::Null);
    assert!(d["packets"][0]["pus_tc_refused"]
        .as_str()
        .unwrap()
        .starts_with("apid check failed"));

    let d = round_trips("tc-frame", BC_UNLOCK, &[]);
    assert_eq!(
        (
            d["kind"].clone(),
            d["bypass"].clone(),
            d["control_command"].clone(),
            d["control"].clone(),
            d["map_id"].clone(),
            d["packets"].clone(),
            d["length"].clone(),
        ),
        (
            json!("bc"),
            json!(true),
            json!(true),
            json!("unlock"),
            Value::Null,
            json!([]),
            json!(7)
        )
    );
    let d = round_trips("tc-frame", BC_SET_VR_5, &[]);
    assert_eq!(d["control"], json!({"set-vr": 5}));
    assert_eq!(d["data_field"], "820005");
}

#[test]
fn tc_frames_encode_from_their_short_json() {
    assert_eq!(
        ok(&[
            "encode",
            "tc-frame",
            &json!({"spacecraft_id": 257, "vcid": 0, "seq": 0, "kind": "ad", "map_id": 0, "data": PING}).to_string()
        ]),
        AD_PING
    );
    // Every key has a default: spacecraft 0x101, VC 0, N(S) 0, AD, MAP 0.
    assert_eq!(
        ok(&["encode", "tc-frame", &json!({"data": PING}).to_string()]),
        AD_PING
    );
    assert_eq!(
        ok(&["encode", "tc-frame", r#"{"kind":"bc","control":"unlock"}"#]),
        BC_UNLOCK
    );
    assert_eq!(
        ok(&["encode", "tc-frame", r#"{"control":{"set-vr":5}}"#]),
        BC_SET_VR_5
    );
    // A BD frame of two packets blocked, N(S) 9, another robot, MAP 3, no FECF: decodes with
    // the options that match it, and round trips.
    let two = format!("{PING}{PING}");
    let hex = ok(&[
        "encode",
        "tc-frame",
        &json!({"spacecraft_id": 0x1ff, "seq": 9, "kind": "bd", "map_id": 3, "data": two, "fecf": null}).to_string(),
    ]);
    assert_eq!(&hex[..12], "21ff001f09c3");
    refused(&["decode", "tc-frame", &hex], 1, "fecf check failed");
    refused(
        &["decode", "tc-frame", &hex, "--no-fecf"],
        1,
        "map-id check failed: TC frame: MAP 3 is not one virtual channel 0 accepts",
    );
    let d = round_trips(
        "tc-frame",
        &hex,
        &["--map-id", "3", "--no-fecf", "--apid", "0x42"],
    );
    assert_eq!(d["packets"].as_array().unwrap().len(), 2);
    assert_eq!(d["fecf"], Value::Null);
    // Without a segment header.
    let hex = ok(&[
        "encode",
        "tc-frame",
        &json!({"map_id": null, "data": PING}).to_string(),
    ]);
    assert_eq!(hex.len(), (5 + 13 + 2) * 2);
    refused(
        &["decode", "tc-frame", &hex],
        1,
        "sequence-flags check failed",
    );
    assert_eq!(
        round_trips("tc-frame", &hex, &["--no-segment-header"])["map_id"],
        Value::Null
    );
}

#[test]
fn tc_frame_refusals_name_their_check() {
    // Another robot's frame, when the receiver is named.
    refused(
        &["decode", "tc-frame", AD_PING, "--spacecraft-id", "0x102"],
        1,
        "spacecraft-id check failed: TC frame: spacecraft ID 0x101, this receiver is 0x102",
    );
    // Data not ending on a packet boundary: refused by the encoder too.
    refused(
        &[
            "encode",
            "tc-frame",
            &json!({"data": &PING[..24]}).to_string(),
        ],
        1,
        "packet-boundary check failed",
    );
    refused(
        &["encode", "tc-frame", r#"{"kind":"bc"}"#],
        2,
        "needs \"control\"",
    );
    refused(
        &["encode", "tc-frame", r#"{"kind":"ad","control":"unlock"}"#],
        2,
        "BC frames",
    );
    refused(
        &["encode", "tc-frame", r#"{"control":{"set-vr":256}}"#],
        2,
        "control",
    );
    refused(
        &["encode", "tc-frame", r#"{"spacecraft_id":1024}"#],
        2,
        "spacecraft_id = 1024",
    );
    refused(
        &["encode", "tc-frame", r#"{"data":"00","colour":1}"#],
        2,
        "unknown key \"colour\"",
    );
    // A derived key that disagrees.
    refused(
        &[
            "encode",
            "tc-frame",
            &json!({"data": PING, "fecf": "0000"}).to_string(),
        ],
        2,
        "fecf = \"0000\" disagrees",
    );
    // 1024 octets at most (the frame length field).
    refused(
        &[
            "encode",
            "tc-frame",
            &json!({"data": "00".repeat(1020)}).to_string(),
        ],
        2,
        "at most 1024",
    );
    // Frame options belong to frames.
    refused(
        &["decode", "pus-tc", PING, "--spacecraft-id", "0x101"],
        2,
        "for tc-frame and tm-frame only",
    );
    refused(
        &["decode", "tc-frame", AD_PING, "--spacecraft-id", "0x400"],
        2,
        "more than 10 bits",
    );
    refused(
        &["decode", "tc-frame", AD_PING, "--map-id", "64"],
        2,
        "MAP ID",
    );
    refused(
        &["decode", "tc-frame", AD_PING, "--vcid", "64"],
        2,
        "virtual channel ID",
    );
}

#[test]
fn the_reference_tm_frame_decodes_and_encodes_both_ways() {
    let frame = reference_tm_frame();
    let d = round_trips("tm-frame", &frame, &["--spacecraft-id", "0x142"]);
    let want = json!({
        "version": 0, "spacecraft_id": 0x142, "vcid": 0, "ocf_flag": true,
        "mc_frame_count": 0x12, "vc_frame_count": 0x34, "secondary_header_flag": false,
        "synch_flag": false, "packet_order_flag": false, "segment_length_id": 3,
        "first_header_pointer": 0, "first_header_pointer_field": 0,
        "ocf": "01000000", "fecf": "1746", "len": 256,
    });
    for (k, v) in want.as_object().unwrap() {
        assert_eq!(&d[k], v, "{k}");
    }
    assert_eq!(d["data"].as_str().unwrap().len(), 244 * 2);
    assert_eq!(d["clcw"], decode(&["decode", "clcw", "01000000"]));
    // Built from the packet, padded with the idle packet the framer would add.
    let short = json!({"spacecraft_id": 0x142, "mc_frame_count": 0x12, "vc_frame_count": 0x34,
                       "data": TM_17_2, "pad": true, "ocf": "01000000"});
    assert_eq!(ok(&["encode", "tm-frame", &short.to_string()]), frame);
    // The OCF as a CLCW object.
    let with_clcw = json!({"spacecraft_id": 0x142, "mc_frame_count": 0x12, "vc_frame_count": 0x34,
                           "data": TM_17_2, "pad": true, "clcw": {}});
    assert_eq!(ok(&["encode", "tm-frame", &with_clcw.to_string()]), frame);
    // Any robot's frame decodes without --spacecraft-id; another robot's is refused with it.
    assert_eq!(
        decode(&["decode", "tm-frame", &frame])["spacecraft_id"],
        0x142
    );
    refused(
        &["decode", "tm-frame", &frame, "--spacecraft-id", "0x143"],
        1,
        "spacecraft-id check failed: TM frame: spacecraft ID must be 0x143, found 0x142",
    );
}

#[test]
fn tm_frames_of_every_first_header_pointer_round_trip() {
    for (fhp, pad) in [
        (json!("only-idle-data"), false),
        (json!("no-packet-start"), false),
        (json!(243), false),
        (json!(21), true),
    ] {
        let data = if pad {
            TM_17_2.to_string()
        } else {
            "55".repeat(244)
        };
        let j = json!({"spacecraft_id": 0x1ff, "vc_frame_count": 255, "first_header_pointer": fhp,
                       "data": data, "pad": pad, "clcw": {"lockout": true, "report_value": 200}});
        let hex = ok(&["encode", "tm-frame", &j.to_string()]);
        let d = round_trips("tm-frame", &hex, &[]);
        assert_eq!(d["first_header_pointer"], fhp);
        assert_eq!(d["clcw"]["lockout"], true);
        assert_eq!(d["clcw"]["report_value"], 200);
    }
    // Other frame parameters: 64 octets without OCF or FECF, VC 7.
    let j = json!({"len": 64, "vcid": 7, "ocf": null, "fecf": null, "data": "55".repeat(58)});
    let hex = ok(&["encode", "tm-frame", &j.to_string()]);
    assert_eq!(hex.len(), 128);
    refused(&["decode", "tm-frame", &hex], 1, "length check failed");
    let d = round_trips(
        "tm-frame",
        &hex,
        &["--frame-len", "64", "--vcid", "7", "--no-ocf", "--no-fecf"],
    );
    assert_eq!(
        (d["ocf"].clone(), d["clcw"].clone()),
        (Value::Null, Value::Null)
    );
}

#[test]
fn tm_frame_refusals() {
    // The data field whole, or padded when asked.
    refused(
        &[
            "encode",
            "tm-frame",
            &json!({"data": TM_17_2, "ocf": "01000000"}).to_string(),
        ],
        2,
        "the data field must be 244 octets, found 21",
    );
    refused(
        &[
            "encode",
            "tm-frame",
            &json!({"data": "55".repeat(240), "pad": true, "ocf": "01000000"}).to_string(),
        ],
        2,
        "4 octets left",
    );
    refused(
        &[
            "encode",
            "tm-frame",
            &json!({"data": "55".repeat(244)}).to_string(),
        ],
        2,
        "give \"ocf\"",
    );
    refused(
        &[
            "encode",
            "tm-frame",
            &json!({"data": "55".repeat(244), "ocf": "010000"}).to_string(),
        ],
        2,
        "ocf: 4 octets, found 3",
    );
    // An OCF that is no CLCW: the frame is valid (its parser takes any OCF), the CLCW refused.
    let hex = ok(&[
        "encode",
        "tm-frame",
        &json!({"data": "55".repeat(244), "ocf": "80000000"}).to_string(),
    ]);
    let d = round_trips("tm-frame", &hex, &[]);
    assert_eq!(d["clcw"], Value::Null);
    assert!(d["clcw_refused"]
        .as_str()
        .unwrap()
        .starts_with("control-word-type check failed"));
    refused(
        &[
            "encode",
            "tm-frame",
            &json!({"data": "55".repeat(244), "clcw": {"vcid": 64}}).to_string(),
        ],
        2,
        "clcw",
    );
    refused(
        &[
            "encode",
            "tm-frame",
            &json!({"data": "55".repeat(244), "clcw": {}, "first_header_pointer": 244}).to_string(),
        ],
        2,
        "first header pointer 244 does not fit (at most 243)",
    );
    refused(
        &[
            "decode",
            "tm-frame",
            &reference_tm_frame(),
            "--frame-len",
            "12",
        ],
        2,
        "no TM frame has length 12",
    );
}

#[test]
fn clcw_every_field_both_ways() {
    // tests/ccsds' example word: Retransmit, FARM-B counter 2, N(R) 7.
    let d = decode(&["decode", "clcw", "01000c07"]);
    assert_eq!(
        d,
        json!({"control_word_type": 0, "clcw_version": 0, "status": 0, "cop_in_effect": 1,
               "vcid": 0, "no_rf_available": false, "no_bit_lock": false, "lockout": false,
               "wait": false, "retransmit": true, "farm_b_counter": 2, "report_value": 7,
               "word": "01000c07"})
    );
    assert_eq!(ok(&["encode", "clcw", &d.to_string()]), "01000c07");
    // Every field at its largest: status 7, VC 63, every flag, counter 3, N(R) 255.
    let all = json!({"status": 7, "vcid": 63, "no_rf_available": true, "no_bit_lock": true,
                     "lockout": true, "wait": true, "retransmit": true, "farm_b_counter": 3,
                     "report_value": 255});
    let hex = ok(&["encode", "clcw", &all.to_string()]);
    // 0 00 111 01 | 111111 00 | 1 1 1 1 1 11 0 | 11111111
    assert_eq!(hex, "1dfcfeff");
    let back = decode(&["decode", "clcw", &hex]);
    for (k, v) in all.as_object().unwrap() {
        assert_eq!(&back[k], v, "{k}");
    }
    refused(
        &["decode", "clcw", "02000c07"],
        1,
        "cop-in-effect check failed",
    );
    refused(
        &["decode", "clcw", "01000d07"],
        1,
        "reserved-spare check failed",
    );
    refused(&["decode", "clcw", "01000c"], 1, "length check failed");
    refused(&["encode", "clcw", r#"{"vcid":64}"#], 2, "clcw");
    refused(
        &["encode", "clcw", r#"{"colour":1}"#],
        2,
        "unknown key \"colour\"",
    );
    refused(
        &["encode", "clcw", r#"{"report_value":7,"word":"01000000"}"#],
        2,
        "disagrees",
    );
    refused(
        &["encode", "clcw", r#"{"cop_in_effect":2}"#],
        2,
        "disagrees",
    );
}

/// In process (no binary spawned, so that many values are cheap): every N(S), every control
/// command and every MAP ID through `encode tc-frame` → the library's own emission →
/// `decode tc-frame` → `encode tc-frame` again, the same octets each time.
#[test]
fn tc_frame_json_round_trips_over_every_seq_map_and_control_command() {
    use mmic::link::tc_frame::{MapId, SpacecraftId, TcContent, TcFrameRepr, Vcid};
    use mmic::link::ControlCommand;
    use mmic_host::link::{decode_tc_frame, encode_tc_frame, FrameOptions};
    let ping = mmic_host::codec::from_hex(PING).unwrap();
    let mut n = 0;
    let mut check = |j: Value, repr: TcFrameRepr<'_>, options: &FrameOptions| {
        let bytes = encode_tc_frame(&j.to_string(), &[0x42]).unwrap();
        let mut want = vec![0u8; repr.len()];
        repr.emit(&mut want).unwrap();
        assert_eq!(bytes, want, "{j}");
        let d = decode_tc_frame(&bytes, options).unwrap();
        assert_eq!(
            encode_tc_frame(&d.to_string(), &[0x42]).unwrap(),
            bytes,
            "{d}"
        );
        n += 1;
    };
    let sc = SpacecraftId::new(0x1a5).unwrap();
    let vc = Vcid::new(0).unwrap();
    let options = |map_id: u8| FrameOptions {
        spacecraft_id: Some(0x1a5),
        map_id: Some(map_id),
        apids: vec![0x42],
        ..FrameOptions::default()
    };
    for seq in 0..=255u8 {
        for (kind, ad) in [("ad", true), ("bd", false)] {
            let map = seq % 64;
            let map_id = Some(MapId::new(map).unwrap());
            let content = if ad {
                TcContent::Ad {
                    map_id,
                    data: &ping,
                }
            } else {
                TcContent::Bd {
                    map_id,
                    data: &ping,
                }
            };
            let repr = TcFrameRepr {
                spacecraft_id: sc,
                vcid: vc,
                seq,
                content,
            };
            let j = json!({"spacecraft_id": 0x1a5, "seq": seq, "kind": kind, "map_id": map, "data": PING});
            check(j, repr, &options(map));
        }
        let vr = seq;
        for (control, c) in [
            (json!({"set-vr": vr}), ControlCommand::SetVr(vr)),
            (json!("unlock"), ControlCommand::Unlock),
        ] {
            let repr = TcFrameRepr {
                spacecraft_id: sc,
                vcid: vc,
                seq,
                content: TcContent::Bc(c),
            };
            let j = json!({"spacecraft_id": 0x1a5, "seq": seq, "kind": "bc", "control": control});
            check(j, repr, &options(0));
        }
    }
    assert_eq!(n, 256 * 4);
}

/// In process: every first header pointer value (0..=243 and the two reserved ones) and every
/// value of each CLCW field in turn, through `encode tm-frame` → `decode tm-frame` → `encode`.
#[test]
fn tm_frame_and_clcw_json_round_trip_over_every_field_value() {
    use mmic_host::link::{decode_clcw, decode_tm_frame, encode_clcw, encode_tm_frame};
    let options = mmic_host::link::FrameOptions::default();
    let mut fhps: Vec<Value> = (0..244).map(|p| json!(p)).collect();
    fhps.extend([json!("no-packet-start"), json!("only-idle-data")]);
    for (i, fhp) in fhps.iter().enumerate() {
        let j = json!({"spacecraft_id": 0x100 + i, "mc_frame_count": i, "vc_frame_count": 255 - i,
                       "first_header_pointer": fhp, "data": "55".repeat(244), "ocf": "01000c07"});
        let bytes = encode_tm_frame(&j.to_string()).unwrap();
        let d = decode_tm_frame(&bytes, &options).unwrap();
        assert_eq!(&d["first_header_pointer"], fhp);
        assert_eq!(d["vc_frame_count"], 255 - i);
        assert_eq!(encode_tm_frame(&d.to_string()).unwrap(), bytes);
    }
    let mut clcws = Vec::new();
    for (field, max) in [
        ("status", 7),
        ("vcid", 63),
        ("farm_b_counter", 3),
        ("report_value", 255),
    ] {
        clcws.extend((0..=max).map(|v| json!({ field: v })));
    }
    for flag in [
        "no_rf_available",
        "no_bit_lock",
        "lockout",
        "wait",
        "retransmit",
    ] {
        clcws.extend([json!({ flag: true }), json!({ flag: false })]);
    }
    assert_eq!(clcws.len(), 8 + 64 + 4 + 256 + 10);
    for c in &clcws {
        let bytes = encode_clcw(&c.to_string()).unwrap();
        let d = decode_clcw(&bytes).unwrap();
        for (k, v) in c.as_object().unwrap() {
            assert_eq!(&d[k], v, "{c}");
        }
        assert_eq!(encode_clcw(&d.to_string()).unwrap(), bytes);
        // The same word through the library.
        let lib = mmic::link::clcw::Clcw::parse(&bytes).unwrap();
        assert_eq!(lib.emit().to_vec(), bytes);
    }
}

/// `mmic decode cfdp`: YAMCS's EOF PDU (its PacketParseTest) as its header's fields and its data
/// field; `mmic encode cfdp` is refused as a usage error (decode only).
#[test]
fn decode_cfdp_reads_yamcs_eof() {
    let d = decode(&[
        "decode",
        "cfdp",
        "00000a130018000000010015048000000000000065fc",
    ]);
    assert_eq!(d["header"]["pdu_type"], "Directive");
    assert_eq!(d["header"]["mode"], "Acknowledged");
    assert_eq!(
        (
            &d["header"]["source"],
            &d["header"]["seq"],
            &d["header"]["dest"]
        ),
        (&json!(0x18), &json!(1), &json!(0x15))
    );
    assert_eq!(d["header"]["data_len"], 10);
    assert_eq!(d["data"], "048000000000000065fc");
    refused(
        &["encode", "cfdp", "{}"],
        mmic_host::exit::EXIT_INPUT.into(),
        "decoded only",
    );
}
