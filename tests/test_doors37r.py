"""A fresh reading of session 36's change (sweep doors37r): each class was found through a
real door and fixed; each test fails on the code before its fix:

* the memory check of a network before it is built (``fits_estimate``) named the key that
  holds most of its points, ``network.grids``, when what made the network too large was its
  observations: a 60 x 50 grid (3,000 points) with ``generate`` of distances from every point
  to every point (no ``nearest``: 9,000,000 observations, 44 GiB) was refused as
  ``network.grids: ... use fewer points or observations``, and the 3,000 points alone fit in
  a few MiB. Observations over ``MANY_SIGHTS`` (50) a point now name the key that declares
  them, ``network.generate`` (``network.observations`` when those listed are most).
* an option typed with a word processor's dash beside a hyphen (``sim run —-trials 40
  x.toml``, ``python -m sim.batch –-jobs 2 x.toml``: what an editor makes of ``---`` or of
  ``--`` typed after a dash) slipped past the check of session 36 (``_dashed``), which read
  the dash as two hyphens, ``---trials``, no option: argparse took it for the study file and
  the line said "unrecognized arguments: 40 x.toml", the dash unnamed (``sim.batch``: "no
  such study file" of each word). A dash beside a hyphen is read as one or two hyphens too:
  "—-trials: not an option (did you mean --trials? U+2014 EM DASH is no hyphen: type -)".
* a masked value of NumPy (``np.ma.masked``, the element of a masked array or an astropy
  table's column that holds none) given to ``sim.load`` or ``run()`` was refused as "trials:
  is nested too deeply" (its ``v[()]`` is itself: the recursion's words); it is now "trials:
  is masked (np.ma.masked, no value): give one, or leave the key out".
* ``run(out=None)`` clears the temporary directories of killed runs of its study, named
  ``$TMPDIR/sim-<study>-<pid>-XXXXXXXX``, by their name alone (and pid, owner, no results, no
  lock): a directory of the user's named so, ``sim-brown_table1-2026-november`` (no process
  2026), was removed with the notes it held. A run's directory now holds the marker
  ``.sim-run`` (its pid), as ``make verify``'s holds ``.sim-verify``; one without it is left.
"""

from __future__ import annotations

import subprocess
import sys
import tempfile

import numpy as np
import pytest
from conftest import ROOT
from oneline import SIM_ERROR, one_line

import sim
import sim.api
from sim.batch import main as batch_main
from sim.cli import main

#: a network of few points whose generated sights (every point to every point) are too many
EVERY_PAIR = """study = "network"
trials = 1000
chunk = 50
seed = 1

[network]
name = "every pair"
grids = [ { prefix = "G", nx = 60, ny = 50, spacing_mm = 10.0, role = "observed", sigma_mm = 0.001 } ]
generate = [ { kind = "distance", from = "G*", to = "G*", sigma_mm = 0.002 } ]

[datum]
kind = "inner"
"""


def test_a_network_too_large_by_its_sights_names_them(capsys, tmp_path, monkeypatch):
    monkeypatch.delenv("SIM_MAX_MEMORY_GB", raising=False)
    path = tmp_path / "pairs.toml"
    path.write_text(EVERY_PAIR, encoding="utf-8")
    one_line(
        capsys,
        main(["check", str(path)]),
        "network.generate: a network of about 3,000 points and 9,006,000 observations",
        prefix=SIM_ERROR,
    )
    with pytest.raises(sim.ConfigError, match=r"^network\.generate: "):
        sim.load(path)


@pytest.mark.parametrize(
    ("door", "argv", "needles"),
    [
        (main, ["run", "\u2014-trials", "40", "x.toml"], ("\u2014-trials", "--trials", "EM DASH")),
        (batch_main, ["\u2013-jobs", "2", "x.toml"], ("\u2013-jobs", "--jobs", "EN DASH")),
    ],
)
def test_an_option_typed_with_a_dash_beside_a_hyphen_is_named(capsys, door, argv, needles):
    one_line(capsys, door(argv), *needles, "is no hyphen")


@pytest.mark.parametrize("value", [np.ma.masked, np.ma.array([400], mask=[True])[0]])
def test_a_masked_value_is_refused_as_masked(value):
    with pytest.raises(sim.ConfigError, match=r"^trials: is masked \(np\.ma\.masked, no value\)"):
        sim.load(ROOT / "studies" / "brown_table1.toml", trials=value)


def test_a_users_directory_named_like_a_killed_runs_is_left(tmp_path, monkeypatch):
    gone = subprocess.run(
        [sys.executable, "-c", "import os; print(os.getpid())"],
        check=True,
        capture_output=True,
        text=True,
    )
    pid = int(gone.stdout)  # no such process now
    mine = tmp_path / f"sim-brown_table1-{pid}-november"
    mine.mkdir()
    (mine / "notes.txt").write_text("the user's")
    monkeypatch.setattr(tempfile, "tempdir", str(tmp_path))

    def stopped(*a, **k):
        raise RuntimeError("stopped")

    monkeypatch.setattr(sim.api, "execute", stopped)
    with pytest.raises(RuntimeError):
        sim.load(ROOT / "studies" / "brown_table1.toml").run(trials=40)
    assert (mine / "notes.txt").read_text() == "the user's"
    assert [p.name for p in tmp_path.iterdir()] == [mine.name]  # the run's own: removed
