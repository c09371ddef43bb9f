"""An independent reading of the CCSDS transfer frames, in Python, for the ground tests: TM transfer
frames (132.0-B-3) with the CLCW in their OCF (232.0-B-4 §4.2) and the packets in them, and the TC
transfer frames (232.0-B-4) YAMCS sends. Written from the standards' bit layouts, not from the Rust
code. spacepackets 0.32 has a TM frame reader too (`spacepackets.ccsds.tm_frame.TmTransferFrame`: the
header, data field, OCF and a CRC check, no packet extraction): test_yamcs_frames.py reads every frame
of the gateway with both and requires them to agree.

    frames = [bytes.fromhex(h) for h in captured]
    x = TmExtractor(frame_len=256, spacecraft_id=0x101)
    for f in frames:
        for packet in x.push(f):        # whole space packets, idle packets dropped
            ...
    x.lost_frames, x.dropped_partial    # what the VC frame counts say was lost

Every check raises FrameError with the name of the field that failed.
"""
from __future__ import annotations

from dataclasses import dataclass, field

from rust_side import crc16_ccitt_false

IDLE_APID = 0x7FF
FHP_NO_PACKET = 0x7FF    # no packet starts in this frame
FHP_ONLY_IDLE = 0x7FE    # the frame holds only idle data


class FrameError(ValueError):
    """A frame refused, with the check that refused it (`.check`)."""

    def __init__(self, check: str, message: str):
        super().__init__(f"{check}: {message}")
        self.check = check


@dataclass(frozen=True)
class Clcw:
    """The Communications Link Control Word (232.0-B-4 §4.2.1), field by field."""
    control_word_type: int
    version: int
    status: int
    cop_in_effect: int
    vcid: int
    no_rf_available: bool
    no_bit_lock: bool
    lockout: bool
    wait: bool
    retransmit: bool
    farm_b_counter: int
    report_value: int

    @staticmethod
    def parse(word: bytes) -> "Clcw":
        if len(word) != 4:
            raise FrameError("clcw-length", f"{len(word)} octets, a CLCW has 4")
        w = int.from_bytes(word, "big")
        bit = lambda pos, n=1: (w >> (32 - pos - n)) & ((1 << n) - 1)  # pos: first bit, 0 = MSB
        return Clcw(control_word_type=bit(0), version=bit(1, 2), status=bit(3, 3), cop_in_effect=bit(6, 2),
                    vcid=bit(8, 6), no_rf_available=bool(bit(16)), no_bit_lock=bool(bit(17)),
                    lockout=bool(bit(18)), wait=bool(bit(19)), retransmit=bool(bit(20)),
                    farm_b_counter=bit(21, 2), report_value=bit(24, 8))


@dataclass(frozen=True)
class TmFrame:
    """One TM transfer frame (132.0-B-3 §4.1), checked."""
    spacecraft_id: int
    vcid: int
    master_count: int
    vc_count: int
    first_header_pointer: int
    data: bytes
    ocf: bytes | None

    @property
    def clcw(self) -> Clcw | None:
        return Clcw.parse(self.ocf) if self.ocf is not None else None

    @staticmethod
    def parse(raw: bytes, *, frame_len: int, ocf: bool = True, fecf: bool = True) -> "TmFrame":
        if len(raw) != frame_len:
            raise FrameError("length", f"{len(raw)} octets, the mission's frames have {frame_len}")
        if fecf and crc16_ccitt_false(raw[:-2]) != int.from_bytes(raw[-2:], "big"):
            raise FrameError("fecf", "the frame error control field does not match")
        h = int.from_bytes(raw[:6], "big")  # 48 bits
        version = h >> 46
        scid = (h >> 36) & 0x3FF
        vcid = (h >> 33) & 0x7
        ocf_flag = (h >> 32) & 1
        mc, vc = (h >> 24) & 0xFF, (h >> 16) & 0xFF
        sec_header, sync, order, seg_len, fhp = (h >> 15) & 1, (h >> 14) & 1, (h >> 13) & 1, (h >> 11) & 3, h & 0x7FF
        if version != 0:
            raise FrameError("version", f"transfer frame version {version}, TM frames have 0")
        if ocf_flag != int(ocf):
            raise FrameError("ocf-flag", f"OCF flag {ocf_flag}, the mission's frames have {int(ocf)}")
        if sec_header:
            raise FrameError("secondary-header", "the mission's frames have no secondary header")
        if sync or order or seg_len != 3:
            raise FrameError("data-field-status", f"sync {sync}, order {order}, segment length ID {seg_len}: "
                             "packets need 0, 0, 11")
        end = frame_len - (2 if fecf else 0) - (4 if ocf else 0)
        data = raw[6:end]
        if fhp not in (FHP_NO_PACKET, FHP_ONLY_IDLE) and fhp >= len(data):
            raise FrameError("first-header-pointer", f"{fhp}, past the data field of {len(data)} octets")
        return TmFrame(scid, vcid, mc, vc, fhp, data, raw[end:end + 4] if ocf else None)


@dataclass
class TmExtractor:
    """Space packets out of a stream of TM frames of one virtual channel (132.0-B-3 §4.1.2.7.5): packets
    spanning frames reassembled; a packet touched by a lost frame (a gap in the VC frame count) dropped
    and counted, never spliced; idle packets (APID 0x7FF) and only-idle frames dropped."""
    frame_len: int
    spacecraft_id: int
    vcid: int = 0
    frames: int = 0
    lost_frames: int = 0
    dropped_partial: int = 0
    idle_packets: int = 0
    fhp_mismatch: int = 0
    repeated: int = 0
    clcws: list = field(default_factory=list)
    _buf: bytearray = field(default_factory=bytearray)
    _synced: bool = False
    _last_vc: int | None = None

    def push(self, raw: bytes) -> list[bytes]:
        f = TmFrame.parse(raw, frame_len=self.frame_len)
        if f.spacecraft_id != self.spacecraft_id:
            raise FrameError("spacecraft-id", f"{f.spacecraft_id:#x}, expected {self.spacecraft_id:#x}")
        if f.vcid != self.vcid:
            raise FrameError("vcid", f"{f.vcid}, expected {self.vcid}")
        self.frames += 1
        if f.ocf is not None:
            self.clcws.append(f.clcw)
        if self._last_vc is not None and (self._last_vc - f.vc_count) % 256 < 128:
            self.repeated += 1      # a copy, or a frame overtaken in transport: skipped whole
            return []
        if self._last_vc is not None and (f.vc_count - self._last_vc) % 256 != 1:
            self.lost_frames += (f.vc_count - self._last_vc - 1) % 256
            if self._buf:
                self.dropped_partial += 1
            self._buf.clear()
            self._synced = False
        self._last_vc = f.vc_count
        if f.first_header_pointer == FHP_ONLY_IDLE:
            return []
        data = f.data
        if not self._synced:
            if f.first_header_pointer == FHP_NO_PACKET:
                return []           # still inside a packet whose start we lost
            data = data[f.first_header_pointer:]
            self._synced = True
        elif f.first_header_pointer != FHP_NO_PACKET and len(self._buf) >= 6:
            # The packet in progress must end exactly where the first header pointer says the next
            # one starts; if not, the stream is inconsistent: drop it, resynchronise there.
            rest = int.from_bytes(self._buf[4:6], "big") + 7 - len(self._buf)
            if rest != f.first_header_pointer:
                self.fhp_mismatch += 1
                self.dropped_partial += 1
                self._buf.clear()
                data = data[f.first_header_pointer:]
        self._buf += data
        return self._packets()

    def _packets(self) -> list[bytes]:
        out = []
        while len(self._buf) >= 6:
            length = int.from_bytes(self._buf[4:6], "big") + 7
            if len(self._buf) < length:
                break
            packet, self._buf = bytes(self._buf[:length]), self._buf[length:]
            if int.from_bytes(packet[:2], "big") & 0x7FF == IDLE_APID:
                self.idle_packets += 1
            else:
                out.append(packet)
        return out


@dataclass(frozen=True)
class TcFrame:
    """One TC transfer frame (232.0-B-4 §4.1), checked: its kind (AD, BD, BC), N(S), and its data."""
    spacecraft_id: int
    vcid: int
    kind: str
    seq: int
    map_id: int | None
    data: bytes

    @staticmethod
    def parse(raw: bytes, *, segment_header: bool = True, fecf: bool = True) -> "TcFrame":
        if len(raw) < 5 + (2 if fecf else 0):
            raise FrameError("truncated", f"{len(raw)} octets")
        h = int.from_bytes(raw[:5], "big")  # 40 bits
        version, bypass, cc = h >> 38, (h >> 37) & 1, (h >> 36) & 1
        scid, vcid, length, seq = (h >> 24) & 0x3FF, (h >> 18) & 0x3F, ((h >> 8) & 0x3FF) + 1, h & 0xFF
        if version != 0:
            raise FrameError("version", f"{version}")
        if length != len(raw):
            raise FrameError("length", f"the header says {length} octets, the datagram has {len(raw)}")
        if fecf and crc16_ccitt_false(raw[:-2]) != int.from_bytes(raw[-2:], "big"):
            raise FrameError("fecf", "the frame error control field does not match")
        kind = {(0, 0): "AD", (1, 0): "BD", (1, 1): "BC"}.get((bypass, cc))
        if kind is None:
            raise FrameError("flags", "bypass 0 with control command 1")
        body = raw[5:len(raw) - (2 if fecf else 0)]
        map_id = None
        if segment_header and kind != "BC":
            if not body or body[0] >> 6 != 3:
                raise FrameError("segment-header", "missing, or not an unsegmented one (sequence flags 11)")
            map_id, body = body[0] & 0x3F, body[1:]
        return TcFrame(scid, vcid, kind, seq, map_id, bytes(body))

    def control(self) -> tuple[str, int | None]:
        """A BC frame's control command: ("unlock", None) or ("set-vr", V(R))."""
        if self.kind != "BC":
            raise FrameError("kind", f"{self.kind} frames carry no control command")
        if self.data == b"\x00":
            return ("unlock", None)
        if len(self.data) == 3 and self.data[:2] == b"\x82\x00":
            return ("set-vr", self.data[2])
        raise FrameError("control-command", self.data.hex())
