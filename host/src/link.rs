//! Space data link frames as JSON, for `mmic encode|decode tc-frame|tm-frame|clcw`: the
//! library's parsers and emitters (`mmic::link`) with the JSON shapes below. A refused frame is
//! a [`PusCodecError::Refused`] naming the failed check ([`TcFrameError::name`],
//! [`TmFrameError::name`], [`ClcwError::name`]) with the library's message; bad JSON or hex is
//! [`PusCodecError::Input`] (exit codes 1 and 2, as for packets).
//!
//! **TC frame** (`encode tc-frame`; every key optional: spacecraft 0x101 = robot 1, VC 0,
//! N(S) 0, kind `ad`, MAP 0, no data):
//!
//! ```json
//! {"spacecraft_id":257,"vcid":0,"seq":0,"kind":"ad","map_id":0,"data":"1842c00700062f1101000012d0"}
//! {"spacecraft_id":257,"kind":"bc","control":"unlock"}
//! {"spacecraft_id":257,"kind":"bc","control":{"set-vr":5}}
//! ```
//!
//! `map_id` null: no segment header; `fecf` null: no FECF. `decode tc-frame` prints those keys
//! and every other header field (`version`, `bypass`, `control_command`, `spare`, `length` =
//! the frame length field, `len` = octets), the segment header's `sequence_flags`, the whole
//! `data_field`, the `packets` of an AD or BD frame (each `hex`, and `pus_tc` as `decode pus-tc`
//! prints it when it is a telecommand of an accepted APID, else `pus_tc_refused` with the
//! check), the `control` command of a BC frame, and the `fecf`; `encode tc-frame` takes that
//! output back, checking that every derived key it is given agrees.
//!
//! The encoder refuses what no receiver takes (data that does not end on a packet boundary,
//! a frame over the standard's 1024 octets) but builds frames for any spacecraft, VC or MAP
//! and up to 1024 octets, so that test frames for other configurations can be made;
//! `decode` checks the mission's (`spec/ccsds/link.toml`) unless told otherwise
//! (`--spacecraft-id`, `--vcid`, `--map-id`, `--frame-len`, `--no-segment-header`,
//! `--no-fecf`).
//!
//! **TM frame** (`encode tm-frame`; spacecraft 0x101, VC 0, counts 0, first header pointer 0,
//! 256 octets unless `len` says otherwise):
//!
//! ```json
//! {"spacecraft_id":322,"mc_frame_count":18,"vc_frame_count":52,"first_header_pointer":0,"data":"0842…","pad":true,"clcw":{…}}
//! ```
//!
//! The data field must be given whole (`data`, exactly the frame's data field length: 244
//! octets in the mission's 256-octet frame), unless `"pad": true`, which fills the rest with
//! one idle packet (APID 0x7FF, octets 0x55, as the on-board framer does); a rest of 1 to 6
//! octets is refused there, since an idle packet is at least 7 and would spill into a next
//! frame. The first header pointer is a number or `"no-packet-start"` / `"only-idle-data"`.
//! The OCF is `ocf` (4 octets hex) or `clcw` (an object as `decode clcw` prints it); null for a
//! frame without one; `fecf` null for a frame without the FECF. `decode tm-frame` prints every
//! header field (the fixed ones too: `version`, `secondary_header_flag`, `synch_flag`,
//! `packet_order_flag`, `segment_length_id`, the `ocf_flag`), the first header pointer as
//! above and as its 11-bit field, the data field, the OCF as hex and as a CLCW (an OCF that is
//! no CLCW leaves the frame valid, the frame parser takes any OCF: `clcw` is then null and
//! `clcw_refused` names the CLCW's failed check), the FECF and `len`.
//!
//! **CLCW** (`encode clcw` / `decode clcw`): every field of the word by name (`status`, `vcid`,
//! `no_rf_available`, `no_bit_lock`, `lockout`, `wait`, `retransmit`, `farm_b_counter`,
//! `report_value`; a field not given to `encode` is 0 or false), the fixed ones
//! (`control_word_type` 0, `clcw_version` 0, `cop_in_effect` 1) and the `word` as hex, both
//! checked when given.

use crate::codec::{from_hex, to_hex};
use crate::pus::{self, check_derived, object, uint, PusCodecError};
use mmic::link::clcw::{Clcw, ClcwError, CLCW_LEN, CLCW_VERSION, CONTROL_WORD_TYPE, COP_1};
use mmic::link::tc_frame::{
    MapId, SpacecraftId, TcContent, TcFrame, TcFrameConfig, TcFrameError, TcFrameRepr,
    TcPrimaryHeader, VcConfig, Vcid, MAX_FRAME_LEN, MISSION_FECF, MISSION_MAP_ID,
    MISSION_SEGMENT_HEADER, MISSION_VCID, SPACECRAFT_ID_BASE, TC_MAX_FRAME_LEN,
};
use mmic::link::tm_frame::{
    FirstHeaderPointer, TmFrame, TmFrameError, TmFrameParams, TmFrameRepr, OCF_LEN, TM_FECF,
    TM_FRAME_LEN, TM_OCF, TM_VCID,
};
use mmic::link::tm_framer::{idle_header, IDLE_OCTET, MIN_PACKET_LEN};
use mmic::link::{ControlCommand, FrameKind};
use serde_json::{json, Map, Value};

/// What `decode tc-frame` and `decode tm-frame` accept: the mission's parameters unless the
/// command line changes them.
#[derive(Debug, Clone, PartialEq, Eq, Default)]
pub struct FrameOptions {
    /// The one spacecraft accepted; `None`: the frame header's (any robot).
    pub spacecraft_id: Option<u16>,
    /// The virtual channel accepted; `None`: the mission's (0).
    pub vcid: Option<u8>,
    /// TC: the MAP accepted; `None`: the mission's (0).
    pub map_id: Option<u8>,
    /// TC: the longest frame accepted; TM: the frame length. `None`: the mission's (256).
    pub frame_len: Option<usize>,
    /// TC: the VC's frames carry no segment header.
    pub no_segment_header: bool,
    /// The frames carry no FECF.
    pub no_fecf: bool,
    /// TM: the frames carry no OCF.
    pub no_ocf: bool,
    /// TC: the APIDs whose telecommands the packets are decoded as (`decode pus-tc`'s).
    pub apids: Vec<u16>,
}

/// A spacecraft ID from the command line: decimal or `0x` hex, 0..=0x3FF (10 bits).
pub fn parse_spacecraft_id(text: &str) -> Result<u16, String> {
    let v = parse_number(text)?;
    u16::try_from(v)
        .ok()
        .filter(|v| *v <= 0x3ff)
        .ok_or_else(|| format!("spacecraft ID {v} is more than 10 bits (0..=1023)"))
}

/// A number from the command line: decimal or `0x` hex.
pub fn parse_number(text: &str) -> Result<u64, String> {
    match text.strip_prefix("0x").or_else(|| text.strip_prefix("0X")) {
        Some(h) => u64::from_str_radix(h, 16),
        None => text.parse(),
    }
    .map_err(|e| format!("{text:?}: {e}"))
}

fn input(what: &'static str) -> impl Fn(String) -> PusCodecError {
    move |reason| PusCodecError::Input { what, reason }
}

fn tc_input(reason: String) -> PusCodecError {
    input("tc-frame JSON")(reason)
}

fn tm_input(reason: String) -> PusCodecError {
    input("tm-frame JSON")(reason)
}

fn clcw_input(reason: String) -> PusCodecError {
    input("clcw JSON")(reason)
}

fn refused_tc(e: TcFrameError) -> PusCodecError {
    PusCodecError::Refused {
        name: e.name(),
        message: e.to_string(),
    }
}

fn refused_tm(e: TmFrameError) -> PusCodecError {
    PusCodecError::Refused {
        name: e.name(),
        message: e.to_string(),
    }
}

fn refused_clcw(e: ClcwError) -> PusCodecError {
    PusCodecError::Refused {
        name: e.name(),
        message: e.to_string(),
    }
}

fn hex_of(
    v: &Value,
    key: &str,
    err: fn(String) -> PusCodecError,
) -> Result<Vec<u8>, PusCodecError> {
    let text = v
        .as_str()
        .ok_or_else(|| err(format!("{key}: expected hex, found {v}")))?;
    from_hex(text).map_err(|e| err(format!("{key}: {e}")))
}

fn fecf_json(fecf: Option<u16>) -> Value {
    fecf.map_or(Value::Null, |f| json!(format!("{f:04x}")))
}

// ---- TC frames ---------------------------------------------------------------------------

const TC_KEYS: [&str; 17] = [
    "spacecraft_id",
    "vcid",
    "seq",
    "kind",
    "map_id",
    "data",
    "control",
    "fecf",
    // derived keys of the decoded form, checked when given
    "version",
    "bypass",
    "control_command",
    "spare",
    "length",
    "len",
    "sequence_flags",
    "data_field",
    "packets",
];

/// Decodes a TC frame with the mission's parameters as `options` change them.
pub fn decode_tc_frame(bytes: &[u8], options: &FrameOptions) -> Result<Value, PusCodecError> {
    let spacecraft_id = options
        .spacecraft_id
        .or_else(|| TcPrimaryHeader::read(bytes).map(|h| h.spacecraft_id))
        .unwrap_or(0);
    let vcs = [VcConfig {
        vcid: Vcid::new(options.vcid.unwrap_or(MISSION_VCID))
            .map_err(|e| input("tc-frame option")(e.to_string()))?,
        segment_header: MISSION_SEGMENT_HEADER && !options.no_segment_header,
        map_ids: 1u64
            << MapId::new(options.map_id.unwrap_or(MISSION_MAP_ID))
                .map_err(|e| input("tc-frame option")(e.to_string()))?
                .get(),
    }];
    let config = TcFrameConfig {
        spacecraft_id: SpacecraftId::new(spacecraft_id)
            .map_err(|e| input("tc-frame option")(e.to_string()))?,
        vcs: &vcs,
        fecf: MISSION_FECF && !options.no_fecf,
        max_frame_len: options.frame_len.unwrap_or(MAX_FRAME_LEN),
    };
    decode_tc_with(bytes, &config, &apids_or_robots(&options.apids))
}

fn apids_or_robots(apids: &[u16]) -> Vec<u16> {
    if apids.is_empty() {
        pus::robot_apids()
    } else {
        apids.to_vec()
    }
}

/// Decodes a TC frame under `config`, its packets as telecommands of `apids`.
pub fn decode_tc_with(
    bytes: &[u8],
    config: &TcFrameConfig<'_>,
    apids: &[u16],
) -> Result<Value, PusCodecError> {
    let frame = TcFrame::new_checked(bytes, config).map_err(refused_tc)?;
    let mut packets = Vec::new();
    for p in frame.packets() {
        let p = p.map_err(refused_tc)?;
        let (tc, why) = match pus::decode_tc(p, apids) {
            Ok(v) => (v, Value::Null),
            Err(e) => (Value::Null, json!(e.to_string())),
        };
        packets.push(json!({"hex": to_hex(p), "pus_tc": tc, "pus_tc_refused": why}));
    }
    let h = frame.header();
    let kind = frame.kind();
    let mut m = Map::new();
    m.insert("kind".into(), json!(kind_name(kind)));
    m.insert("version".into(), json!(h.version));
    m.insert("bypass".into(), json!(h.bypass));
    m.insert("control_command".into(), json!(h.control));
    m.insert("spare".into(), json!(h.spare));
    m.insert("spacecraft_id".into(), json!(h.spacecraft_id));
    m.insert("vcid".into(), json!(h.vcid));
    m.insert("length".into(), json!(h.frame_length));
    m.insert("seq".into(), json!(h.seq));
    let segment = frame.segment();
    m.insert(
        "sequence_flags".into(),
        json!(segment.map(|(flags, _)| flags)),
    );
    m.insert("map_id".into(), json!(segment.map(|(_, map)| map.get())));
    m.insert("data_field".into(), json!(to_hex(frame.data_field())));
    let data = match kind {
        FrameKind::Ad | FrameKind::Bd => json!(to_hex(frame.data())),
        FrameKind::Bc => Value::Null,
    };
    m.insert("data".into(), data);
    m.insert("packets".into(), Value::Array(packets));
    m.insert(
        "control".into(),
        serde_json::to_value(frame.control_command()).unwrap_or(Value::Null),
    );
    m.insert("fecf".into(), fecf_json(frame.fecf()));
    m.insert("len".into(), json!(bytes.len()));
    Ok(Value::Object(m))
}

fn kind_name(kind: FrameKind) -> &'static str {
    match kind {
        FrameKind::Ad => "ad",
        FrameKind::Bd => "bd",
        FrameKind::Bc => "bc",
    }
}

/// A TC frame's content from its JSON's parts: a BC frame has its control and nothing else,
/// an AD or BD frame its data (and segment header) and no control.
fn tc_content(
    kind: FrameKind,
    map_id: Option<MapId>,
    control: Option<ControlCommand>,
    data: &[u8],
) -> Result<TcContent<'_>, PusCodecError> {
    Ok(match (kind, control) {
        (FrameKind::Bc, Some(c)) => {
            if map_id.is_some() || !data.is_empty() {
                return Err(tc_input(
                    "a BC frame has no segment header (map_id) and no data, only its control"
                        .into(),
                ));
            }
            TcContent::Bc(c)
        }
        (FrameKind::Bc, None) => {
            return Err(tc_input(
                "a BC frame needs \"control\": \"unlock\" or {\"set-vr\":N}".into(),
            ))
        }
        (_, Some(_)) => {
            return Err(tc_input(
                "\"control\" belongs to BC frames (kind \"bc\") only".into(),
            ))
        }
        (FrameKind::Ad, None) => TcContent::Ad { map_id, data },
        (FrameKind::Bd, None) => TcContent::Bd { map_id, data },
    })
}

/// The frame's `packets`, when the JSON gives them: by their octets, the frame's own (their
/// `pus_tc` depends on the APIDs decode was given).
fn check_packets(m: &Map<String, Value>, decoded: &Value) -> Result<(), PusCodecError> {
    if let Some(given) = m.get("packets") {
        let octets = |v: &Value| -> Vec<Value> {
            v.as_array()
                .map(|a| {
                    a.iter()
                        .map(|p| p.get("hex").cloned().unwrap_or(Value::Null))
                        .collect()
                })
                .unwrap_or_default()
        };
        let found = octets(&decoded["packets"]);
        if !given.is_array() || octets(given) != found {
            return Err(tc_input(format!(
                "packets = {given} disagrees with the frame, whose packets are {}",
                Value::Array(found)
            )));
        }
    }
    Ok(())
}

/// Encodes a TC frame from its JSON form (see the module docs); its packets are decoded as
/// telecommands of `apids` (every robot's when empty) for the derived keys' check only.
pub fn encode_tc_frame(json: &str, apids: &[u16]) -> Result<Vec<u8>, PusCodecError> {
    let m = &object(json, &TC_KEYS, tc_input)?;
    let get = |k: &str, default: u64, max: u64| -> Result<u64, PusCodecError> {
        m.get(k).map_or(Ok(default), |v| uint(v, k, max, tc_input))
    };
    let spacecraft_id = get("spacecraft_id", u64::from(SPACECRAFT_ID_BASE + 1), 0x3ff)? as u16;
    let vcid = get("vcid", 0, 0x3f)? as u8;
    let seq = get("seq", 0, 0xff)? as u8;
    let kind = match m.get("kind") {
        None if m.get("control").is_some_and(|c| !c.is_null()) => FrameKind::Bc,
        None => FrameKind::Ad,
        Some(Value::String(s)) if s == "ad" => FrameKind::Ad,
        Some(Value::String(s)) if s == "bd" => FrameKind::Bd,
        Some(Value::String(s)) if s == "bc" => FrameKind::Bc,
        Some(v) => {
            return Err(tc_input(format!(
                "kind: \"ad\", \"bd\" or \"bc\", found {v}"
            )))
        }
    };
    let map_id = match m.get("map_id") {
        None if kind != FrameKind::Bc => Some(MapId::new(MISSION_MAP_ID)),
        None | Some(Value::Null) => None,
        Some(v) => Some(MapId::new(uint(v, "map_id", 0x3f, tc_input)? as u8)),
    }
    .transpose()
    .map_err(|e| tc_input(e.to_string()))?;
    let data = match m.get("data") {
        None | Some(Value::Null) => Vec::new(),
        Some(v) => hex_of(v, "data", tc_input)?,
    };
    let control = match m.get("control") {
        None | Some(Value::Null) => None,
        Some(v) => Some(
            serde_json::from_value::<ControlCommand>(v.clone()).map_err(|e| {
                tc_input(format!(
                    "control: \"unlock\" or {{\"set-vr\":0..=255}}, found {v} ({e})"
                ))
            })?,
        ),
    };
    let content = tc_content(kind, map_id, control, &data)?;
    let fecf = !matches!(m.get("fecf"), Some(Value::Null));
    let repr = TcFrameRepr {
        spacecraft_id: SpacecraftId::new(spacecraft_id).map_err(|e| tc_input(e.to_string()))?,
        vcid: Vcid::new(vcid).map_err(|e| tc_input(e.to_string()))?,
        seq,
        content,
    };
    let mut buf = vec![0u8; repr.len_with(fecf).min(TC_MAX_FRAME_LEN)];
    repr.emit_with(fecf, &mut buf)
        .map_err(|e| tc_input(e.to_string()))?;
    // Read back as a receiver configured for exactly this frame would: the packet boundary
    // (and every other check) as the robot runs it.
    let vcs = [VcConfig {
        vcid: repr.vcid,
        segment_header: map_id.is_some(),
        map_ids: u64::MAX,
    }];
    let config = TcFrameConfig {
        spacecraft_id: repr.spacecraft_id,
        vcs: &vcs,
        fecf,
        max_frame_len: TC_MAX_FRAME_LEN,
    };
    let decoded = decode_tc_with(&buf, &config, &apids_or_robots(apids))?;
    let mut derived: Vec<&str> = TC_KEYS
        .iter()
        .copied()
        .skip(8)
        .filter(|k| *k != "packets")
        .collect();
    if fecf {
        derived.push("fecf");
    }
    check_packets(m, &decoded)?;
    check_derived(m, &decoded, &derived, tc_input)?;
    Ok(buf)
}

// ---- TM frames ---------------------------------------------------------------------------

const TM_KEYS: [&str; 19] = [
    "spacecraft_id",
    "vcid",
    "mc_frame_count",
    "vc_frame_count",
    "first_header_pointer",
    "data",
    "pad",
    "ocf",
    "clcw",
    "fecf",
    "len",
    // derived keys of the decoded form, checked when given
    "version",
    "ocf_flag",
    "secondary_header_flag",
    "synch_flag",
    "packet_order_flag",
    "segment_length_id",
    "first_header_pointer_field",
    "clcw_refused",
];

fn fhp_json(p: FirstHeaderPointer) -> Value {
    match p {
        FirstHeaderPointer::Packet(at) => json!(at),
        FirstHeaderPointer::NoPacketStart => json!("no-packet-start"),
        FirstHeaderPointer::OnlyIdleData => json!("only-idle-data"),
    }
}

fn fhp_of(v: &Value) -> Result<FirstHeaderPointer, PusCodecError> {
    match v {
        Value::String(s) if s == "no-packet-start" => Ok(FirstHeaderPointer::NoPacketStart),
        Value::String(s) if s == "only-idle-data" => Ok(FirstHeaderPointer::OnlyIdleData),
        Value::Number(_) => Ok(FirstHeaderPointer::Packet(
            uint(v, "first_header_pointer", 0x7fd, tm_input)? as u16,
        )),
        _ => Err(tm_input(format!(
            "first_header_pointer: an octet offset, \"no-packet-start\" or \"only-idle-data\", found {v}"
        ))),
    }
}

/// Decodes a TM frame with the mission's parameters as `options` change them.
pub fn decode_tm_frame(bytes: &[u8], options: &FrameOptions) -> Result<Value, PusCodecError> {
    let spacecraft_id = options.spacecraft_id.unwrap_or_else(|| {
        bytes
            .first_chunk::<2>()
            .map_or(0, |id| (u16::from_be_bytes(*id) >> 4) & 0x3ff)
    });
    let frame_len = options.frame_len.unwrap_or(TM_FRAME_LEN);
    let vcid = options.vcid.unwrap_or(TM_VCID);
    let ocf = TM_OCF && !options.no_ocf;
    let fecf = TM_FECF && !options.no_fecf;
    let params =
        TmFrameParams::new(frame_len, spacecraft_id, vcid, ocf, fecf).ok_or_else(|| {
            input("tm-frame option")(format!(
                "no TM frame has length {frame_len} (with{} OCF, with{} FECF), VC {vcid} (0..=7), \
             spacecraft {spacecraft_id}",
                if ocf { "" } else { "out" },
                if fecf { "" } else { "out" }
            ))
        })?;
    decode_tm_with(bytes, &params)
}

/// Decodes a TM frame under `params`.
pub fn decode_tm_with(bytes: &[u8], params: &TmFrameParams) -> Result<Value, PusCodecError> {
    let frame = TmFrame::new_checked(bytes, params).map_err(refused_tm)?;
    let r = frame.repr();
    let fecf = params
        .fecf()
        .then(|| bytes.last_chunk::<2>().map(|f| u16::from_be_bytes(*f)))
        .flatten();
    let mut m = Map::new();
    m.insert("version".into(), json!(0));
    m.insert("spacecraft_id".into(), json!(r.spacecraft_id));
    m.insert("vcid".into(), json!(r.vcid));
    m.insert("ocf_flag".into(), json!(params.ocf()));
    m.insert("mc_frame_count".into(), json!(r.mc_frame_count));
    m.insert("vc_frame_count".into(), json!(r.vc_frame_count));
    m.insert("secondary_header_flag".into(), json!(false));
    m.insert("synch_flag".into(), json!(false));
    m.insert("packet_order_flag".into(), json!(false));
    m.insert("segment_length_id".into(), json!(3));
    m.insert(
        "first_header_pointer".into(),
        fhp_json(r.first_header_pointer),
    );
    m.insert(
        "first_header_pointer_field".into(),
        json!(r.first_header_pointer.field()),
    );
    m.insert("data".into(), json!(to_hex(r.data)));
    m.insert(
        "ocf".into(),
        r.ocf.map_or(Value::Null, |o| json!(to_hex(&o))),
    );
    // The frame's parser takes any OCF; the mission's is a CLCW, decoded when it is one.
    let (clcw, clcw_refused) = match r.ocf.map(|o| clcw_json(&o)) {
        None => (Value::Null, Value::Null),
        Some(Ok(c)) => (c, Value::Null),
        Some(Err(e)) => (Value::Null, json!(e.to_string())),
    };
    m.insert("clcw".into(), clcw);
    m.insert("clcw_refused".into(), clcw_refused);
    m.insert("fecf".into(), fecf_json(fecf));
    m.insert("len".into(), json!(bytes.len()));
    Ok(Value::Object(m))
}

/// Encodes a TM frame from its JSON form (see the module docs).
pub fn encode_tm_frame(json: &str) -> Result<Vec<u8>, PusCodecError> {
    let m = &object(json, &TM_KEYS, tm_input)?;
    let get = |k: &str, default: u64, max: u64| -> Result<u64, PusCodecError> {
        m.get(k).map_or(Ok(default), |v| uint(v, k, max, tm_input))
    };
    let spacecraft_id = get("spacecraft_id", u64::from(SPACECRAFT_ID_BASE + 1), 0x3ff)? as u16;
    let vcid = get("vcid", u64::from(TM_VCID), 7)? as u8;
    let frame_len = get("len", TM_FRAME_LEN as u64, 2048)? as usize;
    let ocf: Option<[u8; OCF_LEN]> =
        match (m.get("ocf"), m.get("clcw")) {
            (Some(Value::Null), _) | (None, Some(Value::Null)) => None,
            (Some(v), _) => Some(
                hex_of(v, "ocf", tm_input)?
                    .try_into()
                    .map_err(|b: Vec<u8>| tm_input(format!("ocf: 4 octets, found {}", b.len())))?,
            ),
            (None, Some(c)) => Some(clcw_word(c, tm_input)?),
            (None, None) => return Err(tm_input(
                "give \"ocf\" (4 octets hex) or \"clcw\" (an object as `mmic decode clcw` prints \
                 it), or \"ocf\": null for a frame without an OCF"
                    .into(),
            )),
        };
    let fecf = !matches!(m.get("fecf"), Some(Value::Null));
    let params = TmFrameParams::new(frame_len, spacecraft_id, vcid, ocf.is_some(), fecf)
        .ok_or_else(|| {
            tm_input(format!(
                "len {frame_len}: no room for a data octet after the header, OCF and FECF"
            ))
        })?;
    let mut data = match m.get("data") {
        None | Some(Value::Null) => Vec::new(),
        Some(v) => hex_of(v, "data", tm_input)?,
    };
    let pad = match m.get("pad") {
        None | Some(Value::Bool(false)) => false,
        Some(Value::Bool(true)) => true,
        Some(v) => return Err(tm_input(format!("pad: true or false, found {v}"))),
    };
    let room = params.data_len().saturating_sub(data.len());
    if pad && room > 0 {
        if room < MIN_PACKET_LEN {
            return Err(tm_input(format!(
                "pad: {room} octets left in the {}-octet data field, fewer than the shortest \
                 idle packet ({MIN_PACKET_LEN}); give the data field whole",
                params.data_len()
            )));
        }
        data.extend_from_slice(&idle_header(room));
        data.resize(params.data_len(), IDLE_OCTET);
    }
    let first_header_pointer = m
        .get("first_header_pointer")
        .map_or(Ok(FirstHeaderPointer::Packet(0)), fhp_of)?;
    let repr = TmFrameRepr {
        spacecraft_id,
        vcid,
        mc_frame_count: get("mc_frame_count", 0, 0xff)? as u8,
        vc_frame_count: get("vc_frame_count", 0, 0xff)? as u8,
        first_header_pointer,
        data: &data,
        ocf,
    };
    let mut buf = vec![0u8; params.frame_len()];
    repr.emit(&params, &mut buf)
        .map_err(|e| tm_input(e.to_string()))?;
    let decoded = decode_tm_with(&buf, &params)?;
    let mut derived: Vec<&str> = TM_KEYS.iter().copied().skip(11).collect();
    if m.contains_key("ocf") {
        derived.push("clcw");
    }
    if fecf {
        derived.push("fecf");
    }
    check_derived(m, &decoded, &derived, tm_input)?;
    Ok(buf)
}

// ---- CLCW --------------------------------------------------------------------------------

/// The fixed fields of a CLCW (232.0-B-4 §4.2.1), printed by `decode clcw` and checked when
/// given to `encode clcw`: control word type 0, version 0, COP in effect `01` (COP-1); and the
/// word itself as hex.
const CLCW_DERIVED: [&str; 4] = ["control_word_type", "clcw_version", "cop_in_effect", "word"];

/// The CLCW of an OCF as JSON: every field by name, the fixed ones too, and the word as hex.
pub fn clcw_json(ocf: &[u8]) -> Result<Value, PusCodecError> {
    let c = Clcw::parse(ocf).map_err(refused_clcw)?;
    let mut v = serde_json::to_value(c).unwrap_or(Value::Null);
    if let Value::Object(m) = &mut v {
        m.insert("control_word_type".into(), json!(CONTROL_WORD_TYPE));
        m.insert("clcw_version".into(), json!(CLCW_VERSION));
        m.insert("cop_in_effect".into(), json!(COP_1));
        m.insert("word".into(), json!(to_hex(&c.emit())));
    }
    Ok(v)
}

/// Decodes a CLCW (4 octets).
pub fn decode_clcw(bytes: &[u8]) -> Result<Value, PusCodecError> {
    clcw_json(bytes)
}

/// The four octets of a CLCW given as JSON (`decode clcw`'s output; a field not given is 0 or
/// false; the fixed fields and `word` are checked when given).
fn clcw_word(v: &Value, err: fn(String) -> PusCodecError) -> Result<[u8; CLCW_LEN], PusCodecError> {
    let Value::Object(given) = v else {
        return Err(err(format!("clcw: expected an object, found {v}")));
    };
    let mut fields = match serde_json::to_value(Clcw::default()) {
        Ok(Value::Object(m)) => m,
        _ => Map::new(),
    };
    for (k, x) in given {
        if fields.contains_key(k) {
            fields.insert(k.clone(), x.clone());
        } else if !CLCW_DERIVED.contains(&k.as_str()) {
            let mut keys: Vec<&str> = fields.keys().map(String::as_str).collect();
            keys.extend(CLCW_DERIVED);
            return Err(err(format!(
                "clcw: unknown key {k:?}; keys: {}",
                keys.join(", ")
            )));
        }
    }
    let c: Clcw =
        serde_json::from_value(Value::Object(fields)).map_err(|e| err(format!("clcw: {e}")))?;
    let bytes = c.emit();
    let decoded = clcw_json(&bytes)?;
    check_derived(given, &decoded, &CLCW_DERIVED, err)?;
    Ok(bytes)
}

/// Encodes a CLCW from its JSON form.
pub fn encode_clcw(json: &str) -> Result<Vec<u8>, PusCodecError> {
    let v: Value = serde_json::from_str(json).map_err(|e| clcw_input(e.to_string()))?;
    Ok(clcw_word(&v, clcw_input)?.to_vec())
}
