#!/usr/bin/env python3
"""The attacker's frames against the robot's SDLS TC receiver, made from one captured valid protected TC
frame (for tests/test_sdls_reader.py and by hand). Each `Attack` names what it models and the check of
ground/sdls.py's `TcReceiver` that must refuse it (`expect`), for a receiver of robot 1 (SCID 257, the SA
of SPI 257 only) that has accepted the captured frame once.

What an attacker can do without the key:
- replay the frame as is (`replay`);
- flip any bit: of the primary and segment headers, of the SPI, of the IV, of the ciphertext, of the
  MAC; each with the FECF recomputed (the frame reaches SDLS) and with the FECF left as is (the frame
  checks refuse it first); and of the FECF itself;
- send frames under a key of its own (`wrong-key`: the files of another key directory);
- move the counter: an IV far ahead (last + 2^24, beyond the window of 2^20) keeping the old MAC (`far-ahead-no-key`);
- change the SPI to one the robot has no SA for (`unknown-spi`);
- readdress the frame to another robot (SCID 258: `other-robot-scid`) or make one under another robot's
  SA (`other-robot-spi`: SPI 258 under the other key, to robot 1's SCID);
- replay frames captured earlier (`earlier-N`: older IVs).
With the key (a leak, modelled by `key_dir`): a valid frame re-made with an IV below the last accepted
one (`old-counter`) and one at last + 2^24 with a valid MAC (`far-ahead-with-key`): the window refuses both.

    python ground/sdls_attack.py --frame HEX --wrong-keys DIR [--keys DIR] [--earlier HEX ...]

prints one JSON line per attack (name, expect, hex). Keys are read from files and never printed.
"""
from __future__ import annotations

import argparse
import json
import sys
from dataclasses import dataclass
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))

import sdls  # noqa: E402
from rust_side import crc16_ccitt_false  # noqa: E402

OTHER_SCID = 0x102
FAR = 1 << 24         # beyond the gateway's window (2^20)


@dataclass(frozen=True)
class Attack:
    name: str
    frame: bytes
    expect: str          # the SdlsError check that refuses it


def with_fecf(body: bytes) -> bytes:
    """The frame with its FECF recomputed over all but the last two octets."""
    return body[:-2] + crc16_ccitt_false(body[:-2]).to_bytes(2, "big")


def region(i: int, n: int) -> str:
    """Which part of a protected TC frame of n octets octet i is in."""
    if i < 5:
        return "primary-header"
    if i < 6:
        return "segment-header"
    if i < 8:
        return "spi"
    if i < 20:
        return "iv"
    if i < n - 18:
        return "data"
    if i < n - 2:
        return "mac"
    return "fecf"


def bit_flip_expect(frame: bytes, i: int, bit: int, fecf_recomputed: bool) -> str:
    """The check that refuses `frame` with bit `bit` (0 = MSB) of octet i flipped, for an AD frame of SCID 257,
    VC 0, MAP 0, SPI 257."""
    part = region(i, len(frame))
    if part == "primary-header" and 22 <= i * 8 + bit < 32:
        return "length"                        # checked before the FECF: the datagram's size disagrees
    if part == "fecf" or not fecf_recomputed:
        return "fecf"
    if part == "primary-header":
        pos = i * 8 + bit                      # bit position in the 40-bit header
        if pos < 2:
            return "version"
        if pos == 2:
            return "mac"                       # bypass: AD -> BD, the mask covers it
        if pos == 3:
            return "flags"                     # control command with bypass 0
        if pos < 6:
            return "mac"                       # spare bits, covered by the mask
        if pos < 16:
            return "spacecraft-id"
        if pos < 22:
            return "vcid"
        if pos < 32:
            return "length"
        return "mac"                           # N(S)
    if part == "segment-header":
        return "segment-header" if bit < 2 else "mac"
    if part == "spi":
        return "unknown-spi"
    return "mac"                               # IV (the GCM nonce), ciphertext, MAC


def attacks(captured: bytes, *, wrong_key_dir, key_dir=None, earlier=(), spi: int = sdls.tc_spi(1)) -> list[Attack]:
    captured = bytes(captured)
    n = len(captured)
    _, scid, vcid, kind, seq = sdls.parse_tc_header(captured)
    if kind == "BC":
        raise ValueError("a BC frame is in clear: nothing to attack with SDLS")
    iv = int.from_bytes(captured[8:20], "big")
    data_len = n - 6 - sdls.OVERHEAD - 2
    out = [Attack("replay", captured, "replay")]

    for i in range(n):
        for bit in range(8):
            flipped = bytearray(captured)
            flipped[i] ^= 0x80 >> bit
            part = region(i, n)
            if part != "fecf":
                fixed = with_fecf(bytes(flipped))
                out.append(Attack(f"flip-{part}-{i}.{bit}-fecf-recomputed", fixed,
                                  bit_flip_expect(captured, i, bit, True)))
            out.append(Attack(f"flip-{part}-{i}.{bit}-fecf-as-is", bytes(flipped),
                              bit_flip_expect(captured, i, bit, False)))

    wrong = sdls.SecurityAssociation.from_dir(wrong_key_dir, spi, sdls.TC_AUTH_MASK)
    payload = bytes(data_len)          # the attacker's own "command"
    out.append(Attack("wrong-key", sdls.protect_tc(scid, vcid, seq, payload, wrong, iv + 1), "mac"))
    out.append(Attack("wrong-key-same-iv", sdls.protect_tc(scid, vcid, seq, payload, wrong, iv), "mac"))

    ahead = bytearray(captured)
    ahead[8:20] = (iv + FAR).to_bytes(12, "big")
    out.append(Attack("far-ahead-no-key", with_fecf(bytes(ahead)), "mac"))

    unknown = bytearray(captured)
    unknown[6:8] = (0x0199).to_bytes(2, "big")
    out.append(Attack("unknown-spi", with_fecf(bytes(unknown)), "unknown-spi"))

    readdressed = bytearray(captured)
    h = int.from_bytes(readdressed[:5], "big") & ~(0x3FF << 24) | (OTHER_SCID << 24)
    readdressed[:5] = h.to_bytes(5, "big")
    out.append(Attack("other-robot-scid", with_fecf(bytes(readdressed)), "spacecraft-id"))
    other_key = sdls.key_path(wrong_key_dir, sdls.tc_spi(2))
    if other_key.is_file():
        other = sdls.SecurityAssociation.from_dir(wrong_key_dir, sdls.tc_spi(2), sdls.TC_AUTH_MASK)
        out.append(Attack("other-robot-frame", sdls.protect_tc(OTHER_SCID, vcid, seq, payload, other, iv + 1),
                          "spacecraft-id"))
        out.append(Attack("other-robot-spi", sdls.protect_tc(scid, vcid, seq, payload, other, iv + 1),
                          "unknown-spi"))

    for k, old in enumerate(earlier):
        out.append(Attack(f"earlier-{k}", bytes(old), "replay"))

    if key_dir is not None:
        sa = sdls.SecurityAssociation.from_dir(key_dir, spi, sdls.TC_AUTH_MASK)
        _, plaintext = sdls.process_security(captured, sdls.TC_SEC_START, n - 2, sa)
        if iv > 0:
            out.append(Attack("old-counter", sdls.protect_tc(scid, vcid, seq, plaintext, sa, iv - 1), "replay"))
        out.append(Attack("far-ahead-with-key", sdls.protect_tc(scid, vcid, seq, plaintext, sa, iv + FAR), "ahead"))
    return out


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--frame", required=True, help="the captured protected TC frame, hex")
    ap.add_argument("--wrong-keys", required=True, help="a key directory that is not the robot's (spi-257.key, "
                    "optionally spi-258.key)")
    ap.add_argument("--keys", help="the robot's key directory (models a leaked key: old-counter, far-ahead-with-key)")
    ap.add_argument("--earlier", nargs="*", default=[], help="frames captured earlier, hex")
    a = ap.parse_args(argv)
    for x in attacks(bytes.fromhex(a.frame), wrong_key_dir=a.wrong_keys, key_dir=a.keys,
                     earlier=[bytes.fromhex(e) for e in a.earlier]):
        print(json.dumps({"name": x.name, "expect": x.expect, "hex": x.frame.hex()}))
    return 0


if __name__ == "__main__":
    sys.exit(main())
