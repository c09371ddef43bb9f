"""pytest glue: paths, the Rust fixtures (one `mmic ground fixtures` run per session), and the
failed-test flag fixtures read (rep_call)."""
import sys
from pathlib import Path

import pytest

sys.path.insert(0, str(Path(__file__).resolve().parent))          # fake_robot
sys.path.insert(0, str(Path(__file__).resolve().parents[1]))      # yamcs_harness, ccsdspy_defs, rust_side

import rust_side  # noqa: E402


@pytest.fixture(scope="session")
def rust_fixtures(tmp_path_factory):
    """The directory `mmic ground fixtures` wrote (tm.jsonl, tc.jsonl, hk.bin, hk.json)."""
    return rust_side.fixtures(tmp_path_factory.mktemp("rust-fixtures"))


@pytest.hookimpl(hookwrapper=True)
def pytest_runtest_makereport(item, call):
    outcome = yield
    rep = outcome.get_result()
    setattr(item, "rep_" + rep.when, rep)
