"""A27: ``agnard_block`` with a control weight near zero published noise.

``sim run studies/agnard_block.toml --set weights.control_xy=1e-12`` exited 0 with check
errors of about 1 m, while 3e-6 gave 57 m: below the engine's singularity rule every
adjustment was flagged singular (status 2, no iteration) and the chunks published the
starting values' error (1 m per axis) as the block's accuracy. Above the rule the errors are
a real if weak adjustment (the block shrinks towards its control as the weight falls).
``sim check`` now applies the engine's rule to the noise-free block
(:mod:`sim.studies.agnard.datum`) and refuses in one line.
"""

import numpy as np
import pytest

import sim.instruments.block.independent_models as im
from sim.api import load
from sim.cli import main
from sim.lsq.normals import RCOND
from sim.studies.agnard.datum import MARGIN, datum_rcond
from sim.studies.agnard.schema import block_of, paper_weights
from sim.studies.agnard.simulate import Adjuster, Simulated
from tests.oneline import SIM_ERROR, one_line

STUDY = "studies/agnard_block.toml"


@pytest.mark.parametrize(
    "key, needle",
    [
        ("weights.control_xy", "1e-11 times weights.pass (0.1; paper: 30 times)"),
        ("weights.control_z", "1e-11 times weights.pass (0.1; paper: 20 times)"),
        ("weights.first_pass_control", "1e-12 times weights.first_pass_pass (1; paper: 0.1"),
    ],
)
def test_a_control_weight_near_zero_is_refused_by_check(capsys, key, needle):
    rc = main(["check", STUDY, "--set", f"{key}=1e-12"])
    line = one_line(
        capsys, rc, key, needle, f"engine's singularity limit {RCOND:g}", prefix=SIM_ERROR
    )
    limit = float(line.rsplit("keep the ratio above about ", 1)[1])
    # the limit named is the engine's: between the refused 1e-11 and the paper's ratios
    assert 1e-11 < limit < 1e-6, line


@pytest.mark.parametrize("study", [STUDY, "studies/agnard_block_104.toml"])
def test_the_shipped_studies_pass_the_datum_check(capsys, study):
    assert main(["check", study]) == 0, capsys.readouterr().err


@pytest.fixture(scope="module")
def chunk():
    cfg = dict(load(STUDY).config)
    block = block_of(cfg)
    sim = Simulated(cfg, block, np.random.default_rng(27), 2, cfg["scan.dpi"])
    return cfg, block, sim, Adjuster(block)


def _status(chunk, pattern, ratio):
    cfg, block, sim, adj = chunk
    wo, _ = paper_weights(cfg)
    ctrl, st = adj.structure(pattern)
    res = im.adjust_block(
        st,
        sim.xm[("digital", "corrected")],
        wo,
        sim.ctrl_obs[:, ctrl],
        np.full((ctrl.size, 3), ratio * cfg["weights.pass"]),
        *sim.init,
        sim.X0,
    )
    return res.status, datum_rcond(block, ctrl, np.ones(3), np.full(3, ratio), MARGIN * RCOND)


def test_the_check_refuses_exactly_what_the_engine_flags_singular(chunk):
    """Below the rule the engine flags every trial singular (and the starting values were
    published); the noise-free block's rule said so. Above it, with the margin, no trial is
    flagged and the check lets it run."""
    status, (ok, rc) = _status(chunk, "corners", 1e-10)
    assert not ok and rc is not None and rc < RCOND
    assert (status == 2).all(), status
    status, (ok, rc) = _status(chunk, "corners", 1e-4)
    assert ok and rc is None
    assert (status == 0).all(), status


BROWN = "studies/brown_table1.toml"


@pytest.mark.parametrize(
    "setting, key",
    [
        ("plate.spacing_mm=60", "plate.spacing_mm"),
        ("plate.format_mm=300", "plate.format_mm"),
        ("comparator.station_offset_mm=45.0", "comparator.station_offset_mm"),
        ("comparator.scale_length_mm=200", "comparator.scale_length_mm"),
    ],
)
def test_the_brown_scale_refusal_names_the_key_the_user_changed(capsys, setting, key):
    """The refusal "ranges run ... move the stations in, or use alpha" named
    comparator.scale_length_mm whatever pushed a range off the scale."""
    rc = main(["check", BROWN, "--set", setting])
    line = one_line(capsys, rc, "ranges run from", "comparator.scale_length_mm", prefix=SIM_ERROR)
    assert line.startswith(f"{SIM_ERROR}{key}: "), line
    assert line.endswith(f"changed from their paper or nominal values: {key}"), line


def test_the_regions_five_point_layouts_are_checked_too(capsys):
    """At 3e-8 times the pass weight the configured layouts pass the rule but the region's
    five-point layout with its outer points moved in (inset 0.45, region.toml) does not."""
    rc = main(["check", STUDY, "--set", "weights.control_xy=3e-9"])
    one_line(capsys, rc, "weights.control_xy", "five-point layout, inset 0.45", prefix=SIM_ERROR)
