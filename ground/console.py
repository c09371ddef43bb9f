#!/usr/bin/env python3
"""The operator's console: YAMCS (its web UI is the console) and the simulated robot, started together.

By hand: `ground/console` (the wrapper finds the venv of ground/setup and the `mmic` binary), then open
the URL it prints. Library use (what ground/tests/test_console_browser.py does):

    from console import Console
    with Console(link="frames") as c:
        c.url                      # http://127.0.0.1:<port>/?c=mmic__realtime
        c.page("/telemetry/parameters", system="/MMIC")

What it starts: YAMCS through ground/yamcs_harness.py (`Yamcs(link=...)`, the generated XTCE
spec/ccsds/mmic.xtce.xml, UDP TM in and TC out, its HttpServer with yamcs-web at `/`), then the robot:
`mmic sim --protocol pus [--link frames] --ground-tm-to 127.0.0.1:<tm> --ground-tc-port <tc>
--max-seconds N` (the server board's PUS gateway, board A's two tasks, board B and the plant at scale
1; with `--link frames` the gateway behind FARM-1 and the TM framer, YAMCS's TC link under COP-1; with
`frames-sdls` also `--sdls-keys` (the keys the harness made for YAMCS) and `--sdls-state` (the robot's durable
state, provisioned by `mmic sdls provision` in YAMCS's run directory for those keys)). The
robot's MET is mapped to UTC (the time correlation service `tco0` gets the robot's start as its
power-on), so YAMCS shows the housekeeping at the time it was made. Both run until Ctrl-C, --seconds,
or the robot's end; both are stopped by their process group (YAMCS by the harness, the robot here).
"""
from __future__ import annotations

import argparse
import json
import os
import queue
import signal
import socket
import subprocess
import sys
import threading
import time
from pathlib import Path
from urllib.parse import urlencode

GROUND = Path(__file__).resolve().parent
sys.path.insert(0, str(GROUND))

from rust_side import REPO, XTCE, mmic_bin, provision_robot_state  # noqa: E402
from yamcs_harness import INSTANCE, Yamcs  # noqa: E402

PROCESSOR = "realtime"
CONTEXT = f"{INSTANCE}__{PROCESSOR}"  # yamcs-web's `c` query parameter: instance__processor


class RobotError(RuntimeError):
    pass


class Robot:
    """`mmic sim --protocol pus ... --ground-tm-to` in its own process group. Its JSON lines are read
    by a thread (so its pipe never fills): `ready` is set by {"ready":true}; `tcs` counts the TC
    packets it took ({"dir":"tc"} lines, or with frames the packets FARM-1 passed on from each
    {"dir":"tc-frame"} line), `tc_frames` the TC frames, `tms` the TM packets or frames it sent;
    `last` keeps the last lines for a failure's message."""

    def __init__(self, tm_port: int, tc_port: int, *, link: str, seconds: int, out: Path,
                 sdls_keys: Path | None = None, sdls_state: Path | None = None):
        self.cmd = [mmic_bin(), "sim", "--protocol", "pus", "--ground-tm-to", f"127.0.0.1:{tm_port}",
                    "--ground-tc-port", str(tc_port), "--max-seconds", str(seconds), "--quiet",
                    "--out", str(out)]
        if link != "packets":
            # frames-sdls: the robot's frames with SDLS, under the keys YAMCS was given.
            self.cmd[4:4] = ["--link", "frames"]
        if sdls_keys is not None:
            # and its durable SDLS state (counters, the keys' fingerprints, FARM-1's progress), provisioned for
            # these keys (Console.start: in YAMCS's run directory, outside the key directory)
            self.cmd += ["--sdls-keys", str(sdls_keys), "--sdls-state", str(sdls_state)]
        out.mkdir(parents=True, exist_ok=True)
        self.stderr_path = out / "console-robot.stderr"
        self._stderr = open(self.stderr_path, "w")
        self.proc = subprocess.Popen(self.cmd, stdout=subprocess.PIPE, stderr=self._stderr, text=True,
                                     stdin=subprocess.DEVNULL, start_new_session=True)
        self.started = time.time()
        self.ready = threading.Event()
        self.tcs = self.tc_frames = self.tms = 0
        self.tc_lines: "queue.Queue[dict]" = queue.Queue()
        self.last: list[str] = []
        threading.Thread(target=self._read, daemon=True).start()

    def _read(self):
        assert self.proc.stdout is not None
        for line in self.proc.stdout:
            self.last = (self.last + [line.rstrip()])[-20:]
            try:
                d = json.loads(line)
            except ValueError:
                continue
            if d.get("ready"):
                self.ready.set()
            elif d.get("dir") == "tc":
                self.tcs += 1
                self.tc_lines.put(d)
            elif d.get("dir") == "tc-frame":
                self.tc_frames += 1
                self.tcs += len(d.get("packets") or [])
                self.tc_lines.put(d)
            elif d.get("dir") in ("tm", "tm-frame"):
                self.tms += 1

    def wait_ready(self, timeout: float) -> None:
        end = time.monotonic() + timeout
        while not self.ready.wait(0.2):
            if self.proc.poll() is not None or time.monotonic() > end:
                err = self.stderr_path.read_text(errors="replace")[-2000:]
                why = "exited with status %s" % self.proc.returncode if self.proc.poll() is not None \
                    else f"not ready after {timeout:.0f} s"
                raise RobotError(f"the robot ({' '.join(self.cmd)}) {why}\n{err}")

    def stop(self):
        if self.proc.poll() is None:
            try:
                os.killpg(self.proc.pid, signal.SIGTERM)
                self.proc.wait(5)
            except subprocess.TimeoutExpired:
                os.killpg(self.proc.pid, signal.SIGKILL)
                self.proc.wait()
            except ProcessLookupError:
                pass
        self._stderr.close()


class Console:
    """YAMCS + the simulated robot. Use as a context manager; `url`, `page(...)` give yamcs-web's
    addresses."""

    def __init__(self, *, link: str = "packets", seconds: int = 3600, http_port: int | None = None,
                 tm_port: int | None = None, tc_port: int | None = None, mdb=XTCE,
                 out: Path | None = None, start_timeout: float = 90.0):
        self.link = link
        self.seconds = seconds
        self.out = Path(out) if out else REPO / "target" / "console"
        self.start_timeout = start_timeout
        self.yamcs = Yamcs(mdb, http_port=http_port, tm_port=tm_port, tc_port=tc_port, link=link,
                           max_lifetime=seconds + 60, start_timeout=start_timeout,
                           jvm_options=())  # the JVM's defaults: an operator's run lasts hours
        self.robot: Robot | None = None

    @property
    def url(self) -> str:
        return self.page("/")

    def page(self, path: str, processor: bool = True, **query) -> str:
        """yamcs-web's address of `path` (an Angular route) with the instance's context."""
        q = {"c": CONTEXT if processor else INSTANCE, **query}
        return f"{self.yamcs.url}{path}?{urlencode(q, safe='/')}"

    def start(self) -> "Console":
        self.yamcs.start()
        try:
            keys = state = None
            if self.link == "frames-sdls":
                # the keys YAMCS was given, fresh for this run: the robot's state is provisioned for them
                keys = self.yamcs.sdls_key_dir
                state = provision_robot_state(keys, self.yamcs.run_dir / "robot-sdls.state")
            self.robot = Robot(self.yamcs.tm_port, self.yamcs.tc_port, link=self.link,
                               seconds=self.seconds, out=self.out / "sim", sdls_keys=keys, sdls_state=state)
            self.robot.wait_ready(self.start_timeout)
            # MET -> UTC: the robot's gateway powered on when the process started (to ~0.1 s).
            tco = self.yamcs.client.get_tco_client(INSTANCE, "tco0")
            import datetime as dt

            power_on = dt.datetime.fromtimestamp(self.robot.started, tz=dt.timezone.utc)
            tco.override_coefficients(utc=power_on, obt=0, gradient=2 ** -16, offset=0)
        except BaseException:
            self.stop()
            raise
        return self

    def stop(self) -> None:
        if self.robot is not None:
            self.robot.stop()
        self.yamcs.stop()

    def __enter__(self) -> "Console":
        return self.start()

    def __exit__(self, *exc) -> None:
        self.stop()


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--link", choices=("packets", "frames", "frames-sdls"), default="packets",
                    help="bare PUS packets over UDP, TC/TM transfer frames with COP-1, or those frames "
                         "under SDLS with keys made for the run (default packets)")
    ap.add_argument("--seconds", type=int, default=3600, help="stop after this long (default 3600)")
    ap.add_argument("--http-port", type=int, default=8090, help="YAMCS's web UI and API (default 8090; 0: a free port)")
    ap.add_argument("--tm-port", type=int, default=None, help="UDP TM into YAMCS (default: a free port)")
    ap.add_argument("--tc-port", type=int, default=None, help="UDP TC to the robot (default: a free port)")
    ap.add_argument("--out", default=str(REPO / "target" / "console"),
                    help="the robot's log (sim/sim.jsonl) goes here (default target/console)")
    a = ap.parse_args(argv)
    http = a.http_port or None
    if http:
        with socket.socket() as s:
            if s.connect_ex(("127.0.0.1", http)) == 0:
                ap.error(f"port {http} is taken: --http-port another, or 0 for a free one")
    c = Console(link=a.link, seconds=a.seconds, http_port=http, tm_port=a.tm_port, tc_port=a.tc_port,
                out=Path(a.out))
    # Ctrl-C and SIGTERM both end the run the same way (also when started where SIGINT is ignored,
    # e.g. in the background of a script): YAMCS and the robot are stopped on the way out.
    def interrupt(*_):
        raise KeyboardInterrupt

    signal.signal(signal.SIGINT, interrupt)
    signal.signal(signal.SIGTERM, interrupt)
    print(f"console: starting YAMCS and the simulated robot (link: {a.link}) ...", flush=True)
    with c:
        assert c.robot is not None
        print(f"""console: ready in {c.yamcs.start_seconds:.1f} s (YAMCS) -- open {c.url}
  housekeeping:  {c.page('/telemetry/parameters', system='/MMIC')}
  send command:  {c.page('/commanding/send')}  (e.g. MMIC/mode, mode 2)
  history:       {c.page('/commanding/history')}
  links:         {c.page('/links', processor=False)}{'  (COP-1: ' + c.page('/links/tc-frames.vc0', processor=False) + ')' if a.link.startswith('frames') else ''}
  robot log:     {c.out / 'sim' / 'sim.jsonl'}; YAMCS log: {c.yamcs.log_path}
console: running for {a.seconds} s; Ctrl-C stops YAMCS and the robot""", flush=True)
        end = time.monotonic() + a.seconds
        try:
            while time.monotonic() < end and c.robot.proc.poll() is None:
                time.sleep(0.5)
        except KeyboardInterrupt:
            pass
        if c.robot.proc.poll() is not None and time.monotonic() < end:
            print(f"console: the robot ended (status {c.robot.proc.returncode})", flush=True)
        frames = f" in {c.robot.tc_frames} TC frames" if a.link.startswith("frames") else ""
        print(f"console: {c.robot.tcs} TCs taken by the robot{frames}, {c.robot.tms} TM "
              f"{'frames ' if a.link.startswith('frames') else ''}sent; stopping", flush=True)
    print("console: stopped", flush=True)
    return 0


def run(argv=None) -> int:
    try:
        return main(argv)
    except KeyboardInterrupt:  # during the start: Console.start stopped what it had started
        print("console: interrupted; stopped", flush=True)
        return 130


if __name__ == "__main__":
    sys.exit(run())
