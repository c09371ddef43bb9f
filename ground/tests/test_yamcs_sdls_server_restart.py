"""YAMCS 5.12.8 across restarts of the robot's server board under SDLS (issue 38, item 8): commanding resumes with
no operator action, no telecommand runs twice, YAMCS's COP-1 never goes to alert, and the server board's ST[5]
reports no refusal of YAMCS's authentic frames but `not-reserved` (severity 1, informative).

One YAMCS (`Yamcs(link="frames-sdls")`: COP-1 with cop1T1 = 3 s, the plug-in's SAs) and one robot, `mmic sim
--protocol pus --link frames --sdls-keys DIR --sdls-state FILE --ground-tm-to .. --ground-tc-port ..` with
`--inject reboot-server@S` at every S of RESTARTS: the server board is down 300 ms (BOOT_MS: what reaches it is
lost, what it held in RAM is gone), then boots from its state file (FARM-1's V(R) and the TC window's last IV,
decision restart-server; the SDLS counters, sdls-counters).

Around each restart a `mode operational` command X is issued at S + offset (the robot's clock starts when it says
ready), and in the rounds marked `probe` a `mode standby` P at S + 0.4 s (just after the server is back); the other
rounds issue P only once X is settled (commanding in a quiet link: only FOP-1's timer T1 brings X back). The test
never initiates COP-1 after the first command. What X's fate is, from the robot's own logs:

- **on the wire**: its AD frame reached the server board while it was down (or after): FOP-1 sends it again (T1,
  or at once on the CLCW's retransmit flag once P has overtaken it), it runs once and completes;
- **taken, run after**: FARM-1 accepted it (its V(R), kept durably, acknowledges it) and the gateway still held
  it in its queue at the restart: the queue is written ahead to the store (decision restart-server), restored at
  boot, and the command runs once after the restart and completes;
- **taken, handed over, lost**: the gateway had handed it to its legacy uplink before the restart but board A
  never got it: it is gone with the uplink's RAM and never runs. YAMCS has no reason to send it again (its CLCW
  acknowledged it) and ends it failed when the Started verifier's window closes (PT30S after release): at most
  once, reported within 30 s (exactly once there would need the uplink's state kept too);
- **run before the restart**: board A ran it before the server went down (its reports may be lost with it).

Checked: board A's `executed` events (sim.jsonl) per round are exactly the commands that ran, none twice; every X
on the wire ran once and completed; every X taken before the restart ran once after it (or, handed over and lost, never ran and YAMCS failed it) (Accepted OK, Started
TIMEOUT); YAMCS's COP-1 events (`COP1_tc-frames.vc0`: no ALERT, no SUSPENDED); the robot refused no TC frame
but `not-reserved` (wire log, tc_frame_refused events); the ST[5] packets YAMCS archived have no sdls_refused
event (0x0200 + n) but n = 6 (not-reserved) at severity 1. Measured: how long after the server is back
(S + 0.3 s) the first command of the round completes; bound: cop1T1 + 1.5 s (see BOUND).
"""
from __future__ import annotations

import json
import threading
import time
from pathlib import Path

import pytest
from rust_side import XTCE, RobotProcess, sdls_sim_command, wait
from yamcs_harness import INSTANCE, Yamcs

STEP = 10.0
T1 = 3.0                      # ground/yamcs/links/frames-sdls.yaml cop1T1 (Yamcs(cop1_t1=3))
DOWN = 0.3                    # host/src/sim/inject.rs BOOT_MS
# The first command of a round completes at most this long after the server is back. The worst case is an X lost
# while the server was down with nothing sent after it: FOP-1 sends it again when T1 expires, T1 after X's first
# transmission (which came before the server was back: T1 from the return at most); then the gateway's visit of
# board A (its polls and visits: ~0.25-0.5 s measured), board A's tick, the ST[1] reports in the next TM frame and
# YAMCS's verifiers (~0.1 s): 1.5 s margin for the rest, on a loaded 2-core machine.
BOUND = T1 + 1.5
# (S, offset of X from S, probe P right after the server is back)
ROUNDS = [(6, -0.15, True), (13, +0.1, False), (20, +0.05, True), (27, +0.2, False), (34, 0.0, True)]
TC_LINK = "tc-frames.vc0"
MODES = {1: "standby", 2: "operational"}


def sim_records(out: Path) -> list[dict]:
    rows = []
    path = out / "sim.jsonl"
    if not path.exists():
        return rows
    for line in path.read_text().splitlines():
        try:
            rows.append(json.loads(line))
        except ValueError:
            continue  # a line being written
    return rows


def executed(out: Path) -> list[dict]:
    """Board A's executed telecommands (the gateway's heartbeat polls aside), each with its sim time t_ms."""
    return [dict(r["event"], t_ms=r["t_ms"]) for r in sim_records(out)
            if r.get("kind") == "event" and r.get("node") == "board_a1"
            and r["event"].get("type") == "executed" and r["event"].get("command") != "heartbeat"]


def ack(cmd, name):
    a = cmd.acknowledgments.get(name)
    return a.status if a else None


def st5_events(y) -> list[tuple[int, int, bytes]]:
    """(subservice = severity, event ID, auxiliary data) of every ST[5] event report YAMCS archived (PUS-C TM: service
    and subservice at octets 7 and 8, the 6-octet CUC time at 13, the event ID at 19, 4 octets of auxiliary data)."""
    seen = []
    for p in y.client.get_archive(INSTANCE).list_packets():
        b = p.binary
        if len(b) >= 25 and b[0] >> 4 == 0 and b[7] == 5:
            seen.append((b[8], int.from_bytes(b[19:21], "big"), b[21:25]))
    return seen


def test_commanding_resumes_after_server_restarts_without_an_operator(tmp_path):
    out = tmp_path / "robot"
    out.mkdir()
    y = Yamcs(XTCE, link="frames-sdls", max_lifetime=240)
    r = None
    t_start = time.monotonic()
    try:
        y.start()
        injects = " ".join(f"--inject reboot-server@{s}" for s, _, _ in ROUNDS)
        r = RobotProcess(tm_port=y.tm_port, tc_port=y.tc_port, seconds=120,
                         command=sdls_sim_command(out, y.sdls_key_dir) + " " + injects)
        assert r.ready.wait(STEP), "the robot did not start"
        t0 = time.monotonic()              # the robot's clock: the injections' times count from here
        stamped: list[tuple[float, dict]] = []

        def pump():
            while True:
                d = r.lines.get()
                stamped.append((time.monotonic() - t0, d))
        threading.Thread(target=pump, daemon=True).start()

        link = y.client.get_link(INSTANCE, TC_LINK)
        initiations = 0

        def active():
            nonlocal initiations
            st = link.get_cop1_status()
            if st.state == "UNINITIALIZED":   # only before the first command (YAMCS's own start-up may miss the CLCW)
                link.initialize_cop1("WITH_CLCW_CHECK", clcw_wait_timeout=5)
                initiations += 1
            return st.cop1_active and st.state == "ACTIVE"

        assert wait(active, 30, 0.5), link.get_cop1_status()
        conn = y.client.get_processor(INSTANCE, "realtime").create_command_connection()
        first = conn.issue("/MMIC/mode", args={"mode": 1})
        first.await_complete(STEP)
        assert first.is_success(), first.acknowledgments
        commands = [("setup", first)]
        rounds = []
        for s, offset, probe in ROUNDS:
            assert time.monotonic() - t0 < s + offset - 0.05, "the previous round overran its time"
            while time.monotonic() - t0 < s + offset:
                time.sleep(0.002)
            x = conn.issue("/MMIC/mode", args={"mode": 2})
            rd = dict(s=s, offset=offset, probe=probe, x=x, x_at=time.monotonic() - t0, p=None)
            if probe:
                while time.monotonic() - t0 < s + DOWN + 0.1:
                    time.sleep(0.002)
                rd["p"] = conn.issue("/MMIC/mode", args={"mode": 1})
                rd["p_at"] = time.monotonic() - t0
            # settled: X complete, or failed, or (handed over, lost) acknowledged and past any retransmission
            end = t0 + s + DOWN + BOUND + 0.5
            while time.monotonic() < end and not x.is_complete():
                time.sleep(0.05)
            if not probe:
                rd["p"] = conn.issue("/MMIC/mode", args={"mode": 1})
                rd["p_at"] = time.monotonic() - t0
            rd["p"].await_complete(STEP)
            rounds.append(rd)
            commands += [("x", x), ("p", rd["p"])]
        # YAMCS ends a command taken but never run when its Started verifier's window (PT30S) closes.
        for rd in rounds:
            if not rd["x"].is_complete():
                try:
                    rd["x"].await_complete(max(1.0, rd["x_at"] + 32.0 - (time.monotonic() - t0)))
                except TimeoutError:
                    pass
        time.sleep(1.0)

        # -- what happened -----------------------------------------------------------------------------------
        runs = executed(out)
        wire = [(t, d) for t, d in stamped if d.get("dir") == "tc-frame"]
        accepts = [(t, int(d["hex"][8:10], 16)) for t, d in wire if d.get("farm") == "accept"]
        report = []
        worst = 0.0
        for i, rd in enumerate(rounds):
            s = rd["s"]
            lo = s * 1000 - 1000
            hi = (rounds[i + 1]["s"] * 1000 - 1000) if i + 1 < len(rounds) else 10 ** 9
            ran = [e["command"]["mode"] for e in runs if lo <= e["t_ms"] < hi]
            ran_before = [e for e in runs if lo <= e["t_ms"] < s * 1000 and e["command"]["mode"] == "operational"]
            x, p = rd["x"], rd["p"]
            # X's frame: the first AD frame FARM-1 accepted after X was issued
            x_acc = next((t for t, _ in accepts if t >= rd["x_at"]), None)
            if ran_before:
                fate = "run before the restart"
            elif x_acc is not None and x_acc < s:
                # FARM-1 took it before the restart: restored from the store's queue and run after
                # it, or (handed to the legacy uplink before the restart, never to board A) lost.
                fate = "taken, run after" if "operational" in ran else "taken, handed over, lost"
            else:
                fate = "on the wire"
            back = s + DOWN
            done = []
            for c in (x, p):
                if c.is_success():
                    gen = c.acknowledgments.get("Verifier_Complete")
                    done.append(gen.time.timestamp() if gen and gen.time else None)
            # completion on the robot's clock: from YAMCS's acknowledgment time (wall) to t0
            wall0 = time.time() - (time.monotonic() - t0)
            firsts = [d - wall0 for d in done if d is not None]
            first_after = min(firsts) - back if firsts else None
            row = dict(restart=s, x_offset=rd["offset"], probe=rd["probe"], fate=fate, ran=ran,
                       x=("complete" if x.is_success() else f"failed ({ack(x, 'Verifier_Accepted')}/"
                          f"{ack(x, 'Verifier_Started')})"),
                       p="complete" if p.is_success() else "failed",
                       first_complete_after_back_s=None if first_after is None else round(first_after, 2))
            report.append(row)
            # Board A: P ran once, X ran once or (handed over, lost) never, nothing twice.
            if fate == "taken, handed over, lost":
                assert ran == ["standby"], row
                assert not x.is_success() and ack(x, "Verifier_Accepted") == "OK", row
                assert ack(x, "Verifier_Started") in ("TIMEOUT", "CANCELLED"), row
            else:
                assert ran == ["operational", "standby"], row
                if fate in ("on the wire", "taken, run after"):
                    assert x.is_success(), row
            assert p.is_success(), row
            assert first_after is not None and first_after <= BOUND, row
            worst = max(worst, first_after)
        # nothing ran outside the rounds but the first command (so nothing ran twice)
        assert len(runs) == 1 + sum(len(row["ran"]) for row in report), runs
        # YAMCS's COP-1: initiated once at most (before the first command), never an alert or a suspension
        cop1 = [(e.event_type, e.message) for e in y.client.get_archive(INSTANCE).list_events()
                if (e.source or "") == f"COP1_{TC_LINK}"]
        assert not [e for e in cop1 if e[0] in ("ALERT", "SUSPENDED")], cop1
        assert initiations <= 1
        st = link.get_cop1_status()
        assert st.state == "ACTIVE" and st.nn_r == st.v_s, str(st)
        # The server board refused no authentic frame but not-reserved (never an attack)
        refused = [d.get("refused") for _, d in wire if d.get("refused")]
        events = [r_["event"]["check"] for r_ in sim_records(out)
                  if r_.get("kind") == "event" and r_["event"].get("type") == "tc_frame_refused"]
        assert set(refused) <= {"not-reserved"} and set(events) <= {"not-reserved"}, (refused, events)
        st5 = st5_events(y)
        # (the reading is right: board A's mode changes are there, ID 1, severity 1)
        assert sum(1 for sub, eid, _ in st5 if eid == 1 and sub == 1) >= len(rounds), st5
        security = [(sub, eid - 0x0200, int.from_bytes(aux[:2], "big")) for sub, eid, aux in st5
                    if 0x0200 <= eid <= 0x02FF]
        assert all(n == 6 and sub == 1 for sub, n, _ in security), security
        states = sorted({m.split(" to ")[-1] for t, m in cop1 if t == "STATE_CHANGE"})
        print(f"\nserver-board restarts under YAMCS ({time.monotonic() - t_start:.1f} s): {len(rounds)} restarts, "
              f"bound {BOUND:.1f} s after the server is back (T1 {T1:g} s + 1.5 s), worst {worst:.2f} s; "
              f"COP-1 initiations by the test {initiations}, COP-1 states entered {states}, no alert; "
              f"refusals: wire {refused or 'none'}, ST[5] sdls_refused {security or 'none'}")
        for row in report:
            print("  " + ", ".join(f"{k} {v}" for k, v in row.items()))
    finally:
        if r is not None:
            r.close()
        y.stop()
