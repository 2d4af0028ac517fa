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
* a network whose run's estimate is over the memory limit (``SIM_MAX_MEMORY_GB``, ``sim run
  --max-memory-gb``) was refused after its load: a 20,000-point one under
  ``SIM_MAX_MEMORY_GB=0.4`` was built and factorised (0.47 GiB, over the limit it was
  refused for), a 90,000-point one took two minutes first. The check now refuses it before
  the network is built, with the estimate ``sim check`` shows, naming the key that declares
  the network (``network.grids``, the key holding its points; ``network.gama_xml`` and its file) and the limit.
* ``sim check`` said a run's work in adjustments only, a unit no user knows: the time it
  takes is now said too (``about 2.5 min of one core of the reference machine`` for the
  90,000-point network's 40 trials, which took 107 s of CPU and 1.6 GiB, estimated 2.55 GiB;
  20,000 points: 32 s and 0.54 GiB estimated, 16 s and 0.61 GiB measured).
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
from sim.mc.network_size import network_counts, network_estimate, state_bytes
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
        (  # a chunk larger than the region's vectors (test_doors39m.py)
            "brown_dilution",
            ["region.points=256", "region.rounds=0", "plate.grid=20", "plate.spacing_mm=10"],
            "reduce chunk, trials, plate.grid or errors.settings",
        ),
        (
            "brown_table1",
            ["plate.pattern=random", "plate.n_random=400"],
            "reduce chunk, trials, plate.n_random or errors.settings",
        ),
        ("salsig_encoders", ["vertical.control=100"], "reduce chunk or vertical.control"),
        ("salsig_encoders", ["marks.grid=20"], "reduce chunk or marks.grid"),
    ],
)
def test_a_memory_refusal_names_the_keys_that_set_the_size(name, sets, keys, monkeypatch, capsys):
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


def test_a_network_over_the_memory_limit_is_refused_before_it_is_built(
    tmp_path, monkeypatch, capsys
):
    # before: refused by the estimate only after the network was built and factorised (its
    # declaration's own check, state_bytes, is under the limit here)
    st = tmp_path / "grid.toml"
    st.write_text(
        'study = "network"\ntrials = 40\nchunk = 2\n[network]\ngrids = [ { prefix = "G", '
        'nx = 30, ny = 30, spacing_m = 100.0 } ]\ngenerate = [ { kind = "distance", from = '
        '"G*", to = "G*", nearest = 8, sigma_mm = 2.0 } ]\n[datum]\nkind = "inner"\n'
    )
    flat = {
        "trials": 40,
        "chunk": 2,
        "network.grids": [{"prefix": "G", "nx": 30, "ny": 30, "spacing_m": 100.0}],
        "network.generate": [
            {"kind": "distance", "from": "G*", "to": "G*", "nearest": 8, "sigma_mm": 2.0}
        ],
    }
    cfg = validate(flat, get_study("network").schema, None)
    need, k = network_estimate(cfg)[3], network_counts(cfg)
    gib = (state_bytes(k.points, k.rows) + need) / 2 / 2**30
    assert state_bytes(k.points, k.rows) < gib * 2**30 < need

    def unbuilt(*a, **kw):
        raise AssertionError("the network was built")

    monkeypatch.setattr("sim.studies.network.schema.build", unbuilt)
    monkeypatch.setenv("SIM_MAX_MEMORY_GB", f"{gib:.6g}")
    words = ("900 points and 7,200 observations", f"{need / 2**30:.3g} GiB", f"{gib:.6g} GiB")
    one_line(capsys, main(["check", str(st)]), "network.grids: ", *words)
    monkeypatch.delenv("SIM_MAX_MEMORY_GB")  # the run's own option, while it loads
    args = ["run", str(st), "--out", str(tmp_path / "o"), "--max-memory-gb", f"{gib:.6g}"]
    one_line(capsys, main(args), "network.grids: ", *words)
    assert not (tmp_path / "o").exists()
    # a gama-local file: named with its file, its elements counted (it is not read: doors41x)
    xml = tmp_path / "net.xml"
    pts = '<point id="A" x="0" y="0" fix="xy"/><point id="B" x="1" y="0" adj="xy"/>'
    obs = '<obs from="A">' + '<distance to="B" val="1" stdev="1"/>' * 1000 + "</obs>"
    xml.write_text(
        f"<gama-local><network><points-observations>{pts}{obs}</points-observations>"
        + "</network></gama-local>"
    )
    st.write_text(f'study = "network"\ntrials = 40\nchunk = 2\n[network]\ngama_xml = "{xml}"\n')
    need = network_estimate({"network.gama_xml": str(xml), "trials": 40, "chunk": 2})[3]
    monkeypatch.setenv("SIM_MAX_MEMORY_GB", f"{need / 2 / 2**30:.6g}")
    monkeypatch.setattr("sim.studies.network.schema.merge_gama", unbuilt)
    words = ("2 points and 1,000 observations",)
    one_line(capsys, main(["check", str(st)]), f"network.gama_xml: {xml}: ", *words)


def test_sim_check_says_the_work_as_time_of_one_core(capsys):
    # before: "# work: 2,000 trials, about 2.64e+04 adjustments ..., about 24.5 MiB of memory"
    assert main(["check", str(STUDIES / "network_testfield.toml")]) == 0
    line = capsys.readouterr().out.splitlines()[-1]
    assert line.startswith("# work: 2,000 trials") and line.endswith(
        "; about 1.3 s of one core of the reference machine"
    ), line
