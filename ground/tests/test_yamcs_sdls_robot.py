"""YAMCS 5.12.8 with SDLS on both directions and the Rust robot: the simulated robot behind the server
board's `FrameGateway` secured with `mmic::link::sdls` (`mmic sim --protocol pus --link frames
--sdls-keys DIR`), the keys the harness made for this run (ground/yamcs/links/frames-sdls.yaml, the
plug-in that re-protects COP-1 retransmissions, ground/README.md).

- COP-1 initiates through protected TM frames (their CLCW), `mode` 2 and the reconfiguration a -> m
  complete through ST[1] (the TC frames decrypt on the server board, the reports decrypt in YAMCS);
- YAMCS's TM link refused no frame, and its last accepted TM IV follows the robot's counter;
- board A executed each command once (its own `executed` events).
"""
from __future__ import annotations

import json
import time
from pathlib import Path

import pytest
from rust_side import XTCE, RobotProcess, sdls_sim_command, wait
from yamcs_harness import INSTANCE, Yamcs

STEP = 10.0
MOTION = 90.0




@pytest.fixture(scope="module")
def loop(tmp_path_factory):
    out = tmp_path_factory.mktemp("sdls-robot")
    y = Yamcs(XTCE, link="frames-sdls", max_lifetime=240)
    y.start()
    try:
        r = RobotProcess(tm_port=y.tm_port, tc_port=y.tc_port,
                         command=sdls_sim_command(out, y.sdls_key_dir))
        assert r.ready.wait(STEP), "the robot did not start"
        try:
            yield y, r, out
        finally:
            r.close()
    finally:
        y.stop()


def invalid_frames(y) -> int:
    info = y.client.get_link(INSTANCE, "tm-frames").get_info()
    return int(info._proto.extra.fields["Invalid frames"].string_value)


def complete(cmd, timeout):
    cmd.await_complete(timeout=timeout)
    assert cmd.is_success(), f"{cmd.error} {cmd.acknowledgments}"
    for stage in ("Verifier_Accepted", "Verifier_Started", "Verifier_Complete"):
        a = cmd.acknowledgments.get(stage)
        assert a and a.status == "OK", (stage, cmd.acknowledgments)


def test_commands_complete_and_telemetry_decodes_under_sdls(loop):
    y, robot, out = loop
    link = y.client.get_link(INSTANCE, "tc-frames.vc0")

    def active():
        st = link.get_cop1_status()
        if st.state == "UNINITIALIZED":
            link.initialize_cop1("WITH_CLCW_CHECK", clcw_wait_timeout=5)
        return st.cop1_active and st.state == "ACTIVE"

    assert wait(active, 30, 1.0), link.get_cop1_status()
    commands = y.client.get_processor(INSTANCE, "realtime").create_command_connection()
    cmd = commands.issue("/MMIC/mode", args={"mode": 2})
    complete(cmd, STEP)
    cmd2 = commands.issue("/MMIC/reconfiguration", args={"initial": "a", "target": "m"})
    complete(cmd2, MOTION)
    tm = y.client.get_link(INSTANCE, "tm-frames")
    assert invalid_frames(y) == 0
    assert tm.sdls_get_ctr(513) > 0
    # The robot's wire log: every TC data frame verified (none refused), FARM-1 accepted both.
    tc = [d for d in list(robot.log) if d.get("dir") == "tc-frame"]
    assert tc and all(d.get("refused") is None for d in tc), tc
    assert [d["farm"] for d in tc if d["hex"][:2] == "01"] == ["accept", "accept"], tc
    # Board A ran each command once.
    records = []
    for line in (Path(out) / "sim.jsonl").read_text().splitlines():
        try:
            records.append(json.loads(line))
        except ValueError:
            continue  # a line being written
    executed = [r["event"] for r in records
                if r.get("kind") == "event" and r.get("node") == "board_a1"
                and r["event"].get("type") == "executed" and r["event"].get("command") != "heartbeat"]
    seqs = [e["seq"] for e in executed]
    assert len(seqs) == len(set(seqs)) and len(seqs) >= 2, executed
    print(f"\nSDLS loop: {len(tc)} TC frames, TM IV {tm.sdls_get_ctr(513)}, board A executed {len(executed)}")
