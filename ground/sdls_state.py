#!/usr/bin/env python3
"""The YAMCS plug-in's SDLS counter state files (ground/yamcs-plugin/: `SdlsCounterState`), and their provisioning.

Each SA of `org.mmic.yamcs.ReprotectingAes256Gcm128Factory` keeps its counter in a file of its own (the link's
`stateFile:`, outside the key directory), in the library's scheme (src/link/sdls/counter.rs): the sender's
*reservation* (every IV it may have used is below it) or the receiver's *floor* (every IV it may have accepted is at
or below it). The SA refuses to start without a usable file; this is the explicit step that writes the first one,
once per new key:

    python3 ground/sdls_state.py provision --spi 257 --role tx --key-file KEYS/spi-257.key --out STATE/spi-257.state
    python3 ground/sdls_state.py provision --spi 513 --role rx --key-file KEYS/spi-513.key --out STATE/spi-513.state
    python3 ground/sdls_state.py show STATE/spi-257.state

A new sender starts at IV 0, a new receiver with "nothing accepted yet" (last IV 2^96 - 1). A key that was used
before (its state file lost) must not start there: `--resume-above N`, N at or above every IV used under it (the
sender then starts at N + 1; the receiver refuses every IV up to N). An existing file is never overwritten.

File (ASCII, five lines): `mmic-yamcs-sdls-state 2`, `spi <n>`, `role tx|rx`, `fingerprint <16 hex>` (which key
the counter belongs to, revealing nothing of it: the library's key check value, `Key256::fingerprint` in
src/link/sdls/key.rs, one scheme in every shell: the first 8 octets of AES-256 under the key of the block
b"mmic-kcv-v1\x01\0\0\0\0"), `value <decimal>`. Version 1 recorded an HMAC as the fingerprint; the plug-in
refuses such a file. Neither the key nor the fingerprint is ever printed.
"""
from __future__ import annotations

import argparse
import os
import sys
from pathlib import Path

MAGIC = "mmic-yamcs-sdls-state 2"
IV_SPACE = 1 << 96
NOTHING_ACCEPTED = IV_SPACE - 1
# The block the fingerprint enciphers (src/link/sdls/key.rs FINGERPRINT_BLOCK): a 12-octet label, a zero counter.
FINGERPRINT_BLOCK = b"mmic-kcv-v1\x01\0\0\0\0"
FINGERPRINT_LEN = 8
KEY_LEN = 32


class StateError(ValueError):
    pass


def fingerprint(key: bytes) -> str:
    """The library's key fingerprint (Key256::fingerprint), hex: AES-256-ECB of FINGERPRINT_BLOCK, first 8 octets."""
    from cryptography.hazmat.primitives.ciphers import Cipher, algorithms, modes

    if len(key) != KEY_LEN:
        raise StateError(f"an AES-256 key is {KEY_LEN} octets, not {len(key)}")
    enc = Cipher(algorithms.AES(key), modes.ECB()).encryptor()
    return (enc.update(FINGERPRINT_BLOCK) + enc.finalize())[:FINGERPRINT_LEN].hex()


def read_key(key_file: str | os.PathLike) -> bytes:
    key = Path(key_file).read_bytes()
    if len(key) != KEY_LEN:
        raise StateError(f"{key_file}: {len(key)} octets, AES-256 needs {KEY_LEN}")
    if len(set(key)) == 1:
        raise StateError(f"{key_file}: a weak key (all octets equal)")
    return key


def render(spi: int, role: str, fp: str, value: int) -> str:
    return f"{MAGIC}\nspi {spi}\nrole {role}\nfingerprint {fp}\nvalue {value}\n"


def first_value(role: str, resume_above: int | None) -> int:
    if role == "tx":
        return 0 if resume_above is None else resume_above + 1
    if role == "rx":
        return NOTHING_ACCEPTED if resume_above is None else resume_above
    raise StateError(f"role {role!r}: tx or rx")


def provision(out: str | os.PathLike, spi: int, role: str, key_file: str | os.PathLike,
              resume_above: int | None = None) -> int:
    """Writes the first state of SA `spi` (created exclusively, mode 0600, forced to disk with its directory);
    returns the value written. Refuses an existing file."""
    if not 0 <= spi < 1 << 16:
        raise StateError(f"SPI {spi} out of range")
    if resume_above is not None and not 0 <= resume_above < IV_SPACE - 1:
        raise StateError(f"--resume-above {resume_above}: 0 .. 2^96 - 2")
    value = first_value(role, resume_above)
    text = render(spi, role, fingerprint(read_key(key_file)), value).encode("ascii")
    out = Path(out)
    if out.parent.resolve() == Path(key_file).parent.resolve():
        raise StateError(f"{out}: not in the key directory (keys restored with old counters would reuse IVs)")
    out.parent.mkdir(parents=True, exist_ok=True)
    try:
        fd = os.open(out, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o600)
    except FileExistsError:
        raise StateError(f"{out} exists: a counter state is never overwritten (it would let IVs be used twice); "
                         "delete it only for a new key") from None
    try:
        os.write(fd, text)
        os.fsync(fd)
    finally:
        os.close(fd)
    d = os.open(out.parent, os.O_RDONLY)
    try:
        os.fsync(d)
    finally:
        os.close(d)
    return value


def read(path: str | os.PathLike) -> dict:
    """{"spi", "role", "value"} of a state file (the fingerprint left out)."""
    lines = Path(path).read_text("ascii").splitlines()
    if len(lines) != 5 or lines[0] != MAGIC:
        raise StateError(f"{path}: not an {MAGIC} file")
    fields = dict(l.split(" ", 1) for l in lines[1:])
    return {"spi": int(fields["spi"]), "role": fields["role"], "value": int(fields["value"])}


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    sub = ap.add_subparsers(dest="cmd", required=True)
    p = sub.add_parser("provision", help="write the first counter state of one SA")
    p.add_argument("--spi", type=int, required=True)
    p.add_argument("--role", choices=("tx", "rx"), required=True,
                   help="tx: the SA YAMCS protects with (TC); rx: the one it verifies with (TM)")
    p.add_argument("--key-file", required=True, help="the SA's key (read for its fingerprint only)")
    p.add_argument("--out", required=True, help="the state file (the link's stateFile), not in the key directory")
    p.add_argument("--resume-above", type=int, default=None,
                   help="this key was used before: N at or above every IV used under it")
    s = sub.add_parser("show", help="print a state file's SPI, role and value")
    s.add_argument("file")
    a = ap.parse_args(argv)
    try:
        if a.cmd == "provision":
            v = provision(a.out, a.spi, a.role, a.key_file, a.resume_above)
            what = "next IV" if a.role == "tx" else "last accepted IV"
            print(f"{a.out}: SPI {a.spi} {a.role}, {what} {v}" + (" (nothing accepted yet)" if v == NOTHING_ACCEPTED else ""))
        else:
            print(read(a.file))
    except (StateError, OSError) as e:
        print(f"sdls_state.py: {e}", file=sys.stderr)
        return 2
    return 0


if __name__ == "__main__":
    sys.exit(main())
