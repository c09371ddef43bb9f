"""An independent Python reading of SDLS (CCSDS 355.0-B-2) as the mission uses it (docs: the SDLS plan,
issue 28): AES-256-GCM with a 128-bit MAC, a security header of SPI (2 octets) + IV (12 octets, a
big-endian 96-bit counter that is also the anti-replay sequence number), interoperable with YAMCS
5.12.8's `org.yamcs.security.sdls.SecurityAssociationAes256Gcm128`. Written from the standard and the
plan's byte layout, not from the Rust code; the cipher is the `cryptography` package's AESGCM.

    TC frame: primary header (5) | segment header (1) | SPI (2) | IV (12) | ciphertext | MAC (16) | FECF (2)
    TM frame (256): primary header (6) | SPI (2) | IV (12) | ciphertext (214) | MAC (16) | OCF (4) | FECF (2)

GCM: nonce = IV, AAD = frame[:len(mask)] AND mask, plaintext = the octets between the security header and
the MAC. The FECF covers the frame as sent (over the ciphertext); OCF and FECF are outside the MAC. COP-1
control (BC) frames travel in clear.

Receiving: `TcReceiver` is the robot's TC side (frame checks, SA lookup by SPI, MAC, then the anti-replay
window, in that order, state changed only for a frame accepted whole); `SeqWindow` is the window alone.
Every refusal raises `SdlsError` with the name of the check (`.check`) and the numbers that explain it.

Keys are never printed: `SecurityAssociation`'s repr leaves the key out, and no function logs.
"""
from __future__ import annotations

import os
import secrets
from dataclasses import dataclass, field
from pathlib import Path

from cryptography.exceptions import InvalidTag
from cryptography.hazmat.primitives.ciphers.aead import AESGCM

from rust_side import crc16_ccitt_false

SPI_LEN = 2
IV_LEN = 12
MAC_LEN = 16
HEADER_LEN = SPI_LEN + IV_LEN   # 14: the security header
OVERHEAD = HEADER_LEN + MAC_LEN  # 30
IV_SPACE = 1 << 96               # the IV is a 96-bit counter that never wraps
KEY_LEN = 32

TC_PRIMARY = 5
TC_SEC_START = TC_PRIMARY + 1    # after the segment header: the SPI is at octet 6
TM_PRIMARY = 6
TM_SEC_START = TM_PRIMARY        # no secondary header: the SPI is at octet 6
TM_FRAME_LEN = 256
TM_TRAILER = 4 + 2               # OCF (the CLCW) + FECF, outside the MAC
TM_DATA_LEN = TM_FRAME_LEN - TM_PRIMARY - OVERHEAD - TM_TRAILER  # 214

# The plan's authentication masks (YAMCS `authMask`, hex): whole primary header, segment header (TC), SPI;
# the IV is masked out (GCM authenticates it as the nonce).
TC_AUTH_MASK = bytes.fromhex("ffffffffff" "ff" "ffff") + bytes(IV_LEN)
TM_AUTH_MASK = bytes.fromhex("ffffffffffff" "ffff") + bytes(IV_LEN)

TC_WINDOW = 1 << 20  # the gateway's TC receiver window (spec/ccsds/sdls.toml tc_window)
TM_WINDOW = 100000   # YAMCS's TM receiver (`seqNumWindow`)


def tc_spi(robot: int) -> int:
    """The TC SA of robot n: 0x0100 + n (= its spacecraft ID)."""
    return 0x0100 + robot


def tm_spi(robot: int) -> int:
    """The TM SA of robot n: 0x0200 + n."""
    return 0x0200 + robot


class SdlsError(ValueError):
    """A frame refused, with the check that refused it (`.check`)."""

    def __init__(self, check: str, message: str):
        super().__init__(f"{check}: {message}")
        self.check = check


# -- keys ---------------------------------------------------------------------------------------------
def key_path(key_dir: str | os.PathLike, spi: int) -> Path:
    return Path(key_dir) / f"spi-{spi}.key"


def write_random_keys(key_dir: str | os.PathLike, spis) -> dict[int, Path]:
    """Random 32-octet keys, one file per SPI (`spi-<SPI>.key`, mode 0600, created exclusively). Returns
    the paths, never the keys."""
    key_dir = Path(key_dir)
    key_dir.mkdir(parents=True, exist_ok=True)
    out = {}
    for spi in spis:
        p = key_path(key_dir, spi)
        fd = os.open(p, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o600)
        with os.fdopen(fd, "wb") as f:
            f.write(secrets.token_bytes(KEY_LEN))
        out[spi] = p
    return out


def load_key(key_dir: str | os.PathLike, spi: int) -> bytes:
    key = key_path(key_dir, spi).read_bytes()
    if len(key) != KEY_LEN:
        raise SdlsError("key-length", f"spi-{spi}.key has {len(key)} octets, AES-256 needs {KEY_LEN}")
    return key


@dataclass(frozen=True)
class SecurityAssociation:
    """One SA: its SPI, its key (left out of repr), its authentication mask."""
    spi: int
    key: bytes = field(repr=False)
    mask: bytes

    @staticmethod
    def from_dir(key_dir, spi: int, mask: bytes) -> "SecurityAssociation":
        return SecurityAssociation(spi, load_key(key_dir, spi), mask)


# -- the generic operations (YAMCS's applySecurity / processSecurity) -----------------------------------
def aad(frame: bytes, mask: bytes) -> bytes:
    """The additional authenticated data: the frame's first len(mask) octets AND the mask."""
    if len(frame) < len(mask):
        raise SdlsError("truncated", f"{len(frame)} octets, the mask covers {len(mask)}")
    return bytes(a & m for a, m in zip(frame, mask))


def apply_security(frame: bytearray, sec_start: int, mac_end: int, sa: SecurityAssociation, iv: int) -> None:
    """Protect in place: the data between the security header (at sec_start) and the MAC (ending at mac_end)
    is the plaintext; writes SPI, IV, ciphertext and MAC."""
    if not 0 <= iv < IV_SPACE:
        raise SdlsError("iv-spent", f"IV {iv} outside the 96-bit counter")
    nonce = iv.to_bytes(IV_LEN, "big")
    frame[sec_start:sec_start + SPI_LEN] = sa.spi.to_bytes(SPI_LEN, "big")
    frame[sec_start + SPI_LEN:sec_start + HEADER_LEN] = nonce
    start = sec_start + HEADER_LEN
    plaintext = bytes(frame[start:mac_end - MAC_LEN])
    sealed = AESGCM(sa.key).encrypt(nonce, plaintext, aad(frame, sa.mask))  # ciphertext || tag
    frame[start:mac_end] = sealed


def process_security(frame: bytes, sec_start: int, mac_end: int, sa: SecurityAssociation) -> tuple[int, bytes]:
    """Verify and decrypt: (IV, plaintext). Checks the SPI against the SA and the MAC; no window."""
    if mac_end - sec_start < OVERHEAD or len(frame) < mac_end:
        raise SdlsError("truncated", f"{mac_end - sec_start} octets for security header, data and MAC, "
                        f"at least {OVERHEAD} needed")
    spi = int.from_bytes(frame[sec_start:sec_start + SPI_LEN], "big")
    if spi != sa.spi:
        raise SdlsError("spi", f"SPI {spi}, this SA is {sa.spi}")
    nonce = bytes(frame[sec_start + SPI_LEN:sec_start + HEADER_LEN])
    start = sec_start + HEADER_LEN
    try:
        plaintext = AESGCM(sa.key).decrypt(nonce, bytes(frame[start:mac_end]), aad(frame, sa.mask))
    except InvalidTag:
        raise SdlsError("mac", f"the MAC does not verify (SPI {spi}, IV {int.from_bytes(nonce, 'big')})") from None
    return int.from_bytes(nonce, "big"), plaintext


# -- the anti-replay window -----------------------------------------------------------------------------
@dataclass
class SeqWindow:
    """The receiver's window (the plan): with `last` the last accepted IV and d = (iv - last) mod 2^96,
    d in 1..=W accepted; d = 0 or d > 2^95 a replay; W < d <= 2^95 too far ahead. `last` = None before the
    first frame: the sender's first IV is 0, so the start is as if IV 2^96 - 1 had been seen."""
    window: int
    last: int | None = None

    def check(self, iv: int) -> int:
        """The distance d of an acceptable IV; raises SdlsError('replay' | 'ahead') otherwise. No change."""
        last = IV_SPACE - 1 if self.last is None else self.last
        d = (iv - last) % IV_SPACE
        if d == 0 or d > IV_SPACE // 2:
            raise SdlsError("replay", f"IV {iv} at or before the last accepted {self.last} (distance {d - IV_SPACE if d else 0})")
        if d > self.window:
            raise SdlsError("ahead", f"IV {iv} is {d} past the last accepted {self.last}, the window is {self.window}")
        return d

    def accept(self, iv: int) -> None:
        self.check(iv)
        self.last = iv


# -- TC -------------------------------------------------------------------------------------------------
def tc_header(scid: int, vcid: int, seq: int, length: int, *, bypass: bool = False, control: bool = False) -> bytes:
    h = (int(bypass) << 37) | (int(control) << 36) | (scid << 24) | (vcid << 18) | ((length - 1) << 8) | seq
    return h.to_bytes(5, "big")


def protect_tc(scid: int, vcid: int, seq: int, data: bytes, sa: SecurityAssociation, iv: int, *,
               map_id: int = 0, bypass: bool = False) -> bytes:
    """A protected AD (or, with bypass, BD) frame carrying `data`, as YAMCS makes it."""
    length = TC_SEC_START + OVERHEAD + len(data) + 2
    if length > 1024:
        raise SdlsError("length", f"{length} octets, a TC frame has at most 1024")
    f = bytearray(tc_header(scid, vcid, seq, length, bypass=bypass) + bytes([0xC0 | map_id]))
    f += bytes(HEADER_LEN) + data + bytes(MAC_LEN) + bytes(2)
    apply_security(f, TC_SEC_START, length - 2, sa, iv)
    f[-2:] = crc16_ccitt_false(f[:-2]).to_bytes(2, "big")
    return bytes(f)


def clear_tc(scid: int, vcid: int, seq: int, body: bytes, *, kind: str = "BC") -> bytes:
    """A frame in clear: BC (control command `body`) or, for the attacks, an AD/BD frame without SDLS."""
    bypass, control = {"AD": (False, False), "BD": (True, False), "BC": (True, True)}[kind]
    body = body if kind == "BC" else bytes([0xC0]) + body
    length = TC_PRIMARY + len(body) + 2
    f = tc_header(scid, vcid, seq, length, bypass=bypass, control=control) + body
    return f + crc16_ccitt_false(f).to_bytes(2, "big")


@dataclass(frozen=True)
class TcVerified:
    """A TC frame accepted by `TcReceiver`: its kind (AD, BD, BC), N(S), MAP ID, the plaintext data (for BC:
    the control command), and the SPI and IV it came under (None for BC)."""
    scid: int
    vcid: int
    kind: str
    seq: int
    map_id: int | None
    data: bytes
    spi: int | None
    iv: int | None


def parse_tc_header(raw: bytes) -> tuple[int, int, int, str, int]:
    """(version, scid, vcid, kind, seq) after the length and FECF checks."""
    if len(raw) < TC_PRIMARY + 2:
        raise SdlsError("truncated", f"{len(raw)} octets")
    h = int.from_bytes(raw[:5], "big")
    version, bypass, cc = h >> 38, (h >> 37) & 1, (h >> 36) & 1
    scid, vcid, length, seq = (h >> 24) & 0x3FF, (h >> 18) & 0x3F, ((h >> 8) & 0x3FF) + 1, h & 0xFF
    if length != len(raw):
        raise SdlsError("length", f"the header says {length} octets, the datagram has {len(raw)}")
    fecf = crc16_ccitt_false(raw[:-2])
    if fecf != int.from_bytes(raw[-2:], "big"):
        raise SdlsError("fecf", f"FECF {int.from_bytes(raw[-2:], 'big'):#06x}, computed {fecf:#06x}")
    if version != 0:
        raise SdlsError("version", f"{version}")
    kind = {(0, 0): "AD", (1, 0): "BD", (1, 1): "BC"}.get((bypass, cc))
    if kind is None:
        raise SdlsError("flags", "bypass 0 with control command 1")
    return version, scid, vcid, kind, seq


@dataclass
class TcReceiver:
    """The robot's TC side of SDLS: frame checks (length, FECF, version, spacecraft ID), then BC frames in
    clear, data frames by SPI -> SA (unknown SPI refused), MAC, anti-replay window per SPI. A frame changes
    the window only when accepted whole (the MAC is checked before the window, so a forged IV moves
    nothing)."""
    scid: int
    sas: dict[int, SecurityAssociation]
    window: int = TC_WINDOW
    vcid: int = 0
    windows: dict[int, SeqWindow] = field(default_factory=dict)

    def receive(self, raw: bytes) -> TcVerified:
        _, scid, vcid, kind, seq = parse_tc_header(raw)
        if scid != self.scid:
            raise SdlsError("spacecraft-id", f"{scid:#x}, this robot is {self.scid:#x}")
        if vcid != self.vcid:
            raise SdlsError("vcid", f"{vcid}, expected {self.vcid}")
        body = raw[TC_PRIMARY:-2]
        if kind == "BC":
            return TcVerified(scid, vcid, kind, seq, None, bytes(body), None, None)
        if not body or body[0] >> 6 != 3:
            raise SdlsError("segment-header", "missing, or not an unsegmented one (sequence flags 11)")
        if len(body) < 1 + OVERHEAD:
            raise SdlsError("truncated", f"{len(body) - 1} octets after the segment header, SDLS needs {OVERHEAD}")
        spi = int.from_bytes(raw[TC_SEC_START:TC_SEC_START + SPI_LEN], "big")
        sa = self.sas.get(spi)
        if sa is None:
            raise SdlsError("unknown-spi", f"SPI {spi}: no SA (known: {sorted(self.sas)})")
        iv, plaintext = process_security(raw, TC_SEC_START, len(raw) - 2, sa)
        w = self.windows.setdefault(spi, SeqWindow(self.window))
        w.accept(iv)
        return TcVerified(scid, vcid, kind, seq, body[0] & 0x3F, plaintext, spi, iv)


# -- TM -------------------------------------------------------------------------------------------------
def tm_header(scid: int, vcid: int, mc: int, vc: int, fhp: int, *, ocf: bool = True) -> bytes:
    h = (scid << 36) | (vcid << 33) | (int(ocf) << 32) | ((mc & 0xFF) << 24) | ((vc & 0xFF) << 16) | (3 << 11) | fhp
    return h.to_bytes(6, "big")


def protect_tm(scid: int, vcid: int, mc: int, vc: int, fhp: int, data: bytes, ocf: bytes,
               sa: SecurityAssociation, iv: int) -> bytes:
    """A protected 256-octet TM frame: `data` (214 octets) encrypted, the OCF (4) and FECF in clear.
    The FHP counts from the first octet after the security header."""
    if len(data) != TM_DATA_LEN or len(ocf) != 4:
        raise SdlsError("length", f"data {len(data)} (needs {TM_DATA_LEN}), OCF {len(ocf)} (needs 4)")
    f = bytearray(tm_header(scid, vcid, mc, vc, fhp) + bytes(HEADER_LEN) + data + bytes(MAC_LEN) + ocf + bytes(2))
    apply_security(f, TM_SEC_START, TM_FRAME_LEN - TM_TRAILER, sa, iv)
    f[-2:] = crc16_ccitt_false(f[:-2]).to_bytes(2, "big")
    return bytes(f)


@dataclass(frozen=True)
class TmVerified:
    scid: int
    vcid: int
    mc: int
    vc: int
    fhp: int
    data: bytes
    ocf: bytes
    spi: int
    iv: int


def verify_tm(raw: bytes, sa: SecurityAssociation, window: SeqWindow | None = None) -> TmVerified:
    """Check FECF and length, then SPI, MAC and (if given) the window; the plaintext frame's fields."""
    if len(raw) != TM_FRAME_LEN:
        raise SdlsError("length", f"{len(raw)} octets, the mission's frames have {TM_FRAME_LEN}")
    if crc16_ccitt_false(raw[:-2]) != int.from_bytes(raw[-2:], "big"):
        raise SdlsError("fecf", "the frame error control field does not match")
    h = int.from_bytes(raw[:6], "big")
    iv, plaintext = process_security(raw, TM_SEC_START, TM_FRAME_LEN - TM_TRAILER, sa)
    if window is not None:
        window.accept(iv)
    return TmVerified((h >> 36) & 0x3FF, (h >> 33) & 7, (h >> 24) & 0xFF, (h >> 16) & 0xFF, h & 0x7FF,
                      plaintext, bytes(raw[-6:-2]), sa.spi, iv)
