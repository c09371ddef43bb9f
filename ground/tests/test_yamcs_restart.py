"""YAMCS restarts while the robot runs (the ground's restart, with YAMCS as the ground; issue 29): its
telecommand sequence counts go on from where they were, and the gateway runs its next commands.

YAMCS 5.12.8's own PusCommandPostprocessor numbers each APID's telecommands from 1 again after every
start (its CcsdsSeqCountFiller keeps the counts in memory). The gateway keys telecommands on (APID,
source ID, sequence count) and never runs a key twice, so a restarted YAMCS's `mode operational` with
count 1 (byte for byte the previous session's first telecommand) is answered as that one's copy: YAMCS
shows it complete, and board A did not run it. The plug-in's DurablePusCommandPostprocessor (ground/yamcs-plugin/, decision
`yamcs-sequence-count`) writes each count to data/mmic/mmic-tc-seqcount.txt before the packet leaves.

Both are run against the simulated robot (`mmic sim --protocol pus`, board A's own log): with YAMCS's
own postprocessor the copy is shown (asserted, so that a change in YAMCS or the gateway that removed it
would be seen), with ours the third command gets count 3 and board A runs it.
"""
from __future__ import annotations

import time

import pytest
from rust_side import ROBOT_APID, XTCE, RobotProcess
from test_yamcs_frames import commands_run, sent_binary
from yamcs_harness import INSTANCE, Yamcs

STEP = 15.0   # seconds any single wait may take
SIM = ("{{mmic}} sim --protocol pus --ground-tm-to 127.0.0.1:{{tm_port}} --ground-tc-port {{tc_port}} "
       "--max-seconds {{seconds}} --quiet --out {out}")
OPERATIONAL, STANDBY = 2, 1


def await_run(out, n: int, timeout: float = STEP) -> list[dict]:
    end = time.monotonic() + timeout
    while len(run := commands_run(out)) < n:
        assert time.monotonic() < end, f"board A ran {run}, not {n} commands"
        time.sleep(0.2)
    return run


@pytest.mark.parametrize("durable", [True, False], ids=["durable-counts", "yamcs-own-counts"])
def test_a_restarted_yamcs_numbers_on_and_board_a_runs_its_commands(durable, tmp_path):
    out = tmp_path / "robot"
    y = Yamcs(XTCE, link="packets", max_lifetime=300, durable_seqcount=durable)
    r = None
    t0 = time.monotonic()
    try:
        y.start()
        r = RobotProcess(tm_port=y.tm_port, tc_port=y.tc_port, command=SIM.format(out=out))
        assert r.ready.wait(STEP), "the robot did not start"
        conn = y.client.get_processor(INSTANCE, "realtime").create_command_connection()
        first = []
        for mode in (OPERATIONAL, STANDBY):
            c = conn.issue("/MMIC/mode", args={"mode": mode})
            c.await_complete(timeout=STEP)
            assert c.is_success(), f"{c.error} {c.acknowledgments}"
            first.append((c.attributes["ccsds-seqcount"], sent_binary(c)))
        assert [s for s, _ in first] == [1, 2]
        assert [e["command"] for e in await_run(out, 2)] == [{"mode": "operational"}, {"mode": "standby"}]

        y.restart()  # its client (and the command connection's subscription) closed with it
        conn = y.client.get_processor(INSTANCE, "realtime").create_command_connection()
        c = conn.issue("/MMIC/mode", args={"mode": OPERATIONAL})
        raw = sent_binary(c)
        seq = c.attributes["ccsds-seqcount"]
        if durable:
            assert seq == 3, seq
            c.await_complete(timeout=STEP)
            assert c.is_success(), f"{c.error} {c.acknowledgments}"
            run = await_run(out, 3)
            assert run[-1]["command"] == {"mode": "operational"}, run
            counts = (y.run_dir / "data" / INSTANCE / "mmic-tc-seqcount.txt").read_text()
            assert counts == f"{ROBOT_APID} 3\n", counts
        else:
            # Count 1 again: the previous session's first telecommand, byte for byte; the gateway
            # answers it as that one's copy and board A does not run it.
            # YAMCS then shows it complete from the first one's report: a false report.
            assert seq == 1 and raw == first[0][1], (seq, raw.hex(), first[0][1].hex())
            c.await_complete(timeout=STEP)
            assert c.acknowledgments["Verifier_Complete"].status == "OK", c.acknowledgments
            time.sleep(3.0)
            run = commands_run(out)
            assert len(run) == 2, run
        outcome = {k.replace("Verifier_", ""): a.status for k, a in c.acknowledgments.items()
                   if k.startswith("Verifier_")}
        print(f"\n{'durable' if durable else 'YAMCS own'} counts: first session {[s for s, _ in first]}, "
              f"after the restart {seq}; board A ran {len(commands_run(out))} commands; "
              f"YAMCS's verifiers of the third: {outcome}; restarted in {y.start_seconds:.1f} s; "
              f"{time.monotonic() - t0:.1f} s")
    finally:
        if r is not None:
            r.close()
        y.stop()
