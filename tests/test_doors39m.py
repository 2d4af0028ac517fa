"""Helper m39: real sizes under the memory checks (the estimate, ``--max-memory-gb`` and the
room ``ulimit -v``/``-d`` leaves), for networks of 2,000 to 50,000 points and Brown's region;
one case per class found, each failing on the code before its fix (small sizes here, the
measured ones in the docstrings).

* Brown's region (``region.points``, ``region.rounds``) was not in the memory estimate:
  brown_dilution at ``region.points = 16384`` and ``region.rounds = 8`` peaked at 1.55 GB
  (its region part 1.1 GiB by tracemalloc, 49,152 input vectors) and ``sim check`` said
  "about 1.54 MiB of memory", so no limit refused it (under ``--max-memory-gb 1`` it ran). A
  vector now costs 26 kB (:data:`sim.mc.brown_size.BROWN_REGION_BYTES`: every vector of the
  Concept's region, the largest batch of Table 1's), estimated 1.19 GiB there, and a refusal
  names ``region.points or region.rounds``.
* a network over what ``ulimit -v`` (or ``-d``) leaves was refused only after it was built
  and its normals factorised, or failed in the middle of that: a 50,000-point trilateration
  grid (1.39 GiB estimated) under ``ulimit -v 1300000`` was built (20 s of CPU here, minutes
  at a million points) and refused with "reduce chunk, trials or the sizes in the study
  file"; under ``ulimit -v 1100000`` it failed on "Unable to allocate 68.0 MiB". The check
  before the build (:func:`sim.studies.network.validate.fits_estimate`) now compares the
  estimate with the room too (:func:`sim.room.short_room`), naming ``network.grids`` (the
  key that declares the size) and the limit, in under a second.
* a run the room check passes can still fail mid-run (the libraries it loads later and the
  allocator's arenas are not in the estimate): brown_dilution at its defaults (0.33 GiB
  estimated, 0.43 GiB mapped at the start) failed under ``ulimit -v 1250000`` in its region
  on "MemoryError: Unable to allocate 110. MiB ... (reduce trials, chunk or the sizes in the
  study file)", none of which sets that memory; it ran at 1400000. The line now names the
  limit in force and the keys that set the run's memory (:func:`sim.room.limits_set`).
"""

from __future__ import annotations

import resource
from pathlib import Path

import pytest
from conftest import grid_network

from sim.cli import main
from sim.mc.brown_size import brown_estimate
from sim.mc.config import validate
from sim.room import mapped_bytes
from sim.studies import get_study
from tests.oneline import one_line

ROOT = Path(__file__).resolve().parents[1]
STUDIES = ROOT / "studies"
REGION = ["--set", "region.points=16384", "--set", "region.rounds=8"]


@pytest.mark.parametrize(
    "name, measured",
    [("brown_dilution", 1111 * 2**20), ("brown_table1", 371 * 2**20)],
)
def test_brown_region_is_in_the_memory_estimate_and_its_refusal(
    name, measured, monkeypatch, capsys
):
    # before: 1.54 MiB (brown_dilution) and 0.29 MiB (brown_table1: their chunks) whatever the
    # region; measured (tracemalloc of the region part) 1,111 and 371 MiB
    flat = {"trials": 40, "chunk": 2, "region.points": 16384, "region.rounds": 8}
    cfg = validate(flat, get_study(name).schema, None)
    b = brown_estimate({**cfg, "study": name})[3]
    assert measured / 2 < b < 2 * measured, (b / 2**20, measured / 2**20)
    monkeypatch.setenv("SIM_MAX_MEMORY_GB", "0.2" if name == "brown_table1" else "1")
    args = ["check", str(STUDIES / f"{name}.toml"), *REGION]
    line = one_line(capsys, main(args), "the region's input vectors", "region.rounds")
    assert line.endswith("; reduce region.points or region.rounds"), line


@pytest.mark.parametrize(
    "limit, words", [(resource.RLIMIT_AS, "ulimit -v"), (resource.RLIMIT_DATA, "ulimit -d")]
)
def test_a_network_over_the_room_a_limit_leaves_is_refused_before_it_is_built(
    limit, words, tmp_path, monkeypatch, capsys
):
    # before: built and factorised first (a 50,000-point grid: 20 s), then refused naming
    # no key, or a MemoryError in the build
    st, need = grid_network(tmp_path, 30)
    field = 0 if limit == resource.RLIMIT_AS else 5
    # what the process maps, 1.5 GiB at least: a limit under the suite's 1 GiB floor is refused
    # before any room check (this file run alone maps less)
    used = max(mapped_bytes(field), 3 << 29)
    cap = used + int(need / 2)  # half the estimate left: it cannot fit
    real, real_mapped = resource.getrlimit, mapped_bytes
    monkeypatch.setattr("sim.room.mapped_bytes", lambda f=0: used if f == field else real_mapped(f))

    def limited(which):
        return (cap, real(which)[1]) if which == limit else real(which)

    def unbuilt(*a, **kw):
        raise AssertionError("the network was built")

    monkeypatch.setattr("sim.room.resource.getrlimit", limited)
    monkeypatch.setattr("sim.studies.network.schema.build", unbuilt)
    line = one_line(
        capsys, main(["check", str(st)]), "network.grids: ", "900 points", f"{words} (", "raise"
    )
    assert line.endswith(f"raise {words} or use fewer points or observations"), line


@pytest.mark.long
def test_a_memory_error_mid_run_names_the_limit_and_the_keys(tmp_path, monkeypatch, capsys):
    # before: "(reduce trials, chunk or the sizes in the study file)": brown_dilution's
    # region failed so under ulimit -v 1250000 (estimate 0.33 GiB, 0.82 GiB left at the start)
    def short(*a, **kw):
        raise MemoryError("Unable to allocate 110. MiB for an array")

    real = resource.getrlimit
    cap = 2**50  # set, and far above what the run needs: the room check passes

    def limited(which):
        return (cap, real(which)[1]) if which == resource.RLIMIT_AS else real(which)

    monkeypatch.setattr("sim.room.resource.getrlimit", limited)
    monkeypatch.setattr("sim.studies.brown.region.monotone_at", short)
    args = ["run", str(STUDIES / "brown_dilution.toml"), "--trials", "40", "--no-figures"]
    line = one_line(capsys, main([*args, "--out", str(tmp_path / "o")]), "MemoryError")
    assert line.endswith(
        f"(ulimit -v is {cap // 1024} kB: raise it, or reduce region.points or region.rounds)"
    ), line
