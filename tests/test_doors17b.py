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
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from sim.cli import main
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
