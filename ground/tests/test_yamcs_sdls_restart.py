"""YAMCS restarted under SDLS while the simulated robot runs (issue 38, item 8): the plug-in's SAs keep their counters
in durable state files (ground/yamcs-plugin/, `stateFile`), so after every restart YAMCS's TC IVs are above every IV
it sent before, and a TM frame YAMCS accepted before the restart, sent to it again, is refused as a replay, while
the robot's fresh frames are taken and commands complete.

One YAMCS (`Yamcs(link="frames-sdls")`, the plug-in on both directions) and one robot (`mmic sim --link frames
--sdls-keys`, rust_side.sdls_sim_command: $GROUND_SDLS_ROBOT extends it), four sessions and three restarts:

1. SIGTERM, the same data directory;
2. SIGTERM, YAMCS's data directory emptied (its archive and memento database, where YAMCS's own SA keeps its
   counter; the plug-in's state files are elsewhere, in the run's sdls-state/);
3. SIGKILL while a command is being sent (a crash at whatever instant that is).

In each session a command completes through COP-1 (FOP-1 initiates again from the robot's CLCW). Every TC frame on
the wire (the robot's `tc-frame` lines) is verified with the independent ground/sdls.py and its IV read; every TM
frame the robot sent is there too (`tm-frame`), whence the replays. The robot refuses no TC frame.
"""
from __future__ import annotations

import socket
import time
from datetime import datetime, timezone

import pytest
import sdls
import sdls_state
from rust_side import XTCE, RobotProcess, sdls_sim_command, wait
from yamcs_harness import INSTANCE, Yamcs

STEP = 15.0
TC, TM = sdls.tc_spi(1), sdls.tm_spi(1)


def link_count(y, name: str) -> int:
    info = y.client.get_link(INSTANCE, "tm-frames").get_info()
    return int(info._proto.extra.fields[name].string_value)


def cop1_active(y) -> bool:
    link = y.client.get_link(INSTANCE, "tc-frames.vc0")
    st = link.get_cop1_status()
    if st.state == "UNINITIALIZED":
        link.initialize_cop1("WITH_CLCW_CHECK", clcw_wait_timeout=5)
    return st.cop1_active and st.state == "ACTIVE"


def complete(cmd, timeout=STEP):
    cmd.await_complete(timeout=timeout)
    assert cmd.is_success(), f"{cmd.error} {cmd.acknowledgments}"


def wire(robot, start: int, kind: str, end: int | None = None) -> list[dict]:
    return [d for d in list(robot.log)[start:end] if d.get("dir") == kind]


def tc_ivs(robot, sa, start: int, end: int | None = None) -> list[int]:
    """The IVs of the protected TC frames the robot received between log indices `start` and `end`, each frame
    verified."""
    ivs = []
    for d in wire(robot, start, "tc-frame", end):
        raw = bytes.fromhex(d["hex"])
        if raw[0] >> 4 == 3:            # BC: in clear
            continue
        iv, _ = sdls.process_security(raw, sdls.TC_SEC_START, len(raw) - 2, sa)
        ivs.append(iv)
    return ivs


def test_sdls_counters_survive_yamcs_restarts_sigkill_and_a_lost_database(tmp_path):
    out = tmp_path / "robot"
    y = Yamcs(XTCE, link="frames-sdls", max_lifetime=220)
    r = None
    t0 = time.monotonic()
    tx = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    try:
        y.start()
        tc_sa = sdls.SecurityAssociation.from_dir(y.sdls_key_dir, TC, sdls.TC_AUTH_MASK)
        tm_sa = sdls.SecurityAssociation.from_dir(y.sdls_key_dir, TM, sdls.TM_AUTH_MASK)
        r = RobotProcess(tm_port=y.tm_port, tc_port=y.tc_port,
                         command=sdls_sim_command(out, y.sdls_key_dir, tmp_path / "robot-sdls.state"))
        assert r.ready.wait(STEP), "the robot did not start"
        tm_iv = lambda raw: int.from_bytes(raw[8:20], "big")
        starts, captured, report = [], [], []
        restarts = [None, dict(), dict(wipe_database=True), dict(kill=True)]
        modes = [2, 1, 2, 1]
        for k, how in enumerate(restarts):
            if how is not None:
                # What YAMCS accepted before the restart: a TM frame at or below its last accepted IV.
                last_tm = y.client.get_link(INSTANCE, "tm-frames").sdls_get_ctr(TM)
                sent = [bytes.fromhex(d["hex"]) for d in wire(r, 0, "tm-frame")]
                taken = [f for f in sent if tm_iv(f) <= last_tm]
                assert taken, (last_tm, [tm_iv(f) for f in sent[-5:]])
                captured.append(taken[-1])
                if how.get("kill"):
                    # a command on its way when YAMCS is killed: whatever was protected is below the reservation
                    y.client.get_processor(INSTANCE, "realtime").create_command_connection().issue(
                        "/MMIC/mode", args={"mode": modes[k - 1]})
                    time.sleep(0.1)
                stored = {s: sdls_state.read(y.sdls_state_file(s))["value"] for s in (TC, TM)}
                since = datetime.now(timezone.utc)
                y.restart(**how)
                t_restarted = time.monotonic()
            # (the new YAMCS sends no TC frame before the command below: every frame the robot logged so far,
            # the killed YAMCS's included, belongs to the sessions before)
            starts.append(start := len(r.log))
            assert wait(lambda: cop1_active(y), 30, 0.5), \
                y.client.get_link(INSTANCE, "tc-frames.vc0").get_cop1_status()
            conn = y.client.get_processor(INSTANCE, "realtime").create_command_connection()
            complete(conn.issue("/MMIC/mode", args={"mode": modes[k]}))
            ivs = tc_ivs(r, tc_sa, start)
            assert ivs, "no protected TC frame in this session"
            tm = y.client.get_link(INSTANCE, "tm-frames")
            row = {"session": k + 1, "restart": "start" if how is None else
                   ("SIGKILL" if how.get("kill") else "SIGTERM" + (", database wiped" if how else "")),
                   "tc_ivs": (min(ivs), max(ivs), len(ivs))}
            if how is not None:
                row["resumed_s"] = round(time.monotonic() - t_restarted, 1)   # restart to command complete
                before = tc_ivs(r, tc_sa, 0, start)
                # TC: every IV sent after the restart above every IV sent before, and from the stored reservation on
                assert min(ivs) > max(before), (min(ivs), max(before))
                assert min(ivs) >= stored[TC], (min(ivs), stored[TC])
                # TM: the frames captured before each restart so far, sent again: each refused as a replay
                authentic_refused = link_count(y, "Invalid frames")
                valid = link_count(y, "Valid frames")
                for f in captured:
                    tx.sendto(f, ("127.0.0.1", y.tm_port))
                assert wait(lambda: link_count(y, "Invalid frames") == authentic_refused + len(captured), STEP), \
                    (link_count(y, "Invalid frames"), authentic_refused, len(captured))
                msgs = lambda: [e.message for e in y.client.get_archive(INSTANCE).list_events(start=since)
                                if e.source == "tm-frames" and "AntiReplaySequenceNumberFailure" in e.message]
                assert wait(msgs, STEP), "no AntiReplaySequenceNumberFailure event"   # (repeats are merged)
                # ... and the robot's fresh frames are taken (its IVs above the stored floor)
                last_before = tm.sdls_get_ctr(TM)
                assert wait(lambda: link_count(y, "Valid frames") > valid + 2 and tm.sdls_get_ctr(TM) > last_before,
                            STEP)
                assert link_count(y, "Invalid frames") == authentic_refused + len(captured)
                row.update(tm_stored_floor=stored[TM], tm_replayed=[tm_iv(f) for f in captured],
                           tm_authentic_refused=authentic_refused, restart_s=round(y.start_seconds, 1))
            row["tm_last"] = tm.sdls_get_ctr(TM)
            report.append(row)

        sessions = [tc_ivs(r, tc_sa, a, b) for a, b in zip(starts, starts[1:] + [None])]
        for row, ivs in zip(report, sessions):
            row["tc_ivs"] = (min(ivs), max(ivs), len(ivs))     # the whole session's, up to the restart
        for row, a, b in zip(report, starts, starts[1:] + [None]):
            row["robot_refused"] = [d["refused"] for d in wire(r, a, "tc-frame", b) if d.get("refused")]
        every = [iv for s in sessions for iv in s]
        assert len(every) == len(set(every)), "a TC IV was used twice"
        # The robot refused no TC frame as a replay or for its MAC. After a jump of YAMCS's counter (64 at most,
        # the reservation) its receiver may refuse an authentic frame beyond its own durable floor once
        # (`not-reserved`: MAC verified, the next reservation then covers it; COP-1 sends it again, fresh IV).
        refusals = [d["refused"] for d in wire(r, 0, "tc-frame") if d.get("refused")]
        assert set(refusals) <= {"not-reserved"}, refusals
        # the API cannot move the TC counter back (IVs would be used twice)
        tc_link = y.client.get_link(INSTANCE, "tc-frames")
        with pytest.raises(Exception):
            tc_link.sdls_set_ctr(TC, 0)
        assert tc_link.sdls_get_ctr(TC) > max(every)
        # every TM frame the robot sent verifies with sdls.py (the replays were genuine frames)
        for f in captured:
            sdls.verify_tm(f, tm_sa)
        print(f"\nYAMCS SDLS restarts ({time.monotonic() - t0:.1f} s); the robot's TC refusals: {refusals}")
        for row in report:
            print("  " + ", ".join(f"{k} {v}" for k, v in row.items()))
        print(f"  state files: TC reservation {sdls_state.read(y.sdls_state_file(TC))['value']}, "
              f"TM floor {sdls_state.read(y.sdls_state_file(TM))['value']}")
    finally:
        tx.close()
        if r is not None:
            r.close()
        y.stop()


def test_yamcs_does_not_start_an_sa_without_its_state():
    """Fail closed: an SA whose state file is missing stops YAMCS at start (the instance fails, the server exits),
    the log naming the file and the provisioning step; nothing starts from IV 0 and no file is made."""
    seen = []
    for missing in ("all", TC):
        y = Yamcs(XTCE, link="frames-sdls", max_lifetime=60, sdls_provision=missing != "all")
        try:
            y._render()
            if missing == TC:
                y.sdls_state_file(TC).unlink()
            t0 = time.monotonic()
            with pytest.raises(Exception, match="YAMCS exited|FAILED"):
                y.start(render=False)
            seconds = time.monotonic() - t0
        finally:
            y.stop()
        log = y.log_path.read_text(errors="replace")
        spi = TM if missing == "all" else TC        # the TM link is made first
        f = y.sdls_state_file(spi)
        lines = [l for l in log.splitlines() if "Instance mmic failed" in l]
        assert lines and f"SDLS SA {spi}: its counter state file {f} does not exist" in lines[0], log[-3000:]
        assert "ground/sdls_state.py provision" in lines[0]
        assert not f.exists()
        seen.append(f"SA {spi}: YAMCS stopped in {seconds:.1f} s")
    print("\n" + "; ".join(seen))
