"""Helper m40: the room check (:mod:`sim.room`) of a large network after its load; one case
per class found, each failing on the code before its fix (a small network here, what the
process maps faked; the measured sizes in the docstrings).

* a network that fits under ``ulimit -v`` was refused after its load: the load builds the
  network and factorises its normals (the run's memory, which the estimate counts), and what it
  mapped stays mapped (the heap freed but not handed back, numba); the check before the run
  counted the estimate again on top of it. A 50,176-point grid (nearest 8: 1.39 GiB estimated,
  0.47 GiB mapped before the load, 1.07 GiB after it, 1.87 GiB at the load's peak) was refused
  by ``sim check`` and ``sim run`` after 30 s of building under ``ulimit -v 2000000`` (and
  2.4 GiB), though with the check off it ran to the end under 2,000,000 kB. What a study's load
  maps is now recorded under its config (:func:`sim.room.loaded`, in the load that ``sim run``,
  ``sim check``, ``sim.load`` and the batch share) and counted once: the run's room is what the
  limit leaves beside what the process mapped before the load; what it mapped since beyond the
  load's own is counted as before. The grid now passes the check there and runs to the end.

Held: a limit far too small is still refused before the network is built, naming the key
that sets its size (the check before the build is unchanged); what the process maps after the
load (a caller's arrays between ``sim.load`` and ``run``) is counted.
"""

from __future__ import annotations

import resource

import pytest
from conftest import grid_network

import sim
from sim.cli import main
from sim.mc.config import ConfigError
from sim.room import mapped_bytes
from sim.studies.network import schema
from tests.oneline import one_line


class _Process:
    """What the process maps, faked: the real figure at the start (1.5 GiB at least), ``grown`` more once the
    network is built (its load's heap, kept), and ``later`` more set by the test."""

    def __init__(self, monkeypatch, need: float, room: float, grown: float):
        # at least 1.5 GiB: a limit under the suite's 1 GiB floor is refused before any room
        # check, so the figure of a small process (this file run alone) must not decide it
        self.base = {f: max(mapped_bytes(f), 3 << 29) for f in (0, 5)}
        self.built, self.later, self.grown = False, 0, int(grown)
        cap = self.base[0] + int(room)
        real_limit, real_build = resource.getrlimit, schema.build

        def limited(which):
            return (cap, real_limit(which)[1]) if which == resource.RLIMIT_AS else real_limit(which)

        def build(*a, **kw):
            self.built = True
            return real_build(*a, **kw)

        monkeypatch.setattr("sim.room._LOADS", {})  # the fake loads' records: this test's
        monkeypatch.setattr("sim.room.resource.getrlimit", limited)
        monkeypatch.setattr("sim.room.mapped_bytes", self.mapped)
        monkeypatch.setattr("sim.studies.network.schema.build", build)

    def mapped(self, field: int = 0) -> int:
        return self.base[field] + (self.grown if self.built else 0) + self.later


@pytest.mark.parametrize("door", ["check", "run", "api"])
def test_what_a_networks_load_mapped_is_counted_once(door, tmp_path, monkeypatch, capsys):
    # before: refused after the load, "ulimit -v (...) leaves this process about 0.5 x the
    # estimate beside ... it maps already": the estimate counted on top of the load's own
    st, need = grid_network(tmp_path)
    _Process(monkeypatch, need, room=1.5 * need, grown=need)  # fits once, not twice
    out = tmp_path / "o"
    if door == "api":
        res = sim.load(st).run(out=out, figures=False)
        assert res.claims() is not None
        return
    args = (
        ["run", str(st), "--no-figures", "--out", str(out)] if door == "run" else ["check", str(st)]
    )
    assert main(args) == 0, capsys.readouterr().err
    assert door == "check" or (out / "run.json").is_file()


def test_what_the_process_maps_beyond_the_load_is_still_counted(tmp_path, monkeypatch):
    # held: a caller's arrays between sim.load and run are no part of the load
    st, need = grid_network(tmp_path)
    proc = _Process(monkeypatch, need, room=1.5 * need, grown=need)
    handle = sim.load(st)
    proc.later = int(need)
    with pytest.raises(ConfigError) as e:
        handle.run(out=tmp_path / "o", figures=False)
    words = str(e.value)
    assert "ulimit -v (" in words and "of which the run reuses the" in words, words
    assert not (tmp_path / "o").exists()


def test_a_limit_far_too_small_is_refused_before_the_build(tmp_path, monkeypatch, capsys):
    # held: the check before the build is unchanged
    st, need = grid_network(tmp_path)
    proc = _Process(monkeypatch, need, room=need / 10, grown=need)
    line = one_line(capsys, main(["check", str(st)]), "network.grids: ", "ulimit -v (")
    assert line.endswith("raise ulimit -v or use fewer points or observations"), line
    assert not proc.built
