"""Python `spacepackets` (PyPI) against the Rust side, both ways:
- it decodes every TM type our PUS gateway emits (`mmic ground fixtures`: one scripted session of the
  real gateway; TM(1,1/2/3/4/7/8), (3,25), (5,1..4), (17,2)) and its field values equal what our
  decoder says (`mmic decode pus-tm`, recorded next to each packet);
- it decodes the TCs our encoder made (`mmic encode pus-tc`);
- the TCs it builds are accepted by `mmic decode pus-tc` with the same field values, and a
  corrupted one is refused by name."""
from __future__ import annotations

import json
import tomllib
import warnings

import pytest
from rust_side import REPO, ROBOT_APID, decode_tc, jsonl, mmic
from spacepackets.ecss import PusTc, PusTm

warnings.filterwarnings("ignore", category=DeprecationWarning)
SERVICES = tomllib.loads((REPO / "spec" / "ccsds" / "services.toml").read_text())
FUNCTIONS = tomllib.loads((REPO / "spec" / "ccsds" / "functions.toml").read_text())["function"]


def test_the_session_covers_every_tm_type_of_services_toml(rust_fixtures):
    sent = {(d["decoded"]["service"], d["decoded"]["subservice"]) for d in jsonl(rust_fixtures / "tm.jsonl")}
    spec = {(t["service"], s) for t in SERVICES["tm"] for s in t["subservices"]}
    assert sent == spec, f"sent but not in spec: {sent - spec}; in spec, never sent: {spec - sent}"


def test_spacepackets_decodes_every_tm_we_emit(rust_fixtures):
    lines = jsonl(rust_fixtures / "tm.jsonl")
    assert len(lines) > 40
    for line in lines:
        raw, d = bytes.fromhex(line["hex"]), line["decoded"]
        tm = PusTm.unpack(raw, timestamp_len=6)  # also checks the CRC
        sec = tm.pus_tm_sec_header
        got = {"apid": tm.apid, "seq_count": tm.seq_count, "service": tm.service,
               "subservice": tm.message_subtype, "counter": sec.message_counter,
               "destination_id": sec.dest_id, "source_data": tm.source_data.hex(), "len": len(tm.pack()),
               "time": {"coarse": int.from_bytes(tm.timestamp[:4], "big"),
                        "fine": int.from_bytes(tm.timestamp[4:], "big")},
               "time_ref_status": sec.spacecraft_time_ref}
        want = {k: d[k] for k in got}
        assert got == want, line["what"]
        assert sec.pus_version == 2 and tm.pack() == raw
        assert tm.apid == ROBOT_APID


def test_spacepackets_decodes_the_tcs_we_encode(rust_fixtures):
    for line in jsonl(rust_fixtures / "tc.jsonl"):
        raw, d = bytes.fromhex(line["hex"]), line["decoded"]
        tc = PusTc.unpack(raw)
        if "refused" in d:
            assert tc.app_data[0] == 13  # the unknown function: a valid packet, refused above it
            continue
        got = {"apid": tc.apid, "seq_count": tc.seq_count, "source_id": tc.source_id,
               "service": tc.service, "subservice": tc.message_subtype,
               "ack_bits": tc.pus_tc_sec_header.ack_flags, "app_data": tc.app_data.hex(), "len": len(raw)}
        assert got == {k: d[k] for k in got}, line["what"]


def example_args(f):
    """Arguments for a function from the table: the first value of each range that makes a command."""
    special = {"arm": {"side": 1, "target": 2, "pulse": 2100}, "gripper": {"side": 0, "target": 0, "pulse": 0},
               "hip": {"target": 4, "angle": 9000}, "bolter": {"operation": 0, "pair": 3},
               "primitive": {"primitive": 4, "final_state": ord("d")},
               "reconfiguration": {"initial": ord("a"), "target": ord("m")}}
    return special.get(f["name"], {a["name"]: a["range"][0] for a in f["args"]})


def pack_args(f, values):
    out = bytes([f["id"]])
    for a in f["args"]:
        out += values[a["name"]].to_bytes(2 if a["type"] == "u16" else 1, "big")
    return out


@pytest.mark.parametrize("f", FUNCTIONS, ids=[f["name"] for f in FUNCTIONS])
def test_tcs_built_by_spacepackets_are_accepted(f):
    values = example_args(f)
    app = pack_args(f, values)
    tc = PusTc(service=8, message_subtype=1, apid=ROBOT_APID, seq_count=f["id"] * 3, source_id=0x42,
               ack_flags=0b1001, app_data=app)
    d = decode_tc(tc.pack())
    assert (d["apid"], d["seq_count"], d["source_id"], d["ack_bits"]) == (ROBOT_APID, f["id"] * 3, 0x42, 0b1001)
    assert (d["service"], d["subservice"], d["function"], d["function_id"]) == (8, 1, f["name"], f["id"])
    assert d["app_data"] == app.hex()
    shown = {k: (ord(v) if isinstance(v, str) else v) for k, v in d["args"].items()}
    assert shown == values


@pytest.mark.parametrize("service,subservice,app,key,value", [
    (17, 1, b"", None, None),
    (3, 5, bytes([1, 1]), None, None),
    (3, 6, bytes([1, 1]), None, None),
    (3, 31, bytes([1, 1]) + (2500).to_bytes(4, "big"), "interval_ms", 2500),
])
def test_service_tcs_built_by_spacepackets_are_accepted(service, subservice, app, key, value):
    tc = PusTc(service=service, message_subtype=subservice, apid=0x1FF, seq_count=0x3FFF, app_data=app)
    d = decode_tc(tc.pack())
    assert (d["apid"], d["seq_count"], d["service"], d["subservice"]) == (0x1FF, 0x3FFF, service, subservice)
    names = {(t["service"], t["subservice"]): t["name"] for t in SERVICES["tc"]}
    assert d["request"] == names[(service, subservice)]
    if key:
        assert d[key] == value


@pytest.mark.parametrize("corrupt,name", [
    (lambda b: b[:-1] + bytes([b[-1] ^ 1]), "checksum"),
    (lambda b: b + b"\x00", "length"),
])
def test_a_corrupted_spacepackets_tc_is_refused_by_name(corrupt, name):
    raw = PusTc(service=17, message_subtype=1, apid=ROBOT_APID, seq_count=5).pack()
    r = mmic("decode", "pus-tc", corrupt(bytes(raw)).hex(), check=False)
    assert r.returncode == 1 and f"{name} check failed" in r.stderr, r.stderr
    assert r.stdout == ""
