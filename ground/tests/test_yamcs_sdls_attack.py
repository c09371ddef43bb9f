"""An attacker on the uplink of the Rust robot under SDLS, beside YAMCS: YAMCS 5.12.8 commands the simulated
robot (`mmic sim --protocol pus --link frames --sdls-keys DIR`, as test_yamcs_sdls_robot.py) and an attacker
sends its own frames to the same UDP port YAMCS's TC link sends to.

From one valid protected TC frame captured from the robot's wire log (a `tc-frame` line FARM-1 accepted),
ground/sdls_attack.py builds: the frame again (replay), frames captured earlier, bit flips of every region
(primary header, segment header, SPI, IV, data, MAC; the FECF made good so that the frame reaches SDLS),
a frame under a wrong key, an unknown SPI, the frame readdressed to robot 2 (SCID 258), and, with the key
(a leak: the harness's key directory), an old counter and a counter far ahead. Since the robot has accepted
the captured frame's IV, a copy with a flipped data or MAC bit is refused as a replay before its MAC is
checked; so the MAC is tested on a frame the robot has not seen: one made with the key at the next IV, never
sent itself, of which every bit is flipped in turn.

Each attack frame must be refused for the check the gateway runs first (the wire log's `refused`, its
`tc_frame_refused` event in --out/sim.jsonl), board A's command log (its `executed` events) must not change,
and YAMCS's COP-1 must still work: one more command completes.
"""
from __future__ import annotations

import json
import socket
import time
from pathlib import Path

import pytest
import sdls
import sdls_attack
from rust_side import XTCE, RobotProcess, sdls_sim_command
from yamcs_harness import INSTANCE, Yamcs

STEP = 10.0
SCID = 257
TC_WINDOW = 1 << 20   # spec/ccsds/sdls.toml tc_window


def wait(pred, seconds=STEP, step=0.1):
    end = time.monotonic() + seconds
    while time.monotonic() < end:
        v = pred()
        if v:
            return v
        time.sleep(step)
    return pred()


def records(out: Path) -> list[dict]:
    rows = []
    for line in (out / "sim.jsonl").read_text().splitlines():
        try:
            rows.append(json.loads(line))
        except ValueError:
            continue  # a line being written
    return rows


def executed(out: Path) -> list[int]:
    return [r["event"]["seq"] for r in records(out)
            if r.get("kind") == "event" and r.get("node") == "board_a1"
            and r["event"].get("type") == "executed" and r["event"].get("command") != "heartbeat"]


def complete(cmd, timeout):
    cmd.await_complete(timeout=timeout)
    assert cmd.is_success(), f"{cmd.error} {cmd.acknowledgments}"


def rust_expect(frame: bytes, i: int, bit: int, last_iv: int) -> str:
    """The first check of the server board's `FrameGateway` (frame checks, then SDLS: SPI, window, MAC) that
    refuses `frame` (an AD frame of SCID 257, VC 0, MAP 0, SPI 257) with bit `bit` (0 = MSB) of octet i
    flipped and its FECF made good, the receiver's last accepted IV being `last_iv`."""
    iv = int.from_bytes(frame[8:20], "big")

    def window(v: int) -> str | None:
        d = (v - last_iv) % sdls.IV_SPACE
        if d == 0 or d >= sdls.IV_SPACE // 2:  # the library's table: 2^95 ahead is a replay
            return "replay"
        if d > TC_WINDOW:
            return "too-far-ahead"
        return None

    sdls_check = window(iv) or "bad-mac"
    pos = i * 8 + bit
    if i < 5:
        if pos < 2:
            return "version"
        if pos == 2:
            return sdls_check                  # bypass: AD -> BD, covered by the mask
        if pos == 3:
            return "flags"                     # control command flag with bypass 0
        if pos < 6:
            return "spare"
        if pos < 16:
            return "spacecraft-id"
        if pos < 22:
            return "vcid"
        if pos < 32:
            return "length"
        return sdls_check                      # N(S), covered by the mask
    if i == 5:
        return "sequence-flags" if bit < 2 else "map-id"
    if i < 8:
        return "unknown-spi"
    if i < 20:
        flipped = iv ^ (1 << (95 - ((i - 8) * 8 + bit)))
        return window(flipped) or "bad-mac"
    return sdls_check                          # ciphertext, MAC


@pytest.fixture(scope="module")
def loop(tmp_path_factory):
    out = tmp_path_factory.mktemp("sdls-attack")
    y = Yamcs(XTCE, link="frames-sdls", max_lifetime=240)
    y.start()
    try:
        r = RobotProcess(tm_port=y.tm_port, tc_port=y.tc_port,
                         command=sdls_sim_command(out, y.sdls_key_dir))
        assert r.ready.wait(STEP), "the robot did not start"
        try:
            yield y, r, out, tmp_path_factory.mktemp("sdls-wrong-keys")
        finally:
            r.close()
    finally:
        y.stop()


def test_every_attack_frame_is_refused_and_cop1_still_works(loop):
    y, robot, out, wrong_keys = loop
    t0 = time.monotonic()
    link = y.client.get_link(INSTANCE, "tc-frames.vc0")

    def active():
        st = link.get_cop1_status()
        if st.state == "UNINITIALIZED":
            link.initialize_cop1("WITH_CLCW_CHECK", clcw_wait_timeout=5)
        return st.cop1_active and st.state == "ACTIVE"

    assert wait(active, 30, 1.0), link.get_cop1_status()
    commands = y.client.get_processor(INSTANCE, "realtime").create_command_connection()
    complete(commands.issue("/MMIC/mode", args={"mode": 2}), STEP)

    # The capture: the last protected AD frame FARM-1 accepted (its IV is the receiver's last).
    tc = [d for d in list(robot.log) if d.get("dir") == "tc-frame"]
    accepted = [bytes.fromhex(d["hex"]) for d in tc if d["hex"][:2] == "01" and d.get("farm") == "accept"]
    assert accepted, tc
    captured, earlier = accepted[-1], accepted[:-1]
    last_iv = int.from_bytes(captured[8:20], "big")
    before = executed(out)
    assert before, "board A executed nothing"

    # The attacker's frames, each with the check that must refuse it.
    sdls.write_random_keys(wrong_keys, [sdls.tc_spi(1), sdls.tc_spi(2)])
    made = sdls_attack.attacks(captured, wrong_key_dir=wrong_keys, key_dir=y.sdls_key_dir, earlier=earlier)
    rust_names = {"replay": "replay", "mac": "bad-mac", "ahead": "too-far-ahead", "unknown-spi": "unknown-spi",
                  "spacecraft-id": "spacecraft-id"}
    frames: list[tuple[str, bytes, str]] = []
    for a in made:
        if a.name.startswith("flip-"):
            if not a.name.endswith("fecf-recomputed"):
                continue
            i, bit = (int(x) for x in a.name.split("-")[-3].split("."))
            frames.append((a.name, a.frame, rust_expect(captured, i, bit, last_iv)))
        elif a.name in ("replay", "wrong-key", "wrong-key-same-iv", "far-ahead-no-key", "unknown-spi",
                        "other-robot-scid", "old-counter", "far-ahead-with-key") or a.name.startswith("earlier-"):
            expect = rust_names[a.expect]
            if a.name == "wrong-key-same-iv" or a.name == "far-ahead-no-key":
                # The window runs before the MAC: an IV already used is a replay, one 2^24 ahead too far.
                expect = "replay" if a.name == "wrong-key-same-iv" else "too-far-ahead"
            frames.append((a.name, a.frame, expect))
    # The MAC, on a frame the robot has not seen: made with the key at the next IV, every bit flipped.
    sa = sdls.SecurityAssociation.from_dir(y.sdls_key_dir, sdls.tc_spi(1), sdls.TC_AUTH_MASK)
    _, plaintext = sdls.process_security(captured, sdls.TC_SEC_START, len(captured) - 2, sa)
    fresh = sdls.protect_tc(SCID, 0, (captured[4] + 1) % 256, plaintext, sa, last_iv + 1)
    for i in range(len(fresh) - 2):
        for bit in range(8):
            f = bytearray(fresh)
            f[i] ^= 0x80 >> bit
            frames.append((f"fresh-{sdls_attack.region(i, len(fresh))}-{i}.{bit}",
                           sdls_attack.with_fecf(bytes(f)), rust_expect(fresh, i, bit, last_iv)))
    regions = {n.split("-")[1] for n, _, _ in frames if n.startswith(("flip-", "fresh-"))}
    assert {"primary", "segment", "spi", "iv", "data", "mac"} <= regions, regions

    seen = len(tc)
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as s:
        for k, (_, f, _) in enumerate(frames):
            s.sendto(f, ("127.0.0.1", y.tc_port))
            if k % 20 == 19:
                time.sleep(0.01)  # the robot's socket buffer
    got = wait(lambda: len([d for d in list(robot.log) if d.get("dir") == "tc-frame"]) >= seen + len(frames)
               and [d for d in list(robot.log) if d.get("dir") == "tc-frame"][seen:], 20)
    assert got and len(got) >= len(frames), f"{len(got or [])} of {len(frames)} attack frames logged"
    # Each attack frame, by its octets, refused for the expected check; nothing passed to FARM-1.
    by_hex: dict[str, list[dict]] = {}
    for d in got:
        by_hex.setdefault(d["hex"], []).append(d)
    wrong = []
    for name, f, expect in frames:
        d = by_hex[f.hex()].pop(0)
        if d.get("refused") != expect or d.get("farm") is not None:
            wrong.append((name, expect, d.get("refused"), d.get("farm")))
    assert not wrong, wrong[:20]
    def refused_events():
        rows = [r for r in records(out) if r.get("kind") == "event" and r["event"].get("type") == "tc_frame_refused"]
        return rows if len(rows) >= len(frames) else None

    events = wait(refused_events, 10)
    assert events, f"{len(refused_events() or [])} tc_frame_refused events for {len(frames)} attack frames"
    layers = {r["event"]["layer"] for r in events}
    assert layers == {"sdls", "frame"}, layers

    # Board A's command log is unchanged; YAMCS's COP-1 still works: one more command completes.
    time.sleep(1.0)
    assert executed(out) == before
    complete(commands.issue("/MMIC/mode", args={"mode": 1}), STEP)  # Standby
    after = executed(out)
    assert after[:len(before)] == before and len(after) > len(before), (before, after)
    assert len(set(after)) == len(after), after
    names: dict[str, int] = {}
    for _, _, e in frames:
        names[e] = names.get(e, 0) + 1
    print(f"\nSDLS attack: {len(frames)} attack frames refused ({names}) in {time.monotonic() - t0:.1f} s; "
          f"board A executed {len(before)} before and {len(after)} after one more command")
