#!/usr/bin/env python3
"""Minimal reproduction: a COP-1 retransmission under SDLS in YAMCS 5.12.8 (ground/README.md, "SDLS and
COP-1 retransmissions").

YAMCS (`Yamcs(link="frames-sdls", cop1_t1=1)`, random throwaway keys) and a Python stand-in robot
(sdls_standin.py: SDLS by ground/sdls.py, a minimal FARM-1, protected TM frames with the CLCW). The
stand-in drops the first transmission of the first AD frame; YAMCS's timer T1 runs out and it sends the
frame again. The script verifies every transmission of that frame with the TC key and reports, for
each, its IV, whether the MAC verifies, and whether the plaintext is the packet YAMCS sent (its
command-history `binary`) or the previous transmission's ciphertext.

    target/ground-venv/bin/python ground/repro_cop1_sdls.py              # YAMCS's own SA
    target/ground-venv/bin/python ground/repro_cop1_sdls.py --reprotect  # with ground/yamcs-plugin/

Prints one JSON object; exit status 0 when every transmission carried the packet, 1 when not, 2 when the
experiment could not run (no retransmission seen, COP-1 not active). Frames and packets are printed in
hex; keys never.
"""
from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))

import sdls  # noqa: E402
from rust_side import wait  # noqa: E402
from sdls_standin import StandIn  # noqa: E402
from yamcs_harness import DEFAULT_MDB, INSTANCE, Yamcs  # noqa: E402

TC_LINK = "tc-frames.vc0"




def first_ad_dropper():
    """Drops the first transmission of the first AD frame, nothing else."""
    state = {"done": False}

    def drop(_index: int, raw: bytes) -> bool:
        if state["done"] or len(raw) < 5 or raw[0] & 0x30:     # bypass or control flag: not AD
            return False
        state["done"] = True
        return True
    return drop


def settled(status) -> bool:
    """COP-1 has sent something and FARM-1 acknowledged all of it: nothing waiting, nothing unacknowledged."""
    p = status._proto          # yamcs-client 2.1.0 does not expose the queue sizes as properties
    return bool(status.v_s) and status.nn_r == status.v_s and not p.waitQueueNumTC and not p.sentQueueNumFrames


def binary_of(cmd, seconds: float = 5.0) -> bytes | None:
    """The packet YAMCS sent: `binary` once the postprocessor filled the sequence count (see README)."""
    def get():
        b = cmd.attributes.get("binary")
        seq = cmd.attributes.get("ccsds-seqcount")
        if b and seq is not None and int.from_bytes(b[2:4], "big") & 0x3FFF == seq:
            return b
        return None
    return wait(get, seconds)


def run(reprotect: bool, mdb=DEFAULT_MDB, t1: float = 1.0, extra_seconds: float = 1.5, commands: int = 1) -> dict:
    """`commands` are issued back to back, in AD frames N(S) 0 .. k-1 (1 <= k <= commands: YAMCS may put several
    queued commands into one frame): the first transmission of N(S) 0 is dropped, the others arrive ahead of
    V(R) and FARM-1 discards them, so T1 makes YAMCS send them all again (go-back-N)."""
    y = Yamcs(mdb, link="frames-sdls", cop1_t1=t1, sdls_plugin=reprotect, max_lifetime=120)
    y.start()
    try:
        with StandIn(y.tm_port, y.tc_port, str(y.sdls_key_dir), drop=first_ad_dropper()) as robot:
            link = y.client.get_link(INSTANCE, TC_LINK)
            if not wait(lambda: link.get_cop1_status().state == "ACTIVE", 8):
                link.initialize_cop1("WITH_CLCW_CHECK", clcw_wait_timeout=5)
                if not wait(lambda: link.get_cop1_status().state == "ACTIVE", 8):
                    return {"error": f"COP-1 not ACTIVE: {link.get_cop1_status().state}"}
            conn = y.client.get_processor(INSTANCE, "realtime").create_command_connection()
            cmds = [conn.issue("/MMIC/are_you_alive") for _ in range(commands)]
            packets = [binary_of(c) for c in cmds]
            # the dropped first transmission, then T1 (t1 s), then the retransmissions, then FARM-1's CLCW
            wait(lambda: settled(link.get_cop1_status()), 6 * t1 + 5)
            time.sleep(extra_seconds)   # further retransmissions, if any
            cop1 = link.get_cop1_status()
            records = list(robot.tc)
        return analyse(records, packets, y.sdls_key_dir and sdls.SecurityAssociation.from_dir(
            y.sdls_key_dir, sdls.tc_spi(1), sdls.TC_AUTH_MASK), cop1, reprotect, t1)
    finally:
        y.stop()


def split_packets(data: bytes) -> list[bytes] | None:
    """`data` cut into CCSDS space packets by their length fields, or None when it is not a whole number of
    packets. YAMCS puts commands queued at the same time into one TC frame, so a frame may carry several."""
    out = []
    while data:
        if len(data) < 6 or len(data) < 7 + int.from_bytes(data[4:6], "big"):
            return None
        n = 7 + int.from_bytes(data[4:6], "big")
        out.append(data[:n])
        data = data[n:]
    return out or None


def carried(plain: bytes, packets: list) -> list[int] | None:
    """Indices of the packets YAMCS sent that `plain` is, in order, or None when it is anything else."""
    parts = split_packets(plain)
    if parts is None:
        return None
    idx = [next((i for i, p in enumerate(packets) if p == part), None) for part in parts]
    return None if None in idx or idx != list(range(idx[0], idx[0] + len(idx))) else idx


def analyse(records, packets: list, sa: sdls.SecurityAssociation, cop1, reprotect: bool, t1: float) -> dict:
    """Per TC datagram: kind, N(S), IV, MAC, plaintext; for an AD frame, which of the packets YAMCS sent it
    carries (`carries`; `plaintext_is_packet` when it carries at least one and nothing else) and whether its
    plaintext is the ciphertext of the previous transmission of the same N(S)."""
    out = {"reprotect": reprotect, "cop1T1_s": t1, "packets_sent_by_yamcs": [p.hex() if p else None for p in packets],
           "transmissions": [], "cop1_end": {"state": cop1.state, "v_s": cop1.v_s, "nn_r": cop1.nn_r}}
    prev_cipher = {}
    t0 = records[0].t if records else 0
    for r in records:
        raw = r.raw
        kind = {0: "AD", 2: "BD", 3: "BC"}[(raw[0] >> 4) & 3]
        entry = {"t_s": round(r.t - t0, 3), "kind": kind, "ns": raw[4], "len": len(raw), "dropped": r.dropped,
                 "verdict": r.verdict, "hex": raw.hex()}
        if kind != "BC":
            entry["spi"] = int.from_bytes(raw[6:8], "big")
            entry["iv"] = int.from_bytes(raw[8:20], "big")
            cipher = raw[20:-18]
            try:
                _, plain = sdls.process_security(raw, sdls.TC_SEC_START, len(raw) - 2, sa)
                entry["mac"] = "ok"
                entry["plaintext"] = plain.hex()
                entry["carries"] = carried(plain, packets)
                entry["plaintext_is_packet"] = entry["carries"] is not None
                entry["plaintext_is_previous_ciphertext"] = plain == prev_cipher.get((kind, raw[4]))
            except sdls.SdlsError as e:
                entry["mac"] = e.check
            prev_cipher[(kind, raw[4])] = cipher
        out["transmissions"].append(entry)
    ads = [e for e in out["transmissions"] if e["kind"] == "AD"]
    seen = set()
    first = []
    for e in ads:                           # the first transmissions: up to the first N(S) sent again
        if e["ns"] in seen:
            break
        seen.add(e["ns"])
        first.append(e)
    out["ad_transmissions"] = len(ads)
    out["ad_frames"] = len(first)
    out["retransmitted"] = len(ads) > len(first)
    out["first_transmissions_carry"] = [i for e in first for i in (e.get("carries") or [None])]
    out["farm_accepted"] = [e["ns"] for e in out["transmissions"] if e["verdict"] == "accept"]
    out["all_carry_the_packet"] = bool(ads) and all(e.get("plaintext_is_packet") for e in ads)
    return out


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--reprotect", action="store_true", help="use the plug-in's re-protecting SA (ground/yamcs-plugin/)")
    ap.add_argument("--t1", type=float, default=1.0, help="COP-1 timer T1 in seconds (default 1)")
    ap.add_argument("--commands", type=int, default=1, help="commands issued back to back (default 1)")
    a = ap.parse_args(argv)
    res = run(a.reprotect, t1=a.t1, commands=a.commands)
    print(json.dumps(res, indent=1))
    if "error" in res or not res["retransmitted"]:
        return 2
    return 0 if res["all_carry_the_packet"] else 1


if __name__ == "__main__":
    sys.exit(main())
