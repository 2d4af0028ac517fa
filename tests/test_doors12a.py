"""The items issue 26's last sessions left open (note6, "Noticed and left alone"), one case each;
each failed on the code before its fix.

* a run of fewer than MIN_CHUNKS (20) chunks of a study whose claims take jackknife intervals
  over the chunks (brown_table1, brown_dilution, the network kind) passed ``sim check`` and
  stopped only at the end, after every trial; it is now refused when the study is loaded,
  naming ``chunk`` (or ``trials``). The studies that never call the jackknife still run with 2.
* ``sim show`` / ``sim report`` on a table with a column dropped or retyped by hand said "a
  table under DIR is not as sim wrote it" without naming the file (the error came from the
  code reading a column); the reader now names the file (relative to DIR) and the column.
* ``sim/mc/estimate.py`` counted brown_design's largest ``design.grids`` as a Monte-Carlo chunk
  of every part, and refused ``design.grids = [.., 29]`` as 254 GiB; each part is now counted
  with its own geometry, the design grid as the analytic stack it is.
* ``sim/mc/outputs.py``'s name-length check spelled the staging and swap directories' names
  again; they are now made by one helper each (:func:`sim.mc.outputs.stage_dir`,
  :func:`sim.mc.outputs.swap_dir`), which the run and the check both use.
* brown_design's plates region: a corner of Zeiss points 13 mm from a station, under beta's
  14.5 mm, is outside the region (Table 1's statements fail there), so no reading off the arm
  is ever simulated; the test says why.
"""

import re
import shutil
import tracemalloc
from pathlib import Path

import numpy as np
import pyarrow as pa
import pyarrow.parquet as pq
import pytest
from oneline import one_line

from sim.claims.inference import FAILS, evaluate
from sim.cli import main
from sim.instruments.ranges import brown as B
from sim.mc import outputs
from sim.mc.config import ConfigError
from sim.mc.estimate import check_limits, estimate
from sim.mc.registry import MODULES
from sim.mc.runner import MIN_CHUNKS
from sim.studies import load_study
from sim.studies.design.cells import geometry_eval, plate_setup
from sim.studies.design.chunks import design_chunk
from sim.studies.design.external import zeiss_points
from sim.studies.design.region import SIGMA0, TABLE1, ZEISS, table1_evidence

ROOT = Path(__file__).resolve().parent.parent
#: one shipped study file per study kind
FILES = {
    "agnard_block": "agnard_block",
    "brown_design": "brown_design",
    "brown_dilution": "brown_dilution",
    "brown_table1": "brown_table1",
    "gridplate_two_plates": "gridplate_two_plates",
    "network": "network_plate",
    "salsig_encoders": "salsig_encoders",
    "wolf_polynomial": "wolf_polynomial",
}
#: a call of the chunk jackknife: sim.mc.runner.jackknife, or Brown's MC.jack wrapping it
JACKKNIFE_CALL = re.compile(r"\bjackknife\(|\.jack\(")


def _uses_jackknife(study: str) -> bool:
    """Whether the study's own package calls the chunk jackknife (its source, not a list)."""
    pkg = ROOT / Path(*MODULES[study].split("."))
    return any(JACKKNIFE_CALL.search(p.read_text()) for p in pkg.glob("*.py"))


def test_the_studies_that_use_the_jackknife_are_the_brown_and_network_ones():
    assert set(FILES) == set(MODULES)
    used = {s for s in MODULES if _uses_jackknife(s)}
    assert used == {"brown_dilution", "brown_table1", "network"}


@pytest.mark.parametrize("study", sorted(FILES))
def test_one_chunk_short_is_refused_at_check_and_the_limit_passes(study, capsys):
    """Each study kind needs the chunks its own results use: MIN_CHUNKS where it calls the
    jackknife, else 2 (``sim.mc.config.check_chunks``). One chunk short exits 2 naming
    ``chunk`` at ``sim check``; at the limit (the last chunk short by one trial) it checks."""
    need = MIN_CHUNKS if _uses_jackknife(study) else 2
    f = str(ROOT / "studies" / f"{FILES[study]}.toml")
    chunk = 6 if study == "gridplate_two_plates" else 3  # its self-check needs 6 trials (P39)
    short = ["--set", f"trials={(need - 1) * chunk}", "--set", f"chunk={chunk}"]
    one_line(capsys, main(["check", f, *short]), "chunk", "trials", "at least")
    limit = ["--set", f"trials={need * chunk - 1}", "--set", f"chunk={chunk}"]
    assert main(["check", f, *limit]) == 0, capsys.readouterr().err
    assert f"\nchunk = {chunk} " in capsys.readouterr().out
    if need > 2:  # refused when loaded (the Python API, sweeps, batch), before any trial
        with pytest.raises(ConfigError, match=f"^chunk: .*make chunk at most {chunk - 1}"):
            load_study(f, [f"trials={(need - 1) * chunk}", f"chunk={chunk}"])
        with pytest.raises(ConfigError, match=f"^trials: .*at least {need} trials"):
            load_study(f, [f"trials={need - 1}", "chunk=1"])


@pytest.mark.parametrize(
    "damage, what",
    [
        (lambda t: t.drop_columns(["fit_rms_um"]), "has no column 'fit_rms_um'"),
        (
            lambda t: t.set_column(
                t.schema.get_field_index("fit_rms_um"),
                "fit_rms_um",
                t.column("fit_rms_um").cast(pa.string()),
            ),
            "column 'fit_rms_um'",
        ),
    ],
    ids=["dropped", "retyped"],
)
def test_show_and_report_name_the_damaged_table_and_its_column(tmp_path, capsys, damage, what):
    res = tmp_path / "res"
    d = res / "wolf_polynomial"
    shutil.copytree(ROOT / "results" / "wolf_polynomial", d, ignore=shutil.ignore_patterns("*.png"))
    assert main(["show", str(d), "--markdown"]) == 0  # as sim wrote it: shown
    capsys.readouterr()
    f = d / "degree.parquet"
    pq.write_table(damage(pq.read_table(f)), f)
    one_line(capsys, main(["show", str(d), "--markdown"]), "degree.parquet under", what)
    one_line(
        capsys, main(["report", "--results", str(res)]), "wolf_polynomial/degree.parquet", what
    )
    assert not (res / "REPORT.md").exists()


# --- brown_design's estimate: each part with its own geometry ----------------------------------


def _design_cfg(*over):
    return load_study(ROOT / "studies" / "brown_design.toml", list(over))[1]


def test_the_design_grid_is_counted_as_the_analytic_stack_it_is():
    """``design.grids = [.., 29]`` was refused as 254 GiB: the largest design grid was counted
    as a chunk of 500 Monte-Carlo trials seen from the most positions. The design grid is
    analytic: one (offsets x betas, 2n, 2n) cofactor stack per grid."""
    est = estimate(_design_cfg("design.grids=[3, 4, 5, 6, 29]"))
    check_limits(
        est, max_adjustments=5e9
    )  # about 1.7 GiB, under the default 8 GiB (work: test_design_work)
    assert "29 x 29 points" in est.largest and est.bytes < 2 * 2**30
    # a design grid really too big for the memory limit is still refused, naming the part
    betas = "design.beta_mm=[0.5, 1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0, 9.0]"
    with pytest.raises(ConfigError, match=r"over the 8 GiB limit .*80 offset x beta geometries"):
        check_limits(estimate(_design_cfg("design.grids=[5, 30]", betas)))


def test_the_design_estimate_covers_what_the_analytic_grid_allocates():
    """The estimate of the design grid's part is at least the peak that
    :func:`sim.studies.design.cells.geometry_eval` allocates (tracemalloc), and not far above
    it (a model, not a bound a run could exceed)."""
    # the posteriors' shortest chains (doors33m counts their memory, 37 MiB at 500 steps)
    cfg = _design_cfg("design.grids=[5, 10]", "design.positions=[4]", "chunk=20", "bayes.steps=100")
    est = estimate(cfg)
    assert "10 x 10 points" in est.largest
    tracemalloc.start()
    try:
        geometry_eval(cfg, 4, 10, 90.0, cfg["design.offsets_mm"], cfg["design.beta_mm"])
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert peak <= est.bytes <= 2 * peak, (peak, est.bytes)


def test_the_design_estimate_covers_what_a_monte_carlo_chunk_allocates():
    """The paper's plate in chunks of 500 (the study file): the estimate is at least the peak
    of one chunk of :func:`sim.studies.design.chunks.design_chunk`."""
    cfg = _design_cfg("bayes.steps=500")  # the study's 8,000 steps hold more (doors40b)
    est = estimate(cfg)
    assert est.largest == "the Monte-Carlo check on the paper's plate"
    pts, th = plate_setup(cfg, 4, 5, 90.0, 17.0, 1.0)
    tracemalloc.start()
    try:
        design_chunk(pts, th, 1.0, np.random.default_rng(5), cfg["chunk"])
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert peak <= est.bytes <= 8 * peak, (peak, est.bytes)


# --- the staging names next to --out are made in one place -------------------------------------


def test_the_name_check_measures_the_names_the_run_makes(tmp_path, monkeypatch):
    """The name-length check and the run take the staging and swap names from the same
    helpers: an ``--out`` whose longer one is one byte over the file system's limit is
    refused, one at the limit passes; nothing is made."""
    limit = 255
    monkeypatch.setattr(outputs, "_name_max", lambda d: limit)
    rec = {"config": {"study": "brown_table1"}}
    r = tmp_path / "r"  # the bytes the longer name adds to a name: the pid's digits decide
    extra = max(len(outputs.stage_dir(r).name), len(outputs.swap_dir(r).name)) - 1
    for over in (1, 0):
        out = tmp_path / ("r" * (limit + over - extra))
        names = [outputs.stage_dir(out).name, outputs.swap_dir(out).name]
        assert names[0] == f".{out.name}.partial" and names[1].startswith(f".{out.name}.old.")
        assert max(len(n) for n in names) == limit + over
        if over:
            with pytest.raises(ConfigError, match="^--out: .*over the file system's 255"):
                outputs.check_out(out, str(out), rec, overwrite=False)
        else:
            outputs.check_out(out, str(out), rec, overwrite=False)
    assert list(tmp_path.iterdir()) == []


# --- brown_design's plates region: every Zeiss reading is on the arm --------------------------


def test_table1_keeps_the_plates_region_off_the_arms_unreachable_corner():
    """Zeiss points at +-110 mm with stations 0.5 mm out are 13 mm from a station, under
    beta's 14.5 mm maximum: a reading ``sqrt(d^2 - beta^2) - alpha`` there would be
    imaginary or negative. The plates region never reaches that corner: plates are simulated
    only where Table 1's printed statements hold, and they fail at every station offset the
    corner needs. The Zeiss stand-in lies on the 1 cm lattice within +-110 mm (its half extent
    is at most 115 mm), so the nearest point is at least ``d = 12.5 + o`` mm from a station
    ``o`` mm outside the 245 mm format, and a reading needs ``d^2 >= beta^2 + alpha^2``: with
    beta <= 14.5 mm, only ``o < sqrt(14.5^2 + alpha^2) - 12.5`` (2.01 mm at alpha 0.5 mm) can
    miss the arm."""
    cfg = _design_cfg()
    assert np.abs(zeiss_points(cfg, ZEISS.high)).max() <= 110.0
    alpha = cfg["comparator.alpha_mm"]
    corner = np.hypot(B.SCALE_WIDTH_MM / 2, alpha) - (B.FORMAT_MM / 2 - 110.0)
    assert 2.0 < corner < 2.1
    o, b, s0 = (
        a.ravel()
        for a in np.meshgrid(
            np.linspace(0.5, corner, 26),
            np.linspace(0.0, B.SCALE_WIDTH_MM / 2, 30),
            np.linspace(SIGMA0.low, SIGMA0.high, 5),
            indexing="ij",
        )
    )
    verdicts = evaluate(TABLE1, table1_evidence(o, b, s0, alpha), len(o))
    assert (verdicts == FAILS).any(axis=1).all()  # no such point is in the region
