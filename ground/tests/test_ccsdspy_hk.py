"""ccsdspy (NASA) decodes a TM(3,25) stream recorded from the Rust side (`mmic ground fixtures`:
the real PUS gateway reporting heartbeats with the edge values of every parameter) with a packet
definition generated from the library (spec/ccsds/hk-3-25.ccsdspy.csv = `mmic xtce --ccsdspy`,
through ground/ccsdspy_defs.py); every value is compared with what the Rust side wrote it
carries (hk.json, `mmic decode pus-tm`'s form)."""
from __future__ import annotations

import pytest
from ccsdspy_defs import fields_from_csv, fixed_length
import json

from rust_side import CCSDSPY_CSV, ROBOT_APID, crc16_ccitt_false, mmic


@pytest.fixture
def recording(rust_fixtures):
    raw = (rust_fixtures / "hk.bin").read_bytes()
    expected = json.loads((rust_fixtures / "hk.json").read_text())
    n = len(expected)
    size = len(raw) // n
    assert size * n == len(raw) and all(e["len"] == size for e in expected)
    return rust_fixtures / "hk.bin", [raw[i * size:(i + 1) * size] for i in range(n)], expected


def test_the_committed_field_list_is_what_mmic_generates():
    assert CCSDSPY_CSV.read_text() == mmic("xtce", "--ccsdspy").stdout


def test_ccsdspy_decodes_the_recorded_hk_stream(recording):
    path, packets, expected = recording
    assert len(packets) >= 4
    d = fixed_length(fields_from_csv(CCSDSPY_CSV)).load(str(path), include_primary_header=True)
    n = len(packets)
    assert list(d["CCSDS_APID"]) == [ROBOT_APID] * n
    assert list(d["CCSDS_PACKET_LENGTH"]) == [len(packets[0]) - 7] * n
    assert list(d["CCSDS_SEQUENCE_COUNT"]) == [e["seq_count"] for e in expected]
    assert list(d["pus_version"]) == [2] * n
    assert (list(d["service"]), list(d["subservice"])) == ([3] * n, [25] * n)
    assert list(d["msg_type_counter"]) == [e["counter"] for e in expected]
    assert list(d["destination_id"]) == [e["destination_id"] for e in expected]
    assert list(d["met_coarse"]) == [e["time"]["coarse"] for e in expected]
    assert list(d["met_fine"]) == [e["time"]["fine"] for e in expected]
    assert list(d["hk_sid"]) == [1] * n
    names = list(expected[0]["parameters"])
    assert len(names) == 34
    for name in names:
        assert list(d[name]) == [e["parameters"][name] for e in expected], name
    assert list(d["crc"]) == [crc16_ccitt_false(p[:-2]) for p in packets]
    # The edge values are really there (not a stream of defaults).
    assert {e["parameters"]["last_seq"] for e in expected} >= {0, 65535}
    assert {e["parameters"]["v_bat_a"] for e in expected} >= {0, 65535}
    assert {e["parameters"]["boot"] for e in expected} >= {0, 0x21, 255}


def test_a_corrupted_packet_is_noticed(recording, tmp_path):
    _, packets, expected = recording
    bad = bytearray(b"".join(packets))
    size = len(packets[0])
    bad[size + 20 + 1] ^= 0x01  # the second packet's mode
    path = tmp_path / "bad.bin"
    path.write_bytes(bytes(bad))
    d = fixed_length(fields_from_csv(CCSDSPY_CSV)).load(str(path), include_primary_header=True)
    raw = [bytes(bad[i * size:(i + 1) * size]) for i in range(len(packets))]
    crc_ok = [crc16_ccitt_false(p[:-2]) == c for p, c in zip(raw, d["crc"])]
    assert crc_ok == [i != 1 for i in range(len(packets))]
    assert list(d["mode"]) != [e["parameters"]["mode"] for e in expected]
    # and our decoder refuses that packet by name
    r = mmic("decode", "pus-tm", raw[1].hex(), check=False)
    assert r.returncode == 1 and "checksum" in r.stderr


def test_the_definition_refuses_overlaps():
    with pytest.raises(ValueError, match="before bit"):
        fixed_length([("a", 6, 0, "uint", 16), ("b", 7, 0, "uint", 8)])
    with pytest.raises(ValueError, match="before bit"):
        fixed_length([("in_header", 4, 0, "uint", 16)])
