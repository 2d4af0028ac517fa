"""A whole study with ``SIM_NO_JIT=1`` (every compiled kernel off: the NumPy paths of
:mod:`sim.lsq.compile`'s callers) equals its compiled run within ``make verify``'s tolerance
(:func:`sim.report.verify.compare_dirs`: every numeric cell within its column's tolerance, the
same missing values, the same verdicts). One study per family of compiled kernels, at the
test suite's tiny size: ``brown_table1`` (the Brown multilateration kernel), ``wolf_polynomial``
(the polynomial fit, the shared-design solve, the stress field) and ``agnard_block`` (the
group-block reductions and solves)."""

import os
import subprocess
import sys
from pathlib import Path

import pytest

from sim.lsq import compile
from sim.report.verify import compare_dirs

ROOT = Path(__file__).resolve().parent.parent
TINY = ROOT / "tests" / "data" / "tiny"


def _run(study: str, out: Path, no_jit: bool) -> None:
    lines = [ln.strip() for ln in (TINY / f"{study}.txt").read_text().splitlines()]
    sets = [a for ln in lines if ln and not ln.startswith("#") for a in ("--set", ln)]
    env = {k: v for k, v in os.environ.items() if k != "SIM_NO_JIT"}
    if no_jit:
        env["SIM_NO_JIT"] = "1"
    cmd = [sys.executable, "-m", "sim", "run", str(ROOT / "studies" / f"{study}.toml")]
    cmd += ["--out", str(out), "--quiet", "--workers", "1", *sets]
    done = subprocess.run(cmd, env=env, capture_output=True, text=True)
    assert done.returncode == 0, done.stderr


@pytest.mark.skipif(not compile.available(), reason="numba not installed")
@pytest.mark.parametrize("study", ["brown_table1", "wolf_polynomial", "agnard_block"])
def test_study_without_jit_equals_the_compiled_run(study, tmp_path):
    _run(study, tmp_path / "compiled", no_jit=False)
    _run(study, tmp_path / "numpy", no_jit=True)
    cmp = compare_dirs(tmp_path / "compiled", tmp_path / "numpy", study)
    assert cmp.files > 0
    assert cmp.ok, cmp.failures[:5]
