"""A tiny stand-in for the simulated robot: PUS-C TM out, PUS-C TC in, over UDP on 127.0.0.1.

Packets are built and parsed with Python `spacepackets` (PyPI); the CRC is also checked with an
independent implementation (`crc16_ccitt_false`) so that a wrong CRC cannot hide in one library.
Layout (see ground/yamcs/example-mdb.xml): APID 100; TM secondary header with a 6-octet CUC time
(4 coarse + 2 fine, implicit P-field) = seconds since power-on; TM(3,25) = structure ID u16,
battery voltage u16 mV, mode u8, fault bitmap u32; TM(1,x) = request ID (4 octets) [+ failure code u16].
"""
from __future__ import annotations

import queue
import socket
import struct
import threading
from dataclasses import dataclass, field

from spacepackets.ccsds.spacepacket import PacketType, SequenceFlags
from spacepackets.ecss import PusTc, PusTm

APID = 100
HK_SID = 1


def crc16_ccitt_false(data: bytes) -> int:
    """CRC-16/CCITT-FALSE (poly 0x1021, init 0xFFFF, no reflection, no final XOR), as PUS requires."""
    crc = 0xFFFF
    for b in data:
        crc ^= b << 8
        for _ in range(8):
            crc = ((crc << 1) ^ 0x1021) & 0xFFFF if crc & 0x8000 else (crc << 1) & 0xFFFF
    return crc


def cuc(met_seconds: float) -> bytes:
    """CUC time field: 4 octets of whole seconds + 2 octets of 1/65536 s, no P-field."""
    units = round(met_seconds * 65536)
    return struct.pack(">IH", units >> 16, units & 0xFFFF)


def hk_source_data(battery_mv: int, mode: int, faults: int, sid: int = HK_SID) -> bytes:
    return struct.pack(">HHBI", sid, battery_mv, mode, faults)


@dataclass
class ReceivedTc:
    raw: bytes
    tc: PusTc

    @property
    def request_id(self) -> bytes:  # packet ID + packet sequence control
        return self.raw[:4]


@dataclass
class FakeRobot:
    tm_port: int  # YAMCS's UDP TM link
    tc_port: int  # where YAMCS sends TCs (we bind it)
    # How the next TCs are answered: "complete" -> TM(1,1)+TM(1,7); "fail-acceptance" -> TM(1,2);
    # "fail-completion" -> TM(1,1)+TM(1,8); "silent" -> nothing (the test answers by hand).
    answer: str = "complete"
    failure_code: int = 3
    tcs: "queue.Queue[ReceivedTc]" = field(default_factory=queue.Queue)
    errors: list = field(default_factory=list)  # invalid TCs: the tests assert this stays empty
    _seq: int = 0
    _msg_counters: dict = field(default_factory=dict)

    def __post_init__(self):
        self.tm_sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
        self.tc_sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
        self.tc_sock.bind(("127.0.0.1", self.tc_port))
        self.tc_sock.settimeout(0.2)
        self._stop = threading.Event()
        self._lock = threading.Lock()
        self._thread = threading.Thread(target=self._serve, name="fake-robot", daemon=True)
        self._thread.start()

    def close(self):
        self._stop.set()
        self._thread.join(5)
        self.tm_sock.close()
        self.tc_sock.close()

    # -- TM -------------------------------------------------------------------------------------
    def tm(self, service: int, subservice: int, data: bytes, met: float, apid: int = APID) -> bytes:
        with self._lock:
            key = (apid, service, subservice)
            counter = self._msg_counters.get(key, 0)
            self._msg_counters[key] = (counter + 1) & 0xFFFF
            seq = self._seq
            self._seq = (self._seq + 1) & 0x3FFF
        raw = bytes(PusTm(service=service, message_subtype=subservice, timestamp=cuc(met), source_data=data,
                          apid=apid, seq_count=seq, message_counter=counter).pack())
        assert crc16_ccitt_false(raw[:-2]) == int.from_bytes(raw[-2:], "big")
        return raw

    def send(self, raw: bytes) -> None:
        self.tm_sock.sendto(raw, ("127.0.0.1", self.tm_port))

    def send_hk(self, battery_mv: int, mode: int, faults: int, met: float) -> bytes:
        raw = self.tm(3, 25, hk_source_data(battery_mv, mode, faults), met)
        self.send(raw)
        return raw

    def report(self, subservice: int, request_id: bytes, met: float = 0.0, code: int | None = None):
        data = request_id + (struct.pack(">H", code) if code is not None else b"")
        self.send(self.tm(1, subservice, data, met))

    # -- TC -------------------------------------------------------------------------------------
    def check_tc(self, raw: bytes) -> PusTc:
        """Strict check of one datagram as a PUS-C TC for our APID; raises ValueError naming the fault."""
        if len(raw) < 6 + 5 + 2:
            raise ValueError(f"too short: {len(raw)} octets")
        length = 7 + int.from_bytes(raw[4:6], "big")
        if length != len(raw):
            raise ValueError(f"length field says {length} octets, datagram has {len(raw)}")
        if crc16_ccitt_false(raw[:-2]) != int.from_bytes(raw[-2:], "big"):
            raise ValueError("CRC-16/CCITT-FALSE mismatch")
        tc = PusTc.unpack(raw)  # spacepackets: also verifies the CRC and the PUS version (2)
        h = tc.sp_header
        if h.ccsds_version != 0:
            raise ValueError(f"packet version {h.ccsds_version}")
        if h.packet_type != PacketType.TC:
            raise ValueError("not a TC")
        if not h.sec_header_flag:
            raise ValueError("secondary header flag clear")
        if h.seq_flags != SequenceFlags.UNSEGMENTED:
            raise ValueError(f"sequence flags {h.seq_flags}")
        if h.apid != APID:
            raise ValueError(f"APID {h.apid}")
        return tc

    def _serve(self):
        while not self._stop.is_set():
            try:
                raw, _ = self.tc_sock.recvfrom(65536)
            except socket.timeout:
                continue
            except OSError:
                return
            try:
                tc = self.check_tc(raw)
            except Exception as e:  # noqa: BLE001 - any refusal is recorded for the test
                self.errors.append(f"{e} in {raw.hex()}")
                continue
            rx = ReceivedTc(raw, tc)
            if self.answer == "complete":
                self.report(1, rx.request_id)
                self.report(7, rx.request_id)
            elif self.answer == "fail-acceptance":
                self.report(2, rx.request_id, code=self.failure_code)
            elif self.answer == "fail-completion":
                self.report(1, rx.request_id)
                self.report(8, rx.request_id, code=self.failure_code)
            self.tcs.put(rx)


def main() -> None:
    """By hand: send a TM(3,25) every second and answer every TC, for --seconds."""
    import argparse
    import time

    ap = argparse.ArgumentParser(description=main.__doc__)
    ap.add_argument("--tm-port", type=int, required=True, help="YAMCS's UDP TM port")
    ap.add_argument("--tc-port", type=int, required=True, help="the UDP port YAMCS sends TCs to")
    ap.add_argument("--answer", default="complete", choices=["complete", "fail-acceptance", "fail-completion", "silent"])
    ap.add_argument("--seconds", type=int, default=60)
    a = ap.parse_args()
    robot = FakeRobot(a.tm_port, a.tc_port, answer=a.answer)
    t0 = time.monotonic()
    try:
        while (met := time.monotonic() - t0) < a.seconds:
            robot.send_hk(3600 + int(met) % 200, 2, 0, met)
            while not robot.tcs.empty():
                rx = robot.tcs.get()
                print(f"TC {rx.raw.hex()} -> {a.answer}", flush=True)
            for e in robot.errors:
                print("refused TC:", e, flush=True)
            robot.errors.clear()
            time.sleep(1)
    except KeyboardInterrupt:
        pass
    robot.close()


if __name__ == "__main__":
    main()
