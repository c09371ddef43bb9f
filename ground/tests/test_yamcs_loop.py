"""End-to-end loop: the Rust side (PUS-C over UDP) <-> YAMCS 5.12.8 with the generated XTCE <-> yamcs-client.

One YAMCS for the whole module (ground/yamcs_harness.py), loaded with spec/ccsds/mmic.xtce.xml (`mmic
xtce`; GROUND_MDB: another file, e.g. a mutated copy, to see these tests fail). The robot is the
Rust stand-in `mmic ground robot` (the real PUS gateway + a trivial board A; $GROUND_ROBOT swaps in
another command line, see ground/README.md). Raw TM injected by the tests is made by `mmic encode
pus-tm` or by the gateway (`mmic ground fixtures`), sent as robot 2 (APID 0x102) so as not to disturb
robot 1's sequence counts.
(a) TM(3,25) values (the edge values of all 34 parameters) come back equal through a parameter
    subscription; bad CRC and APIDs outside 0x101..=0x1FF are not taken; units; MET -> UTC.
(b) TCs issued through yamcs-client reach the robot as the bytes YAMCS recorded; the gateway's ST[1]
    reports drive the XTCE verifiers: are-you-alive, mode operational then a reconfiguration complete;
    a reconfiguration in Standby fails with board A's refusal code; a reconfiguration to a stretch state
    fails at acceptance; reports with another request ID do nothing; a TC nobody answers fails on the
    acceptance timeout (yamcs.onTimeout=FAIL); housekeeping is switched off and on by TC; an
    out-of-range argument is refused by YAMCS; the robot's HK read back equals what it sent.
"""
from __future__ import annotations

import datetime as dt
import json
import os
import queue
import socket
import sys
import threading
import time

import pytest
from rust_side import ROBOT_APID, XTCE, RobotProcess, decode_tm, encode_tm, jsonl
from yamcs_harness import INSTANCE, Yamcs


ROBOT2 = 0x102
STEP = 10.0  # seconds any single wait may take
# A motion's wait: the stand-in completes one in 0.5 s, the simulated robot (GROUND_ROBOT =
# `mmic sim ... --ground-tm-to`) needs its real duration at scale 1 (a -> m: about 20 s).
MOTION = 90.0
HEADER = ["ccsds_apid", "ccsds_seq_count", "met_coarse", "met_fine", "msg_type_counter", "hk_sid"]


@pytest.fixture(scope="module")
def yamcs():
    y = Yamcs(os.environ.get("GROUND_MDB", XTCE), max_lifetime=300)
    y.start()
    print(f"\nYAMCS ready in {y.start_seconds:.1f} s, RSS {(y.rss_kib() or 0) // 1024} MiB, {y.url}")
    try:
        yield y
    finally:
        rss = y.rss_kib()
        y.stop()
        print(f"\nYAMCS RSS at the end: {(rss or 0) // 1024} MiB, stopped in {y.stop_seconds:.1f} s; "
              f"log: {y.log_path}")


@pytest.fixture(scope="module")
def robot(yamcs):
    r = RobotProcess(tm_port=yamcs.tm_port, tc_port=yamcs.tc_port)
    assert r.ready.wait(STEP), "the robot did not start"
    yield r
    r.close()


@pytest.fixture(scope="module")
def inject(yamcs):
    """Sends raw TM datagrams to YAMCS's TM link (127.0.0.1 only)."""
    s = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    yield lambda raw: s.sendto(raw, ("127.0.0.1", yamcs.tm_port))
    s.close()


@pytest.fixture(scope="module")
def processor(yamcs):
    return yamcs.client.get_processor(INSTANCE, "realtime")


@pytest.fixture(autouse=True)
def show_yamcs_log_on_failure(request, yamcs):
    yield
    rep = getattr(request.node, "rep_call", None)
    if rep is not None and rep.failed:
        sys.stderr.write(yamcs.log_tail(80))


@pytest.fixture(scope="module")
def hk_expected(rust_fixtures):
    return json.loads((rust_fixtures / "hk.json").read_text())


class HkCollector:
    """Parameter subscription on every HK parameter and header field; one record per packet."""

    def __init__(self, processor, names):
        self.records: "queue.Queue[dict]" = queue.Queue()
        self.names = ["/MMIC/" + n for n in names]
        self.sub = processor.create_parameter_subscription(self.names, on_data=self._on_data,
                                                           send_from_cache=False)

    def _on_data(self, data):
        rec = {}
        for pv in data.parameters:
            name = pv.name.split("/")[-1]
            if name in rec:  # two packets in one delivery: split
                self.records.put(rec)
                rec = {}
            rec[name] = pv
        if rec:
            self.records.put(rec)

    def next_hk(self, apid, timeout=STEP):
        """The next delivery from a TM(3,25) of `apid`."""
        end = time.monotonic() + timeout
        while True:
            rec = self.records.get(timeout=max(0.01, end - time.monotonic()))
            if "hk_sid" in rec and rec["ccsds_apid"].raw_value == apid:
                return rec

    def until(self, apid, seq_count, timeout=STEP):
        """Every TM(3,25) delivery, in order, up to the one of `apid` with `seq_count` (included)."""
        end = time.monotonic() + timeout
        out = []
        while True:
            rec = self.records.get(timeout=max(0.01, end - time.monotonic()))
            if "hk_sid" in rec:
                out.append(rec)
                if (rec["ccsds_apid"].raw_value, rec["ccsds_seq_count"].raw_value) == (apid, seq_count):
                    return out

    def drain(self, seconds, apid):
        time.sleep(seconds)
        out = []
        while not self.records.empty():
            rec = self.records.get_nowait()
            if "hk_sid" in rec and rec["ccsds_apid"].raw_value == apid:
                out.append(rec)
        return out

    def clear(self):
        while not self.records.empty():
            self.records.get_nowait()

    def close(self):
        # cancel() joins the websocket thread, which can take 10 s: do it in the background.
        threading.Thread(target=self.sub.cancel, daemon=True).start()


@pytest.fixture(scope="module")
def hk_subscription(processor, hk_expected):
    c = HkCollector(processor, HEADER + list(hk_expected[0]["parameters"]))
    time.sleep(0.5)  # let the subscription settle on the server
    yield c
    c.close()


@pytest.fixture
def hk(hk_subscription):
    hk_subscription.clear()
    return hk_subscription


def as_robot2(decoded: dict, **changes) -> bytes:
    """The packet our decoder described, re-encoded for APID 0x102 (same source data)."""
    d = {k: decoded[k] for k in ("seq_count", "counter", "destination_id", "time", "service", "subservice",
                                 "source_data")}
    d.update(apid=ROBOT2, **changes)
    return encode_tm(d)


def assert_hk_equal(rec, expected):
    """Every parameter of a YAMCS delivery equals what the packet carried (raw values; the CUC time
    and counters too)."""
    got = {k: v.raw_value for k, v in rec.items()}
    want = dict(expected["parameters"], hk_sid=1, met_coarse=expected["time"]["coarse"],
                met_fine=expected["time"]["fine"], msg_type_counter=expected["counter"],
                ccsds_seq_count=expected["seq_count"], ccsds_apid=expected["apid"])
    diff = {k: (got.get(k), v) for k, v in want.items() if got.get(k) != v}
    assert not diff, f"YAMCS has / the robot sent: {diff}"


# -- (a) telemetry ---------------------------------------------------------------------------------

def test_hk_values_equal_what_the_gateway_sent(inject, hk, hk_expected):
    assert len(hk_expected) >= 4
    for e in hk_expected:
        inject(as_robot2(e))
        rec = hk.next_hk(ROBOT2)
        assert_hk_equal(rec, dict(e, apid=ROBOT2))
        # engineering values: the labels of the enumerations, from the library's names
        assert rec["mode"].eng_value == e["housekeeping"]["mode"].upper()
        state = e["housekeeping"]["target_state"]
        assert rec["target_state"].eng_value == (state if state else "NONE")


def test_a_wrong_value_would_be_noticed(inject, hk, hk_expected):
    e = hk_expected[1]
    inject(as_robot2(e))
    rec = hk.next_hk(ROBOT2)
    for name in ("v_bat_a", "arm_b_now", "faults"):
        wrong = dict(e, apid=ROBOT2, parameters=dict(e["parameters"], **{name: e["parameters"][name] + 1}))
        with pytest.raises(AssertionError, match=name):
            assert_hk_equal(rec, wrong)


def test_bad_crc_and_foreign_apids_are_not_taken(yamcs, inject, hk, hk_expected):
    e = hk_expected[2]
    bad = bytearray(as_robot2(e, seq_count=100))
    bad[-1] ^= 0x01  # CRC wrong
    inject(bytes(bad))
    for apid in (0x100, 0x200):  # just outside the robots' APIDs 0x101..=0x1FF
        d = {k: e[k] for k in ("time", "source_data")}
        inject(encode_tm(dict(d, apid=apid, service=3, subservice=25)))
    inject(as_robot2(e, seq_count=101))
    # YAMCS takes one link's datagrams in order: whatever it took of the first three came before 101
    # (no fixed wait, which a loaded machine can outlast). Robot 1's own HK may come in between.
    got = [(r["ccsds_apid"].raw_value, r["ccsds_seq_count"].raw_value) for r in hk.until(ROBOT2, 101)
           if r["ccsds_apid"].raw_value != ROBOT_APID]
    assert got == [(ROBOT2, 101)], f"YAMCS delivered {got}: the CRC check or the APID restriction does not hold"
    end = time.monotonic() + STEP
    while not (msgs := [e.message for e in yamcs.client.get_archive(INSTANCE).list_events()
                        if e.message.startswith("Corrupted packet received")]):
        assert time.monotonic() < end, "no 'Corrupted packet received' event"
        time.sleep(0.3)
    crc = int.from_bytes(bad[-2:], "big")
    assert f"Corrupted packet received, computed checkword: {crc ^ 1}; packet checkword: {crc}" in msgs


def test_parameters_have_their_units(yamcs):
    mdb = yamcs.client.get_mdb(INSTANCE)
    for name, unit in [("v_bat_a", "mV"), ("i_bo_b", "mA"), ("arm_a_now", "us"), ("hip_target", "0.01 deg")]:
        units = [u.unit for u in mdb.get_parameter(f"/MMIC/{name}")._proto.type.unitSet]
        assert units == [unit], (name, units)


def test_mission_elapsed_time_is_correlated_to_utc(yamcs, inject, hk, hk_expected):
    e = hk_expected[0]
    power_on = dt.datetime(2026, 11, 23, 12, 0, 0, tzinfo=dt.timezone.utc)
    yamcs.client.get_tco_client(INSTANCE, "tco0").override_coefficients(power_on, 0, 2.0 ** -16, 0)
    inject(as_robot2(e, seq_count=200, time={"coarse": 100, "fine": 32768}))
    t = hk.next_hk(ROBOT2)["v_bat_a"].generation_time
    assert t == power_on + dt.timedelta(seconds=100.5), t


# -- (b) telecommands --------------------------------------------------------------------------------

@pytest.fixture(scope="module")
def commands(processor):
    return processor.create_command_connection()


def ack(cmd, name):
    a = cmd.acknowledgments.get(name)
    return a.status if a else None


def issue(robot, commands, name, args=None):
    """Issues a command; returns it and the TC line the robot logged for it (bytes = YAMCS's)."""
    cmd = commands.issue(f"/MMIC/{name}", args=args or {})
    rx = robot.next_tc(STEP)
    assert rx["refused"] is None, rx
    return cmd, bytes.fromhex(rx["hex"])


def complete(cmd, timeout=STEP):
    cmd.await_complete(timeout=timeout)
    assert cmd.is_success(), f"{cmd.error} {cmd.acknowledgments}"
    for stage in ("Verifier_Accepted", "Verifier_Started", "Verifier_Complete"):
        assert ack(cmd, stage) == "OK", (stage, cmd.acknowledgments)


def test_are_you_alive_completes_and_reaches_the_robot_as_recorded(robot, commands):
    cmd, raw = issue(robot, commands, "are_you_alive")
    complete(cmd)
    assert cmd.attributes["binary"] == raw
    assert cmd.attributes["ccsds-seqcount"] == int.from_bytes(raw[2:4], "big") & 0x3FFF
    assert raw[7:9] == bytes([17, 1])


def test_reconfiguration_in_standby_fails_with_the_refusal_code(robot, commands):
    cmd, raw = issue(robot, commands, "reconfiguration", {"initial": "a", "target": "m"})
    assert raw[11:14] == bytes([9]) + b"am"
    cmd.await_complete(timeout=STEP)
    assert cmd.is_failure(), cmd.acknowledgments
    assert ack(cmd, "Verifier_Accepted") == "OK" and ack(cmd, "Verifier_Failed") == "OK"
    assert cmd.error == "Verifier Failed return: REFUSED_NOT_ALLOWED_IN_MODE"
    assert ack(cmd, "Verifier_Complete") != "OK"


def test_mode_operational_then_a_reconfiguration_complete(robot, commands, hk):
    cmd, raw = issue(robot, commands, "mode", {"mode": 2})
    assert raw[11:13] == bytes([10, 2])
    complete(cmd)
    cmd, _ = issue(robot, commands, "reconfiguration", {"initial": "a", "target": "m"})
    complete(cmd, MOTION)
    # The robot's own HK now says so, and every value YAMCS shows is what the robot sent.
    sent = {}
    end = time.monotonic() + STEP
    while True:
        rec = hk.next_hk(0x101)
        while not robot.lines.empty():
            line = robot.lines.get_nowait()
            if line.get("dir") == "tm":
                d = decode_tm(bytes.fromhex(line["hex"]))
                if d["service"] == 3:
                    sent[d["seq_count"]] = d
        d = sent.get(rec["ccsds_seq_count"].raw_value)
        if d and d["housekeeping"]["target_state"] == "m":
            break
        assert time.monotonic() < end, "no HK with target state m"
    assert_hk_equal(rec, d)
    assert (rec["mode"].eng_value, rec["target_state"].eng_value) == ("OPERATIONAL", "m")


def test_a_reconfiguration_to_a_stretch_state_fails_at_acceptance(robot, commands):
    cmd, _ = issue(robot, commands, "reconfiguration", {"initial": "a", "target": "d"})
    cmd.await_complete(timeout=STEP)
    assert cmd.is_failure() and ack(cmd, "Verifier_Accepted") != "OK", cmd.acknowledgments
    assert cmd.error == "Verifier Failed return: NO_SUCH_COMMAND"


def hk_sent_before_completion(robot, tc_seq):
    """Sequence counts of the TM(3,25) the robot sent before its TM(1,7) for the TC with CCSDS sequence
    count `tc_seq` (its log is in sending order)."""
    sent = set()
    end = time.monotonic() + STEP
    while True:
        line = robot.lines.get(timeout=max(0.01, end - time.monotonic()))
        if line.get("dir") != "tm":
            continue
        raw = bytes.fromhex(line["hex"])
        if raw[7] == 3:
            sent.add(decode_tm(raw)["seq_count"])
        elif raw[7:9] == bytes([1, 7]) and decode_tm(raw)["report"]["request"]["seq_count"] == tc_seq:
            return sent


def test_housekeeping_off_and_on_by_tc(robot, commands, hk):
    cmd, _ = issue(robot, commands, "disable_housekeeping")
    complete(cmd)
    # An HK the robot sent just before it took the TC can reach us after the completion (another
    # websocket): only HK sent after the TM(1,7) would be wrong.
    before = hk_sent_before_completion(robot, cmd.attributes["ccsds-seqcount"])
    late = [r["ccsds_seq_count"].raw_value for r in hk.drain(2.5, ROBOT_APID)]
    assert [s for s in late if s not in before] == [], (late, before)
    cmd, _ = issue(robot, commands, "modify_collection_interval", {"interval_ms": 200})
    complete(cmd)
    cmd, _ = issue(robot, commands, "enable_housekeeping")
    complete(cmd)
    n = len(hk.drain(2.0, 0x101))
    assert 5 <= n <= 15, f"{n} HK reports in 2 s at 200 ms"
    cmd, _ = issue(robot, commands, "modify_collection_interval", {"interval_ms": 1000})
    complete(cmd)


def test_reports_with_another_request_id_do_nothing_and_silence_times_out(robot, inject, commands):
    # Robot 2 is not served by this gateway: its TCs are refused by the CCSDS layer, unanswered.
    silent = commands.issue("/MMIC/stop", args={"apid": ROBOT2 + 1})
    cmd = commands.issue("/MMIC/stop", args={"apid": ROBOT2})
    for _ in range(2):
        assert robot.next_tc(STEP)["refused"] == "apid"
    seq = cmd.attributes.get("ccsds-seqcount")
    end = time.monotonic() + STEP
    while seq is None and time.monotonic() < end:
        time.sleep(0.05)
        seq = cmd.attributes.get("ccsds-seqcount")

    def report(sub, seq_count, n):
        return encode_tm({"apid": ROBOT2, "seq_count": 300 + n, "service": 1, "subservice": sub,
                          "report": {"stage": {1: "acceptance", 3: "start", 7: "completion"}[sub],
                                     "request": {"apid": ROBOT2, "seq_count": seq_count}}})
    for n, sub in enumerate((1, 3, 7)):
        inject(report(sub, (seq + 1) & 0x3FFF, n))
    time.sleep(2.0)
    assert not cmd.is_complete(), f"completed by reports for another TC: {cmd.acknowledgments}"
    for n, sub in enumerate((1, 3, 7)):
        inject(report(sub, seq, 3 + n))
    complete(cmd)
    # The other one heard nothing: its acceptance window (10 s) ends and fails it (onTimeout FAIL).
    silent.await_complete(timeout=15)
    assert silent.is_failure(), silent.acknowledgments
    assert ack(silent, "Verifier_Accepted") == "TIMEOUT"


def test_out_of_range_argument_is_refused_by_yamcs(robot, commands):
    from yamcs.client import YamcsError

    # The arms' travel (spec/control/servos.toml), not just the servo range.
    with pytest.raises(YamcsError, match=r"Value 2101 is not in the range \[900,2100\]"):
        commands.issue("/MMIC/arm", args={"side": 0, "target": 2, "pulse": 2101})
    with pytest.raises(YamcsError, match=r"not in the range \[1,3\]"):
        commands.issue("/MMIC/mode", args={"mode": 4})
    with pytest.raises(YamcsError, match="cannot be found in enumeration list"):
        commands.issue("/MMIC/reconfiguration", args={"initial": "a", "target": "z"})
    with pytest.raises(queue.Empty):
        robot.next_tc(1.0)


def test_no_tc_was_refused_by_the_robot_but_robot_2s(robot):
    assert robot.proc.poll() is None, robot.proc.stderr.read()
