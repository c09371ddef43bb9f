"""The Python reader of transfer frames (ground/frames.py) on frames built here by hand from the
standards' layouts: a packet spanning frames, idle data, a lost frame, the CLCW's fields, a TC frame
of each kind. (Against the Rust gateway's frames: test_yamcs_frames.py.)"""
from __future__ import annotations

import pytest
from frames import FHP_NO_PACKET, FHP_ONLY_IDLE, Clcw, FrameError, TcFrame, TmExtractor, TmFrame
from rust_side import crc16_ccitt_false

LEN, SCID = 64, 0x101
DATA = LEN - 6 - 4 - 2


def packet(apid: int, n: int, fill: int) -> bytes:
    """A space packet of n octets (header 6 + data n-6), TM, unsegmented."""
    return ((apid & 0x7FF) | 0x0800).to_bytes(2, "big") + (0xC000).to_bytes(2, "big") + \
        (n - 7).to_bytes(2, "big") + bytes([fill]) * (n - 6)


def frame(vc: int, fhp: int, data: bytes, clcw: bytes = b"\x01\x00\x00\x05") -> bytes:
    assert len(data) == DATA
    h = (SCID << 36) | (0 << 33) | (1 << 32) | ((vc & 0xFF) << 24) | ((vc & 0xFF) << 16) | (0b11 << 11) | fhp
    body = h.to_bytes(6, "big") + data + clcw
    return body + crc16_ccitt_false(body).to_bytes(2, "big")


def test_a_packet_spanning_two_frames_and_idle_fill():
    p1, p2 = packet(0x101, 30, 0xA1), packet(0x101, 60, 0xB2)
    stream = p1 + p2
    idle = packet(0x7FF, DATA * 2 - len(stream), 0x55)
    stream += idle
    f0 = frame(0, 0, stream[:DATA])
    f1 = frame(1, FHP_NO_PACKET if len(p1) + len(p2) - DATA > DATA else len(p1) + len(p2) - DATA, stream[DATA:])
    x = TmExtractor(LEN, SCID)
    assert x.push(f0) == [p1]
    assert x.push(f1) == [p2]
    assert x.idle_packets == 1 and x.lost_frames == 0
    assert x.push(frame(2, FHP_ONLY_IDLE, b"\x55" * DATA)) == []


def frames_of(packets: list[bytes]) -> list[bytes]:
    """The packets laid end to end over frames, each frame's first header pointer at the first packet
    starting in it, the last frame filled with an idle packet (at least 7 octets: may add a frame)."""
    stream, starts = b"", []
    for p in packets:
        starts.append(len(stream))
        stream += p
    room = -len(stream) % DATA
    if room < 7:
        room += DATA
    starts.append(len(stream))
    stream += packet(0x7FF, room, 0x55)
    out = []
    for k in range(len(stream) // DATA):
        inside = [s - k * DATA for s in starts if k * DATA <= s < (k + 1) * DATA]
        out.append(frame(k, inside[0] if inside else FHP_NO_PACKET, stream[k * DATA:(k + 1) * DATA]))
    return out


def test_a_lost_frame_drops_the_packets_it_cut_and_nothing_else():
    # DATA = 52: p1 0..40, p2 40..80 (spans frames 0-1), p3 80..96, p4 96..200 (spans 1-3), p5 200..220
    ps = [packet(0x101, n, i) for i, n in enumerate((40, 40, 16, 104, 20))]
    fs = frames_of(ps)
    x = TmExtractor(LEN, SCID)
    assert [p for f in fs for p in x.push(f)] == ps and x.lost_frames == 0
    for lost in range(len(fs)):
        x = TmExtractor(LEN, SCID)
        got = [p for k, f in enumerate(fs) if k != lost for p in x.push(f)]
        cut = [p for p, s in zip(ps, (0, 40, 80, 96, 200)) if s < (lost + 1) * DATA and s + len(p) > lost * DATA]
        assert got == [p for p in ps if p not in cut], lost
        # a gap is seen between two frames received: not before the first, nor after the last
        assert x.lost_frames == (1 if 0 < lost < len(fs) - 1 else 0)


def test_the_clcw_fields():
    # COP-1 in effect, VC 0, Lockout, Retransmit, FARM-B counter 2, report value 0x2A
    w = (0 << 31) | (0 << 29) | (0 << 26) | (1 << 24) | (0 << 18) | (1 << 13) | (1 << 11) | (2 << 9) | 0x2A
    c = Clcw.parse(w.to_bytes(4, "big"))
    assert (c.cop_in_effect, c.vcid, c.lockout, c.wait, c.retransmit, c.farm_b_counter, c.report_value) == \
        (1, 0, True, False, True, 2, 0x2A)


def test_a_corrupted_frame_is_refused_by_the_fecf():
    f = bytearray(frame(0, FHP_ONLY_IDLE, b"\x55" * DATA))
    f[10] ^= 1
    with pytest.raises(FrameError) as e:
        TmFrame.parse(bytes(f), frame_len=LEN)
    assert e.value.check == "fecf"


def tc(bypass: int, cc: int, seq: int, body: bytes) -> bytes:
    n = 5 + len(body) + 2
    h = (bypass << 37) | (cc << 36) | (SCID << 24) | (0 << 18) | ((n - 1) << 8) | seq
    raw = h.to_bytes(5, "big") + body
    return raw + crc16_ccitt_false(raw).to_bytes(2, "big")


def test_tc_frames_of_each_kind():
    ad = TcFrame.parse(tc(0, 0, 7, b"\xC0" + b"pkt"))
    assert (ad.kind, ad.seq, ad.map_id, ad.data) == ("AD", 7, 0, b"pkt")
    assert TcFrame.parse(tc(1, 1, 0, b"\x00")).control() == ("unlock", None)
    assert TcFrame.parse(tc(1, 1, 0, b"\x82\x00\x05")).control() == ("set-vr", 5)
    with pytest.raises(FrameError) as e:
        TcFrame.parse(tc(0, 1, 0, b"\x00"))
    assert e.value.check == "flags"
