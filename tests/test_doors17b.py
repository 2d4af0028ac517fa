"""The classes of the fresh sweep doors17b (issue 26: the doors' data at its edges, combined:
networks at real size, the GNU Gama round trip over every datum, keys at their bounds
together, a damaged results directory among good ones, many studies in one batch), one case
each; each failed on the code before its fix. The harness that found them (about 300 cases,
``run.sh``) lives outside the project.

* the suite's own export of an inner datum with one fixed point (``adj="XY"`` beside
  ``fix="xy"``, as ``tests/data/gama/one_fixed.xml``, which gama-local adjusts with defect 1)
  read back was refused ("a rank defect of 1 ... that the datum does not cover"): the
  ``adj="XY"`` points made the datum inner only in a file without a fixed point
  (:func:`sim.studies.network.gama.merge_gama`);
* the work estimate was not honest at real size: a trial of a network on the sparse path
  counted one unit adjustment whatever its size (a 100 x 100 grid plate's trial costs 12 ms,
  237 units: 1e5 trials, 20 hours of CPU, were estimated at 5 minutes, never over the limit),
  and a chunk cost nothing besides its trials (100,000 chunks of one trial, half an hour of
  writing files, were estimated at 5 seconds); the sparse path now counts its factor's
  nonzeros and every chunk ``CHUNK_UNITS`` (:mod:`sim.mc.network_size`, :mod:`sim.mc.estimate`);
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from sim.cli import main
from sim.mc.estimate import ADJUSTMENT_S, CHUNK_UNITS, estimate
from sim.studies import load_study
from sim.studies.network.analysis import analyse
from sim.studies.network.definition import build
from sim.studies.network.gama import merge_gama
from sim.studies.network.model import datum

ROOT = Path(__file__).resolve().parent.parent
GAMA = ROOT / "tests" / "data" / "gama"


def _analysed(cfg: dict):
    full = merge_gama(cfg)
    net = build(full)
    return full, net, analyse(net, datum(net, full), 0.001, 0.8)


def test_an_exported_inner_datum_with_one_fixed_point_reads_back(tmp_path, capsys):
    study = tmp_path / "s.toml"
    study.write_text(
        f'study = "network"\ntrials = 40\nchunk = 2\n[network]\ngama_xml = "{GAMA / "one_fixed.xml"}"\n'
    )
    assert main(["check", str(study)]) == 0, capsys.readouterr().err
    full, net, an = _analysed(load_study(study)[1])
    assert full["datum.kind"] == "inner" and full["datum.points"] == ["B", "C", "D"]
    # the same precision as the study that wrote the file (test_gama: as gama-local's)
    _, net0, an0 = _analysed(load_study(GAMA / "one_fixed.toml")[1])
    assert list(net.names) == list(net0.names)
    np.testing.assert_allclose(an.cov, an0.cov, rtol=1e-9, atol=1e-15)


def _plate(nx: int, trials: int, chunk: int) -> dict:
    text = (ROOT / "studies" / "network_gridplate_2500.toml").read_text()
    cfg = load_study(ROOT / "studies" / "network_gridplate_2500.toml")[1]
    assert "nx = 50, ny = 50" in text
    grids = [{**cfg["network.grids"][0], "nx": nx, "ny": nx}]
    return {**cfg, "network.grids": grids, "trials": trials, "chunk": chunk}


def test_the_work_estimate_counts_a_sparse_trial_by_its_size_and_every_chunk():
    # measured (CPU of 400 against 40 trials): 1.9 ms a trial at 50 x 50, 12 ms at 100 x 100
    for nx, ms in ((50, 1.9), (100, 12.0)):
        est = estimate(_plate(nx, 100_000, 20))
        per_trial = (est.adjustments - 100_000 / 20 * CHUNK_UNITS) / 100_000
        units = ms / 1000 / ADJUSTMENT_S
        assert units / 3 < per_trial < units * 3, (nx, per_trial, units)
    tiny = load_study(GAMA / "two_sets.toml")[1]  # 4 points: its trials cost next to nothing
    many = estimate({**tiny, "trials": 100_000, "chunk": 1})
    few = estimate({**tiny, "trials": 100_000, "chunk": 5_000})
    # 6 ms of CPU a chunk of one trial (2,000 of them against 20 of 100): about ten minutes
    assert many.adjustments * ADJUSTMENT_S > 300 > 10 * few.adjustments * ADJUSTMENT_S
