"""ccsdspy (NASA) decodes a recorded stream of PUS-C TM(3,25) packets with a definition built from a
field list (ground/ccsds/hk-3-25.csv through ground/ccsdspy_defs.py); values and CRCs are checked."""
from __future__ import annotations

from pathlib import Path

import pytest
from ccsdspy_defs import fields_from_csv, fixed_length
from fake_robot import APID, HK_SID, FakeRobot, crc16_ccitt_false, cuc, hk_source_data

FIELDS = Path(__file__).resolve().parents[1] / "ccsds" / "hk-3-25.csv"
SENT = [  # battery mV, mode, fault bitmap, MET seconds
    (3700, 2, 0x00000000, 1.5),
    (0, 0, 0x00000001, 2.25),
    (65535, 3, 0xFFFFFFFF, 3.0),
    (4123, 1, 0x80000000, 4294967295 + 65535 / 65536),
    (3321, 2, 0x00A5005A, 10.0078125),
]


class OfflineRobot(FakeRobot):
    """The fake robot's packet builder, without sockets."""

    def __post_init__(self):
        import threading

        self._lock = threading.Lock()


@pytest.fixture
def recording(tmp_path):
    robot = OfflineRobot(tm_port=0, tc_port=0)
    packets = [robot.tm(3, 25, hk_source_data(mv, mode, faults), met) for mv, mode, faults, met in SENT]
    path = tmp_path / "hk.bin"
    path.write_bytes(b"".join(packets))
    return path, packets


def test_ccsdspy_decodes_the_recorded_hk_stream(recording):
    path, packets = recording
    d = fixed_length(fields_from_csv(FIELDS)).load(str(path), include_primary_header=True)
    n = len(SENT)
    assert list(d["CCSDS_APID"]) == [APID] * n
    assert list(d["CCSDS_PACKET_LENGTH"]) == [len(packets[0]) - 7] * n
    assert list(d["CCSDS_SEQUENCE_COUNT"]) == list(range(n))
    assert list(d["pus_version"]) == [2] * n
    assert (list(d["service"]), list(d["subservice"])) == ([3] * n, [25] * n)
    assert list(d["msg_type_counter"]) == list(range(n))
    assert list(d["hk_sid"]) == [HK_SID] * n
    assert list(d["battery_voltage"]) == [s[0] for s in SENT]
    assert list(d["mode"]) == [s[1] for s in SENT]
    assert list(d["fault_bitmap"]) == [s[2] for s in SENT]
    times = [cuc(s[3]) for s in SENT]
    assert list(d["met_coarse"]) == [int.from_bytes(t[:4], "big") for t in times]
    assert list(d["met_fine"]) == [int.from_bytes(t[4:], "big") for t in times]
    assert list(d["crc"]) == [crc16_ccitt_false(p[:-2]) for p in packets]


def test_a_corrupted_packet_is_noticed(recording, tmp_path):
    _, packets = recording
    bad = bytearray(b"".join(packets))
    bad[len(packets[0]) + 21] ^= 0x10  # battery voltage of the second packet
    path = tmp_path / "bad.bin"
    path.write_bytes(bytes(bad))
    d = fixed_length(fields_from_csv(FIELDS)).load(str(path), include_primary_header=True)
    raw = [bytes(bad[i * len(packets[0]):(i + 1) * len(packets[0])]) for i in range(len(packets))]
    crc_ok = [crc16_ccitt_false(p[:-2]) == c for p, c in zip(raw, d["crc"])]
    assert crc_ok == [True, False, True, True, True]
    assert list(d["battery_voltage"]) != [s[0] for s in SENT]


def test_the_definition_refuses_overlaps():
    with pytest.raises(ValueError, match="before bit"):
        fixed_length([("a", 6, 0, "uint", 16), ("b", 7, 0, "uint", 8)])
    with pytest.raises(ValueError, match="before bit"):
        fixed_length([("in_header", 4, 0, "uint", 16)])
