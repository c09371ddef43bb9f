"""The Rust side of the ground tests: the `mmic` binary (its path from $MMIC_BIN, which
ground/run-tests sets after building it) and what it makes.

- `mmic(*args)` runs it and returns the CompletedProcess;
- `fixtures(dir)` writes the interop fixtures (`mmic ground fixtures`): tm.jsonl / tc.jsonl (every TM
  type the real PUS gateway emits and the TCs that made them, with the decoded JSON), hk.bin +
  hk.json (a TM(3,25) stream and what each packet carries);
- `RobotProcess` is the robot the YAMCS loop talks to over UDP. By default the stand-in
  `mmic ground robot` (the real gateway + a trivial board A); $GROUND_ROBOT replaces the command
  line (a format string with {mmic}, {tm_port}, {tc_port}, {seconds}), e.g. for
  `mmic sim --protocol pus` (ground/README.md, "Plugging in the simulator");
- `sdls_sim_command(out, keys, state)` is RobotProcess's command for the simulator behind SDLS, as every
  SDLS test with the Rust robot starts it; $GROUND_SDLS_ROBOT replaces its template. The robot's durable
  SDLS state (`--sdls-state`) is provisioned by it (`provision_robot_state`) the first time, and kept for
  every later start of the same test (a restart of the robot process continues its counters).
"""
from __future__ import annotations

import json
import os
import queue
import shlex
import signal
import subprocess
import threading
import time
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
XTCE = REPO / "spec" / "ccsds" / "mmic.xtce.xml"
CCSDSPY_CSV = REPO / "spec" / "ccsds" / "hk-3-25.ccsdspy.csv"
ROBOT_APID = 0x101  # robot 1 (spec/ccsds/services.toml: 0x100 + n)


def wait(pred, seconds: float = 10.0, step: float = 0.1):
    """Polls `pred` every `step` s until it returns something true or `seconds` pass; its last value."""
    end = time.monotonic() + seconds
    while time.monotonic() < end:
        v = pred()
        if v:
            return v
        time.sleep(step)
    return pred()


def crc16_ccitt_false(data: bytes) -> int:
    """CRC-16/CCITT-FALSE (poly 0x1021, init 0xFFFF, no reflection, no final XOR), as PUS requires;
    written here independently of both Rust and spacepackets."""
    crc = 0xFFFF
    for b in data:
        crc ^= b << 8
        for _ in range(8):
            crc = ((crc << 1) ^ 0x1021) & 0xFFFF if crc & 0x8000 else (crc << 1) & 0xFFFF
    return crc


def mmic_bin() -> str:
    b = os.environ.get("MMIC_BIN")
    if not b:
        target = os.environ.get("CARGO_TARGET_DIR", str(REPO / "target"))
        b = str(Path(target) / "debug" / "mmic")
    if not Path(b).is_file():
        raise FileNotFoundError(f"no mmic binary at {b}: run ground/run-tests (it builds it) or set MMIC_BIN")
    return b


def mmic(*args: str, check: bool = True) -> subprocess.CompletedProcess:
    return subprocess.run([mmic_bin(), *args], capture_output=True, text=True, check=check, timeout=60)


def decode_tm(raw: bytes) -> dict:
    return json.loads(mmic("decode", "pus-tm", raw.hex()).stdout)


def decode_tc(raw: bytes) -> dict:
    return json.loads(mmic("decode", "pus-tc", raw.hex()).stdout)


def encode_tm(obj: dict) -> bytes:
    return bytes.fromhex(mmic("encode", "pus-tm", json.dumps(obj)).stdout.strip())


def encode_tc(obj: dict) -> bytes:
    return bytes.fromhex(mmic("encode", "pus-tc", json.dumps(obj)).stdout.strip())


def fixtures(out: Path) -> Path:
    mmic("ground", "fixtures", "--out", str(out))
    return out


def jsonl(path: Path) -> list[dict]:
    return [json.loads(line) for line in path.read_text().splitlines() if line.strip()]


# The simulated robot behind the space data link with SDLS (`Yamcs(link="frames-sdls")`), as the tests start it.
# $GROUND_SDLS_ROBOT replaces this template: RobotProcess's placeholders ({mmic}, {tm_port}, {tc_port},
# {seconds}) and {out} (the run's --out directory), {keys} (the harness's key directory), {state} (the robot's
# durable SDLS state file: counters, key fingerprints, FARM-1's progress; provisioned by sdls_sim_command, in the
# test's temporary directory, never in the key directory, kept across YAMCS's and the robot's restarts).
SDLS_SIM = ("{mmic} sim --protocol pus --link frames --ground-tm-to 127.0.0.1:{tm_port} "
            "--ground-tc-port {tc_port} --max-seconds {seconds} --quiet --out {out} --sdls-keys {keys} "
            "--sdls-state {state}")


def provision_robot_state(keys, state) -> Path:
    """The explicit provisioning step of the robot's durable SDLS state (`mmic sdls provision --keys DIR --state
    FILE`: the keys' fingerprints and first counters, no key) for the keys of `keys`, once per set of keys: `state`
    must not exist yet (mmic refuses to provision over a state file) and must lie outside the key directory."""
    state = Path(state)
    state.parent.mkdir(parents=True, exist_ok=True)
    p = mmic("sdls", "provision", "--keys", str(keys), "--state", str(state), check=False)
    if p.returncode != 0:
        raise RuntimeError(f"mmic sdls provision --state {state}: exit {p.returncode}: {p.stderr.strip()}")
    return state


def sdls_sim_command(out, keys, state=None) -> str:
    """RobotProcess's `command` for `mmic sim` behind SDLS ($GROUND_SDLS_ROBOT or SDLS_SIM). The robot's state file
    (`state`, default `out/robot-sdls.state`) is provisioned if it does not exist yet (the first start under
    these keys) and otherwise used as it is (a restarted robot continues from it, as a server board from its
    flash)."""
    template = os.environ.get("GROUND_SDLS_ROBOT", SDLS_SIM)
    out = Path(out)
    state = Path(state) if state is not None else out / "robot-sdls.state"
    if not state.exists():
        provision_robot_state(keys, state)
    for k, v in (("{out}", out), ("{keys}", keys), ("{state}", state)):
        template = template.replace(k, str(v).replace("{", "{{").replace("}", "}}"))
    return template


class RobotProcess:
    """The robot on UDP: TCs on 127.0.0.1:tc_port, TM to 127.0.0.1:tm_port. Its JSON lines
    ({"dir":"tc"|"tm","hex":..}; with `mmic sim --link frames` {"dir":"tc-frame"|"tm-frame",..})
    arrive on `self.lines` and are all kept, in order, in `self.log`; `next_tc()` gets the next TC
    it received, `next_tc_frame()` the next TC frame. `command` (a format string as $GROUND_ROBOT)
    replaces the command line of $GROUND_ROBOT and the default."""

    def __init__(self, tm_port: int, tc_port: int, seconds: int = 240, command: str | None = None):
        template = command or os.environ.get(
            "GROUND_ROBOT",
            "{mmic} ground robot --tm-port {tm_port} --tc-port {tc_port} --seconds {seconds}")
        cmd = template.format(mmic=mmic_bin(), tm_port=tm_port, tc_port=tc_port, seconds=seconds)
        self.proc = subprocess.Popen(shlex.split(cmd), stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                                     text=True, start_new_session=True)
        self.lines: "queue.Queue[dict]" = queue.Queue()
        self.tc_lines: "queue.Queue[dict]" = queue.Queue()
        self.tc_frame_lines: "queue.Queue[dict]" = queue.Queue()
        self.log: list[dict] = []
        self.ready = threading.Event()
        threading.Thread(target=self._read, daemon=True).start()

    def _read(self):
        for line in self.proc.stdout:
            try:
                d = json.loads(line)
            except ValueError:
                continue
            if d.get("ready"):
                self.ready.set()
            elif d.get("dir") == "tc":
                self.tc_lines.put(d)
            elif d.get("dir") == "tc-frame":
                self.tc_frame_lines.put(d)
            self.log.append(d)
            self.lines.put(d)

    def next_tc(self, timeout: float) -> dict:
        return self.tc_lines.get(timeout=timeout)

    def next_tc_frame(self, timeout: float) -> dict:
        return self.tc_frame_lines.get(timeout=timeout)

    def close(self):
        if self.proc.poll() is None:
            os.killpg(self.proc.pid, signal.SIGTERM)
            try:
                self.proc.wait(5)
            except subprocess.TimeoutExpired:
                os.killpg(self.proc.pid, signal.SIGKILL)
                self.proc.wait()
