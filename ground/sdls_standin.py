"""A Python stand-in for the robot behind the SDLS-protected space data link, for the experiments with
YAMCS (tests/test_yamcs_sdls.py, repro_cop1_sdls.py): no Rust in the loop, every octet checked by
ground/sdls.py.

- TC: binds 127.0.0.1:tc_port (YAMCS's `UdpTcFrameLink` destination); each datagram is recorded raw, then
  checked by `sdls.TcReceiver` (SPI 257, the plan's mask, window 4096), then goes to a minimal FARM-1:
  an AD frame is accepted when N(S) == V(R) (V(R) += 1), BC Unlock and Set V(R) act, BD frames are taken.
  `drop(n, raw)` may drop a datagram before it is looked at (the COP-1 retransmission experiment): it is
  still recorded, marked dropped, and checked by a separate receiver so its bytes can be compared.
- TM: sends 256-octet SDLS-protected TM frames (SPI 513, IVs 0, 1, 2, ...) to 127.0.0.1:tm_port every
  `period` seconds and right after each TC datagram, the CLCW (report value V(R)) in the OCF; packets
  given to `send_packet` go out one per frame at FHP 0, the rest of the data field an idle packet; a
  frame without packet is only-idle (FHP 0x7FE). `sent_tm` keeps every frame sent (for replays).
"""
from __future__ import annotations

import socket
import threading
import time
from dataclasses import dataclass, field

import sdls
from rust_side import crc16_ccitt_false

SCID = 0x101
TC_SPI = sdls.tc_spi(1)
TM_SPI = sdls.tm_spi(1)
APID = 0x101


def idle_packet(length: int) -> bytes:
    """A CCSDS idle packet (APID 0x7FF) of `length` octets (>= 7)."""
    return bytes([0x07, 0xFF, 0xC0, 0x00]) + (length - 7).to_bytes(2, "big") + bytes(length - 6)


def pus_tm(service: int, subservice: int, seq: int, data: bytes = b"", *, apid: int = APID,
           met_coarse: int = 0, counter: int = 0) -> bytes:
    """A PUS-C TM packet as the gateway makes it: primary header, secondary header (version 2, service,
    subservice, message type counter, destination 0, CUC 4 + 2), source data, CRC-16/CCITT-FALSE."""
    body = bytes([0x20, service, subservice]) + counter.to_bytes(2, "big") + bytes(2) \
        + met_coarse.to_bytes(4, "big") + bytes(2) + data
    length = 6 + len(body) + 2
    p = bytes([0x08 | (apid >> 8), apid & 0xFF, 0xC0 | ((seq >> 8) & 0x3F), seq & 0xFF]) \
        + (length - 7).to_bytes(2, "big") + body
    return p + crc16_ccitt_false(p).to_bytes(2, "big")


def clcw(v_r: int, *, lockout: bool = False, wait: bool = False, retransmit: bool = False) -> bytes:
    """Type 0, version 0, status 0, COP-1 in effect, VC 0, no flags but those given, report value V(R)."""
    return bytes([0x01, 0x00, (lockout << 5) | (wait << 4) | (retransmit << 3), v_r & 0xFF])


@dataclass
class TcRecord:
    raw: bytes
    t: float
    dropped: bool
    verdict: str                     # accept, discard:<why>, unlock, set-vr:<n>, bd, refused:<check>
    frame: sdls.TcVerified | None    # None when SDLS refused it
    error: str | None = None


@dataclass
class StandIn:
    tm_port: int
    tc_port: int
    key_dir: str
    period: float = 0.2
    drop: object = None              # callable(index, raw) -> bool
    tc: list[TcRecord] = field(default_factory=list)
    sent_tm: list[bytes] = field(default_factory=list)
    v_r: int = 0

    def __post_init__(self):
        self.tc_sa = sdls.SecurityAssociation.from_dir(self.key_dir, TC_SPI, sdls.TC_AUTH_MASK)
        self.tm_sa = sdls.SecurityAssociation.from_dir(self.key_dir, TM_SPI, sdls.TM_AUTH_MASK)
        self.receiver = sdls.TcReceiver(SCID, {TC_SPI: self.tc_sa})
        self.side_receiver = sdls.TcReceiver(SCID, {TC_SPI: self.tc_sa}, window=1 << 20)  # dropped ones
        self.tm_iv = 0
        self.mc = 0
        self.seq = 0
        self.packets: list[bytes] = []
        self.lock = threading.Lock()
        # Held from taking a frame's IV to its sendto: the periodic sender and a test's
        # send_packet would otherwise race, and a frame with the lower IV sent second is a replay
        # to YAMCS (an "Invalid frames" count seen once in CI, on a loaded machine).
        self.send_lock = threading.Lock()
        self.stop_event = threading.Event()
        self.rx = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
        self.rx.bind(("127.0.0.1", self.tc_port))
        self.rx.settimeout(0.05)
        self.tx = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
        self.threads = [threading.Thread(target=self._tc_loop, daemon=True),
                        threading.Thread(target=self._tm_loop, daemon=True)]

    def __enter__(self):
        for t in self.threads:
            t.start()
        return self

    def __exit__(self, *exc):
        self.stop_event.set()
        for t in self.threads:
            t.join(2)
        self.rx.close()
        self.tx.close()

    # -- TM ---------------------------------------------------------------------------------------
    def send_packet(self, packet: bytes) -> None:
        with self.lock:
            self.packets.append(packet)
        self.send_tm()

    def next_pus_seq(self) -> int:
        with self.lock:
            self.seq = (self.seq + 1) & 0x3FFF
            return self.seq

    def make_tm(self) -> bytes:
        """The next protected frame (consumes an IV and the frame counts)."""
        with self.lock:
            packet = self.packets.pop(0) if self.packets else None
            iv, self.tm_iv = self.tm_iv, self.tm_iv + 1
            mc, self.mc = self.mc, (self.mc + 1) & 0xFF
            v_r = self.v_r
        if packet is None:
            data, fhp = idle_packet(sdls.TM_DATA_LEN), 0x7FE
        else:
            data, fhp = packet + idle_packet(sdls.TM_DATA_LEN - len(packet)), 0
        return sdls.protect_tm(SCID, 0, mc, mc, fhp, data, clcw(v_r), self.tm_sa, iv)

    def send_tm(self) -> bytes:
        with self.send_lock:
            f = self.make_tm()
            self.send_raw_tm(f)
        return f

    def send_raw_tm(self, frame: bytes) -> None:
        with self.lock:
            self.sent_tm.append(frame)
        self.tx.sendto(frame, ("127.0.0.1", self.tm_port))

    def _tm_loop(self):
        while not self.stop_event.wait(self.period):
            self.send_tm()

    # -- TC ---------------------------------------------------------------------------------------
    def _tc_loop(self):
        while not self.stop_event.is_set():
            try:
                raw = self.rx.recv(2048)
            except socket.timeout:
                continue
            except OSError:
                return
            self._on_tc(raw)
            self.send_tm()

    def _on_tc(self, raw: bytes) -> None:
        t = time.monotonic()
        dropped = bool(self.drop and self.drop(len(self.tc), raw))
        rx = self.side_receiver if dropped else self.receiver
        try:
            f = rx.receive(raw)
        except sdls.SdlsError as e:
            self.tc.append(TcRecord(raw, t, dropped, f"refused:{e.check}", None, str(e)))
            return
        if dropped:
            self.tc.append(TcRecord(raw, t, True, "dropped", f))
            return
        with self.lock:
            if f.kind == "AD":
                if f.seq == self.v_r:
                    self.v_r = (self.v_r + 1) & 0xFF
                    verdict = "accept"
                else:
                    verdict = "discard:" + ("behind" if (self.v_r - f.seq) % 256 < 128 else "ahead")
            elif f.kind == "BD":
                verdict = "bd"
            elif f.data == b"\x00":
                verdict = "unlock"
            elif len(f.data) == 3 and f.data[:2] == b"\x82\x00":
                self.v_r = f.data[2]
                verdict = f"set-vr:{f.data[2]}"
            else:
                verdict = "discard:invalid"
        self.tc.append(TcRecord(raw, t, False, verdict, f))
