"""End-to-end loop: fake robot (PUS-C over UDP) <-> YAMCS 5.12.8 <-> yamcs-client.

One YAMCS for the whole module (started by ground/yamcs_harness.py with the example XTCE).
(a) TM(3,25) values sent by the robot come back equal through a parameter subscription; a packet
    with a bad CRC or another APID is not taken; the CUC mission-elapsed time becomes UTC through
    the time correlation service.
(b) TC(8,1) issued through yamcs-client reaches the robot as a valid PUS-C TC; the robot's ST[1]
    reports drive the XTCE verifiers: (1,1)+(1,7) -> completed, (1,2) -> failed, a report with
    another request ID does nothing; an out-of-range argument is refused by YAMCS.
"""
from __future__ import annotations

import datetime as dt
import os
import queue
import sys
import threading
import time

import pytest
from fake_robot import APID, HK_SID, FakeRobot  # ground/tests (conftest.py puts ground/ on the path)
from yamcs_harness import DEFAULT_MDB, INSTANCE, Yamcs

HK = ["/MMIC/hk_sid", "/MMIC/battery_voltage", "/MMIC/mode", "/MMIC/fault_bitmap",
      "/MMIC/met_coarse", "/MMIC/met_fine", "/MMIC/msg_type_counter"]
CMD = "/MMIC/PERFORM_FUNCTION"
STEP = 10.0  # seconds any single wait may take


@pytest.fixture(scope="module")
def yamcs():
    # GROUND_MDB: another XTCE with the same names (e.g. a mutated copy, to see these tests fail)
    y = Yamcs(os.environ.get("GROUND_MDB", DEFAULT_MDB), max_lifetime=300)
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
    r = FakeRobot(tm_port=yamcs.tm_port, tc_port=yamcs.tc_port)
    yield r
    r.close()


@pytest.fixture(scope="module")
def processor(yamcs):
    return yamcs.client.get_processor(INSTANCE, "realtime")


@pytest.fixture(autouse=True)
def show_yamcs_log_on_failure(request, yamcs):
    yield
    rep = getattr(request.node, "rep_call", None)
    if rep is not None and rep.failed:
        sys.stderr.write(yamcs.log_tail(80))


class HkCollector:
    """Parameter subscription; one record (name -> ParameterValue) per delivery."""

    def __init__(self, processor):
        self.records: "queue.Queue[dict]" = queue.Queue()
        self.sub = processor.create_parameter_subscription(HK, on_data=self._on_data, send_from_cache=False)

    def _on_data(self, data):
        rec = {}
        for pv in data.parameters:
            if pv.name in rec:  # two packets in one delivery: split
                self.records.put(rec)
                rec = {}
            rec[pv.name] = pv
        if rec:
            self.records.put(rec)

    def next_hk(self, timeout=STEP):
        """The next delivery that carries a battery voltage (i.e. came from a TM(3,25))."""
        end = time.monotonic() + timeout
        while True:
            rec = self.records.get(timeout=max(0.01, end - time.monotonic()))
            if "/MMIC/battery_voltage" in rec:
                return rec

    def drain(self, seconds):
        time.sleep(seconds)
        out = []
        while not self.records.empty():
            rec = self.records.get_nowait()
            if "/MMIC/battery_voltage" in rec:
                out.append(rec)
        return out

    def clear(self):
        while not self.records.empty():
            self.records.get_nowait()

    def close(self):
        # cancel() joins the websocket thread, which can take 10 s: do it in the background.
        threading.Thread(target=self.sub.cancel, daemon=True).start()


@pytest.fixture(scope="module")
def hk_subscription(processor):
    c = HkCollector(processor)
    time.sleep(0.5)  # let the subscription settle on the server
    yield c
    c.close()


@pytest.fixture
def hk(hk_subscription):
    hk_subscription.clear()
    return hk_subscription


def assert_hk_equal(rec, battery_mv, mode_label, mode_raw, faults, met):
    got = {k.split("/")[-1]: (v.eng_value, v.raw_value) for k, v in rec.items()}
    coarse, fine = int(met), round((met % 1) * 65536)
    expected = {"hk_sid": (HK_SID, HK_SID), "battery_voltage": (battery_mv, battery_mv),
                "mode": (mode_label, mode_raw), "fault_bitmap": (faults, faults),
                "met_coarse": (coarse, coarse), "met_fine": (fine, fine)}
    for name, value in expected.items():
        assert got.get(name) == value, f"{name}: YAMCS has {got.get(name)}, the robot sent {value}"


# -- (a) telemetry ---------------------------------------------------------------------------------

MODES = {0: "OFF", 1: "STANDBY", 2: "OPERATIONAL", 3: "SAFE"}
HK_CASES = [  # battery mV, mode, fault bitmap, MET seconds: edges of every field
    (3700, 2, 0x00000000, 1.5),
    (0, 0, 0x00000001, 2.25),
    (65535, 3, 0xFFFFFFFF, 3.0),
    (4123, 1, 0x80000000, 4294967295 + 65535 / 65536),
    (3321, 2, 0x00A5005A, 10.0078125),
]


def test_hk_values_equal_what_the_robot_sent(robot, hk):
    for mv, mode, faults, met in HK_CASES:
        robot.send_hk(mv, mode, faults, met)
        assert_hk_equal(hk.next_hk(), mv, MODES[mode], mode, faults, met)


def test_a_wrong_value_would_be_noticed(robot, hk):
    robot.send_hk(3700, 2, 0, 1.0)
    rec = hk.next_hk()
    with pytest.raises(AssertionError, match="battery_voltage"):
        assert_hk_equal(rec, 3701, "OPERATIONAL", 2, 0, 1.0)
    with pytest.raises(AssertionError, match="mode"):
        assert_hk_equal(rec, 3700, "SAFE", 2, 0, 1.0)


def test_bad_crc_and_other_apid_are_not_taken(yamcs, robot, hk):
    bad = bytearray(robot.tm(3, 25, bytes.fromhex("0001" "0457" "02" "00000000"), 5.0))  # 1111 mV
    bad[-1] ^= 0x01  # CRC wrong
    robot.send(bytes(bad))
    robot.send(robot.tm(3, 25, bytes.fromhex("0001" "08ae" "02" "00000000"), 5.0, apid=APID + 1))  # 2222 mV
    robot.send_hk(3333, 2, 0, 6.0)
    got = [r["/MMIC/battery_voltage"].eng_value for r in hk.drain(2.0)]
    assert got == [3333], f"YAMCS delivered {got}: the CRC check or the APID restriction does not hold"
    # The PusPacketPreprocessor said why it dropped the first one (an event, archived).
    end = time.monotonic() + STEP
    while not (msgs := [e.message for e in yamcs.client.get_archive(INSTANCE).list_events()
                        if e.message.startswith("Corrupted packet received")]):
        assert time.monotonic() < end, "no 'Corrupted packet received' event"
        time.sleep(0.3)
    crc = int.from_bytes(bad[-2:], "big")
    assert msgs == [f"Corrupted packet received, computed checkword: {crc ^ 1}; packet checkword: {crc}"]


def test_battery_voltage_has_its_unit(yamcs):
    p = yamcs.client.get_mdb(INSTANCE).get_parameter("/MMIC/battery_voltage")
    units = [u.unit for u in p._proto.type.unitSet]
    assert units == ["mV"], units


def test_mission_elapsed_time_is_correlated_to_utc(yamcs, robot, hk):
    # No coefficients yet: YAMCS stamps the packet with its reception time, whatever the MET says.
    before = dt.datetime.now(dt.timezone.utc)
    robot.send_hk(3700, 2, 0, 1000.0)
    t = hk.next_hk()["/MMIC/battery_voltage"].generation_time
    assert abs((t - before).total_seconds()) < 5, f"uncorrelated generation time {t} vs now {before}"
    # Power-on at a known UTC: obt 0 <-> power_on, one obt unit = 2^-16 s.
    power_on = dt.datetime(2026, 11, 23, 12, 0, 0, tzinfo=dt.timezone.utc)
    yamcs.client.get_tco_client(INSTANCE, "tco0").override_coefficients(power_on, 0, 2.0 ** -16, 0)
    robot.send_hk(3700, 2, 0, 100.5)
    t = hk.next_hk()["/MMIC/battery_voltage"].generation_time
    assert t == power_on + dt.timedelta(seconds=100.5), t


# -- (b) telecommands --------------------------------------------------------------------------------

def get_tc(robot, timeout=STEP):
    rx = robot.tcs.get(timeout=timeout)
    assert not robot.errors, robot.errors
    return rx


@pytest.fixture(scope="module")
def commands(processor):
    return processor.create_command_connection()


def ack_status(cmd, name):
    a = cmd.acknowledgments.get(name)
    return a.status if a else None


def test_tc_is_accepted_and_completed_through_st1(yamcs, robot, commands):
    robot.answer = "complete"
    cmd = commands.issue(CMD, args={"function_id": "SET_MODE", "value": 2})
    rx = get_tc(robot)
    assert (rx.tc.service, rx.tc.message_subtype, rx.tc.app_data) == (8, 1, bytes([1, 2]))
    assert rx.tc.sp_header.apid == APID and rx.tc.pus_tc_sec_header.ack_flags == 9
    cmd.await_complete(timeout=STEP)
    assert cmd.is_success(), f"{cmd.error} {cmd.acknowledgments}"
    assert ack_status(cmd, "Verifier_Accepted") == "OK"
    assert ack_status(cmd, "Verifier_Complete") == "OK"
    # The robot got exactly what YAMCS recorded (postprocessor: length, sequence count, CRC).
    # (cmd.binary is the MDB encoding before postprocessing: sequence count 0, no CRC.)
    assert cmd.attributes["binary"] == rx.raw
    assert cmd.binary == rx.raw[:2] + b"\xc0\x00\x00\x00" + rx.raw[6:-2]
    assert cmd.attributes["ccsds-seqcount"] == rx.tc.sp_header.seq_count
    # The archived command history says the same.
    end = time.monotonic() + STEP
    while True:
        # (yamcs-client 2.1's list_command_history(CMD) asks /commands/MMIC/...: 404 on 5.12.8)
        entries = [e for e in yamcs.client.get_archive(INSTANCE).list_command_history()
                   if e.id == cmd.id]
        if entries and entries[0].is_complete() or time.monotonic() > end:
            break
        time.sleep(0.3)
    assert entries and entries[0].is_success(), entries
    assert entries[0].acknowledgments["Verifier_Complete"].status == "OK"
    assert entries[0].binary == rx.raw


def test_tc_answered_with_acceptance_failure_fails(robot, commands):
    robot.answer, robot.failure_code = "fail-acceptance", 3
    cmd = commands.issue(CMD, args={"function_id": "RECONFIGURE", "value": 1})
    rx = get_tc(robot)
    assert rx.tc.app_data == bytes([2, 1])
    cmd.await_complete(timeout=STEP)
    assert cmd.is_failure(), cmd.acknowledgments
    assert ack_status(cmd, "Verifier_Failed") == "OK"  # the FailedVerifier matched TM(1,2)
    assert cmd.error == "Verifier Failed return: REFUSED_IN_MODE"  # ReturnParmRef: the failure code
    assert ack_status(cmd, "Verifier_Complete") != "OK"


def test_tc_answered_with_completion_failure_fails(robot, commands):
    robot.answer, robot.failure_code = "fail-completion", 4
    cmd = commands.issue(CMD, args={"function_id": "STOP", "value": 0})
    get_tc(robot)
    cmd.await_complete(timeout=STEP)
    assert cmd.is_failure(), cmd.acknowledgments
    assert ack_status(cmd, "Verifier_Accepted") == "OK"
    assert ack_status(cmd, "Verifier_Complete") != "OK"  # PENDING, then CANCELLED
    assert cmd.error == "Verifier Failed return: EXECUTION_FAULT"


def test_reports_with_another_request_id_do_not_complete_the_tc(robot, commands):
    robot.answer = "silent"
    cmd = commands.issue(CMD, args={"function_id": "SET_MODE", "value": 1})
    rx = get_tc(robot)
    seq = rx.tc.sp_header.seq_count
    other = rx.raw[:2] + ((0xC000 | ((seq + 1) & 0x3FFF)).to_bytes(2, "big"))  # next sequence count
    robot.report(1, other)
    robot.report(7, other)
    time.sleep(2.0)
    assert not cmd.is_complete(), f"completed by reports for another TC: {cmd.acknowledgments}"
    robot.report(1, rx.request_id)
    robot.report(7, rx.request_id)
    cmd.await_complete(timeout=STEP)
    assert cmd.is_success(), cmd.acknowledgments


def test_out_of_range_argument_is_refused_by_yamcs(robot, commands):
    robot.answer = "complete"
    from yamcs.client import YamcsError

    with pytest.raises(YamcsError, match=r"Value 4 is not in the range \[0,3\]"):
        commands.issue(CMD, args={"function_id": "SET_MODE", "value": 4})
    with pytest.raises(YamcsError, match="cannot be found in enumeration list"):
        commands.issue(CMD, args={"function_id": "NO_SUCH_FUNCTION", "value": 0})
    with pytest.raises(queue.Empty):
        robot.tcs.get(timeout=1.0)
    assert not robot.errors, robot.errors


def test_no_invalid_tc_reached_the_robot(robot):
    assert not robot.errors, robot.errors
