"""The classes of the review R39 (a deeper reading of session 38's merges), one case each;
each failed on the code before its fix.

* a network whose points differ in precision by more than 1e7 in sigma (a point measured at
  0.1 um from two fixed points beside one placed to 1 m): P38's noise floor of the datum
  (a point's variance below 1e-14 of the largest is rounding noise, held by the datum) took the
  precise point for held. The run ended with exit 0, the point missing from ``points.parquet``
  and its README.md saying it was "held in part by the datum constraints" of a fixed datum of
  0 constraints. A variance is noise only where it is also far below what the point's own
  observations give it (``1 / N_ii``).
* ``NUMBA_DISABLE_JIT=1``, a value numba reads (docs/cli.md: "like ``SIM_NO_JIT=1``"): numba's
  ``njit`` then hands back the kernel itself, so :func:`sim.lsq.compile.available` said the
  compiled kernels ran while their plain-Python loops did, slower than the NumPy twins and with
  a third set of last digits (``brown_table1``'s claims equal neither the compiled run's nor
  ``SIM_NO_JIT=1``'s), recorded as the compiled path (no word in ``numerics``). The NumPy twins
  run, as under ``SIM_NO_JIT=1`` (the same tables), and ``numerics`` records the variable.
* a ``ulimit -d`` (or ``-v``) under the 1 GiB the commands refuse as they start (session 37):
  ``sim.load`` took it, and a run of ``brown_table1`` at 40 trials failed in its middle,
  "StudyError: ... MemoryError: Unable to allocate 3.65 MiB ... (reduce trials, chunk or the
  sizes in the study file)", advice that cannot help. ``sim.load`` refuses it in the
  commands' words (``sim.ConfigError``).
* a key typed in another unit through the doors beside ``--set`` (session 38 made
  ``--set plate.spacing_um=45000`` say "its value is in mm, not um: convert it"): a sweep's
  ``plate.spacing_um = [...]`` and a network record's ``sigma_um = 1.2`` were still only
  "did you mean ...spacing_mm / sigma_mm?", and the value renamed as it stood was a spacing
  or a sigma 1000 times the one meant. Both say the unit to convert to.
* ``sim.cli.main([...])`` called from Python (docs/python.md: it "runs in any thread" and
  returns its exit code): the checks of the environment ran only in the ``sim`` command's entry
  point, so ``SIM_NO_JIT=0`` ran a study with the compiled kernels off, exit 0 (the command
  refuses it), and so did a ``NUMBA_`` value numba cannot read or a ``ulimit -d`` under 1 GiB.
  ``main`` refuses them in the command's words, exit 2.
* a run the room check of ``ulimit -v`` let through (its estimate leaves out the libraries
  loaded later and the allocator's slack: ``brown_table1`` on a 100 x 100 plate, 1,200 trials
  in chunks of 60, estimated at 0.814 GiB beside the 0.885 GiB left under ``ulimit -v
  1400000``) failed after 78 s, "MemoryError: Unable to allocate 64.1 MiB ... (reduce trials,
  chunk or the sizes in the study file)", naming no limit. A run out of memory under a
  ``ulimit -v`` or ``-d`` names it first: "(ulimit -v is 1400000 kB: raise it, or reduce ...)".
"""

from __future__ import annotations

import os
import resource
import subprocess
import sys
from pathlib import Path

import pyarrow.parquet as pq
import pytest

import sim

ROOT = Path(__file__).resolve().parents[1]
TABLE1 = str(ROOT / "studies" / "brown_table1.toml")

SPREAD = """\
study = "network"
trials = 40
chunk = 2
seed = 1

[network]
name = "spread"
points = [
  { name = "A", x_mm = 0.0, y_mm = 0.0, role = "fixed" },
  { name = "B", x_mm = 1000.0, y_mm = 0.0, role = "fixed" },
  { name = "C", x_mm = 10.0, y_mm = 10.0 },
  { name = "D", x_mm = 500.0, y_mm = 500.0 },
]
generate = [
  { kind = "dx", from = "A", to = "C", sigma_mm = 0.0001 },
  { kind = "dy", from = "A", to = "C", sigma_mm = 0.0001 },
  { kind = "dx", from = "B", to = "C", sigma_mm = 0.0001 },
  { kind = "dy", from = "B", to = "C", sigma_mm = 0.0001 },
  { kind = "dx", from = "A", to = "D", sigma_mm = 1000.0 },
  { kind = "dy", from = "A", to = "D", sigma_mm = 1000.0 },
  { kind = "dx", from = "B", to = "D", sigma_mm = 1000.0 },
  { kind = "dy", from = "B", to = "D", sigma_mm = 1000.0 },
]

[datum]
kind = "fixed"
"""


def test_a_precise_point_beside_a_loose_one_is_estimated(tmp_path):
    f = tmp_path / "spread.toml"
    f.write_text(SPREAD, encoding="utf-8")
    res = sim.load(f).run(out=tmp_path / "out", figures=False)
    points = pq.read_table(Path(res.path) / "points.parquet")
    assert points.column("point").to_pylist() == ["C", "D"]
    sx = dict(zip(points.column("point").to_pylist(), points.column("sigma_x_mm").to_pylist()))
    assert abs(sx["C"] - 0.0001 / 2**0.5) < 1e-9, sx  # two readings of 0.1 um each
    assert "held in part" not in (Path(res.path) / "README.md").read_text(encoding="utf-8")


def test_numba_disable_jit_runs_the_numpy_paths_and_is_recorded():
    code = (
        "from sim.lsq import compile; from sim.mc.storage import numerics; "
        "print(compile.available(), numerics().get('NUMBA_DISABLE_JIT'))"
    )
    env = {**os.environ, "NUMBA_DISABLE_JIT": "1"}
    env.pop("SIM_NO_JIT", None)
    proc = subprocess.run(
        [sys.executable, "-c", code], env=env, capture_output=True, text=True, timeout=120
    )
    assert proc.returncode == 0, proc.stderr
    assert proc.stdout.split() == ["False", "1"], proc.stdout  # the NumPy twins, recorded


@pytest.mark.parametrize(
    "limit, kb, words",
    [
        (resource.RLIMIT_DATA, 460_000, "ulimit -d is 460000 kB"),
        (resource.RLIMIT_AS, 900_000, "ulimit -v is 900000 kB"),
    ],
)
def test_sim_load_refuses_a_memory_limit_the_commands_refuse(limit, kb, words):
    hard = resource.getrlimit(limit)[1]
    if hard != resource.RLIM_INFINITY and hard < kb * 1024:
        pytest.skip("the hard limit is lower than the test's")
    code = (
        "import sim\n"
        "try:\n"
        f"    sim.load({TABLE1!r}, trials=40)\n"
        "except sim.ConfigError as e:\n"
        "    print('refused:', e)\n"
    )
    proc = subprocess.run(
        [sys.executable, "-c", code],
        preexec_fn=lambda: resource.setrlimit(limit, (kb * 1024, hard)),
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert proc.returncode == 0, proc.stderr[-500:]
    assert proc.stdout.startswith("refused: not enough memory: " + words), proc.stdout


def test_a_key_in_another_unit_says_to_convert_through_every_door(tmp_path):
    text = Path(TABLE1).read_text(encoding="utf-8")
    swept = tmp_path / "swept.toml"
    swept.write_text(text + "\n[sweep]\nplate.spacing_um = [45000, 50000]\n", encoding="utf-8")
    plate = (ROOT / "studies" / "network_plate.toml").read_text(encoding="utf-8")
    net = tmp_path / "net_um.toml"
    net.write_text(plate.replace("sigma_mm = 0.0012", "sigma_um = 1.2"), encoding="utf-8")
    for f, key in ((swept, "sweep.plate.spacing_um"), (net, "network.grids[0].sigma_um")):
        with pytest.raises(sim.ConfigError) as e:
            sim.load(f)
        assert str(e.value).startswith(f"{key}: unknown "), str(e.value)
        assert "its value is in mm, not um: convert it" in str(e.value), str(e.value)


def test_sim_cli_main_from_python_refuses_what_the_command_refuses(monkeypatch, capsys):
    from sim import cli

    monkeypatch.setenv("SIM_NO_JIT", "0")
    assert cli.main(["check", TABLE1]) == 2
    out, err = capsys.readouterr()
    assert out == "" and err.startswith("sim: error: SIM_NO_JIT: must be 1"), (out, err)


def test_a_run_out_of_memory_under_a_ulimit_names_it(monkeypatch):
    from sim import room, run_failure
    from sim.studies import get_study

    real = resource.getrlimit
    monkeypatch.setattr(
        room.resource,
        "getrlimit",
        lambda r: (1_400_000 * 1024, real(r)[1]) if r == resource.RLIMIT_AS else real(r),
    )
    e = MemoryError("Unable to allocate 64.1 MiB for an array with shape (60, 10000, 2, 7)")
    study = get_study("brown_table1")
    words = str(run_failure.numeric_failure(e, study, {"study": "brown_table1"}))
    assert words.endswith(
        "(ulimit -v is 1400000 kB: raise it, or reduce chunk, trials or the sizes in the study "
        "file)"
    ), words
    caps = {resource.RLIMIT_AS: 1_400_000 * 1024, resource.RLIMIT_DATA: 1_300_000 * 1024}
    monkeypatch.setattr(  # both limits set: the advice raises them both
        room.resource, "getrlimit", lambda r: (caps[r], real(r)[1]) if r in caps else real(r)
    )
    words = str(run_failure.numeric_failure(e, study, {"study": "brown_table1"}))
    assert "ulimit -v is 1400000 kB, ulimit -d is 1300000 kB: raise them, or reduce" in words
