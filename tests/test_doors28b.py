"""The classes of the sweep doors28b (a study author porting study files between kinds, and a
batch of many study files), one case each; each failed on the code before its fix.

* A study file copied from another study with ``study`` changed (``brown_dilution.toml`` as
  ``gridplate_two_plates``, a network file as ``brown_table1``, Brown's keys under a network's
  ``[sweep]``, brown_dilution's key set by ``--set`` on brown_table1) was refused
  ``plate.format_mm: unknown key``, with a guess from the new study's own keys (``did you
  mean block.format_mm?``, agnard's own key): nothing named the study whose key it is, nor
  how many more of the file's keys were that study's (:mod:`sim.studies.ported`). A
  ``kind = "gridplate_two_plates"`` written to switch the study was answered "did you mean
  datum.kind?" (the network's datum); a file whose ``study`` line was deleted is told which
  studies its keys fit.
* A study file of one study named as another's (``mine/brown_table1.toml`` holding
  ``study = "brown_dilution"``, run by ``sim.batch --results R``): ``sim report --results R``
  compared the run's config with ``studies/brown_table1.toml``'s, key by key, "did not run the
  configuration of studies/brown_table1.toml: `checks.bias_shift_um` = 100 (the file: )" for
  every key of the other study; it now says whose run the directory holds
  (:func:`sim.report.glance.design_notes`).
* ``python -m sim.batch`` over many files: a file whose run would refuse its config (a ported
  file, a bad value, a study that does not exist) was found only when its run started, after
  the others had run (hours in ``make reproduce``); it is now resolved before any run, every
  such file named, one line each, exit 2 (:func:`sim.batch_checks._configs_problems`). Of
  several missing files or clashes only the first was named; a directory was "no study
  file", and a shell pattern that matched nothing said nothing of it
  (:func:`sim.mc.study_file.study_file_problem`, :func:`sim.batch_checks._clashes`); a run over the
  memory or work limit is refused with them.
"""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest

from sim import batch
from sim.cli import main
from tests.oneline import SIM_ERROR, one_line

ROOT = Path(__file__).resolve().parents[1]
STUDIES = ROOT / "studies"


def _ported(tmp_path: Path, source: str, kind: str, extra: str = "") -> str:
    """``studies/<source>.toml`` copied with ``study = "<kind>"`` (and ``extra`` appended)."""
    text = (STUDIES / f"{source}.toml").read_text(encoding="utf-8")
    lines = [f'study = "{kind}"' if s.startswith("study = ") else s for s in text.splitlines()]
    path = tmp_path / f"{source}_as_{kind}.toml"
    path.write_text("\n".join(lines) + "\n" + extra, encoding="utf-8")
    return str(path)


@pytest.mark.parametrize(
    ("source", "kind", "needles"),
    [
        (
            "brown_dilution",
            "gridplate_two_plates",
            ["plate.format_mm: unknown key of the study gridplate_two_plates", "brown_dilution"],
        ),
        ("brown_dilution", "agnard_block", ["plate.format_mm", "of brown_dilution that"]),
        ("network_plate", "brown_table1", ["network.name", "a key of network", "4 keys"]),
        ("brown_design", "brown_table1", ["scale.graduated_mm", "a key of brown_design"]),
        ("gridplate_two_plates", "wolf_polynomial", ["plate.grid", "gridplate_two_plates"]),
    ],
)
def test_a_file_ported_from_another_study_names_whose_keys_it_holds(
    capsys, tmp_path, source, kind, needles
):
    path = _ported(tmp_path, source, kind)
    line = one_line(capsys, main(["check", path]), *needles, prefix=SIM_ERROR)
    assert "did you mean" not in line, line  # no guess from the new study's own keys


def test_a_ported_file_counts_the_other_studys_keys(capsys, tmp_path):
    path = _ported(tmp_path, "brown_dilution", "gridplate_two_plates")
    line = one_line(capsys, main(["check", path]), "brown_dilution", prefix=SIM_ERROR)
    # every key of the file that gridplate_two_plates has not is brown_dilution's
    assert "the file holds 14 keys of brown_dilution" in line and "11 more" in line, line


def test_a_sweep_of_another_studys_key_is_named_with_that_study(capsys, tmp_path):
    path = _ported(
        tmp_path, "network_plate", "network", '[sweep]\n"plate.spacing_mm" = [35.0, 45.0]\n'
    )
    one_line(
        capsys,
        main(["check", path]),
        "sweep.plate.spacing_mm: unknown key of the study network",
        "brown_dilution",
        prefix=SIM_ERROR,
    )


def test_an_override_of_another_studys_key_names_that_study_alone(capsys):
    argv = ["check", str(STUDIES / "brown_table1.toml"), "--set", "dilution.grids=[3,4]"]
    line = one_line(capsys, main(argv), "dilution.grids", "a key of brown_dilution")
    assert "the file holds" not in line, line  # the key is the override's, not the file's


def test_a_key_of_no_study_keeps_its_guess(capsys):
    argv = ["check", str(STUDIES / "brown_table1.toml"), "--set", "plate.gird=4"]
    line = one_line(capsys, main(argv), "plate.gird: unknown key (did you mean plate.grid?)")
    assert "a key of" not in line, line


def test_a_file_of_a_study_whose_keys_the_other_reads_still_loads(capsys, tmp_path):
    # brown_table1's keys are all brown_dilution's: the port is legitimate
    path = _ported(tmp_path, "brown_table1", "brown_dilution")
    assert main(["check", path]) == 0
    assert "brown_dilution" in capsys.readouterr().out


def test_the_python_api_names_the_other_studys_key_too(tmp_path):
    import sim

    path = _ported(tmp_path, "network_plate", "brown_table1")
    with pytest.raises(sim.ConfigError, match=r"network\.name: .*a key of network"):
        sim.load(path, trials=40)


def test_a_results_directory_named_as_another_study_is_not_compared_key_by_key(capsys, tmp_path):
    shutil.copytree(ROOT / "results" / "brown_dilution", tmp_path / "brown_table1")
    assert main(["report", "--results", str(tmp_path)]) == 0
    capsys.readouterr()
    text = (tmp_path / "REPORT.md").read_text(encoding="utf-8")
    assert "(the file: )" not in text and "did not run the configuration" not in text
    assert "holds a run of the study `brown_dilution`, not of `studies/brown_table1.toml`" in text


def test_kind_written_for_study_says_how_a_file_names_its_study(capsys, tmp_path):
    path = tmp_path / "kind.toml"
    text = (STUDIES / "network_plate.toml").read_text(encoding="utf-8")
    path.write_text('kind = "gridplate_two_plates"\n' + text, encoding="utf-8")
    line = one_line(capsys, main(["check", str(path)]), 'write study = "gridplate_two_plates"')
    assert line.startswith(f"{SIM_ERROR}kind: unknown key") and "datum.kind" not in line, line


def test_a_file_without_study_is_told_which_studies_its_keys_fit(capsys, tmp_path):
    path = tmp_path / "nostudy.toml"
    text = (STUDIES / "brown_table1.toml").read_text(encoding="utf-8")
    path.write_text(text.replace('study = "brown_table1"', ""), encoding="utf-8")
    one_line(
        capsys,
        main(["check", str(path)]),
        "study: missing",
        "every key of the file is a key of brown_dilution, brown_table1",
        prefix=SIM_ERROR,
    )
    path.write_text("trials = 40\n", encoding="utf-8")  # keys of every study: no list
    line = one_line(capsys, main(["check", str(path)]), "study: missing")
    assert "every key" not in line, line


def _lines(capsys) -> list[str]:
    """Standard error's lines since the last read, each one a line of the batch driver."""
    err = capsys.readouterr().err
    lines = err.splitlines()
    assert err.endswith("\n") and "Traceback" not in err, err
    assert all(line.startswith("sim.batch: ") for line in lines), err
    return lines


def test_a_batch_names_every_broken_file_before_any_run(capsys, tmp_path):
    good = tmp_path / "good.toml"
    good.write_text((STUDIES / "network_plate.toml").read_text(encoding="utf-8"))
    files = [
        good,
        Path(_ported(tmp_path, "brown_dilution", "gridplate_two_plates")),
        Path(_ported(tmp_path, "network_plate", "brown_table1")),
        tmp_path / "nosuch_study.toml",
        tmp_path / "typo.toml",
    ]
    files[3].write_text('study = "nosuch"\n')
    files[4].write_text(good.read_text().replace("seed = 1", "seed = -1"))
    results = tmp_path / "R"
    rc = batch.main(["--results", str(results), *map(str, files), "--", "--trials", "40"])
    lines = _lines(capsys)
    assert rc == 2 and len(lines) == 4, lines
    for f, needle in zip(
        files[1:], ["plate.format_mm: unknown key", "network.name", "study: unknown", "seed"]
    ):
        assert any(line.startswith(f"sim.batch: {f}: ") and needle in line for line in lines), (
            f,
            lines,
        )
    assert not results.exists()  # no run started, the good file's neither


def test_a_batch_names_every_missing_file_and_every_clash(capsys, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    (tmp_path / "d").mkdir()
    (tmp_path / "d" / "a.toml").write_text((STUDIES / "network_plate.toml").read_text())
    (tmp_path / "a.toml").write_text((STUDIES / "network_plate.toml").read_text())
    (tmp_path / "b.toml").write_text((STUDIES / "network_plate.toml").read_text())
    argv = ["a.toml", "nope1.toml", "d", "no*.toml", "nope2.toml", "d/a.toml", "b.toml", "./b.toml"]
    assert batch.main(argv) == 2
    lines = _lines(capsys)
    assert lines == [
        "sim.batch: nope1.toml: no such study file",
        "sim.batch: d: is a directory, not a study file (its study files are d/*.toml)",
        "sim.batch: no*.toml: no such study file (a pattern that matched no file: the shell "
        "passed it on as it is)",
        "sim.batch: nope2.toml: no such study file",
        "sim.batch: a.toml and d/a.toml would both write results/a",
        "sim.batch: b.toml is listed twice",
    ], lines
    assert not (tmp_path / "results").exists()


def test_a_batch_names_a_pipe_as_no_regular_file(capsys, tmp_path):
    import os

    os.mkfifo(tmp_path / "pipe.toml")  # there, but no study file: was "no study file"
    assert batch.main([str(tmp_path / "pipe.toml"), "/dev/null"]) == 2
    assert _lines(capsys) == [
        f"sim.batch: {tmp_path / 'pipe.toml'}: not a regular file (a pipe or a device): name "
        "the study file",
        "sim.batch: /dev/null: not a regular file (a pipe or a device): name the study file",
    ]


def test_a_batch_refuses_a_run_over_the_work_limit_before_any_run(capsys, tmp_path):
    good = tmp_path / "good.toml"
    good.write_text((STUDIES / "network_plate.toml").read_text(encoding="utf-8"))
    big = tmp_path / "big.toml"  # a run its own start refuses, after the others had run
    big.write_text(good.read_text().replace("trials = 2000", "trials = 1000000"))
    big.write_text(big.read_text().replace("chunk = 100", "chunk = 10000"))
    results = tmp_path / "R"  # about 9e6 adjustments, the good file's 2e4
    argv = ["--results", str(results), str(good), str(big), "--", "--max-adjustments", "1e6"]
    assert batch.main(argv) == 2
    (line,) = _lines(capsys)
    assert line.startswith(f"sim.batch: {big}: network: the run needs") and "limit" in line
    assert not results.exists()


def test_a_batch_refuses_results_its_runs_would_not_replace_before_any_run(capsys, tmp_path):
    files = []
    for name in ("a", "b", "c", "d"):
        files.append(tmp_path / f"{name}.toml")
        files[-1].write_text((STUDIES / "network_plate.toml").read_text(encoding="utf-8"))
    results = tmp_path / "R"
    results.mkdir()
    (results / "b").symlink_to(tmp_path)  # each run refused it, after the others had run
    (results / "c").write_text("mine")
    (results / "d").mkdir()
    (results / "d" / "notes.txt").write_text("mine")
    assert batch.main(["--results", str(results), *map(str, files), "--", "--trials", "40"]) == 2
    lines = _lines(capsys)
    assert len(lines) == 3, lines
    for name, needle in (("b", "symbolic link"), ("c", "is a file"), ("d", "no sim run record")):
        assert any(
            line.startswith(f"sim.batch: {tmp_path / name}.toml: --results: {results / name} ")
            and needle in line
            for line in lines
        ), (name, lines)
    assert sorted(p.name for p in results.iterdir()) == ["b", "c", "d"]  # a was not run
    assert (results / "d" / "notes.txt").read_text() == "mine"
