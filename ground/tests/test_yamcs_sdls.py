"""YAMCS 5.12.8 with SDLS on both directions (ground/yamcs/links/frames-sdls.yaml, `Yamcs(link="frames-sdls")`,
random keys per run) against a Python stand-in robot (ground/sdls_standin.py: ground/sdls.py's receiver, a
minimal FARM-1, protected TM frames with the CLCW). No Rust: these are the facts the Rust side builds on.

(a) YAMCS's protected TC frames verify under the plan's layout and mask (and not under YAMCS's default
    mask: the `authMask` option is in effect); the first protected frame has IV 0; the FECF covers the
    ciphertext; BD frames are protected, BC frames (Unlock, Set V(R)) in clear.
(b) YAMCS takes our protected TM frames (packets archived, link counters), with verifySeqNum on; a
    replayed frame and a forged one are refused (`Invalid frames`, the link's warning event naming
    AntiReplaySequenceNumberFailure / MacVerificationFailure), their packets not archived.
(c) COP-1 retransmissions (T1 = 1 s, three commands in one to three AD frames: YAMCS may put queued
    commands into one frame; the first transmission of N(S) 0 dropped, so every frame goes again): with YAMCS's own SA the MACs of the retransmissions verify but their plaintexts are the
    first transmissions' ciphertexts; with the plug-in's SA (ground/yamcs-plugin/) they are the packets
    again, under fresh IVs (repro_cop1_sdls.py).
(d) with YAMCS's own SA (`sdls_plugin=False`), the first TM frame after YAMCS starts is not window-checked (the
    plug-in's SA, on both directions otherwise, checks it: test_sdls_state.py, test_yamcs_sdls_restart.py).
"""
from __future__ import annotations

import time

import pytest
import repro_cop1_sdls
import sdls
from rust_side import XTCE, crc16_ccitt_false
from rust_side import wait as _wait


def wait(pred, seconds=10.0, step=0.05):
    return _wait(pred, seconds, step)
from sdls_standin import StandIn, pus_tm
from yamcs_harness import INSTANCE, PLUGIN_JAR, Yamcs

STEP = 10.0
# YAMCS's default TC mask (StandardAuthMask.TC with a segment header): VCID bits, segment header, SPI.
YAMCS_DEFAULT_TC_MASK = bytes([0, 0, 0xFC, 0, 0, 0xFF, 0xFF, 0xFF]) + bytes(12)




@pytest.fixture(scope="module")
def loop():
    y = Yamcs(XTCE, link="frames-sdls", max_lifetime=240)
    y.start()
    try:
        with StandIn(y.tm_port, y.tc_port, str(y.sdls_key_dir)) as robot:
            link = y.client.get_link(INSTANCE, "tc-frames.vc0")
            assert wait(lambda: link.get_cop1_status().state == "ACTIVE"), link.get_cop1_status()
            yield y, robot, link
    finally:
        y.stop()
        assert not y.sdls_key_dir.exists()          # the throwaway keys went with the run


def issue(y, name, **kw):
    cmd = y.client.get_processor(INSTANCE, "realtime").create_command_connection().issue(name, **kw)
    packet = repro_cop1_sdls.binary_of(cmd)
    assert packet, cmd.attributes
    return packet


def records_after(robot, n, pred, seconds=STEP):
    return wait(lambda: [r for r in robot.tc[n:] if pred(r)], seconds)


def test_tc_frames_verify_under_the_plans_layout_bd_protected_bc_clear(loop):
    y, robot, link = loop
    n = len(robot.tc)
    packet = issue(y, "/MMIC/are_you_alive")
    ad = records_after(robot, n, lambda r: r.frame and r.frame.kind == "AD")
    assert ad and ad[0].verdict == "accept", robot.tc[n:]
    raw = ad[0].raw
    print(f"\nYAMCS's first protected TC frame ({len(raw)} octets): {raw.hex()}")
    assert len(raw) == 5 + 1 + 14 + len(packet) + 16 + 2
    assert int.from_bytes(raw[2:4], "big") & 0x3FF == len(raw) - 1       # the length field: the whole frame
    assert int.from_bytes(raw[:2], "big") & 0x3FF == 0x101 and raw[0] >> 4 == 0  # SCID 257, AD
    assert raw[4] == 0 and raw[5] == 0xC0                                 # N(S) 0, segment header MAP 0
    assert int.from_bytes(raw[6:8], "big") == 257                         # SPI
    assert raw[8:20] == bytes(12)                                         # the first IV: 0
    assert int.from_bytes(raw[-2:], "big") == crc16_ccitt_false(raw[:-2])  # FECF over the ciphertext
    assert packet not in raw
    assert ad[0].frame.data == packet and ad[0].frame.iv == 0
    sa = sdls.SecurityAssociation.from_dir(y.sdls_key_dir, 257, sdls.TC_AUTH_MASK)
    assert sdls.process_security(raw, 6, len(raw) - 2, sa) == (0, packet)
    default = sdls.SecurityAssociation(257, sa.key, YAMCS_DEFAULT_TC_MASK)
    with pytest.raises(sdls.SdlsError):                                   # so YAMCS used our authMask
        sdls.process_security(raw, 6, len(raw) - 2, default)

    # BD: a command with the cop1Bypass option: protected too, the next IV
    n = len(robot.tc)
    packet = issue(y, "/MMIC/are_you_alive", extra={"cop1Bypass": True})
    bd = records_after(robot, n, lambda r: r.frame and r.frame.kind == "BD")
    assert bd, robot.tc[n:]
    assert bd[0].raw[0] >> 4 == 2 and bd[0].frame.data == packet and bd[0].frame.iv == 1
    assert bd[0].raw[6:8] == b"\x01\x01" and len(bd[0].raw) == 51

    # BC: Unlock and Set V(R) go in clear (no SPI, no IV, no MAC)
    n = len(robot.tc)
    link.disable_cop1(bypass_all=False)      # FOP-1 initiates only from its Initial state (6)
    link.initialize_cop1("UNLOCK")
    unlock = records_after(robot, n, lambda r: r.frame and r.frame.kind == "BC")
    assert unlock and unlock[0].raw[5:-2] == b"\x00" and len(unlock[0].raw) == 8, robot.tc[n:]
    assert unlock[0].verdict == "unlock"
    assert wait(lambda: link.get_cop1_status().state == "ACTIVE")
    n = len(robot.tc)
    link.disable_cop1(bypass_all=False)
    link.initialize_cop1("SET_VR", v_r=robot.v_r)
    setvr = records_after(robot, n, lambda r: r.frame and r.frame.kind == "BC")
    assert setvr and setvr[0].raw[5:-2] == bytes([0x82, 0, robot.v_r]) and len(setvr[0].raw) == 10
    assert wait(lambda: link.get_cop1_status().state == "ACTIVE")
    print(f"BD frame: {bd[0].raw.hex()}\nBC Unlock: {unlock[0].raw.hex()}\nBC Set V(R): {setvr[0].raw.hex()}")
    # every data frame YAMCS sent was verified, none refused, IVs consecutive from 0
    ivs = [r.frame.iv for r in robot.tc if r.frame and r.frame.kind != "BC"]
    assert ivs == list(range(len(ivs))) and not [r for r in robot.tc if r.verdict.startswith("refused")]


def invalid_frames(y) -> int:
    info = y.client.get_link(INSTANCE, "tm-frames").get_info()
    return int(info._proto.extra.fields["Invalid frames"].string_value)


def test_tm_frames_accepted_replay_and_forgery_refused(loop):
    y, robot, _ = loop
    archive = y.client.get_archive(INSTANCE)
    vc0 = y.client.get_link(INSTANCE, "tm-frames.vc0")
    before_in = vc0.get_info()._proto.dataInCount
    packets = [pus_tm(17, 2, robot.next_pus_seq(), met_coarse=k) for k in range(3)]
    for p in packets:
        robot.send_packet(p)
    assert wait(lambda: vc0.get_info()._proto.dataInCount >= before_in + 3)
    archived = lambda: {p.binary for p in archive.list_packets()}
    assert wait(lambda: set(packets) <= archived()), "our packets did not reach YAMCS's archive"
    tm = y.client.get_link(INSTANCE, "tm-frames")
    assert tm.sdls_get_ctr(513) >= 3                    # YAMCS's last accepted TM IV moves with ours
    assert invalid_frames(y) == 0

    carrying = [f for f in robot.sent_tm if int.from_bytes(f[4:6], "big") & 0x7FF == 0]
    old = carrying[0]                                   # a genuine frame that carried a packet
    n_archived = len(archived())
    bad = invalid_frames(y)
    robot.send_raw_tm(old)
    assert wait(lambda: invalid_frames(y) == bad + 1), "the replay was not refused"
    forged = bytearray(robot.make_tm())
    forged[30] ^= 1
    robot.send_raw_tm(bytes(forged[:-2]) + crc16_ccitt_false(bytes(forged[:-2])).to_bytes(2, "big"))
    assert wait(lambda: invalid_frames(y) == bad + 2), "the forged frame was not refused"
    messages = lambda: [e.message for e in archive.list_events() if e.source == "tm-frames"]
    assert wait(lambda: any("SPI 513: AntiReplaySequenceNumberFailure" in m for m in messages())), messages()
    assert wait(lambda: any("SPI 513: MacVerificationFailure" in m for m in messages())), messages()
    time.sleep(0.5)
    assert len(archived()) == n_archived               # the replayed frame's packet was not taken again
    print("\nYAMCS's events: " + " | ".join(m for m in messages()))


def test_a_frame_may_carry_several_of_the_packets_yamcs_sent():
    """YAMCS puts commands queued at once into one TC frame (CI, 2026-11-29: N(S) 1 carried the second and
    the third command): `carried` names them in order, and anything else (a part, a stranger, the order
    changed, garbage) is None. No YAMCS: the packets of that run."""
    p = [bytes.fromhex(h) for h in ("1901c00100062f110100008987", "1901c00200062f1101000041f2",
                                    "1901c00300062f110100000621")]
    assert repro_cop1_sdls.carried(p[0], p) == [0]
    assert repro_cop1_sdls.carried(p[1] + p[2], p) == [1, 2]
    assert repro_cop1_sdls.carried(p[0] + p[1] + p[2], p) == [0, 1, 2]
    assert repro_cop1_sdls.carried(p[2] + p[1], p) is None                 # out of order
    assert repro_cop1_sdls.carried(p[0] + p[2], p) is None                 # one left out
    assert repro_cop1_sdls.carried(p[1] + p[2][:-1], p) is None            # cut short
    assert repro_cop1_sdls.carried(p[1] + b"\x00", p) is None              # a stray octet
    assert repro_cop1_sdls.carried(bytes.fromhex("8f90e847a35733a0b138b0e7fd"), p) is None   # ciphertext
    assert repro_cop1_sdls.carried(b"", p) is None


def test_cop1_retransmission_with_yamcs_sa_is_encrypted_twice():
    """Three commands back to back, in k AD frames (YAMCS may put queued commands into one frame); the first
    transmission of N(S) 0 dropped, the others discarded as ahead by FARM-1; T1 expires and YAMCS sends all k
    again (go-back-N)."""
    res = repro_cop1_sdls.run(False, commands=3)
    ads = [t for t in res["transmissions"] if t["kind"] == "AD"]
    print(f"\n{[{k: v for k, v in t.items() if k != 'hex'} for t in ads]}")
    assert res["retransmitted"], res
    k = res["ad_frames"]
    assert 1 <= k <= 3, res
    first, again = ads[:k], ads[k:]
    assert [t["ns"] for t in first] == list(range(k)) and first[0]["dropped"]
    assert all(t["plaintext_is_packet"] for t in first)
    assert res["first_transmissions_carry"] == [0, 1, 2]                   # each command once, in order
    assert [t["ns"] for t in again[:k]] == list(range(k))
    assert [t["iv"] for t in ads] == list(range(len(ads)))                # a fresh IV each time ...
    for t in again:
        assert t["mac"] == "ok"                                            # ... the MAC verifies ...
        assert not t["plaintext_is_packet"] and t["plaintext_is_previous_ciphertext"], t  # ... garbage
    assert res["farm_accepted"] == list(range(k))     # FARM-1 takes them: COP-1 thinks the TCs delivered
    assert res["cop1_end"]["nn_r"] == res["cop1_end"]["v_s"] == k


@pytest.mark.skipif(not PLUGIN_JAR.is_file(), reason="run ground/setup: it builds ground/yamcs-plugin/")
def test_cop1_retransmission_with_the_plugin_carries_the_packet():
    res = repro_cop1_sdls.run(True, commands=3)
    ads = [t for t in res["transmissions"] if t["kind"] == "AD"]
    print(f"\n{[{k: v for k, v in t.items() if k != 'hex'} for t in ads]}")
    assert res["retransmitted"], res
    k = res["ad_frames"]
    assert 1 <= k <= 3, res
    assert [t["iv"] for t in ads] == list(range(len(ads)))                 # a fresh IV each time
    assert all(t["mac"] == "ok" and t["plaintext_is_packet"] for t in ads), ads
    assert res["first_transmissions_carry"] == [0, 1, 2]
    assert ads[0]["dropped"] and [t["ns"] for t in ads[k:2 * k]] == list(range(k))
    assert [t["carries"] for t in ads[k:2 * k]] == [t["carries"] for t in ads[:k]]   # the same packets again
    assert res["farm_accepted"] == list(range(k))
    assert res["cop1_end"]["nn_r"] == res["cop1_end"]["v_s"] == k


def test_tm_first_frame_after_start_is_not_window_checked():
    """YAMCS's TM SA without a persisted counter (fresh data directory) and without `initialSeqNum` skips the
    window for the first frame and adopts its IV (SecurityAssociationAes256Gcm128's constructor sets
    skipVerifyingNextSeqNum). So an old recorded frame that arrives first is taken, and the genuine frames,
    far ahead of it, are then refused until an operator sets the counter (PUT /api/sdls/.../513/seq)."""
    y = Yamcs(XTCE, link="frames-sdls", max_lifetime=120, sdls_plugin=False)   # YAMCS's own SA
    y.start()
    try:
        with StandIn(y.tm_port, y.tc_port, str(y.sdls_key_dir), period=3600) as robot:  # frames when asked
            tm = y.client.get_link(INSTANCE, "tm-frames")
            valid = lambda: int(tm.get_info()._proto.extra.fields["Valid frames"].string_value)
            robot.tm_iv = 7
            robot.send_tm()                              # an "old" frame (IV 7) arrives first: taken
            assert wait(lambda: valid() == 1) and invalid_frames(y) == 0
            robot.tm_iv = 5_000_000                      # the robot's genuine frames: refused, too far ahead
            robot.send_tm()
            assert wait(lambda: invalid_frames(y) == 1)
            assert tm.sdls_get_ctr(513) == 7
            tm.sdls_set_ctr(513, 5_000_000)              # the operator's way out
            robot.send_tm()
            assert wait(lambda: valid() == 2) and invalid_frames(y) == 1
            assert tm.sdls_get_ctr(513) == 5_000_001
    finally:
        y.stop()
