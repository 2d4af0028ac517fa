"""The classes of the confirmation sweep doors16 (issue 26: every key of every study file,
the documented promises, GNU Gama's vocabulary), one case each; each failed on the code
before its fix.

* a network whose observations are fewer than its unknowns and leave a rank defect
  (``network.generate = []`` in ``studies/network_testfield.toml``) ended in NumPy's
  "zero-size array to reduction operation minimum" (the API's ``ValueError``, the command
  line's "sim: error: ValueError: ..." naming no key): the reduced SVD of a wide matrix
  holds no null space (:func:`sim.studies.network.rank_defect._parameters`);
* Wolf's ``table1.file``/``table3.file`` naming a file too long for the file system raised
  pathlib's ``OSError`` from ``sim.load`` (the command line's line named no key), and one
  holding a line break gave a two-line ``ConfigError`` (:mod:`sim.studies.wolf.tables`); so did
  ``network.gama_xml`` (:func:`sim.studies.network.gama_vocab.read_bytes`);
* a free point no observation reaches, in a network below the sparse path's size, was blamed
  on ``datum.kind`` ("a rank defect ... fix points, add observations, or use datum.kind =
  inner", which does not help) without naming the point, as docs/network.md promises and the
  sparse path does (:func:`sim.studies.network.schema.check`);
* a point or observation of a ``network.gama_xml`` file that the network refuses (a sight to
  itself: gama-local reads it) was named by ``network.observations``, a key the study file
  does not hold, and not by the file (:func:`sim.studies.network.schema._build`);
* ``sim show`` printed another study's claims table copied into a results directory as this
  run's, exit 0 (docs/cli.md: a table replaced by hand is one line naming the directory;
  :func:`sim.report.read.check_claims_table`);
* a ``network.gama_xml`` file without a fixed point and with ``adj="XY"`` points is adjusted
  in the inner datum (docs/gama.md), but ``sim check`` and the run record showed the study
  file's ``datum.kind = 'fixed'`` (:func:`sim.studies.network.schema.check`);
* Brown's closure note said "1.7 um per setting (double) and the comparator's 1.1 um" whatever
  ``errors.*`` said (:func:`sim.studies.brown.claims._closure`);
* explicit ``datum.constraints`` that leave a rank defect (a coefficient of 1e-300: legal, but
  no constraint) were blamed on ``datum.kind`` (the earlier class was NaN or inf there);
* brown_design's chi-square false-alarm self-checks compared the rate of a test run at
  ``coverage.alpha`` with the book's 5 %: at any other legal level (0.01, 1e-12) the
  self-check "failed" (:func:`sim.studies.design.claims._at_level`).

Sentences of the documentation found false and corrected: docs/cli.md and docs/python.md
("picks the largest chunk": ``--trials`` keeps the file's chunk when it gives 20 chunks);
docs/network.md (a decimal angle in a gama-local file is gon, not degrees; ``<vectors>`` are
read, not refused).
"""

from __future__ import annotations

import shutil
from pathlib import Path

import numpy as np
import pytest
from oneline import one_line

import sim
from sim.cli import main
from sim.studies.brown.claims import _closure
from sim.studies.design import claims as design_claims

ROOT = Path(__file__).resolve().parent.parent


def test_a_network_with_fewer_observations_than_unknowns_names_the_datum(tmp_path, capsys):
    study = tmp_path / "free.toml"  # nothing holds it: the rank defect's message
    study.write_text(
        (ROOT / "studies/network_testfield.toml")
        .read_text()
        .replace('role = "fixed"', 'role = "free"')
    )
    # every point reached by one of two angles (8 unknowns): the rank defect, named
    sets = {
        "network.generate": [],
        "network.grids": [],
        "compare.fix": [],
        "output.inner_over": [],
        "network.observations": [
            {"kind": "angle", "at": "A", "from": "B", "to": "C", "sigma_arcsec": 2.0},
            {"kind": "angle", "at": "D", "from": "C", "to": "A", "sigma_arcsec": 2.0},
        ],
    }
    with pytest.raises(sim.ConfigError) as e:
        sim.load(str(study), **sets)
    assert e.value.key == "datum.kind" and "rank defect of 6" in str(e.value), str(e.value)
    # the points that no observation reaches (the file's one angle reaches three): named
    err = one_line(capsys, main(["check", str(study), "--set", "network.generate=[]"]))
    assert err.startswith("sim: error: network.points: points 'A', 'B', 'C' and 10 more"), err
    assert "no observation reaches them" in err, err


def test_a_gama_file_name_with_a_line_break_is_one_line():
    with pytest.raises(sim.ConfigError) as e:
        sim.load(str(ROOT / "studies/network_brown.toml"), **{"network.gama_xml": "a\nb"})
    assert e.value.key == "network.gama_xml" and "\n" not in str(e.value), str(e.value)


NETWORK = """study = "network"
trials = 200
chunk = 10
[network]
points = [ { name = "A", x_mm = 0.0, y_mm = 0.0, role = "fixed" },
           { name = "B", x_mm = 400.0, y_mm = 0.0, role = "fixed" },
           { name = "C", x_mm = 400.0, y_mm = 300.0, role = "fixed" },
           { name = "P", x_mm = 150.0, y_mm = 120.0 }, { name = "Q", x_mm = 10.0, y_mm = 20.0 } ]
generate = [ { kind = "distance", from = ["A", "B", "C"], to = "P", sigma_mm = 0.002 } ]
"""


def test_a_free_point_no_observation_reaches_is_named(tmp_path):
    study = tmp_path / "unobserved.toml"
    study.write_text(NETWORK)
    with pytest.raises(sim.ConfigError) as e:
        sim.load(str(study))
    assert e.value.key == "network.points", str(e.value)
    assert "point 'Q' is declared in the study file but no observation reaches it" in str(e.value)


def test_an_observation_of_a_gama_file_is_refused_naming_the_file(tmp_path):
    text = (ROOT / "tests/data/gama/user_defaults.xml").read_text()
    bad = '<distance to="A" val="1" />'  # from A to A: gama-local reads it
    xml = tmp_path / "self.xml"
    xml.write_text(text.replace('<distance to="B" val="250.19992006393608" />', bad, 1))
    study = tmp_path / "s.toml"
    study.write_text(
        f'study = "network"\ntrials = 200\nchunk = 10\n[network]\ngama_xml = "{xml}"\n'
    )
    with pytest.raises(sim.ConfigError) as e:
        sim.load(str(study))
    msg = str(e.value)
    assert e.value.key == "network.gama_xml" and "self.xml" in msg and "a sight to itself" in msg


@pytest.mark.parametrize(
    "value,words", [("a" * 5000, "File name too long"), ("a\nb", "control character")]
)
def test_a_table_file_name_the_file_system_refuses_is_one_line_naming_the_key(value, words):
    with pytest.raises(sim.ConfigError) as e:
        sim.load(str(ROOT / "studies/wolf_polynomial.toml"), **{"table3.file": value})
    assert e.value.key == "table3.file" and words in str(e.value), str(e.value)
    assert "\n" not in str(e.value)


def test_sim_show_refuses_another_studys_claims_copied_in(tmp_path, capsys):
    d = tmp_path / "brown_table1"
    shutil.copytree(ROOT / "results/brown_table1", d)
    shutil.copy(ROOT / "results/network_brown/claims.parquet", d / "claims.parquet")
    assert main(["show", str(d)]) == 2
    err = capsys.readouterr().err
    assert "a table of 'network'" in err and err.count("\n") == 1, err


def test_a_free_gama_file_resolves_the_inner_datum_it_is_adjusted_in(tmp_path, capsys):
    xml = tmp_path / "free.xml"  # adj="XY" and no fixed point: the inner datum (docs/gama.md)
    text = (ROOT / "tests/data/gama/user_defaults.xml").read_text()
    xml.write_text(text.replace('fix="xy"', 'adj="XY"'))
    study = tmp_path / "s.toml"
    study.write_text(
        f'study = "network"\ntrials = 200\nchunk = 10\n[network]\ngama_xml = "{xml}"\n'
    )
    assert sim.load(str(study)).config["datum.kind"] == "inner"
    assert main(["check", str(study)]) == 0
    assert 'datum.kind = "inner"' in capsys.readouterr().out


def test_brown_closure_note_states_the_configured_settings():
    """At errors.settings = 1 and a 3 um setting the note said "1.7 um per setting (double)"."""
    cfg = {"errors.settings": 1, "errors.setting_sigma_um": 3.0, "errors.comparator_sigma_um": 1.1}
    s0 = np.linspace(1.5, 2.5, 40)
    note = _closure(cfg, s0, 3.2)["brown.table1_closure.rms_um"].note
    assert "3 um per setting (single) and the comparator's 1.1 um" in note, note
    cfg.update({"errors.settings": 2, "errors.setting_sigma_um": 1.7})
    note = _closure(cfg, s0, 1.6)["brown.table1_closure.rms_um"].note
    assert "1.7 um per setting (double) and the comparator's 1.1 um" in note, note


def test_constraints_that_leave_a_defect_are_named(capsys):
    tiny = '[{"S1.x" = 1e-300}, {"S3.x" = 1.0}, {"S4.y" = 1.0, "S2.y" = 1.0}]'
    study = str(ROOT / "studies/network_brown.toml")
    assert main(["check", study, "--set", f"datum.constraints={tiny}"]) == 2
    err = capsys.readouterr().err
    assert err.startswith("sim: error: datum.constraints: ") and "rank defect of 3" in err, err


def test_brown_design_false_alarm_is_checked_at_the_configured_level():
    """The chi-square test ran at coverage.alpha, its rate was checked against 5 % (a self-check
    that failed at any other legal level)."""
    book = design_claims.load_book()
    design_claims._at_level(book, 0.01)
    s = book.spec("coverage.pivot.false_alarm")
    assert s["ref"] == 0.01 and s["tol"] == pytest.approx(0.002)
    book = design_claims.load_book()
    design_claims._at_level(book, 0.05)
    assert book.spec("coverage.affine.false_alarm") == design_claims.load_book().spec(
        "coverage.affine.false_alarm"
    )
