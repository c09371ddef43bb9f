"""ground/sdls.py (the independent SDLS reading) and ground/sdls_attack.py, without YAMCS: published
AES-GCM vectors through sdls.py's own functions, the plan's byte layout of TC and TM frames, the
receiver window, and every attacker's frame refused with its reason while the original is accepted
once. Keys are random per test (tmp_path), never printed."""
from __future__ import annotations

import os
import stat

import pytest
import sdls
import sdls_attack
from frames import TcFrame, TmFrame
from rust_side import crc16_ccitt_false
from sdls_standin import clcw, idle_packet, pus_tm

# GCM specification (McGrew & Viega), test cases 14 and 16, the AES-256 ones with a 96-bit IV (the same
# in NIST SP 800-38D's examples): published, not secrets.
TC14 = dict(key="00" * 32, iv="00" * 12, aad="", pt="00" * 16,
            ct="cea7403d4d606b6e074ec5d3baf39d18", tag="d0d1c8a799996bf0265b98b5d48ab919")
TC16 = dict(key="feffe9928665731c6d6a8f9467308308feffe9928665731c6d6a8f9467308308", iv="cafebabefacedbaddecaf888",
            aad="feedfacedeadbeeffeedfacedeadbeefabaddad2",
            pt="d9313225f88406e5a55909c5aff5269a86a7a9531534f7da2e4c303d8a318a721c3c0c95956809532fcf0e2449a6b525b16aedf5aa0de657ba637b39",
            ct="522dc1f099567d07f47f37a32a84427d643a8cdcbfe5c0c97598a2bd2555d1aa8cb08e48590dbb3da7b08b1056828838c5f61e6393ba7a0abcc9f662",
            tag="76fc6ece0f4e1768cddf8853bb2d551b")


@pytest.fixture
def keys(tmp_path):
    d = tmp_path / "keys"
    sdls.write_random_keys(d, [257, 513])
    return d


@pytest.fixture
def wrong_keys(tmp_path):
    d = tmp_path / "wrong"
    sdls.write_random_keys(d, [257, 258])
    return d


def tc_sa(keys):
    return sdls.SecurityAssociation.from_dir(keys, 257, sdls.TC_AUTH_MASK)


def tm_sa(keys):
    return sdls.SecurityAssociation.from_dir(keys, 513, sdls.TM_AUTH_MASK)


@pytest.mark.parametrize("v", [TC14, TC16], ids=["gcm-case-14", "gcm-case-16"])
def test_published_gcm_vector_through_apply_and_process_security(v):
    """The vector's AAD laid as a frame's masked header (mask all ones over it), its IV as the counter, its
    plaintext as the data: apply_security must give its ciphertext and tag, process_security its plaintext."""
    aad, pt = bytes.fromhex(v["aad"]), bytes.fromhex(v["pt"])
    sa = sdls.SecurityAssociation(0x1234, bytes.fromhex(v["key"]), b"\xff" * len(aad))
    frame = bytearray(aad + bytes(sdls.HEADER_LEN) + pt + bytes(sdls.MAC_LEN))
    sec = len(aad)
    sdls.apply_security(frame, sec, len(frame), sa, int(v["iv"], 16))
    assert frame[:sec] == aad
    assert frame[sec:sec + 2] == b"\x12\x34" and frame[sec + 2:sec + 14].hex() == v["iv"]
    assert frame[sec + 14:-16].hex() == v["ct"]
    assert frame[-16:].hex() == v["tag"]
    iv, plain = sdls.process_security(bytes(frame), sec, len(frame), sa)
    assert (iv, plain) == (int(v["iv"], 16), pt)
    frame[-1] ^= 1
    with pytest.raises(sdls.SdlsError) as e:
        sdls.process_security(bytes(frame), sec, len(frame), sa)
    assert e.value.check == "mac"


def test_masks_are_the_plans():
    assert sdls.TC_AUTH_MASK.hex() == "ff" * 8 + "00" * 12
    assert sdls.TM_AUTH_MASK.hex() == "ff" * 8 + "00" * 12
    assert len(sdls.TC_AUTH_MASK) == len(sdls.TM_AUTH_MASK) == 20
    assert (sdls.tc_spi(1), sdls.tm_spi(1), sdls.OVERHEAD, sdls.TM_DATA_LEN) == (257, 513, 30, 214)


def test_key_files_are_random_0600_and_not_in_repr(keys, tmp_path):
    for spi in (257, 513):
        p = sdls.key_path(keys, spi)
        assert stat.S_IMODE(os.stat(p).st_mode) == 0o600 and p.stat().st_size == 32
    assert sdls.load_key(keys, 257) != sdls.load_key(keys, 513)
    sa = tc_sa(keys)
    assert sa.key.hex() not in repr(sa) and "key" not in repr(sa)
    with pytest.raises(FileExistsError):
        sdls.write_random_keys(keys, [257])        # never overwritten
    (tmp_path / "short").mkdir()
    (tmp_path / "short" / "spi-1.key").write_bytes(b"x" * 16)
    with pytest.raises(sdls.SdlsError) as e:
        sdls.load_key(tmp_path / "short", 1)
    assert e.value.check == "key-length"


def test_tc_layout(keys):
    sa = tc_sa(keys)
    packet = bytes.fromhex("1901c00100062f110100008987")
    f = sdls.protect_tc(0x101, 0, 7, packet, sa, iv=5)
    assert len(f) == 5 + 1 + 14 + len(packet) + 16 + 2
    assert int.from_bytes(f[2:4], "big") & 0x3FF == len(f) - 1           # length field counts the whole frame
    assert f[5] == 0xC0 and f[6:8] == b"\x01\x01" and int.from_bytes(f[8:20], "big") == 5
    assert int.from_bytes(f[-2:], "big") == crc16_ccitt_false(f[:-2])    # FECF over the ciphertext
    assert packet not in f
    plain = TcFrame.parse(f)                                             # frames.py reads it as a frame
    assert (plain.kind, plain.seq, plain.map_id) == ("AD", 7, 0)
    r = sdls.TcReceiver(0x101, {257: sa})
    v = r.receive(f)
    assert (v.kind, v.seq, v.map_id, v.data, v.spi, v.iv) == ("AD", 7, 0, packet, 257, 5)
    bd = sdls.protect_tc(0x101, 0, 0, packet, sa, iv=6, bypass=True)
    assert r.receive(bd).kind == "BD"
    bc = sdls.clear_tc(0x101, 0, 0, b"\x82\x00\x05")                   # Set V(R) 5, in clear
    v = r.receive(bc)
    assert (v.kind, v.data, v.spi, v.iv) == ("BC", b"\x82\x00\x05", None, None)
    for data, check in [(packet, "truncated"), (packet * 4, "unknown-spi")]:  # data frames in clear: refused
        with pytest.raises(sdls.SdlsError) as e:
            r.receive(sdls.clear_tc(0x101, 0, 8, data, kind="AD"))
        assert e.value.check == check


def test_tm_layout(keys):
    sa = tm_sa(keys)
    p = pus_tm(17, 2, 1)
    data = p + idle_packet(sdls.TM_DATA_LEN - len(p))
    f = sdls.protect_tm(0x101, 0, 3, 3, 0, data, clcw(4), sa, iv=9)
    assert len(f) == 256 and f[6:8] == b"\x02\x01" and int.from_bytes(f[8:20], "big") == 9
    assert f[-6:-2] == clcw(4)                                           # OCF in clear, outside the MAC
    plain = TmFrame.parse(f, frame_len=256)                              # frames.py: header, OCF, FECF
    assert (plain.spacecraft_id, plain.vcid, plain.master_count, plain.first_header_pointer) == (0x101, 0, 3, 0)
    assert plain.clcw.report_value == 4
    v = sdls.verify_tm(f, sa, sdls.SeqWindow(sdls.TM_WINDOW))
    assert (v.data, v.iv, v.fhp, v.ocf) == (data, 9, 0, clcw(4))
    # the OCF is not authenticated (355.0): a changed CLCW with a fixed FECF still verifies
    g = bytearray(f)
    g[-3] ^= 0xFF
    g = sdls_attack.with_fecf(bytes(g))
    assert sdls.verify_tm(g, sa).ocf != clcw(4)
    # the whole primary header is: a changed VC count does not
    h = bytearray(f)
    h[3] ^= 1
    with pytest.raises(sdls.SdlsError) as e:
        sdls.verify_tm(sdls_attack.with_fecf(bytes(h)), sa)
    assert e.value.check == "mac"


def test_window():
    w = sdls.SeqWindow(4096)
    w.accept(0)                                   # the sender's first IV
    for iv, check in [(0, "replay"), (4097, "ahead"), ((1 << 96) - 1, "replay"), (1 << 95, "ahead"),
                      ((1 << 95) + 1, "replay")]:
        with pytest.raises(sdls.SdlsError) as e:
            w.check(iv)
        assert e.value.check == check, iv
    w.accept(4096)                                # d = W: accepted
    w.accept(4100)                                # gaps are fine (lost frames)
    with pytest.raises(sdls.SdlsError) as e:
        w.accept(4099)                            # one below the last: a replay, even if never seen
    assert e.value.check == "replay" and w.last == 4100
    fresh = sdls.SeqWindow(10)
    fresh.accept(9)                               # from the start: IVs 0..W-1
    with pytest.raises(sdls.SdlsError):
        sdls.SeqWindow(10).accept(10)
    with pytest.raises(sdls.SdlsError) as e:
        sdls.apply_security(bytearray(64), 0, 64, sdls.SecurityAssociation(1, bytes(32), b""), 1 << 96)
    assert e.value.check == "iv-spent"


def test_every_attack_refused_with_its_reason_and_the_original_accepted_once(keys, wrong_keys):
    sa = tc_sa(keys)
    packet = bytes.fromhex("1901c00100062f110100008987")
    earlier = [sdls.protect_tc(0x101, 0, n, packet, sa, iv=n) for n in range(3)]
    captured = sdls.protect_tc(0x101, 0, 3, packet, sa, iv=3)
    nxt = sdls.protect_tc(0x101, 0, 4, packet, sa, iv=4)
    atts = sdls_attack.attacks(captured, wrong_key_dir=wrong_keys, key_dir=keys, earlier=earlier)
    names = [a.name for a in atts]
    assert len(atts) == len(set(names))
    n = len(captured)
    assert sum(a.name.startswith("flip-") for a in atts) == (n - 2) * 8 * 2 + 2 * 8
    for must in ("replay", "wrong-key", "far-ahead-no-key", "unknown-spi", "other-robot-scid",
                 "other-robot-frame", "other-robot-spi", "earlier-0", "old-counter", "far-ahead-with-key"):
        assert must in names

    def receiver():
        r = sdls.TcReceiver(0x101, {257: sa})
        for f in earlier:
            r.receive(f)
        assert r.receive(captured).iv == 3       # the original, once
        return r

    r = receiver()
    seen = {}
    for a in atts:
        with pytest.raises(sdls.SdlsError) as e:
            r.receive(a.frame)
        assert e.value.check == a.expect, (a.name, str(e.value))
        seen[a.expect] = seen.get(a.expect, 0) + 1
    # nothing refused moved the window: the next genuine frame is accepted
    assert r.windows[257].last == 3
    assert r.receive(nxt).iv == 4
    assert set(seen) == {"replay", "fecf", "mac", "version", "flags", "spacecraft-id", "vcid", "length",
                         "segment-header", "unknown-spi", "ahead"}, seen


def test_other_robot_spi_with_an_sa_of_another_key(keys, wrong_keys):
    """A gateway that also holds SA 258 (robot 2's, its own key) refuses a frame made under another key
    for SPI 258 on its MAC; without that SA, as unknown."""
    sa = tc_sa(keys)
    captured = sdls.protect_tc(0x101, 0, 0, b"\x00" * 13, sa, iv=0)
    attack = {a.name: a for a in sdls_attack.attacks(captured, wrong_key_dir=wrong_keys)}["other-robot-spi"]
    theirs = sdls.SecurityAssociation(258, os.urandom(32), sdls.TC_AUTH_MASK)
    with pytest.raises(sdls.SdlsError) as e:
        sdls.TcReceiver(0x101, {257: sa, 258: theirs}).receive(attack.frame)
    assert e.value.check == "mac"
    with pytest.raises(sdls.SdlsError) as e:
        sdls.TcReceiver(0x101, {257: sa}).receive(attack.frame)
    assert e.value.check == "unknown-spi"


def test_attack_cli(keys, wrong_keys, capsys):
    captured = sdls.protect_tc(0x101, 0, 0, b"\x01" * 13, tc_sa(keys), iv=0)
    assert sdls_attack.main(["--frame", captured.hex(), "--wrong-keys", str(wrong_keys)]) == 0
    out = capsys.readouterr().out
    assert out.count("\n") > 800 and sdls.load_key(keys, 257).hex() not in out
    assert sdls.load_key(wrong_keys, 257).hex() not in out
