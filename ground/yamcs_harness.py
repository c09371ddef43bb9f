#!/usr/bin/env python3
"""Start a throw-away YAMCS server for the mmic instance, hand out a yamcs-client, stop it.

Library use (what the tests do):

    from yamcs_harness import Yamcs
    with Yamcs(mdb="ground/yamcs/example-mdb.xml") as y:
        client = y.client            # yamcs.client.YamcsClient on y.http_port
        # send TM to 127.0.0.1:y.tm_port, receive TC on 127.0.0.1:y.tc_port

CLI (by hand):  python ground/yamcs_harness.py run [--mdb FILE] [--seconds N] [--http-port P] ...

Each run renders the templates of ground/yamcs/etc/ into a fresh directory under target/ground/
(etc/, data/, cache/, yamcs.log), starts `java ... org.yamcs.YamcsServer` under `timeout`, in its own
process group, waits until the HTTP API answers and the instance is RUNNING, and on exit (also on
failure or Ctrl-C) stops that process group by its PID: SIGTERM, then SIGKILL after a grace period.
On a failed start the tail of yamcs.log is printed.
"""
from __future__ import annotations

import argparse
import json
import os
import shutil
import signal
import socket
import subprocess
import sys
import time
import urllib.error
import urllib.request
from pathlib import Path

GROUND = Path(__file__).resolve().parent
REPO = GROUND.parent
TEMPLATES = GROUND / "yamcs" / "etc"
DEFAULT_MDB = GROUND / "yamcs" / "example-mdb.xml"
INSTANCE = "mmic"


def free_port(kind: int = socket.SOCK_STREAM) -> int:
    """A port that is free on 127.0.0.1 right now (TCP for HTTP, UDP for the links)."""
    with socket.socket(socket.AF_INET, kind) as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def yamcs_classpath() -> str:
    import fprime_yamcs_bundle  # the YAMCS 5.12.8 server jars, from PyPI

    lib = Path(fprime_yamcs_bundle.LIB_DIR)
    jars = sorted(str(p) for p in lib.glob("*.jar"))
    if not jars:
        raise RuntimeError(f"no jars in {lib}")
    return ":".join(jars)


def rss_kib(pid: int) -> int | None:
    """Resident set size of a process and all its descendants (KiB), from /proc."""
    total, todo, seen = 0, [pid], set()
    while todo:
        p = todo.pop()
        if p in seen:
            continue
        seen.add(p)
        try:
            for line in Path(f"/proc/{p}/status").read_text().splitlines():
                if line.startswith("VmRSS:"):
                    total += int(line.split()[1])
            for t in Path(f"/proc/{p}/task").iterdir():
                todo += [int(c) for c in (t / "children").read_text().split()]
        except (FileNotFoundError, ProcessLookupError, PermissionError):
            continue
    return total or None


class YamcsStartError(RuntimeError):
    pass


class Yamcs:
    """A YAMCS server for one run. Use as a context manager."""

    def __init__(self, mdb: str | os.PathLike = DEFAULT_MDB, *, http_port: int | None = None,
                 tm_port: int | None = None, tc_port: int | None = None,
                 run_dir: str | os.PathLike | None = None, start_timeout: float = 60.0,
                 max_lifetime: int = 600, java: str | None = None, xmx: str = "512m"):
        self.mdb = Path(mdb).resolve()
        if not self.mdb.is_file():
            raise FileNotFoundError(self.mdb)
        self.http_port = http_port or free_port(socket.SOCK_STREAM)
        self.tm_port = tm_port or free_port(socket.SOCK_DGRAM)
        self.tc_port = tc_port or free_port(socket.SOCK_DGRAM)
        stamp = time.strftime("%Y%m%d-%H%M%S") + f"-{os.getpid()}"
        self.run_dir = Path(run_dir) if run_dir else REPO / "target" / "ground" / f"yamcs-{stamp}"
        self.start_timeout = start_timeout
        self.max_lifetime = max_lifetime  # hard bound: `timeout` kills YAMCS after this many seconds
        self.java = java or os.environ.get("JAVA", "java")
        self.xmx = xmx
        self.proc: subprocess.Popen | None = None
        self.log_path = self.run_dir / "yamcs.log"
        self.start_seconds: float | None = None
        self.stop_seconds: float | None = None
        self.client = None

    @property
    def url(self) -> str:
        return f"http://127.0.0.1:{self.http_port}"

    # -- set-up ---------------------------------------------------------------------------------
    def _prune(self, keep: int = 5) -> None:
        """Remove all but the newest `keep` earlier run directories (about 7 MB each)."""
        runs = sorted(self.run_dir.parent.glob("yamcs-*"), key=lambda p: p.stat().st_mtime)
        for old in runs[:-keep] if len(runs) > keep else []:
            shutil.rmtree(old, ignore_errors=True)

    def _render(self) -> None:
        if self.run_dir.parent.name == "ground" and self.run_dir.parent.parent.name == "target":
            self._prune()
        if self.run_dir.exists():
            shutil.rmtree(self.run_dir)
        etc = self.run_dir / "etc"
        etc.mkdir(parents=True)
        (self.run_dir / "data").mkdir()
        values = {"@HTTP_PORT@": str(self.http_port), "@TM_PORT@": str(self.tm_port),
                  "@TC_PORT@": str(self.tc_port), "@MDB@": str(self.mdb)}
        for tpl in TEMPLATES.glob("*.yaml"):
            text = tpl.read_text()
            for k, v in values.items():
                text = text.replace(k, v)
            if "@" in "".join(l.split("#")[0] for l in text.splitlines() if "@" in l):
                raise ValueError(f"unreplaced placeholder in {tpl}")
            (etc / tpl.name).write_text(text)

    def _get_json(self, path: str):
        with urllib.request.urlopen(self.url + path, timeout=2) as r:
            return json.load(r)

    def start(self) -> "Yamcs":
        self._render()
        cmd = ["timeout", "--kill-after=10", str(self.max_lifetime),
               self.java, f"-Xmx{self.xmx}", "-cp", yamcs_classpath(), "org.yamcs.YamcsServer",
               "--etc-dir", "etc", "--data-dir", "data"]
        t0 = time.monotonic()
        with open(self.log_path, "wb") as log:
            # cwd = run dir: YAMCS writes ./cache there. Own session: one PID stops the whole group.
            self.proc = subprocess.Popen(cmd, cwd=self.run_dir, stdout=log, stderr=subprocess.STDOUT,
                                         stdin=subprocess.DEVNULL, start_new_session=True)
        try:
            while True:
                if self.proc.poll() is not None:
                    raise YamcsStartError(f"YAMCS exited with status {self.proc.returncode}")
                if time.monotonic() - t0 > self.start_timeout:
                    raise YamcsStartError(f"YAMCS not ready after {self.start_timeout:.0f} s")
                try:
                    if self._get_json(f"/api/instances/{INSTANCE}").get("state") == "RUNNING":
                        break
                except (urllib.error.URLError, ConnectionError, TimeoutError, ValueError):
                    pass
                time.sleep(0.2)
            self.start_seconds = time.monotonic() - t0
            from yamcs.client import YamcsClient

            self.client = YamcsClient(f"127.0.0.1:{self.http_port}")
        except BaseException:
            self.stop()
            sys.stderr.write(self.log_tail())
            raise
        return self

    # -- tear-down ------------------------------------------------------------------------------
    def stop(self, grace: float = 15.0) -> None:
        if self.client is not None:
            try:
                self.client.close()
            except Exception:
                pass
            self.client = None
        p, self.proc = self.proc, None
        if p is None or p.poll() is not None:
            return
        t0 = time.monotonic()
        try:
            self._kill(p, grace)
        finally:
            self.stop_seconds = time.monotonic() - t0

    @staticmethod
    def _kill(p: subprocess.Popen, grace: float) -> None:
        for sig, wait in ((signal.SIGTERM, grace), (signal.SIGKILL, 5.0)):
            try:
                os.killpg(p.pid, sig)  # the group led by our `timeout` process (start_new_session)
            except ProcessLookupError:
                return
            try:
                p.wait(wait)
                return
            except subprocess.TimeoutExpired:
                continue

    def rss_kib(self) -> int | None:
        return rss_kib(self.proc.pid) if self.proc else None

    def log_tail(self, n: int = 60) -> str:
        try:
            lines = self.log_path.read_text(errors="replace").splitlines()
        except FileNotFoundError:
            return f"(no log at {self.log_path})\n"
        return f"---- last {n} lines of {self.log_path} ----\n" + "\n".join(lines[-n:]) + "\n"

    def __enter__(self) -> "Yamcs":
        return self.start()

    def __exit__(self, *exc) -> None:
        self.stop()


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    sub = ap.add_subparsers(dest="cmd", required=True)
    run = sub.add_parser("run", help="start YAMCS, print its ports, stop after --seconds or Ctrl-C")
    run.add_argument("--mdb", default=str(DEFAULT_MDB), help="XTCE file (default: the example)")
    run.add_argument("--seconds", type=int, default=600, help="stop after this long (default 600)")
    for name in ("http", "tm", "tc"):
        run.add_argument(f"--{name}-port", type=int, default=None, help="default: a free port")
    a = ap.parse_args(argv)
    y = Yamcs(a.mdb, http_port=a.http_port, tm_port=a.tm_port, tc_port=a.tc_port,
              max_lifetime=a.seconds + 30)
    signal.signal(signal.SIGTERM, lambda *_: sys.exit(0))
    with y:
        print(json.dumps({"http": y.url, "instance": INSTANCE, "tm_udp_in": f"127.0.0.1:{y.tm_port}",
                          "tc_udp_out": f"127.0.0.1:{y.tc_port}", "run_dir": str(y.run_dir),
                          "start_seconds": round(y.start_seconds, 2), "rss_mib": (y.rss_kib() or 0) // 1024}),
              flush=True)
        try:
            time.sleep(a.seconds)
        except KeyboardInterrupt:
            pass
    print("stopped", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
