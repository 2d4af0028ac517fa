"""Helper w45: agnard_block's work estimate against the block's geometry; one case per class
found, each failing on the code before its fix (tiny sizes here, the measured ones in the
docstrings and in :mod:`sim.mc.agnard_size`).

* The estimate counted a block solve by its models and ground points alone, not by how many
  models see each point: at the tiny size ``block.base_mm = 10`` took 61 s of CPU against 6.2
  s for the defaults while ``sim check`` said "about 6.5 s" for both, and with
  ``block.pass_rows = 20`` too a main trial takes 23 times the paper's (1.9 s against 0.082
  s), so a run the work limit passed could run for hours. Each solve is now weighed by the
  block's model observations (each signalised point times the models along its strip and the
  strips across that see it, and the pass points that two models or more see, laid out as
  :func:`sim.instruments.block.layout.make_block` lays them, a pass point's counted half) over
  those of the paper's geometry at the block's size, to the power 1.2
  (:func:`sim.mc.agnard_size.geometry_factor`; measured, the 2 x 8 block's main trial at bases
  of 90, 45 and 10 mm and 4 to 20 pass rows: within 0.85 and 1.18 of the time; the tiny run,
  CPU against the estimate: the defaults 6.2 s / 6.5 s, base 45 mm 12.6 / 18, base 10 mm 48.7
  / 47, 20 pass rows 7.9 / 14, both 134 / 132). The committed studies keep the paper's
  geometry: their estimate is unchanged.
* The refusal of a run over the work limit said "reduce trials or the lists in the study
  file" of a run whose cost was its geometry: a design whose solves cost more than 1.5 times
  the paper's now also names the geometry keys off the paper's ("or change block.base_mm or
  block.pass_rows"; of a sweep's costliest cell, a swept one as "the values of
  sweep.block.base_mm").
"""

from __future__ import annotations

import tomllib

import pytest
from conftest import ROOT, tiny_overrides
from oneline import one_line

import sim
from sim.cli import main
from sim.instruments.block.layout import make_block
from sim.mc.agnard_size import geometry_factor, model_observations

STUDY = str(ROOT / "studies" / "agnard_block.toml")


def _tiny(**more):
    """The tiny configuration's overrides as values, with ``more``."""
    sets = (a.split("=", 1) for a in tiny_overrides("agnard_block")[1::2])
    return {**{k: tomllib.loads(f"v = {v}")["v"] for k, v in sets}, **more}


@pytest.mark.parametrize(
    "strips, models, base, ground, rows",
    [(2, 8, 90.0, 178, 4), (2, 8, 10.0, 178, 20), (2, 8, 45.0, 500, 4), (3, 12, 30.0, 300, 6)],
)
def test_the_observations_counted_are_the_blocks(strips, models, base, ground, rows):
    b = make_block(strips, models, base_mm=base, n_ground=ground, pass_rows=rows)
    c = {
        "block.strips": strips,
        "block.models": models,
        "block.base_mm": base,
        "block.ground_points": ground,
        "block.pass_rows": rows,
    }
    assert model_observations(c) == pytest.approx(b.obs_model.size, rel=0.05)


def test_a_short_base_and_many_pass_rows_are_estimated_at_their_cost():
    est = lambda **k: sim.load(STUDY, **_tiny(**k)).estimate().adjustments  # noqa: E731
    paper, short = est(), est(**{"block.base_mm": 10.0})
    both = est(**{"block.base_mm": 10.0, "block.pass_rows": 20})
    assert 5 < short / paper < 20  # measured 61 s / 6.2 s of CPU; equal before
    assert both > 2 * short
    for f in ("agnard_block.toml", "agnard_block_104.toml"):  # the paper's geometry: unchanged
        assert geometry_factor(sim.load(ROOT / "studies" / f).config) == 1.0


def test_a_design_over_the_work_limit_is_refused_naming_its_keys(capsys):
    args = ["check", STUDY, *tiny_overrides("agnard_block"), "--max-adjustments", "5e5"]
    assert main(args) == 0  # the paper's geometry: 1.3e5
    capsys.readouterr()
    rc = main([*args, "--set", "block.base_mm=10", "--set", "block.pass_rows=20"])
    one_line(capsys, rc, "over the limit of 5e+05", "block.base_mm or block.pass_rows")


def test_a_swept_geometry_over_the_work_limit_is_named_as_swept(tmp_path, capsys):
    f = tmp_path / "agnard_swept.toml"
    f.write_text(
        (ROOT / "studies" / "agnard_block.toml").read_text()
        + '\n[sweep]\n"block.base_mm" = [90.0, 10.0]\n'
    )
    args = ["check", str(f), *tiny_overrides("agnard_block"), "--max-adjustments", "5e5"]
    one_line(capsys, main(args), "change the values of sweep.block.base_mm, which holds most of it")
