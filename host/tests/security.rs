//! Security where `mmic sim` runs (issue 38): nothing runs weaker than asked, the durable state
//! of given keys survives the process (no IV reused, no frame of an earlier run accepted), and
//! the provisioning step refuses what would undo that.
//!
//! Each test runs the real binary, as a user would.

use mmic::ccsds::primary::{Apid, SeqCount};
use mmic::ccsds::tc::TcRepr;
use mmic::ccsds::tc_header::{AckFlags, TcSecondaryHeader};
use mmic::link::sdls::{self, mission, SaTable};
use mmic::link::tc_frame::{MapId, SpacecraftId, TcContent, TcFrameRepr, Vcid};
use mmic::units::BoardNumber;
use serde_json::Value;
use std::io::{BufRead, BufReader, Read};
use std::net::UdpSocket;
use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};
use std::time::{Duration, Instant};

fn mmic(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_mmic"))
        .args(args)
        .output()
        .expect("run mmic")
}

/// A fresh directory under the target directory.
fn scratch(name: &str) -> PathBuf {
    let d = PathBuf::from(env!("CARGO_TARGET_TMPDIR"))
        .join(format!("security-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// Random keys for robot 1 (spi-257.key, spi-513.key), mode 0600, in `dir`.
fn keys(dir: &Path) -> (Vec<u8>, Vec<u8>) {
    std::fs::create_dir_all(dir).unwrap();
    let random = || {
        let mut b = vec![0u8; 32];
        std::fs::File::open("/dev/urandom")
            .unwrap()
            .read_exact(&mut b)
            .unwrap();
        b
    };
    let (tc, tm) = (random(), random());
    for (spi, k) in [(257, &tc), (513, &tm)] {
        let p = dir.join(format!("spi-{spi}.key"));
        std::fs::write(&p, k).unwrap();
        std::os::unix::fs::PermissionsExt::set_mode(
            &mut std::fs::metadata(&p).unwrap().permissions(),
            0o600,
        );
    }
    (tc, tm)
}

fn refused(args: &[&str], needle: &str) {
    let t = Instant::now();
    let o = mmic(args);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{args:?}: {err}");
    assert!(err.contains(needle), "{args:?}: {err:?} lacks {needle:?}");
    // Refused before anything ran: no wait, no output of a run.
    assert!(t.elapsed() < Duration::from_secs(10), "{args:?}");
    assert!(!String::from_utf8_lossy(&o.stdout).contains("\"ready\""));
}

/// Every option set that cannot give the SDLS asked for is refused (exit 2), naming what is
/// missing. The first is issue 38's silent downgrade: on main at ca6056d it ran the link in
/// clear and took a clear TC(8,1).
#[test]
fn every_option_set_weaker_than_asked_is_refused_naming_what_is_missing() {
    let d = scratch("downgrade");
    let kd = d.join("keys");
    keys(&kd);
    let (k, state) = (kd.to_str().unwrap(), d.join("state.json"));
    let st = state.to_str().unwrap();
    let inside = kd.join("state.json");
    let ext = [
        "--ground-tm-to",
        "127.0.0.1:9",
        "--ground-tc-port",
        "0",
        "--max-seconds",
        "1",
    ];
    let pf = ["sim", "--protocol", "pus", "--link", "frames"];
    let cases: Vec<(Vec<&str>, &str)> = vec![
        (
            [&pf[..], &["--sdls"], &ext[..]].concat(),
            "needs --sdls-keys",
        ),
        (
            [&pf[..], &["--sdls-keys", k], &ext[..]].concat(),
            "--sdls-state",
        ),
        ([&pf[..], &["--sdls-keys", k]].concat(), "--sdls-state"),
        (
            [&pf[..], &["--sdls-state", st]].concat(),
            "needs --sdls-keys",
        ),
        (
            [
                &pf[..],
                &["--sdls-keys", k, "--sdls-state", inside.to_str().unwrap()],
            ]
            .concat(),
            "inside the key directory",
        ),
        (
            [&pf[..], &["--sdls-keys", k, "--sdls-state", st]].concat(),
            "mmic sdls provision",
        ),
        (
            [&pf[..], &["--sdls-keys", k, "--sdls-state", st], &ext[..]].concat(),
            "mmic sdls provision",
        ),
        (vec!["sim", "--protocol", "pus", "--sdls"], "--link frames"),
        (
            vec![
                "sim",
                "--protocol",
                "pus",
                "--sdls-keys",
                k,
                "--sdls-state",
                st,
            ],
            "--link frames",
        ),
        (vec!["sim", "--sdls"], "--link frames"),
        (
            [&pf[..], &["--sdls-attack", "0.1"]].concat(),
            "needs --sdls",
        ),
        (
            [&pf[..], &["--sdls", "--sdls-attack", "0.1"], &ext[..]].concat(),
            "virtual time",
        ),
    ];
    for (args, needle) in &cases {
        refused(args, needle);
    }
    println!("{} option sets refused with exit 2", cases.len());
}

/// Provisioning refuses weak keys, a key file of the wrong length, an existing state file (a
/// second provisioning would start the counters afresh: IV reuse) and one inside the keys.
#[test]
fn provisioning_refuses_weak_keys_an_existing_state_and_one_beside_the_keys() {
    let d = scratch("provision");
    let kd = d.join("keys");
    keys(&kd);
    let (k, st) = (kd.to_str().unwrap(), d.join("state.json"));
    let st_s = st.to_str().unwrap();
    let o = mmic(&["sdls", "provision", "--keys", k, "--state", st_s]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let text = std::fs::read_to_string(&st).unwrap();
    for spi in ["257", "513"] {
        let key = std::fs::read(kd.join(format!("spi-{spi}.key"))).unwrap();
        let hex: String = key.iter().map(|b| format!("{b:02x}")).collect();
        assert!(
            !text.contains(&hex[..16]),
            "a key's octets in the state file"
        );
    }
    let again = mmic(&["sdls", "provision", "--keys", k, "--state", st_s]);
    assert_eq!(again.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&again.stderr).contains("exists"));
    let inside = kd.join("s.json");
    let o = mmic(&[
        "sdls",
        "provision",
        "--keys",
        k,
        "--state",
        inside.to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(2));
    let weak = d.join("weak");
    std::fs::create_dir_all(&weak).unwrap();
    std::fs::write(weak.join("spi-257.key"), [0u8; 32]).unwrap();
    std::fs::write(weak.join("spi-513.key"), [0x5au8; 32]).unwrap();
    let o = mmic(&[
        "sdls",
        "provision",
        "--keys",
        weak.to_str().unwrap(),
        "--state",
        d.join("w.json").to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("not a key"));
    std::fs::write(weak.join("spi-257.key"), [1u8; 31]).unwrap();
    let o = mmic(&[
        "sdls",
        "provision",
        "--keys",
        weak.to_str().unwrap(),
        "--state",
        d.join("w2.json").to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("31 octets"));
    assert!(!d.join("w.json").exists() && !d.join("w2.json").exists());
}

/// A protected AD frame of the ground for robot 1: TC(17,1) in frame N(S) = `ns`, under IV
/// `iv` of the TC key.
fn tc_frame(key: &[u8], ns: u8, iv: u128, count: u16) -> Vec<u8> {
    let board = BoardNumber::ONE;
    let mut table: SaTable<1> = SaTable::new();
    table
        .add(mission::tc_sender(
            board,
            sdls::Key256::from_slice(key).unwrap(),
            Some(iv),
        ))
        .unwrap();
    let due: Vec<_> = table.due().collect();
    for (spi, v) in due {
        table.persisted(spi, v);
    }
    let mut ping = [0u8; 13];
    TcRepr {
        apid: Apid::new(0x101).unwrap(),
        seq_count: SeqCount::new(count).unwrap(),
        header: TcSecondaryHeader {
            ack: AckFlags::ALL,
            service: 17,
            subservice: 1,
            source_id: 9,
        },
        app_data: &[],
    }
    .emit(&mut ping)
    .unwrap();
    let repr = TcFrameRepr {
        spacecraft_id: SpacecraftId::of_board(board),
        vcid: Vcid::new(0).unwrap(),
        seq: ns,
        content: TcContent::Ad {
            map_id: Some(MapId::new(0).unwrap()),
            data: &ping,
        },
    };
    let mut buf = [0u8; 128];
    let n = sdls::frames::protect_tc(&mut table, mission::tc_spi(board), &repr, &mut buf).unwrap();
    buf[..n].to_vec()
}

/// One life of the external-ground simulator on `keys`/`state`: it takes `send` (TC frames)
/// once ready, runs `seconds`, and returns the TM frames' IVs and the wire log's TC lines.
fn external_life(
    keys: &Path,
    state: &Path,
    send: &[Vec<u8>],
    seconds: u32,
) -> (Vec<u128>, Vec<Value>) {
    let tm = UdpSocket::bind("127.0.0.1:0").unwrap();
    tm.set_read_timeout(Some(Duration::from_millis(100)))
        .unwrap();
    let tm_to = tm.local_addr().unwrap().to_string();
    let secs = seconds.to_string();
    let mut child = Command::new(env!("CARGO_BIN_EXE_mmic"))
        .args([
            "sim",
            "--protocol",
            "pus",
            "--link",
            "frames",
            "--sdls-keys",
            keys.to_str().unwrap(),
            "--sdls-state",
            state.to_str().unwrap(),
            "--ground-tm-to",
            &tm_to,
            "--ground-tc-port",
            "0",
            "--max-seconds",
            &secs,
            "--quiet",
            "--out",
            state.with_extension("out").to_str().unwrap(),
        ])
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let mut lines = BufReader::new(child.stdout.take().unwrap()).lines();
    let first: Value = serde_json::from_str(&lines.next().unwrap().unwrap()).unwrap();
    let port = first["tc_port"].as_u64().expect("the ready line") as u16;
    let reader = std::thread::spawn(move || {
        lines
            .map_while(Result::ok)
            .filter_map(|l| serde_json::from_str::<Value>(&l).ok())
            .filter(|v| v["dir"] == "tc-frame")
            .collect::<Vec<_>>()
    });
    let up = UdpSocket::bind("127.0.0.1:0").unwrap();
    let mut ivs = Vec::new();
    let end = Instant::now() + Duration::from_secs(u64::from(seconds) + 5);
    let mut sent = false;
    let mut buf = [0u8; 512];
    while Instant::now() < end {
        if let Ok(n) = tm.recv(&mut buf) {
            if n == 256 {
                ivs.push(u128::from_be_bytes(
                    [&[0u8; 4][..], &buf[8..20]].concat().try_into().unwrap(),
                ));
            }
            // The first TM frame: the server board runs; the frames go up.
            if !sent {
                for f in send {
                    up.send_to(f, ("127.0.0.1", port)).unwrap();
                    std::thread::sleep(Duration::from_millis(50));
                }
                sent = true;
            }
        }
        if child.try_wait().unwrap().is_some() {
            break;
        }
    }
    let _ = child.kill();
    let _ = child.wait();
    (ivs, reader.join().unwrap())
}

/// Issue 38's nonce reuse across process restarts, closed: two runs of the external-ground
/// simulator on the same keys and state file. The second run's TM IVs are all above the
/// first's (on main at ca6056d both started at 0), a TC frame the first run accepted is refused
/// as a replay in the second (board A ran it again there), and the ground's next frame (the
/// next IV, the next N(S)) is taken at once: FARM-1 and the TC window resumed exactly.
/// Wall clock: run by `wall_clock::the_wall_clock_tests_side_by_side`.
pub(crate) fn the_external_ground_simulator_keeps_its_counters_across_processes() {
    let d = scratch("restart");
    let kd = d.join("keys");
    let (tc, _) = keys(&kd);
    let st = d.join("state.json");
    let o = mmic(&[
        "sdls",
        "provision",
        "--keys",
        kd.to_str().unwrap(),
        "--state",
        st.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let first = tc_frame(&tc, 0, 0, 1);
    let (ivs1, tc1) = external_life(&kd, &st, std::slice::from_ref(&first), 2);
    assert!(!ivs1.is_empty());
    assert_eq!(tc1.len(), 1, "{tc1:?}");
    assert_eq!(tc1[0]["refused"], Value::Null, "{tc1:?}");
    assert_eq!(tc1[0]["farm"], "accept", "{tc1:?}");
    let next = tc_frame(&tc, 1, 1, 2);
    let (ivs2, tc2) = external_life(&kd, &st, &[first, next], 2);
    let max1 = ivs1.iter().max().unwrap();
    let min2 = ivs2.iter().min().unwrap();
    assert!(min2 > max1, "TM IVs {ivs1:?} then {ivs2:?}");
    assert_eq!(tc2.len(), 2, "{tc2:?}");
    assert_eq!(tc2[0]["refused"], "replay", "{tc2:?}");
    assert_eq!(tc2[1]["refused"], Value::Null, "{tc2:?}");
    assert_eq!(
        tc2[1]["farm"], "accept",
        "FARM-1 resumed at V(R) = 1: {tc2:?}"
    );
    println!(
        "TM IVs: first life {:?}, second life {:?}; the first life's TC frame refused as a replay, the next taken at once",
        (ivs1.iter().min().unwrap(), max1),
        (min2, ivs2.iter().max().unwrap())
    );
}

/// The key schedule and the GHASH key are zeroized on drop only with the `zeroize` features of
/// `aes`, `ghash` and `polyval` (aes-gcm's own feature clears one temporary block): the
/// workspace's feature resolution must keep all three (`src/link/sdls/key.rs` also asserts it
/// at compile time, for the RISC-V targets the firmware builds).
#[test]
fn the_crates_holding_key_material_are_built_with_zeroize() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let cargo = std::env::var("CARGO").unwrap_or_else(|_| "cargo".into());
    // This host's target (the other platforms' crates need not be downloaded).
    let rustc = Command::new("rustc")
        .arg("-vV")
        .output()
        .expect("rustc -vV");
    let host = String::from_utf8_lossy(&rustc.stdout)
        .lines()
        .find_map(|l| l.strip_prefix("host: ").map(str::to_string))
        .expect("rustc's host");
    let o = Command::new(cargo)
        .args([
            "metadata",
            "--format-version",
            "1",
            "--offline",
            "--filter-platform",
        ])
        .arg(&host)
        .arg("--manifest-path")
        .arg(root.join("Cargo.toml"))
        .output()
        .expect("cargo metadata");
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let m: Value = serde_json::from_slice(&o.stdout).unwrap();
    let nodes = m["resolve"]["nodes"].as_array().unwrap();
    for name in ["aes", "ghash", "polyval", "aes-gcm"] {
        let node = nodes
            .iter()
            .find(|n| {
                let id = n["id"].as_str().unwrap_or("");
                id.contains(&format!("#{name}@"))
            })
            .unwrap_or_else(|| panic!("{name} is not in the build"));
        let features: Vec<&str> = node["features"]
            .as_array()
            .unwrap()
            .iter()
            .filter_map(Value::as_str)
            .collect();
        assert!(
            features.contains(&"zeroize"),
            "{name} without zeroize: {features:?}"
        );
    }
}
