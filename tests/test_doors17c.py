"""The classes of the sweep doors17c (issue 26: a new user's realistic mistakes in the first
hour, with README.md and docs/*.md open), one case each; each failed on the code before its
fix.

* a point typed with one coordinate in metres and the other in millimetres (``x_m = 0.15,
  y_mm = 120.0``: the README's network edited by hand) was accepted, the point silently a
  thousand times off in one axis (docs/network.md: one unit per field); the same for a grid's
  ``spacing_m`` with ``origin_mm`` and a random set's ``half_extent_m`` with ``center_mm``
  (:func:`sim.studies.network.validate.one_unit`);
* a ``network.gama_xml`` file with one ``fix="xy"`` point and ``adj="XY"`` points (which
  gama-local adjusts, and which the suite's own export writes for an inner datum with one
  fixed point: ``tests/data/gama/one_fixed.xml``), read with the study file of docs/gama.md,
  was refused with "a rank defect of 1 ... that the datum (0 constraints) does not cover"
  (:func:`sim.studies.network.gama.merge_gama`);
* ``st.run(out=...)`` into a directory it may not use answered in the command line's words
  ("--out: ... use --overwrite to replace it"), naming an option a caller of ``run()`` cannot
  pass: the API names ``out`` and ``overwrite=True`` (:func:`sim.api._api_words`);
* ``sim.Results("studies", "network").claims()`` (a directory that holds no results) said
  "network has no table 'claims'; it has " and an empty list, not that the directory is not
  a results directory (:meth:`sim.api.Results.table`);
* ``python -m sim.batch --results FILE`` (a file, or a dangling link, where the results
  directory goes) started every run, each failing with "--out: cannot write to FILE: Not a
  directory", one line per study naming an option the command line did not hold
  (:func:`sim.batch.main`);
* a mistyped option where an argument is still missing (``sim --verison``, ``sim check
  --hlep``) was answered "the following arguments are required: COMMAND" (or ``study``),
  naming what the user did not do wrong and not the option (:class:`sim.cli_args._Parser`);
* ``--set “plate.grid=4”`` (typographic quotes pasted from a web page) answered
  "“plate.grid: unknown key (did you mean plate.grid?)", a guess that reads as the key
  given; the quote is named (:func:`sim.mc.config.validate`); so is one in a study file
  (``study = “network”``: "malformed TOML: Invalid value (at line 1, column 9)" alone,
  :func:`sim.mc.config.read_toml`);
* the study named as a new user names it (``sim check brown_table1``, ``studies/brown_table1``
  without ``.toml``, ``studies\\brown_table1.toml`` from Windows, ``sim.load("brown_table1")``)
  was "no such study file" with no way on; the file that exists is suggested
  (:func:`sim.mc.study_file.study_file_hint`); the same for a ``network.gama_xml`` path with
  Windows backslashes (:func:`sim.studies.network.gama_vocab.read_bytes`);
* a mistyped key of ``[sweep]`` (``network.nmae``) was "unknown key" with no guess, where the
  same typo outside ``[sweep]`` is answered with one (:func:`sim.mc.sweep.expand`).
"""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pytest
from oneline import one_line

import sim
from sim.batch import main as batch
from sim.cli import main

ROOT = Path(__file__).resolve().parent.parent
GAMA = ROOT / "tests" / "data" / "gama"

README_NET = """study = "network"
trials = 40
chunk = 2
[network]
points = [ { name = "A", x_mm = 0.0, y_mm = 0.0, role = "fixed" },
           { name = "B", x_mm = 400.0, y_mm = 0.0, role = "fixed" },
           { name = "C", x_mm = 400.0, y_mm = 300.0, role = "fixed" },
           { name = "D", x_mm = 0.0, y_mm = 300.0, role = "fixed" },
           { name = "P", x_mm = 150.0, y_mm = 120.0 } ]
generate = [ { kind = "distance", from = ["A", "B", "C", "D"], to = "P", sigma_mm = 0.002 },
             { kind = "direction", from = ["A", "B", "C", "D"], to = "*", sigma_arcsec = 2.0 } ]
"""


@pytest.mark.parametrize(
    ("edit", "needles"),
    [
        (("x_mm = 150.0", "x_m = 0.15"), ("network.points[4].x_m", "y_mm", "one unit")),
        (
            (
                "[network]\n",
                '[network]\ngrids = [ { prefix = "N", nx = 2, ny = 2, '
                "spacing_m = 0.02, origin_mm = [100.0, 100.0] } ]\n",
            ),
            ("network.grids[0].spacing_m", "origin_mm", "one unit"),
        ),
        (
            (
                "[network]\n",
                '[network]\nrandom = [ { prefix = "R", n = 3, '
                "half_extent_mm = 50.0, center_m = [0.2, 0.15] } ]\n",
            ),
            ("network.random[0].center_m", "half_extent_mm", "one unit"),
        ),
    ],
)
def test_a_point_with_metres_and_millimetres_is_refused(tmp_path, capsys, edit, needles):
    study = tmp_path / "net.toml"
    study.write_text(README_NET.replace(*edit))
    one_line(capsys, main(["check", str(study)]), *needles)
    ok = tmp_path / "ok.toml"  # one unit per point, either one: accepted
    ok.write_text(README_NET.replace("x_mm = 150.0, y_mm = 120.0", "x_m = 0.15, y_m = 0.12"))
    assert main(["check", str(ok)]) == 0


def test_a_gama_file_with_one_fixed_point_and_xy_points_is_read_as_gama_local_reads_it(
    tmp_path, monkeypatch
):
    study = tmp_path / "g.toml"
    xml = (GAMA / "one_fixed.xml").as_posix()
    study.write_text(f'study = "network"\ntrials = 40\nchunk = 2\n[network]\ngama_xml = "{xml}"\n')
    st = sim.load(study)
    assert st.config["datum.kind"] == "inner"
    a = st.run().table("points").to_pydict()
    b = sim.load(GAMA / "one_fixed.toml", trials=40, chunk=2).run().table("points").to_pydict()
    assert a["point"] == b["point"] == ["B", "C", "D"]
    for k in ("sigma_x_mm", "sigma_y_mm"):  # the same precision as the hand-written study
        np.testing.assert_allclose(a[k], b[k], rtol=1e-9)
    # two fixed points leave no defect: adj="XY" then changes nothing (the fixed datum)
    tf = (GAMA / "testfield.xml").read_text().replace('adj="xy"', 'adj="XY"', 1)
    (tmp_path / "tf.xml").write_text(tf)
    study.write_text('study = "network"\ntrials = 40\nchunk = 2\n[network]\ngama_xml = "tf.xml"\n')
    monkeypatch.chdir(tmp_path)
    assert sim.load(study).config["datum.kind"] == "fixed"


def test_the_api_names_its_own_arguments_for_an_output_directory_it_refuses(tmp_path):
    net = tmp_path / "net.toml"
    net.write_text(README_NET)
    st = sim.load(net)
    st.run(out=tmp_path / "o")
    brown = sim.load(ROOT / "studies" / "brown_table1.toml", trials=40, chunk=2)
    with pytest.raises(sim.ConfigError) as e:
        brown.run(out=tmp_path / "o")
    assert str(e.value).startswith("out: ") and "overwrite=True" in str(e.value)
    assert "--" not in str(e.value)
    with pytest.raises(sim.ConfigError, match=r"^out: .*choose another out\)$"):
        st.run(out=net)
    assert net.read_text() == README_NET and (tmp_path / "o" / "run.json").is_file()


def test_results_of_a_directory_without_tables_names_the_directory(tmp_path):
    (tmp_path / "notes.txt").write_text("mine")
    with pytest.raises(sim.ConfigError, match=r"^path: .* is not a results directory"):
        sim.Results(tmp_path, "network").claims()


@pytest.mark.parametrize("kind", ["file", "dangling link"])
def test_batch_results_that_is_not_a_directory_is_one_line_before_any_run(tmp_path, capsys, kind):
    net = tmp_path / "net.toml"
    net.write_text(README_NET)
    res = tmp_path / "res"
    if kind == "file":
        res.write_text("mine")
    else:
        res.symlink_to(tmp_path / "nowhere")
    rc = batch(["--results", str(res), str(net), "--", "--no-figures"])
    why = "is not a directory" if kind == "file" else "is a symbolic link to "  # (left5)
    one_line(capsys, rc, "sim.batch: --results: ", why)
    assert not (tmp_path / "nowhere").exists()
    assert kind != "file" or res.read_text() == "mine"


@pytest.mark.parametrize(
    ("argv", "needles"),
    [
        (
            ["--verison"],
            (
                "sim: error: unrecognized arguments: --verison (did you mean --version?) (see sim --help)",
            ),
        ),
        (["check", "--hlep"], ("sim check: unrecognized arguments: --hlep",)),
        (["run", "--trails=40"], ("sim run: unrecognized arguments: --trails=40",)),
        (["run", "--no-figures"], ("sim run: the following arguments are required: study",)),
    ],
)
def test_a_mistyped_option_is_named_before_a_missing_argument(capsys, argv, needles):
    one_line(capsys, main(argv), *needles)


def test_a_key_with_a_typographic_quote_names_the_quote(capsys):
    brown = str(ROOT / "studies" / "brown_table1.toml")
    line = one_line(capsys, main(["check", brown, "--set", "\u201cplate.grid=4\u201d"]))
    assert "typographic quote \u201c" in line and "did you mean" not in line


def test_a_study_file_with_typographic_quotes_names_the_quote(tmp_path, capsys):
    study = tmp_path / "net.toml"
    study.write_text(
        README_NET.replace('y_mm = 0.0, role = "fixed"', "y_mm = 0.0, role = \u201cfixed\u201d"),
        encoding="utf-8",
    )
    one_line(
        capsys,
        main(["check", str(study)]),
        "malformed TOML",
        "at line 5",
        "typographic quote \u201c",
    )
    study.write_text(README_NET.replace("trials = 40", "trials = "), encoding="utf-8")
    assert "typographic" not in one_line(capsys, main(["check", str(study)]), "malformed TOML")


@pytest.mark.parametrize(
    "name",
    ["brown_table1", "brown_table1.toml", "studies/brown_table1", "studies\\brown_table1.toml"],
)
def test_a_study_named_without_its_path_suggests_the_file(capsys, monkeypatch, name):
    monkeypatch.chdir(ROOT)
    hint = "(did you mean studies/brown_table1.toml?)"
    one_line(capsys, main(["check", name]), "no such study file", hint)
    with pytest.raises(sim.ConfigError, match=r"^study_file: .*" + re.escape(hint)):
        sim.load(name)
    assert one_line(capsys, main(["check", "nosuch"])).endswith("nosuch: no such study file")


def test_a_gama_path_with_backslashes_suggests_the_file(tmp_path, capsys, monkeypatch):
    monkeypatch.chdir(ROOT)
    study = tmp_path / "g.toml"
    study.write_text(
        'study = "network"\ntrials = 40\nchunk = 2\n[network]\n'
        'gama_xml = "tests\\\\data\\\\gama\\\\one_fixed.xml"\n'
    )
    one_line(
        capsys,
        main(["check", str(study)]),
        "network.gama_xml: cannot read tests\\data\\gama\\one_fixed.xml",
        "(did you mean tests/data/gama/one_fixed.xml?)",
    )


def test_a_mistyped_sweep_key_is_answered_with_a_guess(tmp_path, capsys):
    study = tmp_path / "s.toml"
    study.write_text(README_NET + '[sweep]\nnetwork.nmae = ["a", "b"]\n')
    one_line(
        capsys,
        main(["check", str(study)]),
        "sweep.network.nmae: unknown key (did you mean sweep.network.name?)",
    )
