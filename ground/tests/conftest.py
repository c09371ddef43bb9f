"""pytest glue: lets fixtures see whether the test that used them failed (rep_call)."""
import sys
from pathlib import Path

import pytest

sys.path.insert(0, str(Path(__file__).resolve().parent))          # fake_robot
sys.path.insert(0, str(Path(__file__).resolve().parents[1]))      # yamcs_harness, ccsdspy_defs


@pytest.hookimpl(hookwrapper=True)
def pytest_runtest_makereport(item, call):
    outcome = yield
    rep = outcome.get_result()
    setattr(item, "rep_" + rep.when, rep)
