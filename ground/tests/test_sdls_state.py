"""The YAMCS plug-in's durable SDLS counters without YAMCS: the SA exactly as a link makes it (its factory), one
`java` process per start of the SA (ground/yamcs-plugin/ SdlsCounterTool), killed with SIGKILL for a crash; every
frame checked with the independent ground/sdls.py.

- provisioning (ground/sdls_state.py): the first states, never an overwrite, never in the key directory;
- one key fingerprint in every shell: the library's (`mmic sdls provision` writes it into the robot's state file),
  sdls_state.py's and the plug-in's agree (the plug-in opens a state sdls_state.py provisioned) for the same keys;
- fail closed: a missing, malformed, other SPI's, other key's state, a state in the key directory, a receiver
  without `verifySeqNum`, a sender's state on a receiver: the SA does not start, and says which file and how to
  provision it;
- the sender (TC): IVs continue above the stored reservation after every restart, SIGKILLs at random instants
  included, never an IV twice;
- the receiver (TM): the first frame is window-checked (unlike YAMCS's own SA); after a restart every frame
  accepted before is a replay, SIGKILL included; fresh frames are accepted.
"""
from __future__ import annotations

import os
import random
import signal
import subprocess
import time
from pathlib import Path

import pytest
import sdls
import sdls_state
from yamcs_harness import PLUGIN_JAR, yamcs_classpath

TC, TM = sdls.tc_spi(1), sdls.tm_spi(1)
TC_BLOCK, TM_BLOCK, TM_WINDOW = 64, 16, 100000
pytestmark = pytest.mark.skipif(not PLUGIN_JAR.is_file(), reason="run ground/setup: it builds ground/yamcs-plugin/")


def tool(*args: str) -> list[str]:
    return ["java", "-cp", f"{yamcs_classpath()}:{PLUGIN_JAR}", "org.mmic.yamcs.SdlsCounterTool", *args]


@pytest.fixture
def sa(tmp_path):
    keys, state = tmp_path / "keys", tmp_path / "state"
    sdls.write_random_keys(keys, (TC, TM))
    sdls_state.provision(state / f"spi-{TC}.state", TC, "tx", sdls.key_path(keys, TC))
    sdls_state.provision(state / f"spi-{TM}.state", TM, "rx", sdls.key_path(keys, TM))
    return keys, state


def open_sa(keys, state_file, spi, rx=False) -> str:
    out = subprocess.run(tool("open", str(sdls.key_path(keys, spi)), str(state_file), str(spi),
                              *(["rx"] if rx else [])), capture_output=True, text=True, timeout=30)
    assert out.returncode == 0, out.stderr
    return out.stdout.strip()


def tc_ivs(keys, lines) -> list[int]:
    """Each frame verified with sdls.py (the plan's mask, the key): its IV."""
    sa = sdls.SecurityAssociation.from_dir(keys, TC, sdls.TC_AUTH_MASK)
    ivs = []
    for line in lines:
        raw = bytes.fromhex(line)
        iv, data = sdls.process_security(raw, sdls.TC_SEC_START, len(raw) - 2, sa)
        assert len(data) == 4
        ivs.append(iv)
    return ivs


def test_provisioning_writes_the_first_states_once_and_apart_from_the_keys(sa, tmp_path):
    keys, state = sa
    assert sdls_state.read(state / f"spi-{TC}.state") == {"spi": TC, "role": "tx", "value": 0}
    assert sdls_state.read(state / f"spi-{TM}.state") == {"spi": TM, "role": "rx", "value": 2**96 - 1}
    assert (state / f"spi-{TC}.state").stat().st_mode & 0o777 == 0o600
    with pytest.raises(sdls_state.StateError, match="never overwritten"):
        sdls_state.provision(state / f"spi-{TC}.state", TC, "tx", sdls.key_path(keys, TC))
    with pytest.raises(sdls_state.StateError, match="not in the key directory"):
        sdls_state.provision(keys / "x.state", TC, "tx", sdls.key_path(keys, TC))
    weak = tmp_path / "weak" / "k.key"
    weak.parent.mkdir()
    weak.write_bytes(bytes(32))
    with pytest.raises(sdls_state.StateError, match="weak"):
        sdls_state.provision(tmp_path / "w.state", TC, "tx", weak)
    assert sdls_state.provision(tmp_path / "r.state", TC, "tx", sdls.key_path(keys, TC), resume_above=1000) == 1001
    assert sdls_state.provision(tmp_path / "s.state", TM, "rx", sdls.key_path(keys, TM), resume_above=1000) == 1000
    # the CLI prints no key and no fingerprint
    out = subprocess.run(["python3", str(Path(sdls_state.__file__)), "show", str(state / f"spi-{TC}.state")],
                         capture_output=True, text=True, timeout=30)
    assert out.returncode == 0 and "fingerprint" not in out.stdout, out


def test_one_key_fingerprint_in_every_shell(tmp_path):
    """The library's key check value (Key256::fingerprint: AES-256 of FINGERPRINT_BLOCK, first 8 octets), as
    `mmic sdls provision` records it (entries 0x1000 | SPI of both ends), equals sdls_state.py's; the plug-in takes a
    state sdls_state.py provisioned for the key and refuses it for another key (so its fingerprint is the same
    function). Random keys, never printed; the fingerprints compared, not shown."""
    import json

    from rust_side import mmic

    for run in range(3):
        keys = tmp_path / f"keys{run}"
        sdls.write_random_keys(keys, (TC, TM))
        robot_state = tmp_path / f"robot{run}.state"
        mmic("sdls", "provision", "--keys", str(keys), "--state", str(robot_state))
        doc = json.loads(robot_state.read_text())
        for spi in (TC, TM):
            key = sdls.key_path(keys, spi).read_bytes()
            ours = sdls_state.fingerprint(key)
            for end in ("server", "ground"):
                lib = [e for e in doc[end] if int(e["key"], 16) == 0x1000 | spi]
                assert len(lib) == 1 and int(lib[0]["value"], 16) == int(ours, 16), (end, spi)
            role = "tx" if spi == TC else "rx"
            f = tmp_path / f"yamcs{run}" / f"spi-{spi}.state"
            sdls_state.provision(f, spi, role, sdls.key_path(keys, spi))
            assert open_sa(keys, f, spi, rx=spi == TM) == "ok"
            other = tmp_path / f"other{run}"
            sdls.write_random_keys(other, (spi,))
            msg = open_sa(other, f, spi, rx=spi == TM)
            assert msg.startswith("refused: ") and "another key" in msg, msg


def test_the_sa_does_not_start_without_a_usable_state(sa, tmp_path):
    keys, state = sa
    tc_state = state / f"spi-{TC}.state"
    good = tc_state.read_text()
    other_keys = tmp_path / "other-keys"
    sdls.write_random_keys(other_keys, (TC,))
    cases = {
        "missing": (state / "none.state", "does not exist"),
        "other SPI": (state / f"spi-{TM}.state", "it is the state of SPI 513"),
        "garbage": (tmp_path / "garbage.state", "not an mmic-yamcs-sdls-state 2 file"),
        "version 1 (HMAC fingerprint)": (tmp_path / "v1.state", "a version-1 file"),
        "value out of range": (tmp_path / "big.state", "out of the 96-bit counter's range"),
        "in the key directory": (keys / "spi-257.state", "is in the key directory"),
    }
    (tmp_path / "garbage.state").write_text("0\n")
    (tmp_path / "v1.state").write_text(good.replace("mmic-yamcs-sdls-state 2", "mmic-yamcs-sdls-state 1"))
    (tmp_path / "big.state").write_text(good.replace("value 0", f"value {2**97}"))
    (keys / "spi-257.state").write_text(good)
    seen = {}
    for name, (path, why) in cases.items():
        msg = open_sa(keys, path, TC)
        seen[name] = msg
        assert msg.startswith("refused: ") and why in msg and str(path) in msg, (name, msg)
        if name != "in the key directory":
            assert "sdls_state.py provision" in msg, msg
    # another key's state (the same file, the SA now under another key)
    msg = open_sa(other_keys, tc_state, TC)
    assert msg.startswith("refused: ") and "another key" in msg and str(tc_state) in msg, msg
    # a receiver that would not check the window
    msg = open_sa(keys, state / f"spi-{TM}.state", TM, rx=False)
    assert msg.startswith("refused: ") and "verifySeqNum: true" in msg, msg
    # a sender's state where a receiver's is expected (the files swapped)
    msg = open_sa(keys, tc_state, TC, rx=True)
    assert msg.startswith("refused: ") and "--role rx" in msg, msg
    assert open_sa(keys, tc_state, TC) == "ok" and open_sa(keys, state / f"spi-{TM}.state", TM, rx=True) == "ok"
    print("\n" + "\n".join(f"{k}: {v[:160]}" for k, v in seen.items()))


def test_the_sender_continues_above_its_reservation_after_restarts_and_sigkills(sa):
    keys, state = sa
    f = state / f"spi-{TC}.state"
    rng = random.Random(38)
    runs: list[list[int]] = []
    stored_before: list[int] = []
    # two clean runs, then SIGKILLs at random instants (some within the first reservation's write)
    for n in (5, 70):
        stored_before.append(sdls_state.read(f)["value"])
        out = subprocess.run(tool("tx", str(sdls.key_path(keys, TC)), str(f), str(TC), str(TC_BLOCK), str(n)),
                             capture_output=True, text=True, timeout=30)
        assert out.returncode == 0, out.stderr
        runs.append(tc_ivs(keys, out.stdout.split()))
    for _ in range(6):
        stored_before.append(sdls_state.read(f)["value"])
        p = subprocess.Popen(tool("tx", str(sdls.key_path(keys, TC)), str(f), str(TC), str(TC_BLOCK), "100000000"),
                             stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, text=True, start_new_session=True)
        lines = []
        want = rng.choice((0, 1, rng.randrange(2, 400)))
        while len(lines) < want:
            lines.append(p.stdout.readline().strip())
        time.sleep(rng.random() * 0.002)
        os.killpg(p.pid, signal.SIGKILL)
        p.wait(10)
        lines += p.stdout.read().split()                    # printed before the kill
        runs.append(tc_ivs(keys, [l for l in lines if len(l) == 2 * 42]))
        sdls_state.read(f)                                   # never torn
    every = [iv for r in runs for iv in r]
    assert len(every) == len(set(every)), "an IV was used twice"
    assert runs[0] == list(range(5)) and runs[1][0] == TC_BLOCK
    for i, r in enumerate(runs):
        assert r == list(range(r[0], r[0] + len(r))) if r else True   # consecutive within a run
        if r:
            assert r[0] == stored_before[i], (i, r[0], stored_before[i])      # from the stored reservation
            assert all(r[0] > iv for prev in runs[:i] for iv in prev)        # above every IV before
    print(f"\nTC IVs per start (6 of them SIGKILLed): {[(r[0], r[-1]) if r else None for r in runs]}; "
          f"stored reservations at each start: {stored_before}; {len(every)} IVs, none twice")


def tm_frames(keys, ivs) -> list[bytes]:
    sa = sdls.SecurityAssociation.from_dir(keys, TM, sdls.TM_AUTH_MASK)
    return [sdls.protect_tm(0x101, 0, iv & 0xFF, iv & 0xFF, 0x7FE, bytes(sdls.TM_DATA_LEN),
                            bytes([1, 0, 0, 0]), sa, iv) for iv in ivs]


def rx(keys, f, frames) -> list[tuple[str, int]]:
    out = subprocess.run(tool("rx", str(sdls.key_path(keys, TM)), str(f), str(TM), str(TM_BLOCK), str(TM_WINDOW)),
                         input="\n".join(fr.hex() for fr in frames) + "\n", capture_output=True, text=True,
                         timeout=30)
    assert out.returncode == 0, out.stderr
    return [(l.split()[0], int(l.split()[1])) for l in out.stdout.splitlines()]


def test_the_receiver_refuses_after_a_restart_every_frame_it_accepted_before(sa):
    keys, state = sa
    f = state / f"spi-{TM}.state"
    # the first frame is window-checked: an IV far from "nothing accepted" is refused, IV 0.. taken
    got = rx(keys, f, tm_frames(keys, [5_000_000, *range(30)]))
    assert [s for s, _ in got] == ["AntiReplaySequenceNumberFailure"] + ["NoFailure"] * 30, got
    assert got[-1][1] == 29
    floor = sdls_state.read(f)["value"]
    assert floor == 17 + TM_BLOCK        # written at IV 0 (16), then at IV 17, the first beyond it
    # restart: every frame accepted before (0..29) is a replay; so are the unseen ones up to the floor (the
    # cost of the reservation: at most TM_BLOCK); above it, taken
    got = rx(keys, f, tm_frames(keys, [0, 29, *range(30, floor + 1), floor + 1, floor + 2]))
    assert [s for s, _ in got] == ["AntiReplaySequenceNumberFailure"] * (floor - 29 + 2) + ["NoFailure"] * 2, got
    # a SIGKILL at a random instant while frames come in: afterwards, every frame accepted is refused
    start = sdls_state.read(f)["value"] + 1      # the stored floor after the run above: the next start's last
    frames = tm_frames(keys, range(start, start + 200))
    p = subprocess.Popen(tool("rx", str(sdls.key_path(keys, TM)), str(f), str(TM), str(TM_BLOCK), str(TM_WINDOW)),
                         stdin=subprocess.PIPE, stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, text=True,
                         start_new_session=True)
    for fr in frames[:200]:
        p.stdin.write(fr.hex() + "\n")
    p.stdin.flush()
    accepted = 0
    while accepted < 150:
        s, last = p.stdout.readline().split()
        assert s == "NoFailure"
        accepted += 1
    os.killpg(p.pid, signal.SIGKILL)
    p.wait(10)
    for stream in (p.stdin, p.stdout):
        try:
            stream.close()
        except OSError:
            pass
    # at least the 150 read back were accepted, up to 200 may have been: each is at or below the stored floor,
    # and every frame there is now refused
    floor = sdls_state.read(f)["value"]
    assert floor >= start + 149
    replays = [fr for iv, fr in zip(range(start, start + 200), frames) if iv <= floor]
    got = rx(keys, f, replays + tm_frames(keys, [floor + 1]))
    assert all(s == "AntiReplaySequenceNumberFailure" for s, _ in got[:-1]), got
    assert got[-1] == ("NoFailure", floor + 1)
    print(f"\nTM: killed after at least 150 frames accepted (IVs from {start}); the stored floor {floor}; the "
          f"{len(replays)} frames sent at or below it all refused after the restart, IV {floor + 1} accepted")
