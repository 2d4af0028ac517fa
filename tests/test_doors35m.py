"""Helper m35: the real sizes of loading and running a large network, and the estimate of them.

Networks of 20,000 to 90,000 points (a national-grid trilateration grid, nearest-8 distances,
inner datum; the same as a ``gama_xml`` file) were loaded and run under ``/usr/bin/time`` and
compared with what ``sim check`` says; one case per class, each failing on the code before its
fix (small sizes here, the measured ones in the docstrings).

* loading a 90,000-point network (``load_study``, ``sim check``) peaked at 2.5 GiB for a
  factor and selected inverse of 0.4 GiB: the reliability took every observation row's
  ``s x s`` block of cofactors at once (26 million entries, the datum's low-rank terms
  gathered for each), and the factorisation held SuperLU's own factor while it built the
  filled pattern with three index arrays of the factor's size. The rows now go by blocks,
  SuperLU's factor is freed first and the factor is put on its pattern in place: 1.35 GiB,
  the same numbers to the last bit.
* a memory refusal of brown_dilution, brown_table1 or salsig_encoders said "reduce chunk,
  trials or the sizes in the study file"; a salsig region of a million models (all in memory
  at once, whatever the chunk) was told to reduce chunk or trials. The refusal now names the
  keys that set the memory (``plate.grid`` or ``plate.n_random`` and ``errors.settings``,
  ``dilution.grids``; salsig's key of the most points, or ``region.trials``).
"""

from __future__ import annotations

import tracemalloc
from pathlib import Path

import numpy as np
import pytest

from sim.cli import main
from sim.mc.config import validate
from sim.studies import get_study
from sim.studies.network import sparse_analysis as sa
from sim.studies.network.definition import build
from sim.studies.network.model import datum
from tests.oneline import one_line

ROOT = Path(__file__).resolve().parents[1]
STUDIES = ROOT / "studies"


def _grid(side: int, kind: str = "distance") -> tuple:
    """A side x side trilateration (or triangulation) grid, nearest 8, inner datum: its
    network and datum."""
    sig = "sigma_mm" if kind == "distance" else "sigma_arcsec"
    flat = {
        "trials": 40,
        "chunk": 2,
        "network.grids": [{"prefix": "G", "nx": side, "ny": side, "spacing_m": 100.0}],
        "network.generate": [
            {"kind": kind, "from": "G*", "to": "G*", "nearest": 8, sig: 2.0},
        ],
        "datum.kind": "inner",
    }
    cfg = validate(flat, get_study("network").schema, None)
    net = build(cfg)
    return net, datum(net, cfg)


def test_the_sparse_pre_analysis_holds_a_few_times_its_factor_not_every_rows_block(
    monkeypatch,
):
    # before: a 60 x 60 grid's pre-analysis peaked at 8 times the bytes of the factor and
    # selected inverse it keeps (24 a nonzero), growing with the rows (2.5 GiB at 90,000
    # points); now about 3 times, and the blocks of rows give the same numbers
    net, dt = _grid(60)
    monkeypatch.setattr(sa, "RELIABILITY_ROWS", 10**9, raising=False)
    whole = sa.analyse_sparse(net, dt, 0.001, 0.8)  # (and the compiled kernels warmed up)
    monkeypatch.setattr(sa, "RELIABILITY_ROWS", 2048, raising=False)
    tracemalloc.start()
    try:
        an = sa.analyse_sparse(net, dt, 0.001, 0.8)
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    held = 24 * an.factor.nnz
    assert peak < 5 * held, (peak / held, peak, held)
    for k in ("cov", "redundancy", "mdb", "ext_max_mm", "bnr"):
        assert np.array_equal(getattr(an, k), getattr(whole, k)), k
    assert np.array_equal(an.factor.data, whole.factor.data)


@pytest.mark.parametrize(
    "name, sets, keys",
    [
        ("brown_dilution", [], "reduce chunk, trials, plate.grid or errors.settings"),
        (
            "brown_table1",
            ["plate.pattern=random", "plate.n_random=400"],
            "reduce chunk, trials, plate.n_random or errors.settings",
        ),
        ("salsig_encoders", ["vertical.control=100"], "reduce chunk or vertical.control"),
        ("salsig_encoders", ["marks.grid=20"], "reduce chunk or marks.grid"),
    ],
)
def test_a_memory_refusal_names_the_keys_that_set_the_size(
    name, sets, keys, monkeypatch, capsys
):
    # before: "reduce chunk, trials or the sizes in the study file"
    monkeypatch.setenv("SIM_MAX_MEMORY_GB", "0.001")
    args = ["check", str(STUDIES / f"{name}.toml")] + [a for s in sets for a in ("--set", s)]
    line = one_line(capsys, main(args), "over the 0.001 GiB limit", keys)
    assert line.endswith(keys) and "sizes in the study file" not in line, line


def test_a_salsig_region_too_large_for_memory_is_told_region_trials(monkeypatch, capsys):
    # before: a region of a million models (9.3 GiB, all at once whatever the chunk) was
    # told to "reduce chunk, trials or the sizes in the study file"
    monkeypatch.delenv("SIM_MAX_MEMORY_GB", raising=False)
    args = ["check", str(STUDIES / "salsig_encoders.toml"), "--set", "region.trials=1000000"]
    line = one_line(capsys, main(args), "over the 8 GiB limit", "; reduce region.trials")
    assert line.endswith("; reduce region.trials"), line
