"""Issue 26, helper R49: a hostile reading of session 48's first merges (P48's salsig and
gridplate shares, U48's Makefile, H48's chunk digests, R48's environment and table checks,
L48's network estimate). Each test names the class of bad input and what was wrong before."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from test_doors37k import run_make, venv_project

import sim
from sim.cli import main
from sim.env_vars import blas_threads_problem
from sim.mc.config import ConfigError
from sim.studies.gridplate.schema import no_fixed_point_share
from sim.studies.picking import load_picking_chunk
from sim.studies.salsig.schema import transfer_share
from tests.oneline import SIM_ERROR, one_line

ROOT = Path(__file__).resolve().parent.parent
STUDIES = ROOT / "studies"


@pytest.mark.parametrize(
    "value, says",
    [
        ("9" * 5000, "OpenBLAS would ignore it"),  # strtol saturates, the cast wraps to -1
        ("0" * 5000 + "3", None),  # atoi reads 3: a whole number of threads
        ("-" + "7" * 4400, "OpenBLAS would ignore it"),
    ],
)
def test_openblas_threads_of_thousands_of_digits_is_one_line(monkeypatch, value, says):
    """An environment variable of thousands of digits (``OPENBLAS_NUM_THREADS=999...9``, a
    script's runaway expansion): Python's ``int`` refuses more than 4,300 digits, and every
    command (``sim check``, ``sim.load``) ended in that ValueError, a traceback, where the
    variable's one line was due. It is read as OpenBLAS's ``atoi`` reads it now."""
    monkeypatch.setenv("OPENBLAS_NUM_THREADS", value)
    got = blas_threads_problem()
    if says is None:
        assert got is None
    else:
        assert got.startswith("OPENBLAS_NUM_THREADS: must be a whole number") and says in got


def test_salsig_transfer_share_of_tiny_sigmas_is_their_ratios():
    """Sigmas within their bounds whose squares underflow (``comparator.sigma_um = 1e-200``,
    ``b8.sigma_um = 1e-200``): the FIG. 2 share divided by ``sqrt(sb**2 + sc**2) = 0``,
    ``sim check`` said "ZeroDivisionError: float division by zero" naming no key, and
    ``sim.load`` raised it. The share depends on the sigmas' ratio alone (the property)."""
    _, base = load_picking_chunk(STUDIES / "salsig_encoders.toml", False)
    for sb_over_sc in (1.0, 8.0, 0.125):
        want = transfer_share({**base, "comparator.sigma_um": 3.0, "b8.sigma_um": 3.0 * sb_over_sc})
        tiny = {"comparator.sigma_um": 1e-200, "b8.sigma_um": 1e-200 * sb_over_sc}
        assert transfer_share({**base, **tiny}) == pytest.approx(want, rel=1e-12)


def test_gridplate_no_fixed_point_share_of_tiny_sigmas_is_their_ratios():
    """The same underflow in gridplate's share (``comparator.coord_sigma_um = 1e-170``,
    ``grid.sigma_true_um = 0``, a stated sigma below it: each within its bounds and past
    the earlier checks): ``sc**2 + sgt**2 = 0``, a ZeroDivisionError at ``sim check``. The
    share depends on the sigmas' ratios alone."""
    _, base = load_picking_chunk(STUDIES / "gridplate_two_plates.toml", False)
    for stated, true in ((1.0, 0.0), (0.9, 0.5)):
        sig = {"comparator.coord_sigma_um": 1.2, "grid.sigma_true_um": true * 1.2}
        want = no_fixed_point_share({**base, **sig, "grid.sigma_stated_um": stated * 1.2})
        tiny = {"comparator.coord_sigma_um": 1e-170, "grid.sigma_true_um": true * 1e-170}
        got = no_fixed_point_share({**base, **tiny, "grid.sigma_stated_um": stated * 1e-170})
        assert np.isfinite(got) and got == pytest.approx(want, rel=1e-9), (stated, got, want)
        assert 0.0 < want < 1.0


def _fake_pytest(d: Path, long_rc: int) -> None:
    """The stand-in Python of :func:`venv_project` answering ``-m pytest``: the fuzz passes,
    and the tests marked long exit ``long_rc`` (5: pytest's "no tests ran", none marked)."""
    fake = d.parent / "python"
    text = fake.read_text(encoding="utf-8")
    cases = f'  *"-m pytest -m long"*) exit {long_rc};;\n  *"-m pytest"*) exit 0;;\n'
    fake.write_text(text.replace('case "$*" in\n', 'case "$*" in\n' + cases), encoding="utf-8")


def test_make_fuzz_passes_when_no_test_is_marked_long(tmp_path):
    """A documented command failing after its work passed: ``make fuzz`` ran the fuzz, then
    ``pytest -m long``, which exits 5 ("no tests ran") when no test is marked long (none was
    when it came): make said "Error 5" and failed. No test marked long passes now; a long
    test that fails still fails make fuzz."""
    d = venv_project(tmp_path, ["numpy>=1"])
    _fake_pytest(d, 5)
    p = run_make(d, "fuzz", "FUZZ_CASES=1")
    assert p.returncode == 0, (p.stdout, p.stderr)
    _fake_pytest(d, 1)
    assert run_make(d, "fuzz", "FUZZ_CASES=1").returncode != 0


def test_make_run_jobs_is_not_a_j_word_of_a_variable_given(tmp_path):
    """Silent nonsense: RUN_JOBS's default (make's -jN) was read from MAKEFLAGS, which holds
    the command line's variables too: ``make reproduce RUN_FLAGS="--workers 1 -j9"`` ran 9
    studies at a time, and with ``make -j4`` too, RUN_JOBS was "4 9", refused as a setting
    the user never gave. make's own -j alone counts now. A legitimate command refused:
    ``make -j$(nproc) reproduce`` on a machine of over 64 cores passed ``--jobs 128``, which
    sim.batch refuses ("must be <= 64", an option the user never gave); it runs 64 now."""
    d = venv_project(tmp_path, ["numpy"])
    for args, jobs in (([], "2"), (["-j4"], "4"), (["-j128"], "64")):
        p = run_make(d, "-n", *args, "reproduce", "RUN_FLAGS=--workers 1 -j9")
        assert f"-m sim.batch --stale-only --report --jobs {jobs} " in p.stdout, (args, p)


def test_set_value_of_thousands_of_digits_names_the_key(capsys):
    """An override of over 4,300 digits (``--set trials=999...9``, ``--set 'x=[1, 999...9]'``):
    Python's int-from-text limit inside the TOML reader was "sim: error: ValueError: Exceeds
    the limit (4300 digits) for integer string conversion ..." naming no key (a study file's
    was named; ``sim.load_study``'s overrides raised it raw). The key is named now."""
    big = "9" * 5000
    for value in (big, f"[1, {big}]"):
        argv = ["check", str(STUDIES / "brown_table1.toml"), "--set", f"trials={value}"]
        line = one_line(capsys, main(argv), prefix=SIM_ERROR + "trials: ")
        assert "integer of over 4300 digits" in line, line
    with pytest.raises(ConfigError, match="integer of over 4300 digits"):
        sim.load_study(STUDIES / "brown_table1.toml", overrides=[f"trials={big}"])
