#!/usr/bin/env python3
"""An attacker suite against the external-ground simulator under SDLS (issue 38, item 9).

The robot is the shell a user runs: `mmic sim --protocol pus --link frames --sdls-keys DIR --sdls-state FILE
--ground-tm-to ADDR --ground-tc-port P` (the server board's FARM-1 and SDLS, the PUS gateway, boards A and B).
Everything on this side is written here from the standards' layouts alone, with the `cryptography` package's
AES-GCM and nothing of the project (no ground/sdls.py, no ground/frames.py, no Rust): TC transfer frames (CCSDS
232.0), TM transfer frames and their CLCW (132.0, 232.0 §4.2), COP-1's control commands (232.1), SDLS's security
header and trailer (355.0: SPI, a 96-bit IV that is the anti-replay counter, a 128-bit MAC; the AAD the frame's
first 20 octets ANDed with the mission's mask), PUS-C packets (ECSS-E-ST-70-41C). What it knows of the mission is
public: spacecraft ID 0x100 + n, SPIs 0x100 + n (TC) and 0x200 + n (TM), APID 0x100 + n, TM frames of 256 octets
with the CLCW and the FECF, function 10 = `mode`.

The suite makes its own keys and provisions the robot's state once (`mmic sdls provision`), then acts as the
legitimate ground holding those keys (a minimal ground: stop-and-wait COP-1 over the CLCW, its own ST[1]
timeouts) and as the attacker. The kinds of attack:

- downgrade: option sets that cannot give the protection asked for: exit 2, a message naming what is missing,
  no `ready` line, nothing bound to the TC port while it ran;
- restarts: the robot run several times on the same keys and state (SIGTERM and SIGKILL); every TM frame of
  every run captured and verified: no TM IV twice under the key; the TC frames the ground sent in earlier runs
  replayed into each later run: refused, nothing executed;
- replays: within a run, accepted frames sent again, and the oldest ones: refused;
- bc-forgery: Set V(R) and Unlock from another address (127.0.0.2): refused `bc-origin`; from the ground's own
  address (another socket on 127.0.0.1: on loopback every local process shares it, documented): obeyed by
  FARM-1 (not protected at COP-1, decision sdls-clear-bc): nothing executes, the ground's commands still complete
  or are reported (the end-to-end guarantee);
- clcw-relay: an on-path relay between robot and ground drops chosen AD frames, forges Set V(R) past them and
  rewrites every CLCW's N(R) (the FECF made good) so that COP-1 believes them delivered: the ground's own ST[1]
  timeouts find and report each lost command, nothing runs twice;
- other-robots: frames of robot 2 (SPI 258 and 514, spacecraft 0x102), with a guessed key and with robot 1's;
- floods: thousands of bad frames a second (garbage, bad FECF, bad MAC, other SPIs, BC frames from 127.0.0.2)
  while the ground commands: every one of its commands completes.

"Commands executed by attack" = board A's executed telecommands (the robot's own log, --out/sim.jsonl: its
`executed` events, heartbeat polls aside) during a kind's phase, less the ground's commands that completed in
it: a command run twice, or run without being the ground's, counts. It prints a table and exits 1 on any
violation (2 on a set-up failure). About 40 s.

    python3 ground/attack_suite.py [--mmic target/debug/mmic] [--keep DIR] [-v]
"""
from __future__ import annotations

import argparse
import json
import os
import random
import secrets
import shutil
import signal
import socket
import subprocess
import sys
import tempfile
import threading
import time
from pathlib import Path

from cryptography.exceptions import InvalidTag
from cryptography.hazmat.primitives.ciphers.aead import AESGCM

# -- the mission's public numbers -----------------------------------------------------------------------------
ROBOT = 1
SCID = 0x100 + ROBOT              # spacecraft ID of robot n
OTHER_SCID = 0x100 + 2
TC_SPI, TM_SPI = 0x100 + ROBOT, 0x200 + ROBOT
OTHER_TC_SPI, OTHER_TM_SPI = 0x100 + 2, 0x200 + 2
APID = 0x100 + ROBOT
TM_LEN = 256
IV_LEN, MAC_LEN = 12, 16
MASK = b"\xff" * 8 + bytes(IV_LEN)    # AAD: primary header (+ segment header on TC) + SPI; the IV masked out
SOURCE_ID = 0x0038                    # this ground's PUS source ID
MODE = 10                             # function ID of `mode` (1 standby, 2 operational)
T1 = 1.0                              # this ground's COP-1 retransmission timer, s
ST1_WAIT = 3.0                        # after a frame is acknowledged: its ST[1] completion comes within this, s
CMD_DEADLINE = 10.0                   # a command not complete by then is reported lost, s

# -- CRC-16/CCITT-FALSE (the frames' FECF, the packets' CRC): poly 0x1021, init 0xFFFF -------------------------
_CRC = []
for _i in range(256):
    _c = _i << 8
    for _ in range(8):
        _c = ((_c << 1) ^ 0x1021) if _c & 0x8000 else (_c << 1)
    _CRC.append(_c & 0xFFFF)


def crc16(data: bytes) -> int:
    crc = 0xFFFF
    for b in data:
        crc = ((crc << 8) & 0xFFFF) ^ _CRC[(crc >> 8) ^ b]
    return crc


def with_fecf(body: bytes) -> bytes:
    return body + crc16(body).to_bytes(2, "big")


def masked(header: bytes) -> bytes:
    return bytes(a & m for a, m in zip(header, MASK))


# -- TC transfer frames (232.0) and SDLS on them (355.0) ------------------------------------------------------
def tc_primary(scid: int, length: int, ns: int, *, bypass: int = 0, control: int = 0, vcid: int = 0) -> bytes:
    h = (bypass << 37) | (control << 36) | (scid << 24) | (vcid << 18) | ((length - 1) << 8) | (ns & 0xFF)
    return h.to_bytes(5, "big")


def ad_frame(key: bytes, iv: int, ns: int, packet: bytes, *, scid: int = SCID, spi: int = TC_SPI,
             bypass: int = 0) -> bytes:
    """A protected AD (or BD) frame: primary header, segment header (unsegmented, MAP 0), SPI, IV, ciphertext,
    MAC, FECF."""
    length = 5 + 1 + 2 + IV_LEN + len(packet) + MAC_LEN + 2
    head = tc_primary(scid, length, ns, bypass=bypass) + b"\xc0" + spi.to_bytes(2, "big") + iv.to_bytes(IV_LEN, "big")
    sealed = AESGCM(key).encrypt(iv.to_bytes(IV_LEN, "big"), packet, masked(head))
    return with_fecf(head + sealed)


def bc_frame(command: bytes, scid: int = SCID) -> bytes:
    """A BC frame (in clear, as 355.0 leaves it): Unlock = 00, Set V(R) = 82 00 V(R)."""
    return with_fecf(tc_primary(scid, 5 + len(command) + 2, 0, bypass=1, control=1) + command)


UNLOCK = b"\x00"


def set_vr(v: int) -> bytes:
    return b"\x82\x00" + bytes([v & 0xFF])


def tc_ns(frame: bytes) -> int:
    return frame[4]


def tc_kind(frame: bytes) -> str:
    return {0: "AD", 2: "BD", 3: "BC"}.get(frame[0] >> 4 & 3, "?")


# -- PUS-C telecommands ---------------------------------------------------------------------------------------
def pus_tc(seq: int, service: int, subservice: int, app: bytes) -> bytes:
    body = bytes([0x2F, service, subservice]) + SOURCE_ID.to_bytes(2, "big") + app   # PUS 2, all ST[1] reports
    length = 6 + len(body) + 2
    head = ((1 << 12) | (1 << 11) | APID).to_bytes(2, "big") + ((3 << 14) | (seq & 0x3FFF)).to_bytes(2, "big") \
        + (length - 7).to_bytes(2, "big")
    return with_fecf(head + body)


# -- TM transfer frames (132.0) with SDLS and the CLCW ---------------------------------------------------------
class TmError(ValueError):
    pass


def tm_fields(raw: bytes) -> dict:
    h = int.from_bytes(raw[:6], "big")
    return {"scid": (h >> 36) & 0x3FF, "vcid": (h >> 33) & 7, "vcc": (h >> 16) & 0xFF, "fhp": h & 0x7FF,
            "spi": int.from_bytes(raw[6:8], "big"), "iv": int.from_bytes(raw[8:20], "big")}


def tm_open(raw: bytes, key: bytes) -> tuple[dict, bytes]:
    """Checks a TM frame (length, FECF, SCID, SPI, MAC) and returns its fields and its plaintext data field."""
    if len(raw) != TM_LEN:
        raise TmError("length")
    if crc16(raw[:-2]) != int.from_bytes(raw[-2:], "big"):
        raise TmError("fecf")
    f = tm_fields(raw)
    if f["scid"] != SCID or f["spi"] != TM_SPI:
        raise TmError("scid/spi")
    try:
        data = AESGCM(key).decrypt(raw[8:20], raw[20:TM_LEN - 6], masked(raw[:20]))
    except InvalidTag:
        raise TmError("mac") from None
    return f, data


def clcw(raw: bytes) -> dict:
    w = int.from_bytes(raw[TM_LEN - 6:TM_LEN - 2], "big")
    return {"lockout": w >> 13 & 1, "wait": w >> 12 & 1, "retransmit": w >> 11 & 1, "nr": w & 0xFF}


def rewrite_clcw(raw: bytes, nr: int) -> bytes:
    """The frame with the CLCW's N(R) replaced, its Lockout, Wait and Retransmit flags cleared, the FECF made
    good (the CLCW is outside the MAC)."""
    w = int.from_bytes(raw[TM_LEN - 6:TM_LEN - 2], "big")
    w = (w & ~0xFF & ~(0b111 << 11)) | (nr & 0xFF)
    return with_fecf(raw[:TM_LEN - 6] + w.to_bytes(4, "big"))


# -- the robot --------------------------------------------------------------------------------------------------
def free_udp_port() -> int:
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def udp_bound(port: int) -> bool:
    """Whether some socket is bound to UDP port `port` (/proc/net/udp, IPv4)."""
    try:
        lines = Path("/proc/net/udp").read_text().splitlines()[1:]
    except OSError:
        return False
    return any(int(l.split()[1].split(":")[1], 16) == port for l in lines)


class Robot:
    """`mmic sim` as the external ground's robot. Its stdout's JSON lines (the wire log) are read by a thread into
    `lines` (with the time each arrived); `executed()` reads board A's executed telecommands from its log."""

    def __init__(self, mmic: str, work: Path, name: str, keys: Path, state: Path, tm_to: int):
        self.out = work / name
        self.tc_port = free_udp_port()
        self.cmd = [mmic, "sim", "--protocol", "pus", "--link", "frames", "--ground-tm-to", f"127.0.0.1:{tm_to}",
                    "--ground-tc-port", str(self.tc_port), "--max-seconds", "120", "--quiet", "--out",
                    str(self.out), "--sdls-keys", str(keys), "--sdls-state", str(state)]
        self.stderr = open(work / f"{name}.stderr", "w")
        self.proc = subprocess.Popen(self.cmd, stdout=subprocess.PIPE, stderr=self.stderr, text=True,
                                     stdin=subprocess.DEVNULL, start_new_session=True)
        self.lines: list[tuple[float, dict]] = []
        self.ready = threading.Event()
        threading.Thread(target=self._read, daemon=True).start()
        if not self.ready.wait(15):
            self.stop()
            raise RuntimeError(f"the robot did not start: {(work / f'{name}.stderr').read_text()[-2000:]}")

    def _read(self):
        for line in self.proc.stdout:
            try:
                d = json.loads(line)
            except ValueError:
                continue
            if d.get("ready"):
                self.ready.set()
            self.lines.append((time.monotonic(), d))

    def tc_lines(self, since: float = 0.0) -> list[dict]:
        return [d for t, d in list(self.lines) if t >= since and d.get("dir") == "tc-frame"]

    def executed(self) -> int:
        n = 0
        path = self.out / "sim.jsonl"
        if not path.exists():
            return 0
        for line in path.read_text().splitlines():
            if '"executed"' not in line:
                continue
            try:
                r = json.loads(line)
            except ValueError:
                continue
            ev = r.get("event", {})
            if r.get("node") == "board_a1" and ev.get("type") == "executed" and ev.get("command") != "heartbeat":
                n += 1
        return n

    def stop(self, sig=signal.SIGTERM):
        if self.proc.poll() is None:
            try:
                os.killpg(self.proc.pid, sig)
                self.proc.wait(10)
            except (ProcessLookupError, subprocess.TimeoutExpired):
                try:
                    os.killpg(self.proc.pid, signal.SIGKILL)
                except ProcessLookupError:
                    pass
                self.proc.wait()
        self.stderr.close()


# -- the legitimate ground ---------------------------------------------------------------------------------------
class GroundState:
    """What the ground keeps across the robot's restarts (its own durable state): its TC counter, its PUS sequence
    count, its last accepted TM IV; and every TM IV it saw (the reuse check) and every TC frame it sent."""

    def __init__(self, tc_key: bytes, tm_key: bytes):
        self.tc_key, self.tm_key = tc_key, tm_key
        self.tc_iv = 0
        self.seq = 0
        self.tm_last: int | None = None
        self.tm_ivs: list[int] = []
        self.tm_bad: dict[str, int] = {}
        self.tm_replayed = 0
        self.sent: list[bytes] = []


class Ground:
    """The minimal legitimate ground on one UDP socket (127.0.0.1): TM frames in (verified, IVs recorded, packets
    extracted, CLCW kept), TC frames out to `tc_to` (the robot, or a relay)."""

    def __init__(self, st: GroundState, tc_to: tuple[str, int] | None = None, record_ivs: bool = True):
        self.st = st
        self.sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
        self.sock.bind(("127.0.0.1", 0))
        self.sock.settimeout(0.2)
        self.port = self.sock.getsockname()[1]
        self.tc_to = tc_to
        self.record_ivs = record_ivs
        self.lock = threading.Lock()
        self.clcw: dict | None = None
        self.clcw_n = 0                   # CLCWs received so far
        self.reports: dict[int, list[tuple[int, int]]] = {}   # PUS seq -> [(subservice, failure code)]
        self.frames = 0
        self._buf = bytearray()
        self._synced = False
        self._vcc: int | None = None
        self.stopping = threading.Event()
        self.thread = threading.Thread(target=self._rx, daemon=True)
        self.thread.start()

    def close(self):
        self.stopping.set()
        self.thread.join(2)
        self.sock.close()

    def _rx(self):
        while not self.stopping.is_set():
            try:
                raw = self.sock.recv(4096)
            except socket.timeout:
                continue
            except OSError:
                return
            try:
                f, data = tm_open(raw, self.st.tm_key)
            except TmError as e:
                self.st.tm_bad[str(e)] = self.st.tm_bad.get(str(e), 0) + 1
                continue
            with self.lock:
                self.frames += 1
                if self.record_ivs:
                    self.st.tm_ivs.append(f["iv"])
                if self.st.tm_last is not None and f["iv"] <= self.st.tm_last:
                    self.st.tm_replayed += 1     # an IV not above the last one: a replay (or an IV used again)
                    continue
                self.st.tm_last = f["iv"]
                self.clcw = clcw(raw)
                self.clcw_n += 1
                for p in self._extract(f, data):
                    self._packet(p)

    def _extract(self, f: dict, data: bytes) -> list[bytes]:
        """Space packets out of the frames' data fields (132.0 §4.1.2.7): first header pointer, spanning packets,
        a gap in the VC frame count drops the packet in progress."""
        if self._vcc is not None and (f["vcc"] - self._vcc) % 256 != 1:
            self._buf.clear()
            self._synced = False
        self._vcc = f["vcc"]
        fhp = f["fhp"]
        if fhp == 0x7FE:
            return []
        if not self._synced:
            if fhp == 0x7FF:
                return []
            data = data[fhp:]
            self._synced = True
        self._buf += data
        out = []
        while len(self._buf) >= 6:
            n = int.from_bytes(self._buf[4:6], "big") + 7
            if len(self._buf) < n:
                break
            p, self._buf = bytes(self._buf[:n]), self._buf[n:]
            if int.from_bytes(p[:2], "big") & 0x7FF != 0x7FF:
                out.append(p)
        return out

    def _packet(self, p: bytes):
        if len(p) < 23 or p[0] >> 4 != 0 or crc16(p[:-2]) != int.from_bytes(p[-2:], "big"):
            return
        if p[7] == 1:                     # ST[1]: the request ID at the source data's start (after 6 + 13 octets)
            if int.from_bytes(p[19:21], "big") & 0x7FF != APID:
                return
            seq = int.from_bytes(p[21:23], "big") & 0x3FFF
            code = int.from_bytes(p[23:25], "big") if p[8] in (2, 4, 6, 8) and len(p) >= 27 else 0
            self.reports.setdefault(seq, []).append((p[8], code))

    def wait_report(self, seq: int, subservice: int, timeout: float) -> bool:
        end = time.monotonic() + timeout
        while time.monotonic() < end:
            if any(s == subservice for s, _ in self.reports.get(seq, [])):
                return True
            time.sleep(0.05)
        return False

    def send_raw(self, frame: bytes):
        self.sock.sendto(frame, self.tc_to)

    def wait_clcw(self, after: int, timeout: float = 3.0) -> dict | None:
        end = time.monotonic() + timeout
        while time.monotonic() < end:
            with self.lock:
                if self.clcw_n > after:
                    return dict(self.clcw)
            time.sleep(0.01)
        return None

    def _ad(self, ns: int, packet: bytes) -> bytes:
        f = ad_frame(self.st.tc_key, self.st.tc_iv, ns, packet)
        self.st.tc_iv += 1
        self.st.sent.append(f)
        return f

    def command(self, mode: int, fence: bool = True) -> str:
        """One `mode` telecommand (`transact`). Without its ST[1] completion it is only *unconfirmed*: a frame of it
        an attacker withheld can still be delivered later, while no later frame of this ground has passed the
        robot's SDLS (the anti-replay counter is the only freshness there is). So the ground fences it: it sends
        an are-you-alive TC(17,1) (answered by the gateway with board A's heartbeat, run by no one); once the fence
        completes, every earlier frame of the ground is below the robot's durable anti-replay floor and the command
        is 'lost' for good (never sent again under a new sequence count). Returns 'complete', 'failed:<code>',
        'lost' (fenced), or 'unknown' (not fenced: `fence=False`, or no fence confirmed)."""
        out = self.transact(pus_tc(self.next_seq(), 8, 1, bytes([MODE, mode])))
        if out != "lost":
            return out
        if not fence:
            return "unknown"
        for _ in range(3):
            if self.transact(pus_tc(self.next_seq(), 17, 1, b"")) == "complete":
                return "lost"
        return "unknown"

    def next_seq(self) -> int:
        self.st.seq = (self.st.seq + 1) & 0x3FFF
        return self.st.seq

    def transact(self, packet: bytes) -> str:
        """One telecommand, stop-and-wait: sent with N(S) = the CLCW's N(R) under a fresh IV, sent again (fresh IV,
        the same packet) every T1 while the CLCW does not acknowledge it, Unlock on Lockout; once acknowledged, its
        ST[1] completion awaited ST1_WAIT. Returns 'complete', 'failed:<code>' or 'lost' (no completion by its own
        ST[1] timeouts)."""
        seq = int.from_bytes(packet[2:4], "big") & 0x3FFF
        with self.lock:
            n0 = self.clcw_n
        c = self.wait_clcw(n0 - 1 if n0 else 0) or {"nr": 0, "lockout": 0}
        if c["lockout"]:
            self.send_raw(bc_frame(UNLOCK))
            c = self.wait_clcw(self.clcw_n) or c
        ns = c["nr"]
        start = time.monotonic()
        self.send_raw(self._ad(ns, packet))
        sent_at, acked_at = time.monotonic(), None
        with self.lock:
            seen = self.clcw_n
        while time.monotonic() - start < CMD_DEADLINE:
            rep = self.reports.get(seq, [])
            if any(s == 7 for s, _ in rep):
                return "complete"
            fails = [code for s, code in rep if s in (2, 4, 6, 8)]
            if fails:
                return f"failed:{fails[0]:#06x}"
            if any(s == 1 for s, _ in rep) and acked_at is None:
                acked_at = time.monotonic()
            with self.lock:
                fresh = self.clcw_n > seen
                c = dict(self.clcw) if self.clcw else None
                seen = self.clcw_n
            if fresh and c and acked_at is None and 0 < (c["nr"] - ns) % 256 < 128:
                acked_at = time.monotonic()           # the CLCW acknowledges it
            if acked_at is not None:
                if time.monotonic() - acked_at > ST1_WAIT:
                    return "lost"
            elif time.monotonic() - sent_at > T1 and c is not None:
                if c["lockout"]:
                    self.send_raw(bc_frame(UNLOCK))
                elif c["nr"] != ns:
                    ns = c["nr"]                      # FARM-1 elsewhere (a restart, a forged Set V(R)): follow it
                self.send_raw(self._ad(ns, packet))
                sent_at = time.monotonic()
            time.sleep(0.01)
        return "lost"


# -- the on-path relay --------------------------------------------------------------------------------------------
class Relay:
    """Between the ground and the robot: TC frames from the ground forwarded to the robot from the relay's own
    socket (the ground's address), TM frames from the robot forwarded to the ground. Every `every`-th new AD frame
    N(S) after `victimize()` is a victim: every copy withheld (kept in `withheld`). Every CLCW is rewritten to acknowledge all the
    ground sent (N(R) = its highest N(S) + 1, Lockout, Wait and Retransmit cleared, the FECF made good): COP-1
    believes the victim delivered. Before the ground's next AD frame goes through, a Set V(R) to that frame's N(S)
    is forged so that FARM-1 takes it (FARM-1 waits at the victim's N(S) until then). TM frames are captured as
    the robot sent them (their IVs checked for reuse)."""

    def __init__(self, robot_tc: int, ground: int):
        self.tc = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
        self.tc.bind(("127.0.0.1", 0))
        self.tm = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
        self.tm.bind(("127.0.0.1", 0))
        self.tc_port, self.tm_port = self.tc.getsockname()[1], self.tm.getsockname()[1]
        self.robot_tc, self.ground = robot_tc, ground
        self.next_is_victim = False
        self.seen: list[int] = []
        self.victims: list[int] = []
        self.high: int | None = None
        self.pending: bool = False           # a victim withheld, FARM-1 not yet moved past it
        self.captured: list[bytes] = []
        self.withheld: list[tuple[int, bytes]] = []     # (N(S), frame): the victims' frames, every copy
        self.dropped = self.forged = self.rewritten = 0
        self.stop = threading.Event()
        self.threads = [threading.Thread(target=self._pump_tc, daemon=True),
                        threading.Thread(target=self._pump_tm, daemon=True)]
        for s in (self.tc, self.tm):
            s.settimeout(0.1)
        for t in self.threads:
            t.start()

    def set_robot(self, robot_tc: int):
        self.robot_tc = robot_tc

    def victimize(self):
        """The ground's next new AD frame (by N(S)) is withheld, every copy."""
        self.next_is_victim = True

    def _pump_tc(self):
        while not self.stop.is_set():
            try:
                f = self.tc.recv(4096)
            except socket.timeout:
                continue
            except OSError:
                return
            if tc_kind(f) == "AD":
                ns = tc_ns(f)
                if ns not in self.seen:
                    self.seen.append(ns)
                    if self.next_is_victim:
                        self.victims.append(ns)
                        self.next_is_victim = False
                if self.high is None or 0 < (ns - self.high) % 256 < 128:
                    self.high = ns
                if ns in self.victims:
                    self.dropped += 1
                    self.withheld.append((ns, f))
                    self.pending = True
                    continue
                if self.pending:
                    self.tc.sendto(bc_frame(set_vr(ns)), ("127.0.0.1", self.robot_tc))
                    self.forged += 1
                    self.pending = False
                    time.sleep(0.01)
            self.tc.sendto(f, ("127.0.0.1", self.robot_tc))

    def _pump_tm(self):
        while not self.stop.is_set():
            try:
                f = self.tm.recv(4096)
            except socket.timeout:
                continue
            except OSError:
                return
            self.captured.append(f)
            if len(f) == TM_LEN and self.high is not None:
                g = rewrite_clcw(f, (self.high + 1) & 0xFF)
                if g != f:
                    self.rewritten += 1
                f = g
            self.tm.sendto(f, ("127.0.0.1", self.ground))

    def close(self):
        self.stop.set()
        for t in self.threads:
            t.join(1)
        self.tc.close()
        self.tm.close()


# -- the suite ----------------------------------------------------------------------------------------------------
class Suite:
    def __init__(self, mmic: str, work: Path, verbose: bool):
        self.mmic, self.work, self.verbose = mmic, work, verbose
        self.rows: dict[str, dict] = {}
        self.violations: list[str] = []
        self.notes: list[str] = []

    def row(self, kind: str) -> dict:
        return self.rows.setdefault(kind, {"tried": 0, "refused": 0, "executed": 0, "ivs": 0, "reused": 0,
                                           "note": ""})

    def check(self, ok: bool, what: str):
        if not ok:
            self.violations.append(what)
            print(f"VIOLATION: {what}", flush=True)

    def log(self, msg: str):
        if self.verbose:
            print(msg, flush=True)

    # keys and the robot's state, once
    def provision(self):
        self.keys = self.work / "keys"
        self.keys.mkdir(mode=0o700)
        for spi in (TC_SPI, TM_SPI):
            fd = os.open(self.keys / f"spi-{spi}.key", os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o600)
            with os.fdopen(fd, "wb") as f:
                f.write(secrets.token_bytes(32))
        self.state = self.work / "robot.state"
        p = subprocess.run([self.mmic, "sdls", "provision", "--keys", str(self.keys), "--state", str(self.state)],
                           capture_output=True, text=True, timeout=30)
        if p.returncode != 0:
            raise RuntimeError(f"mmic sdls provision: {p.stderr}")
        self.gs = GroundState((self.keys / f"spi-{TC_SPI}.key").read_bytes(),
                              (self.keys / f"spi-{TM_SPI}.key").read_bytes())

    def phase(self, robot: Robot, ground_commands: list[str], before: int) -> int:
        """Executed by attack in a phase: board A's executed telecommands since `before`, less the ground's
        commands that completed in it."""
        time.sleep(0.8)            # anything still on its way runs now
        ran = robot.executed() - before
        done = sum(1 for o in ground_commands if o == "complete")
        return ran - done

    # -- kinds ------------------------------------------------------------------------------------------------
    def downgrade(self):
        r = self.row("downgrade")
        k2 = self.work / "other-keys"
        k2.mkdir(mode=0o700)
        for spi in (TC_SPI, TM_SPI):
            (k2 / f"spi-{spi}.key").write_bytes(secrets.token_bytes(32))
        weak = self.work / "weak-keys"
        weak.mkdir(mode=0o700)
        (weak / f"spi-{TC_SPI}.key").write_bytes(bytes(32))
        (weak / f"spi-{TM_SPI}.key").write_bytes(secrets.token_bytes(32))
        half = self.work / "half-keys"
        half.mkdir(mode=0o700)
        (half / f"spi-{TC_SPI}.key").write_bytes(secrets.token_bytes(32))
        inside = self.keys / "robot.state"
        K, S = str(self.keys), str(self.state)
        cases = [
            ("--sdls without keys (clear link asked to be secure)", ["--link", "frames", "--sdls"], "--sdls-keys"),
            ("keys without the durable state", ["--link", "frames", "--sdls-keys", K], "--sdls-state"),
            ("state without keys", ["--link", "frames", "--sdls-state", S], "--sdls-keys"),
            ("SDLS over bare packets (no frames)", ["--sdls-keys", K, "--sdls-state", S], "--link frames"),
            ("SDLS over the legacy protocol", ["--protocol", "legacy", "--link", "frames", "--sdls-keys", K,
                                               "--sdls-state", S], "--protocol pus"),
            ("state inside the key directory", ["--link", "frames", "--sdls-keys", K, "--sdls-state", str(inside)],
             "inside the key directory"),
            ("state never provisioned", ["--link", "frames", "--sdls-keys", K, "--sdls-state",
                                         str(self.work / "none.state")], "provision"),
            ("state of other keys", ["--link", "frames", "--sdls-keys", str(k2), "--sdls-state", S], "another key"),
            ("an all-zero key", ["--link", "frames", "--sdls-keys", str(weak), "--sdls-state", S], "not a key"),
            ("a key missing", ["--link", "frames", "--sdls-keys", str(half), "--sdls-state", S], "spi-513.key"),
            ("the attack simulator on an external ground", ["--link", "frames", "--sdls-keys", K, "--sdls-state", S,
                                                            "--sdls-attack", "0.5"], "--sdls-attack"),
        ]
        for what, extra, needle in cases:
            port = free_udp_port()
            if "--protocol" not in extra:
                extra = ["--protocol", "pus"] + extra
            args = [self.mmic, "sim", "--ground-tm-to", "127.0.0.1:9", "--ground-tc-port", str(port),
                    "--max-seconds", "5", "--quiet", "--out", str(self.work / "downgrade-out")] + extra
            r["tried"] += 1
            p = subprocess.Popen(args, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                                 start_new_session=True)
            bound = False
            end = time.monotonic() + 5
            while p.poll() is None and time.monotonic() < end:
                bound = bound or udp_bound(port)
                time.sleep(0.001)
            if p.poll() is None:
                os.killpg(p.pid, signal.SIGKILL)
            out, err = p.communicate()
            ok = p.returncode == 2 and needle in err and '"ready"' not in out and not bound
            if ok:
                r["refused"] += 1
            self.check(ok, f"downgrade '{what}': exit {p.returncode}, bound {bound}, message {err.strip()[:200]!r}"
                           f" (expected exit 2 naming {needle!r})")
            self.log(f"  downgrade: {what}: exit {p.returncode}: {err.strip()[:140]}")

    def run_a(self):
        """Run 1: commands; replays within the run; other robots' frames; BC forgery; a flood."""
        g = Ground(self.gs)
        robot = Robot(self.mmic, self.work, "run1", self.keys, self.state, g.port)
        self.robots.append(robot)
        g.tc_to = ("127.0.0.1", robot.tc_port)
        try:
            base = robot.executed()
            outs = [g.command(2), g.command(1)]
            self.check(outs == ["complete", "complete"], f"run 1: the ground's first commands: {outs}")
            self.check(self.phase(robot, outs, base) == 0, "run 1: board A ran other than the ground's commands")
            self.replays(g, robot)
            self.other_robots(g, robot)
            self.bc_forgery(g, robot)
            self.flood(g, robot)
        finally:
            g.close()
            robot.stop(signal.SIGKILL)           # a crash: the state file as the last durable write left it

    def refusals(self, robot: Robot, since: float) -> dict[str, int]:
        time.sleep(0.5)
        out: dict[str, int] = {}
        for d in robot.tc_lines(since):
            k = d.get("refused") or d.get("farm") or "?"
            out[k] = out.get(k, 0) + 1
        return out

    def replays(self, g: Ground, robot: Robot):
        r = self.row("replays")
        accepted = [bytes.fromhex(d["hex"]) for d in robot.tc_lines() if d.get("farm") == "accept"]
        frames = accepted + accepted[:1] * 3 + list(self.gs.sent[:1])
        # ... and the accepted frames with N(S) moved to FARM-1's V(R) (the header is authenticated: refused before
        # the MAC as replays, since their IVs are spent)
        c = g.wait_clcw(g.clcw_n) or {"nr": 0}
        for f in accepted:
            h = bytearray(f[:-2])
            h[4] = c["nr"]
            frames.append(with_fecf(bytes(h)))
        since, base = time.monotonic(), robot.executed()
        for f in frames:
            g.send_raw(f)
            time.sleep(0.005)
        got = self.refusals(robot, since)
        r["tried"] += len(frames)
        r["refused"] += got.get("replay", 0)
        r["executed"] += self.phase(robot, [], base)
        self.check(got.get("replay", 0) == len(frames), f"replays within a run: {got} for {len(frames)} frames")
        self.log(f"  replays: {got}")

    def other_robots(self, g: Ground, robot: Robot):
        r = self.row("other-robots")
        guess = secrets.token_bytes(32)
        pkt = pus_tc(0x3FF0, 8, 1, bytes([MODE, 2]))
        base_iv = self.gs.tc_iv + 5
        frames, expect = [], []
        for key in (guess, self.gs.tc_key):          # a guessed key, and robot 1's
            for spi in (OTHER_TC_SPI, OTHER_TM_SPI):
                frames.append(ad_frame(key, base_iv, 0, pkt, spi=spi))
                expect.append("unknown-spi")
            frames.append(ad_frame(key, base_iv, 0, pkt, scid=OTHER_SCID, spi=OTHER_TC_SPI))
            expect.append("spacecraft-id")
            frames.append(ad_frame(key, base_iv, 0, pkt, scid=OTHER_SCID, spi=TC_SPI))
            expect.append("spacecraft-id")
        frames.append(ad_frame(guess, base_iv, 0, pkt))     # robot 1's SPI, a guessed key
        expect.append("bad-mac")
        since, base = time.monotonic(), robot.executed()
        for f in frames:
            g.send_raw(f)
            time.sleep(0.005)
        lines = robot.tc_lines(since)
        got = [d.get("refused") for d in lines]
        r["tried"] += len(frames)
        r["refused"] += sum(1 for d in lines if d.get("refused"))
        r["executed"] += self.phase(robot, [], base)
        self.check(sorted(map(str, got)) == sorted(expect), f"other robots' frames: refused {got}, expected {expect}")
        self.log(f"  other robots: {got}")

    def bc_forgery(self, g: Ground, robot: Robot):
        r = self.row("bc-forgery")
        # from another address: refused by origin, before FARM-1
        other = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
        other.bind(("127.0.0.2", 0))
        c0 = g.wait_clcw(g.clcw_n) or {"nr": 0}
        forged = [bc_frame(set_vr(c0["nr"] + 1)), bc_frame(UNLOCK), bc_frame(set_vr(c0["nr"] + 100)),
                  bc_frame(set_vr(0))]
        since, base = time.monotonic(), robot.executed()
        for f in forged:
            other.sendto(f, ("127.0.0.1", robot.tc_port))
            time.sleep(0.005)
        got = self.refusals(robot, since)
        other.close()
        r["tried"] += len(forged)
        r["refused"] += got.get("bc-origin", 0)
        self.check(got.get("bc-origin", 0) == len(forged), f"BC frames from 127.0.0.2: {got}")
        c1 = g.wait_clcw(g.clcw_n) or {"nr": -1}
        self.check(c1["nr"] == c0["nr"], f"FARM-1's V(R) moved by BC frames from another address: {c0} -> {c1}")
        outs = [g.command(2)]
        self.check(outs == ["complete"], f"a command after BC forgery from another address: {outs}")
        # from the ground's own address (another socket on 127.0.0.1): FARM-1 obeys (loopback shares the address);
        # a denial of service at most
        same = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
        same.bind(("127.0.0.1", 0))
        since2 = time.monotonic()
        rng = random.Random(38)
        mine = []
        for i in range(4):
            c = g.wait_clcw(g.clcw_n) or {"nr": 0}
            for f in (bc_frame(set_vr(c["nr"] + rng.choice((1, 3, 7, 60)))), bc_frame(UNLOCK)):
                same.sendto(f, ("127.0.0.1", robot.tc_port))
                mine.append(f.hex())
                r["tried"] += 1
                time.sleep(0.02)
            outs.append(g.command(1 + i % 2))
        same.close()
        got2 = self.refusals(robot, since2)
        # (the ground's own Unlock frames are byte for byte the attacker's: counted by verdict, at most 8)
        obeyed = min(len(mine), sum(1 for d in robot.tc_lines(since2)
                                    if d["hex"] in mine and d.get("farm") and not d["farm"].endswith("(not executed)")))
        r["executed"] += self.phase(robot, outs, base)
        lost = outs.count("lost")
        self.check(all(o in ("complete", "lost") for o in outs), f"BC forgery: the ground's commands {outs}")
        self.notes.append(f"bc-forgery: {len(forged)} from 127.0.0.2 refused bc-origin, FARM-1's V(R) unmoved; "
                          f"{obeyed} of {len(mine)} from the ground's own address obeyed by FARM-1 (documented: not "
                          f"protected at COP-1), the ground's 5 commands: {outs.count('complete')} complete, {lost} "
                          f"reported lost, none ran unseen")
        self.log(f"  bc forgery: other address {got}; own address {got2}; commands {outs}")

    def flood(self, g: Ground, robot: Robot, seconds: float = 3.0):
        r = self.row("floods")
        rng = random.Random(9)
        guess = secrets.token_bytes(32)
        pkt = pus_tc(0x3FF1, 8, 1, bytes([MODE, 2]))
        pool = []
        for i in range(600):
            k = i % 6
            iv = self.gs.tc_iv + 1000 + rng.randrange(1 << 16)
            if k == 0:
                pool.append(os.urandom(rng.randrange(1, 300)))                       # garbage
            elif k == 1:
                f = bytearray(ad_frame(self.gs.tc_key, iv, rng.randrange(256), pkt))
                f[-1] ^= 1
                pool.append(bytes(f))                                                 # bad FECF
            elif k == 2:
                f = bytearray(ad_frame(self.gs.tc_key, iv, rng.randrange(256), pkt))
                f[-4] ^= 0x10
                pool.append(with_fecf(bytes(f[:-2])))                                 # bad MAC, FECF good
            elif k == 3:
                pool.append(ad_frame(guess, iv, rng.randrange(256), pkt))             # guessed key
            elif k == 4:
                pool.append(ad_frame(guess, iv, 0, pkt, spi=OTHER_TC_SPI))            # another robot's SPI
            else:
                pool.append(("bc", bc_frame(set_vr(rng.randrange(256)))))              # BC from another address
        socks = {"127.0.0.1": socket.socket(socket.AF_INET, socket.SOCK_DGRAM),
                 "127.0.0.2": socket.socket(socket.AF_INET, socket.SOCK_DGRAM)}
        socks["127.0.0.1"].bind(("127.0.0.1", 0))
        socks["127.0.0.2"].bind(("127.0.0.2", 0))
        sent = [0]
        stop = threading.Event()

        def blast():
            dest = ("127.0.0.1", robot.tc_port)
            i = 0
            while not stop.is_set():
                f = pool[i % len(pool)]
                if isinstance(f, tuple):
                    socks["127.0.0.2"].sendto(f[1], dest)
                else:
                    socks["127.0.0.1"].sendto(f, dest)
                sent[0] += 1
                i += 1
                if i % 25 == 0:
                    time.sleep(0.005)     # some thousands a second, not a saturated core
        since, base = time.monotonic(), robot.executed()
        t = threading.Thread(target=blast, daemon=True)
        t0 = time.monotonic()
        t.start()
        outs = []
        while time.monotonic() - t0 < seconds or len(outs) < 3:
            outs.append(g.command(2 - len(outs) % 2))
            if len(outs) >= 6:
                break
        stop.set()
        t.join(2)
        dt = time.monotonic() - t0
        for s in socks.values():
            s.close()
        got = self.refusals(robot, since)
        r["tried"] += sent[0]
        r["refused"] += sum(1 for d in robot.tc_lines(since) if d.get("refused"))
        r["executed"] += self.phase(robot, outs, base)
        self.check(outs and all(o == "complete" for o in outs), f"the ground's commands under a flood: {outs}")
        self.check(sent[0] / dt >= 1000, f"the flood ran at {sent[0] / dt:.0f} frames/s only")
        self.notes.append(f"floods: {sent[0]} bad frames in {dt:.1f} s ({sent[0] / dt:.0f}/s) while the ground's "
                          f"{len(outs)} commands all completed; the robot logged {sum(got.values())} TC frames"
                          + (" (the rest lost in its socket buffer)" if sum(got.values()) < sent[0] else "")
                          + "; by verdict: "
                          + ", ".join(f"{k} {v}" for k, v in sorted(got.items())))
        self.log(f"  flood: {sent[0]} frames, {sent[0] / dt:.0f}/s; robot saw {got}; commands {outs}")

    def restart_run(self, n: int, sig, relay: bool = False):
        """A later run on the same keys and state: every TC frame the ground sent in earlier runs replayed first
        (refused, nothing executed), then the ground's commands complete (or, through the relay, are reported)."""
        r = self.row("restarts")
        # the ground's frames of the earlier runs that reached the robot (a frame an on-path attacker withheld is
        # not a replay: clcw-relay releases those)
        reached = {d["hex"] for rb in self.robots for d in rb.tc_lines()}
        old = [f for f in self.gs.sent if f.hex() in reached]
        rl = None
        if relay:
            g = Ground(self.gs, record_ivs=False)   # the relay captures the robot's TM as sent
            rl = Relay(0, g.port)
            robot = Robot(self.mmic, self.work, f"run{n}", self.keys, self.state, rl.tm_port)
            rl.set_robot(robot.tc_port)
            g.tc_to = ("127.0.0.1", rl.tc_port)
        else:
            g = Ground(self.gs)
            robot = Robot(self.mmic, self.work, f"run{n}", self.keys, self.state, g.port)
            g.tc_to = ("127.0.0.1", robot.tc_port)
        self.robots.append(robot)
        try:
            g.wait_clcw(0, 5)
            since, base = time.monotonic(), robot.executed()
            attacker = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
            attacker.bind(("127.0.0.1", 0))
            for f in old:
                attacker.sendto(f, ("127.0.0.1", robot.tc_port))
                time.sleep(0.003)
            attacker.close()
            got = self.refusals(robot, since)
            r["tried"] += len(old)
            r["refused"] += got.get("replay", 0)
            r["executed"] += self.phase(robot, [], base)
            self.check(got.get("replay", 0) == len(old), f"run {n}: the earlier runs' {len(old)} TC frames: {got}")
            self.log(f"  run {n}: replayed {len(old)} frames of earlier runs: {got}")
            if self.withheld:
                self.release_withheld(robot, f"run {n}, after a restart", ground=g)
                self.withheld = []
            if not relay:
                base = robot.executed()
                outs = [g.command(2), g.command(1)]
                self.check(outs == ["complete", "complete"], f"run {n}: the ground's commands: {outs}")
                r["executed"] += self.phase(robot, outs, base)
            else:
                self.clcw_relay(g, rl, robot)
        finally:
            g.close()
            robot.stop(sig)
            if rl is not None:
                rl.close()
                for f in rl.captured:
                    try:
                        fd, _ = tm_open(f, self.gs.tm_key)
                        self.gs.tm_ivs.append(fd["iv"])
                    except TmError as e:
                        self.gs.tm_bad["relay:" + str(e)] = self.gs.tm_bad.get("relay:" + str(e), 0) + 1

    def release_withheld(self, robot: Robot, when: str, frames: list[bytes] | None = None,
                         ground: Ground | None = None):
        """The relay's withheld frames sent to the robot from the relay's address. Those of fenced commands must
        not run; an unfenced one may run once (its command was 'unknown' to the ground, not 'lost')."""
        r = self.row("clcw-relay")
        frames = self.withheld if frames is None else frames
        unfenced = [f for f in frames if f in getattr(self, "unfenced", [])]
        sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
        sock.bind(("127.0.0.1", 0))
        since, base = time.monotonic(), robot.executed()
        for f in frames:
            sock.sendto(f, ("127.0.0.1", robot.tc_port))
            time.sleep(0.003)
        sock.close()
        got = self.refusals(robot, since)
        ran = self.phase(robot, [], base)
        late = min(ran, 1) if unfenced else 0     # the unfenced command, run late (at most once)
        r["tried"] += len(frames)
        r["refused"] += sum(1 for d in robot.tc_lines(since) if d.get("refused"))
        r["executed"] += ran - late
        self.check(ran - late == 0, f"clcw relay: withheld frames released in {when}: {ran} ran ({got}), "
                                    f"{len(frames) - len(unfenced)} of them of fenced ('lost') commands")
        msg = (f"clcw-relay: {len(frames)} withheld frames released in {when} ({len(frames) - len(unfenced)} of "
               f"fenced commands): {got}, {ran} ran")
        if unfenced:
            seen = ground is not None and ground.wait_report(self.unfenced_seq, 7, 3.0)
            msg += (f"; the unfenced command {'ran once, late' if late else 'did not run'}"
                    + (f" (the ground saw its late ST[1] completion: {seen})" if late else "")
                    + ": a ground may call a command not run only after a later frame of its own is confirmed")
            self.late_runs = late
        self.notes.append(msg)
        self.log(f"  withheld frames released in {when}: {got}, {ran} ran")

    def clcw_relay(self, g: Ground, rl: Relay, robot: Robot):
        """Seven commands through the relay; the 3rd, 5th and 7th withheld while the relay's CLCWs say delivered.
        The ground finds each by its own ST[1] timeout; it fences the 3rd and 5th (lost for good), not the 7th (a
        ground that gives up: unknown). The withheld frames are released: the fenced ones in this run (refused);
        all of them after the next restart (run 4): the fenced refused, the unfenced one may run then (once, late)."""
        r = self.row("clcw-relay")
        base = robot.executed()
        outs = []
        for i in range(7):
            if i in (2, 4, 6):
                rl.victimize()
            outs.append(g.command(2 - i % 2, fence=i != 6))
            if i == 6:
                self.unfenced_seq = self.gs.seq
        time.sleep(0.8)
        ran = robot.executed() - base
        done = outs.count("complete")
        r["tried"] += rl.forged + rl.dropped + rl.rewritten
        r["executed"] += ran - done
        self.check(ran == done, f"clcw relay: board A ran {ran}, the ground saw {done} complete ({outs})")
        self.check(outs == ["complete", "complete", "lost", "complete", "lost", "complete", "unknown"],
                   f"clcw relay: the relay withheld the 3rd, 5th and 7th command, the ground reported {outs}")
        self.notes.append(f"clcw-relay: {rl.dropped} AD frames withheld, {rl.forged} Set V(R) forged, "
                          f"{rl.rewritten} CLCWs rewritten (N(R) past the withheld frames, flags cleared); the "
                          f"ground's 7 commands: {done} complete, {outs.count('lost')} found lost by its ST[1] "
                          f"timeouts and fenced, {outs.count('unknown')} left unfenced; none ran twice")
        fenced = [f for ns, f in rl.withheld if ns != rl.victims[-1]]
        self.withheld = [f for _, f in rl.withheld]
        self.unfenced = [f for ns, f in rl.withheld if ns == rl.victims[-1]]
        self.release_withheld(robot, "the same run", fenced)

    def run(self) -> int:
        t0 = time.monotonic()
        self.robots: list[Robot] = []
        self.withheld: list[bytes] = []
        self.provision()
        self.downgrade()
        self.run_a()
        self.restart_run(2, signal.SIGTERM)
        self.restart_run(3, signal.SIGKILL, relay=True)
        self.restart_run(4, signal.SIGTERM)
        # every TM frame of every run: verified, no IV twice under the key
        ivs = self.gs.tm_ivs
        reused = len(ivs) - len(set(ivs))
        r = self.row("restarts")
        r["ivs"], r["reused"] = len(ivs), reused
        self.check(reused == 0, f"{reused} TM IVs used twice across {len(self.robots)} runs")
        self.check(not self.gs.tm_bad, f"TM frames that did not verify: {self.gs.tm_bad}")
        self.check(self.gs.tm_replayed == 0, f"{self.gs.tm_replayed} TM frames with an IV not above the last")
        for kind, row in self.rows.items():
            self.check(row["executed"] == 0, f"{kind}: {row['executed']} commands executed by attack")
        elapsed = time.monotonic() - t0
        print(f"\nattack suite: {len(self.robots)} robot runs on one key set and state file ({len(self.robots) - 1} "
              f"restarts), {elapsed:.1f} s")
        print(f"{'kind':<14}{'attacks tried':>14}{'refused':>9}{'executed by attack':>20}{'IVs checked':>13}"
              f"{'IVs reused':>12}")
        for kind in ("downgrade", "restarts", "replays", "bc-forgery", "clcw-relay", "other-robots", "floods"):
            row = self.row(kind)
            print(f"{kind:<14}{row['tried']:>14}{row['refused']:>9}{row['executed']:>20}{row['ivs']:>13}"
                  f"{row['reused']:>12}")
        tot = {k: sum(r[k] for r in self.rows.values()) for k in ("tried", "refused", "executed", "ivs", "reused")}
        print(f"{'total':<14}{tot['tried']:>14}{tot['refused']:>9}{tot['executed']:>20}{tot['ivs']:>13}"
              f"{tot['reused']:>12}")
        print("(refused: by the check expected for that attack; bc-forgery from the ground's own address, "
              "clcw-relay and the floods' BC frames act on COP-1 by design, see below)")
        for n in self.notes:
            print("  " + n)
        if self.violations:
            print(f"\n{len(self.violations)} VIOLATION(S):")
            for v in self.violations:
                print("  " + v)
            return 1
        print("no violation")
        return 0


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    repo = Path(__file__).resolve().parents[1]
    default = os.environ.get("MMIC_BIN") or str(Path(os.environ.get("CARGO_TARGET_DIR", repo / "target"))
                                                 / "debug" / "mmic")
    ap.add_argument("--mmic", default=default, help="the mmic binary (default $MMIC_BIN or target/debug/mmic)")
    ap.add_argument("--keep", default=None, help="work in this directory (made; kept) instead of a temporary one")
    ap.add_argument("-v", "--verbose", action="store_true")
    a = ap.parse_args(argv)
    if not Path(a.mmic).is_file():
        print(f"attack_suite: no mmic binary at {a.mmic} (cargo build -p mmic-host --bin mmic)", file=sys.stderr)
        return 2
    if a.keep:
        work = Path(a.keep)
        work.mkdir(parents=True)
        cleanup = False
    else:
        work = Path(tempfile.mkdtemp(prefix="mmic-attacks-"))
        cleanup = True
    os.chmod(work, 0o700)
    suite = Suite(a.mmic, work, a.verbose)
    try:
        return suite.run()
    except Exception as e:   # a set-up failure, not a finding
        import traceback
        traceback.print_exc()
        print(f"attack_suite: could not run: {e}", file=sys.stderr)
        return 2
    finally:
        for r in getattr(suite, "robots", []):
            r.stop(signal.SIGKILL)
        if cleanup:
            shutil.rmtree(work, ignore_errors=True)      # the keys with it


if __name__ == "__main__":
    sys.exit(main())
