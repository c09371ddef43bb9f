//! `mmic encode|decode pus-tc|pus-tm` and `mmic xtce` end to end: golden TC, every function and
//! service round trip, every refused input of spec/ccsds/bad-inputs.toml refused by name with
//! exit code 1, every TM the gateway emits round trip, and the generated files fresh and
//! structurally the library's tables.

use mmic::pus::housekeeping::FIELDS;
use mmic_host::{ground, spec, xtce};
use serde::Deserialize;
use serde_json::{json, Value};
use std::path::PathBuf;

use crate::cli::{fails as refused, ok};

fn repo(path: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("..")
        .join(path)
}

#[test]
fn the_readme_tc_encodes_to_its_golden_bytes_and_back() {
    let j = r#"{"apid":257,"seq_count":1,"source_id":0,"ack":"all","function":"reconfiguration","args":{"initial":"a","target":"m"}}"#;
    let hex = ok(&["encode", "pus-tc", j]);
    // 0x1901: TC, secondary header, APID 0x101; c001: unsegmented, count 1; 0009: 10 octets
    // after the primary header; 2f: PUS-C, ack all; 08 01: TC(8,1); 0000: source ID; 09 'a' 'm'.
    assert_eq!(hex, "1901c00100092f0801000009616db8a6");
    assert_eq!(
        mmic::ccsds::pec(&[
            0x19, 0x01, 0xc0, 0x01, 0x00, 0x09, 0x2f, 0x08, 0x01, 0x00, 0x00, 0x09, 0x61, 0x6d
        ]),
        0xb8a6
    );
    let d: Value = serde_json::from_str(&ok(&["decode", "pus-tc", &hex])).unwrap();
    assert_eq!(d["function"], "reconfiguration");
    assert_eq!(d["args"], json!({"initial": "a", "target": "m"}));
    assert_eq!(
        d["command"],
        json!({"reconfigure": {"initial": "a", "target": "m"}})
    );
    assert_eq!(
        (
            d["apid"].clone(),
            d["seq_count"].clone(),
            d["ack_bits"].clone()
        ),
        (json!(257), json!(1), json!(15))
    );
    assert_eq!(
        ok(&["encode", "pus-tc", r#"{"service":17,"subservice":1}"#]),
        "1901c00000062f11010000ce54"
    );
}

fn example_args(f: &spec::Function) -> Value {
    let special = match f.name.as_str() {
        "arm" => json!({"side": 1, "target": 2, "pulse": 2100}),
        "gripper" => json!({"side": 0, "target": 1, "pulse": 0}),
        "hip" => json!({"target": 4, "angle": 35999}),
        "bolter" => json!({"operation": 1, "pair": 4}),
        "primitive" => json!({"primitive": 7, "final_state": "d"}),
        "reconfiguration" => json!({"initial": "e", "target": "n"}),
        _ => Value::Null,
    };
    if !special.is_null() {
        return special;
    }
    f.args
        .iter()
        .map(|a| {
            (
                a.name.clone(),
                if a.is_state() {
                    json!("a")
                } else {
                    json!(a.range[0])
                },
            )
        })
        .collect::<serde_json::Map<_, _>>()
        .into()
}

#[test]
fn every_function_and_service_round_trips_through_the_binary() {
    let mut inputs: Vec<Value> = spec::functions()
        .iter()
        .enumerate()
        .map(|(i, f)| {
            json!({"apid": 0x101 + i, "seq_count": 100 + i, "source_id": 7, "ack": i % 16,
                   "function": f.name, "args": example_args(f)})
        })
        .collect();
    assert_eq!(inputs.len(), 12);
    inputs.push(json!({"service": 17, "subservice": 1, "seq_count": 0x3FFF, "apid": 0x1FF}));
    inputs.push(json!({"service": 3, "subservice": 5, "ack": "none"}));
    inputs.push(json!({"service": 3, "subservice": 6, "ack": {"acceptance": true, "start": false, "progress": false, "completion": true}}));
    inputs.push(json!({"service": 3, "subservice": 31, "interval_ms": 3_600_000}));
    for input in inputs {
        let hex = ok(&["encode", "pus-tc", &input.to_string()]);
        let text = ok(&["decode", "pus-tc", &hex]);
        let d: Value = serde_json::from_str(&text).unwrap();
        for (k, v) in input.as_object().unwrap() {
            match k.as_str() {
                "ack" => {
                    let bits = match v {
                        Value::Number(n) => n.as_u64().unwrap(),
                        Value::String(s) if s == "none" => 0,
                        Value::String(_) => 15,
                        _ => 9,
                    };
                    assert_eq!(d["ack_bits"], json!(bits), "{input}");
                }
                _ => assert_eq!(&d[k], v, "{k} of {input}"),
            }
        }
        // The decoded form encodes back to the same bytes.
        assert_eq!(ok(&["encode", "pus-tc", &text]), hex, "{input}");
    }
}

#[test]
fn encode_pus_tc_refuses_what_the_robot_refuses_and_bad_json() {
    refused(
        &[
            "encode",
            "pus-tc",
            r#"{"function":"mode","args":{"mode":4}}"#,
        ],
        1,
        "argument-out-of-range",
    );
    refused(
        &[
            "encode",
            "pus-tc",
            r#"{"function":"reconfiguration","args":{"initial":"a","target":"d"}}"#,
        ],
        1,
        "no-such-command",
    );
    refused(
        &["encode", "pus-tc", r#"{"service":9,"subservice":1}"#],
        1,
        "unknown-service",
    );
    refused(
        &["encode", "pus-tc", r#"{"function":"warp"}"#],
        2,
        "unknown function \"warp\"",
    );
    refused(
        &[
            "encode",
            "pus-tc",
            r#"{"function":"mode","args":{"mood":2}}"#,
        ],
        2,
        "no argument \"mood\"",
    );
    refused(
        &[
            "encode",
            "pus-tc",
            r#"{"function":"mode","args":{"mode":2},"colour":1}"#,
        ],
        2,
        "unknown key \"colour\"",
    );
    refused(
        &[
            "encode",
            "pus-tc",
            r#"{"function":"mode","args":{"mode":2},"function_id":9}"#,
        ],
        2,
        "disagrees",
    );
    refused(
        &[
            "encode",
            "pus-tc",
            r#"{"apid":2048,"service":17,"subservice":1}"#,
        ],
        2,
        "apid = 2048",
    );
    refused(&["decode", "pus-tc", "19zz"], 2, "invalid hex");
}

#[derive(Deserialize)]
struct Row {
    name: String,
    parser: String,
    hex: String,
    error: String,
}

#[derive(Deserialize)]
struct BadInputs {
    row: Vec<Row>,
}

/// Every row of spec/ccsds/bad-inputs.toml through `mmic decode`: packets as `pus-tc|pus-tm
/// --apid 0x042`, TC frames as `tc-frame --spacecraft-id 0x101` and TM frames as `tm-frame
/// --spacecraft-id 0x142` (the receivers the rows are written for, see the toml's comments):
/// exit code 1, the check's name in stderr, nothing on stdout.
#[test]
fn every_bad_input_is_refused_by_name() {
    let text = std::fs::read_to_string(repo("spec/ccsds/bad-inputs.toml")).unwrap();
    let bad: BadInputs = toml::from_str(&text).unwrap();
    let mut names = std::collections::BTreeSet::new();
    let (mut tc_frames, mut tm_frames) = (
        std::collections::BTreeSet::new(),
        std::collections::BTreeSet::new(),
    );
    for r in &bad.row {
        let (kind, option, value) = match r.parser.as_str() {
            "tc" | "tc-service" => ("pus-tc", "--apid", "0x042"),
            "tm" => ("pus-tm", "--apid", "0x042"),
            "tc-frame" => ("tc-frame", "--spacecraft-id", "0x101"),
            "tm-frame" => ("tm-frame", "--spacecraft-id", "0x142"),
            "cfdp" => {
                refused(
                    &["decode", "cfdp", &r.hex],
                    1,
                    &format!("{} check failed", r.error),
                );
                continue;
            }
            p => panic!("row {}: parser {p} unknown to this test", r.name),
        };
        refused(
            &["decode", kind, &r.hex, option, value],
            1,
            &format!("{} check failed", r.error),
        );
        match kind {
            "tc-frame" => tc_frames.insert(r.error.clone()),
            "tm-frame" => tm_frames.insert(r.error.clone()),
            _ => names.insert(r.error.clone()),
        };
    }
    assert!(bad.row.len() >= 38);
    // Every check of the wire and services layers, and of both frames, was exercised.
    for n in mmic::ccsds::PacketError::NAMES
        .iter()
        .chain(mmic::pus::request::RequestError::NAMES.iter())
    {
        assert!(names.contains(*n), "no bad-input row for {n}");
    }
    for n in mmic::link::tc_frame::TcFrameError::NAMES {
        assert!(tc_frames.contains(n), "no tc-frame bad-input row for {n}");
    }
    for n in mmic::link::tm_frame::TmFrameError::NAMES {
        assert!(tm_frames.contains(n), "no tm-frame bad-input row for {n}");
    }
    // Without --apid, APID 0x042 is no robot's: the good TC of the table is refused as `apid`.
    refused(
        &["decode", "pus-tc", "1842c00700062f1101000012d0"],
        1,
        "apid check failed",
    );
    assert!(ok(&[
        "decode",
        "pus-tc",
        "1842c00700062f1101000012d0",
        "--apid",
        "66"
    ])
    .contains("are_you_alive"));
}

#[test]
fn every_tm_the_gateway_emits_decodes_and_encodes_back() {
    let (tms, _) = ground::session();
    let mut kinds = std::collections::BTreeSet::new();
    for (what, p) in &tms {
        let hex = mmic_host::codec::to_hex(p);
        let text = ok(&["decode", "pus-tm", &hex]);
        let d: Value = serde_json::from_str(&text).unwrap();
        kinds.insert((
            d["service"].as_u64().unwrap(),
            d["subservice"].as_u64().unwrap(),
        ));
        assert_eq!(ok(&["encode", "pus-tm", &text]), hex, "{what}");
    }
    let spec: std::collections::BTreeSet<(u64, u64)> = spec::services()
        .tm
        .iter()
        .flat_map(|t| {
            t.subservices
                .iter()
                .map(|s| (u64::from(t.service), u64::from(*s)))
        })
        .collect();
    assert_eq!(
        kinds, spec,
        "the session emits every TM type of services.toml"
    );
    // A HK report from a heartbeat, and a report, from their JSON.
    let hk = ok(&[
        "encode",
        "pus-tm",
        r#"{"housekeeping":{"board":1,"mode":"operational","faults":[],"refusal":null,"last_seq":3,"target_state":"m","command_complete":true,"active_bolter":null,"bolter_attempt":0,"hip_target":18000,"hip_now":18000,"arm_a_target":1500,"arm_a_now":1500,"arm_b_target":1500,"arm_b_now":1500,"gripper_a_target":1500,"gripper_a_now":1500,"gripper_b_target":1500,"gripper_b_now":1500,"electrical_a":{"v_bat":12000,"i_bat":1,"i_loc":2,"i_grip":3,"i_3v3":4,"v_reg":5,"i_bo":6},"electrical_b":{"v_bat":11000,"i_bat":1,"i_loc":2,"i_grip":3,"i_3v3":4,"v_reg":5,"i_bo":6}}}"#,
    ]);
    let d: Value = serde_json::from_str(&ok(&["decode", "pus-tm", &hk])).unwrap();
    assert_eq!(
        (
            d["parameters"]["v_bat_a"].clone(),
            d["parameters"]["target_state"].clone()
        ),
        (json!(12000), json!(b'm'))
    );
    let r = ok(&[
        "encode",
        "pus-tm",
        r#"{"report":{"stage":"start","request":{"apid":257,"seq_count":9},"failure":{"code":262,"data":64}}}"#,
    ]);
    let d: Value = serde_json::from_str(&ok(&["decode", "pus-tm", &r])).unwrap();
    assert_eq!(d["subservice"], 4);
    assert_eq!(
        d["report"]["failure"]["name"],
        "FAULT_LOCOMOTION_OVERCURRENT_IDLE"
    );
    refused(
        &["decode", "pus-tm", &r, "--apid", "258"],
        1,
        "apid check failed",
    );
    refused(
        &["encode", "pus-tm", r#"{"service":2,"subservice":1}"#],
        1,
        "unknown-service",
    );
    refused(
        &[
            "encode",
            "pus-tm",
            r#"{"service":5,"subservice":1,"source_data":"000100000000"}"#,
        ],
        1,
        "source-data",
    );
}

fn fresh(path: &str, text: &str) {
    let p = repo(path);
    if std::env::var_os("MMIC_REGENERATE").is_some() {
        std::fs::write(&p, text).unwrap();
    }
    let committed = std::fs::read_to_string(&p).unwrap_or_default();
    assert!(
        committed == text,
        "{path} is stale: regenerate with `MMIC_REGENERATE=1 cargo test -p mmic-host --test cli pus::` \
         (or `mmic xtce [--ccsdspy] > {path}`)"
    );
}

#[test]
fn committed_xtce_and_ccsdspy_list_are_fresh() {
    let x = xtce::generate().unwrap();
    assert_eq!(ok(&["xtce"]), x.trim_end());
    fresh("spec/ccsds/mmic.xtce.xml", &x);
    fresh("spec/ccsds/hk-3-25.ccsdspy.csv", &xtce::ccsdspy_csv());
    let again = xtce::generate().unwrap();
    assert_eq!(x, again, "deterministic");
}

/// The text of the element `<tag name="name" ...>...</tag>` in `xml`.
fn element<'a>(xml: &'a str, tag: &str, name: &str) -> &'a str {
    let open = format!("<{tag} name=\"{name}\"");
    let start = xml.find(&open).unwrap_or_else(|| panic!("no {open}"));
    let rest = &xml[start..];
    let end = rest
        .find(&format!("</{tag}>"))
        .map(|e| e + tag.len() + 3)
        .or_else(|| rest.find("/>").map(|e| e + 2))
        .unwrap();
    &rest[..end]
}

fn attr<'a>(text: &'a str, key: &str) -> Vec<&'a str> {
    text.split(&format!("{key}=\""))
        .skip(1)
        .map(|s| s.split('"').next().unwrap())
        .collect()
}

/// The TM(3,25) container holds `FIELDS` in order, each with a type of its size; every function
/// argument has the range of functions.toml. (A swapped or resized field in the generator fails
/// here even after the committed file is regenerated.)
#[test]
fn xtce_structure_is_the_librarys_tables() {
    let x = xtce::generate().unwrap();
    let hk = element(&x, "SequenceContainer", "hk-report");
    let refs = attr(hk, "parameterRef");
    let entries: Vec<&str> = refs
        .iter()
        .copied()
        .filter(|r| !r.starts_with("ccsds_") && *r != "service" && *r != "subservice")
        .collect();
    let mut want = vec!["hk_sid"];
    want.extend(FIELDS.iter().map(|f| f.name));
    assert_eq!(entries, want);
    for f in FIELDS.iter() {
        let p = element(&x, "Parameter", f.name);
        let ty = attr(p, "parameterTypeRef")[0];
        let t = ["IntegerParameterType", "EnumeratedParameterType"]
            .iter()
            .find_map(|tag| {
                x.contains(&format!("<{tag} name=\"{ty}\""))
                    .then(|| element(&x, tag, ty))
            })
            .unwrap();
        assert_eq!(
            attr(t, "sizeInBits"),
            [(f.len * 8).to_string()],
            "{}",
            f.name
        );
    }
    for f in spec::functions() {
        let c = element(&x, "MetaCommand", &f.name);
        let names: Vec<&str> = attr(c, "argumentRef");
        let want: Vec<&str> = f.args.iter().map(|a| a.name.as_str()).collect();
        assert_eq!(names, want, "{}", f.name);
        for a in f.args.iter().filter(|a| !a.is_state()) {
            let t = element(
                &x,
                "IntegerArgumentType",
                &format!("{}_{}_type", f.name, a.name),
            );
            assert_eq!(attr(t, "minInclusive"), [a.range[0].to_string()]);
            assert_eq!(attr(t, "maxInclusive"), [a.range[1].to_string()]);
        }
    }
}

/// `mmic sim --protocol pus --ground-tm-to`: the simulated robot serves an external ground
/// over UDP. A TC sent to the port of its first line reaches board A through the gateway:
/// `mode` operational is accepted, started and completed (TM(1,1), (1,3), (1,7)), and the
/// gateway's housekeeping then says Operational; the packet lines are the ones it sent.
#[test]
fn the_simulator_takes_telecommands_from_an_external_ground() {
    use std::io::{BufRead, BufReader};
    use std::net::UdpSocket;
    use std::time::{Duration, Instant};
    let ground = UdpSocket::bind("127.0.0.1:0").unwrap();
    ground
        .set_read_timeout(Some(Duration::from_millis(200)))
        .unwrap();
    let tm_to = ground.local_addr().unwrap().to_string();
    let out = std::env::temp_dir().join(format!("mmic-ext-{}", std::process::id()));
    let mut child = std::process::Command::new(env!("CARGO_BIN_EXE_mmic"))
        .args(["sim", "--protocol", "pus", "--ground-tm-to", &tm_to])
        .args(["--ground-tc-port", "0", "--max-seconds", "20", "--out"])
        .arg(&out)
        .stdout(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    let mut lines = BufReader::new(child.stdout.take().unwrap()).lines();
    let ready: Value = serde_json::from_str(&lines.next().unwrap().unwrap()).unwrap();
    assert_eq!(ready["ready"], true);
    let port = ready["tc_port"].as_u64().unwrap() as u16;
    let tc = ok(&[
        "encode",
        "pus-tc",
        r#"{"apid":257,"seq_count":5,"source_id":3,"function":"mode","args":{"mode":2}}"#,
    ]);
    ground
        .send_to(
            &mmic_host::codec::from_hex(&tc).unwrap(),
            ("127.0.0.1", port),
        )
        .unwrap();
    let (mut stages, mut operational) = (Vec::new(), false);
    let mut received = Vec::new();
    let end = Instant::now() + Duration::from_secs(15);
    while Instant::now() < end && !(stages.len() == 3 && operational) {
        let mut b = [0u8; 512];
        let Ok(n) = ground.recv(&mut b) else { continue };
        let hex: String = b[..n].iter().map(|x| format!("{x:02x}")).collect();
        let d: Value = serde_json::from_str(&ok(&["decode", "pus-tm", &hex])).unwrap();
        received.push(hex);
        match (d["service"].as_u64(), d["subservice"].as_u64()) {
            (Some(1), Some(s)) if d["report"]["request"]["seq_count"] == 5 => stages.push(s),
            (Some(3), Some(25)) => operational |= d["housekeeping"]["mode"] == "operational",
            _ => {}
        }
    }
    let _ = child.kill();
    let _ = child.wait();
    assert_eq!(stages, [1, 3, 7]);
    assert!(operational, "no HK in Operational");
    // The robot's own lines: the TC it took, and every TM it sent.
    let logged: Vec<Value> = lines
        .map_while(Result::ok)
        .filter_map(|l| serde_json::from_str(&l).ok())
        .collect();
    assert!(logged
        .iter()
        .any(|l| l["dir"] == "tc" && l["hex"] == tc.as_str() && l["refused"].is_null()));
    for hex in &received {
        assert!(logged
            .iter()
            .any(|l| l["dir"] == "tm" && l["hex"] == hex.as_str()));
    }
    let _ = std::fs::remove_dir_all(out);
}

/// `mmic sim --protocol pus --link frames --ground-tm-to`: the same behind the space data link.
/// The ground here is the library's own FOP-1 end (`GroundLink`): it initiates the AD service on
/// the robot's first CLCW, sends `mode` operational in an AD frame, and extracts the ST[1]
/// reports from the 256-octet TM frames; the robot's lines are one per frame (`tc-frame` with
/// FARM-1's verdict and the packets, `tm-frame` for every frame it sent).
#[test]
fn the_simulator_takes_tc_frames_from_an_external_ground() {
    use mmic::link::fop::FopState;
    use mmic::link::tm_frame::TM_FRAME_LEN;
    use mmic::node::ground::frames::GroundLink;
    use mmic::units::BoardNumber;
    use std::io::{BufRead, BufReader};
    use std::net::UdpSocket;
    use std::time::{Duration, Instant};
    let ground = UdpSocket::bind("127.0.0.1:0").unwrap();
    ground
        .set_read_timeout(Some(Duration::from_millis(50)))
        .unwrap();
    let tm_to = ground.local_addr().unwrap().to_string();
    let out = std::env::temp_dir().join(format!("mmic-ext-frames-{}", std::process::id()));
    let mut child = std::process::Command::new(env!("CARGO_BIN_EXE_mmic"))
        .args(["sim", "--protocol", "pus", "--link", "frames"])
        .args(["--ground-tm-to", &tm_to, "--ground-tc-port", "0"])
        .args(["--max-seconds", "20", "--out"])
        .arg(&out)
        .stdout(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    let mut lines = BufReader::new(child.stdout.take().unwrap()).lines();
    let ready: Value = serde_json::from_str(&lines.next().unwrap().unwrap()).unwrap();
    assert_eq!(ready["ready"], true);
    let port = ready["tc_port"].as_u64().unwrap() as u16;
    let tc = ok(&[
        "encode",
        "pus-tc",
        r#"{"apid":257,"seq_count":5,"source_id":3,"function":"mode","args":{"mode":2}}"#,
    ]);
    let packet = mmic_host::codec::from_hex(&tc).unwrap();
    let start = Instant::now();
    let now = || start.elapsed().as_millis() as u32;
    let mut link: GroundLink<10, 8, 1024> = GroundLink::new(BoardNumber::ONE);
    let mut frames_out: Vec<Vec<u8>> = Vec::new();
    link.start(now(), &mut |f: &[u8]| frames_out.push(f.to_vec()));
    let (mut sent, mut stages, mut received) = (false, Vec::new(), Vec::new());
    let end = Instant::now() + Duration::from_secs(15);
    while Instant::now() < end && stages.len() < 3 {
        if !sent && link.state() == FopState::Active {
            link.send(&packet, now(), &mut |f: &[u8]| frames_out.push(f.to_vec()))
                .unwrap();
            sent = true;
        }
        for f in frames_out.drain(..) {
            ground.send_to(&f, ("127.0.0.1", port)).unwrap();
        }
        let mut b = [0u8; 512];
        let Ok(n) = ground.recv(&mut b) else {
            link.tick(now(), &mut |f: &[u8]| frames_out.push(f.to_vec()));
            continue;
        };
        assert_eq!(n, TM_FRAME_LEN, "one 256-octet TM frame per datagram");
        received.push(
            b[..n]
                .iter()
                .map(|x| format!("{x:02x}"))
                .collect::<String>(),
        );
        let mut packets = Vec::new();
        link.tm_frame(
            now(),
            &b[..n],
            &mut |f: &[u8]| frames_out.push(f.to_vec()),
            &mut |p: &[u8]| packets.push(p.to_vec()),
        )
        .unwrap();
        for p in packets {
            let hex: String = p.iter().map(|x| format!("{x:02x}")).collect();
            let d: Value = serde_json::from_str(&ok(&["decode", "pus-tm", &hex])).unwrap();
            if d["service"] == 1 && d["report"]["request"]["seq_count"] == 5 {
                stages.push(d["subservice"].as_u64().unwrap());
            }
        }
    }
    let _ = child.kill();
    let _ = child.wait();
    assert_eq!(stages, [1, 3, 7]);
    assert_eq!(link.counters().confirmed, 1, "{:?}", link.counters());
    let logged: Vec<Value> = lines
        .map_while(Result::ok)
        .filter_map(|l| serde_json::from_str(&l).ok())
        .collect();
    let tc_frames: Vec<&Value> = logged.iter().filter(|l| l["dir"] == "tc-frame").collect();
    assert_eq!(tc_frames.len(), 1, "{tc_frames:?}");
    assert_eq!(tc_frames[0]["farm"], "accept");
    assert!(tc_frames[0]["refused"].is_null());
    assert_eq!(tc_frames[0]["packets"], json!([tc]));
    for hex in &received {
        assert!(logged
            .iter()
            .any(|l| l["dir"] == "tm-frame" && l["hex"] == hex.as_str()));
    }
    assert!(logged.iter().all(|l| l["dir"] != "tc" && l["dir"] != "tm"));
    let _ = std::fs::remove_dir_all(out);
}
