"""Doors sweep 32e: the environment of a run (make variables on the command line).

* a documented setting of the Makefile spelt without its underscore, with a hyphen, or in
  lower case (``make verify VERIFYFLAGS="--study brown_table1"`` re-ran every study,
  ``make test TESTWORKERS=0`` ran the tests on 2 processes, ``make fuzz FUZZCASES=5`` fuzzed
  300 cases): dropped without a word. Now one line naming the variable and the spelling it
  should have, exit 2, before any command runs; the right spelling is still read, and such a
  name set in the environment is left alone.
"""

from __future__ import annotations

import pytest
from test_doors18c import MAKE, fake_project, run_make

pytestmark = pytest.mark.skipif(MAKE is None, reason="no make on this machine")


def _fake(tmp_path):
    log, fake = tmp_path / "calls.log", tmp_path / "python"
    fake.write_text(f'#!/bin/sh\necho "$*" >> {log}\n', encoding="utf-8")
    fake.chmod(0o755)
    return log, fake_project(tmp_path, str(fake))


@pytest.mark.parametrize(
    "target, setting, meant",
    [
        ("verify", "VERIFYFLAGS=--study brown_table1", "VERIFY_FLAGS"),
        ("reproduce", "RUNFLAGS=--trials 40", "RUN_FLAGS"),
        ("reproduce", "run-flags=--seed 7", "RUN_FLAGS"),
        ("reproduce", "RUNJOBS=1", "RUN_JOBS"),
        ("test", "TESTWORKERS=0", "TEST_WORKERS"),
        ("fuzz", "FUZZCASES=5", "FUZZ_CASES"),
        ("fuzz", "fuzzseed=3", "FUZZ_SEED"),
        ("bench", "BENCHOUT=/tmp/x", "BENCH_OUT"),
        ("mutation", "MUTATION-WORKERS=1", "MUTATION_WORKERS"),
    ],
)
def test_a_setting_spelt_without_its_underscore_is_named(tmp_path, target, setting, meant):
    log, d = _fake(tmp_path)
    p = run_make(d, target, setting)
    err = p.stderr.removesuffix("\n")
    name = setting.split("=")[0]
    assert p.returncode == 2 and "\n" not in err, p.stderr
    assert f"{name} is not a setting of this Makefile; {meant}=" in err, err
    assert not log.exists()  # nothing ran


def test_the_right_spelling_is_read_and_the_environment_left_alone(tmp_path, monkeypatch):
    log, d = _fake(tmp_path)
    monkeypatch.setenv("RUNFLAGS", "x")  # some other tool's variable, not meant for make
    p = run_make(d, "verify", "VERIFY_FLAGS=--study brown_table1")
    assert p.returncode == 0, p.stderr
    assert "--study brown_table1" in log.read_text()
