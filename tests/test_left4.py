"""What the last session left under issue 26 (brief L4), one case each; each failed on the code
before its fix.

* ``TQDM_NCOLS=abc`` (any ``TQDM_`` variable tqdm cannot read) ended ``sim.load(...)`` of the
  Python API in a traceback from ``tqdm.utils`` while ``sim.api`` was imported (only the
  command lines checked the variables): tqdm is imported by a bar only, and ``sim.load`` (or a
  bar, if the variable is set later) refuses with one :class:`sim.ConfigError` naming the
  variable (:func:`sim.mc.progress.check_environment`);
* a ``[sweep]`` of ``datum.kind`` over a GNU Gama file with ``adj="XY"`` points and fewer than
  two fixed points ran its "fixed" cell in the inner datum while ``sweep.parquet`` labelled it
  "fixed": the fallback is the default's only (:func:`sim.mc.config.given`); an explicit
  ``fixed`` (file, ``--set``, API, sweep cell) is refused naming the key and the number of
  fixed points, and the sweep records that cell as infeasible with the reason;
* ``python -m sim.batch a.toml b.toml -- --set nosuch=1`` printed one "unknown key" line per
  study after starting each run: a key no study of the batch has is one line and exit 2 before
  any run; a key only some lack is said once before the runs start
  (:func:`sim.batch_checks._unknown_sets`);
* ``[sweep] trials = 40`` (one value, not a list) was read as a sweep of one cell: any swept
  key given one value is refused with one short line naming ``sweep.<key>`` and showing the
  list it takes;
* the work estimate left out the region parts of brown, brown_design and salsig (salsig's
  ``region.trials`` at its bound asked for ~9 GiB and hours, and was estimated at seconds and
  108 MiB), and counted agnard's about 30 times high: each is now measured
  (:mod:`sim.mc.estimate`, :func:`sim.mc.workunits.design_estimate`);
* a relative ``network.gama_xml`` is read from the working directory (documented); run from
  elsewhere, the file beside the study file was "cannot read x.xml: No such file" with no
  hint: the line now names the working directory and the file that exists
  (:func:`sim.studies._beside_the_study`);
* ``sim run --out .`` (or ``..`` from a subdirectory) inside an earlier results directory
  replaced the directory the shell was in and printed "results in ./" (the shell saw an empty,
  deleted directory): an existing ``--out`` that holds the working directory is refused with
  one line, before anything is written (:func:`sim.mc.outputs.check_out`);
"""

import os
import subprocess
import sys
from pathlib import Path

import pyarrow.parquet as pq
import pytest
from oneline import SIM_ERROR, one_line

import sim
from sim.batch import main as batch_main
from sim.batch_checks import _unknown_sets
from sim.cli import main
from sim.mc.estimate import ADJUSTMENT_S, check_limits, estimate
from sim.studies import load_study

ROOT = Path(__file__).resolve().parents[1]
BROWN = ROOT / "studies" / "brown_table1.toml"
GAMA = ROOT / "tests" / "data" / "gama"


def _python(env: dict, *lines: str) -> subprocess.CompletedProcess:
    code = "\n".join(lines) + "\n"
    return subprocess.run(
        [sys.executable, "-c", code],
        capture_output=True,
        text=True,
        timeout=120,
        env={**os.environ, **env},
    )


def test_tqdm_variables_are_one_config_error_of_the_api_not_a_traceback_at_import():
    for env, name in (
        ({"TQDM_NCOLS": "abc"}, "TQDM_NCOLS"),
        ({"TQDM_POSITION": "1.5"}, "TQDM_POSITION"),
    ):
        p = _python(
            env,
            "import sim, sim.api, sim.mc.progress",  # importing is not using a bar
            "try:",
            f"    sim.load({str(BROWN)!r}, trials=40)",
            "except sim.ConfigError as e:",
            "    print('refused:', e)",
        )
        out = p.stdout.strip()
        assert p.returncode == 0 and p.stderr == "", (env, p.stderr)
        assert "\n" not in out and out.startswith(f"refused: {name}: tqdm cannot read it"), out


def test_a_tqdm_variable_set_after_loading_is_refused_by_the_bar():
    # TQDM_LOCK_ARGS=x passes tqdm's import and fails only when a bar is drawn
    p = _python(
        {},
        "import os, sim",
        "from sim.mc.progress import Progress",
        "os.environ['TQDM_LOCK_ARGS'] = 'x'",
        "try:",
        "    Progress(10, 'x')",
        "except sim.ConfigError as e:",
        "    print('refused:', e)",
    )
    out = p.stdout.strip()
    assert p.returncode == 0 and p.stderr == "", p.stderr
    assert out.startswith("refused: TQDM_LOCK_ARGS: tqdm cannot read it"), out


def test_good_tqdm_variables_still_run():
    p = _python(
        {"TQDM_NCOLS": "80"},
        "import sim",
        f"h = sim.load({str(BROWN)!r}, trials=40)",
        "print(type(h).__name__)",
    )
    assert p.returncode == 0 and p.stdout.strip() == "StudyHandle", p.stderr


def _one_fixed(tmp_path, extra: str = "") -> Path:
    study = tmp_path / "s.toml"
    study.write_text(
        f'study = "network"\ntrials = 40\nchunk = 2\n[network]\n'
        f'gama_xml = "{GAMA / "one_fixed.xml"}"\n{extra}',
        encoding="utf-8",
    )
    return study


FIXED_WORDS = ("datum.kind", '"fixed" cannot hold', "one_fixed.xml has 1 fixed point")


def test_an_explicit_fixed_datum_that_cannot_hold_is_refused_the_default_falls_back(
    tmp_path, capsys
):
    study = _one_fixed(tmp_path)
    assert main(["check", str(study)]) == 0  # the default: gama-local's inner datum
    assert 'datum.kind = "inner"' in capsys.readouterr().out
    rc = main(["check", str(study), "--set", "datum.kind=fixed"])
    one_line(capsys, rc, *FIXED_WORDS, prefix=SIM_ERROR)
    rc = main(["check", str(_one_fixed(tmp_path, '[datum]\nkind = "fixed"\n'))])
    one_line(capsys, rc, *FIXED_WORDS, prefix=SIM_ERROR)
    with pytest.raises(sim.ConfigError) as e:
        sim.load(study, datum__kind="fixed")
    assert str(e.value).startswith('datum.kind: "fixed" cannot hold'), e.value
    assert sim.load(study, datum__kind="inner").config["datum.kind"] == "inner"


def test_a_swept_fixed_datum_that_cannot_hold_is_not_run_under_its_label(tmp_path, capsys):
    study = _one_fixed(tmp_path, '[sweep]\n"datum.kind" = ["fixed", "inner"]\n')
    out = tmp_path / "o"
    assert main(["run", str(study), "--quiet", "--out", str(out)]) == 0, capsys.readouterr().err
    rows = pq.read_table(out / "sweep.parquet").to_pylist()
    assert [r["datum.kind"] for r in rows] == ["fixed", "inner"]
    assert [r["feasible"] for r in rows] == [False, True]
    assert all(w in rows[0]["reason"] for w in FIXED_WORDS), rows[0]["reason"]


def test_a_set_key_no_study_of_the_batch_has_is_one_line_before_any_run(tmp_path, capsys):
    files = [str(BROWN), str(ROOT / "studies" / "network_plate.toml")]
    res = tmp_path / "res"
    for key in ("nosuch", "network.nosuch"):
        rc = batch_main([*files, "--results", str(res), "--", "--set", f"{key}=1"])
        line = one_line(capsys, rc, f"--set {key}: unknown key (no study of the batch has it)")
        assert line.startswith("sim.batch: run options: "), line
        assert not res.exists()  # refused before any run
    rc = batch_main([*files, "--results", str(res), "--", "--set", "nosuch"])
    one_line(capsys, rc, "--set needs key=value", prefix="sim.batch: run options: ")
    # a key some studies have: no problem, one note naming those that lack it
    why, note = _unknown_sets([Path(f) for f in files], ["--set", "plate.grid=4"])
    assert why is None and note == (
        "--set plate.grid: unknown to network_plate.toml (network), whose run will refuse it"
    )
    assert _unknown_sets([Path(f) for f in files], ["--set", "trials=40"]) == (None, None)


@pytest.mark.parametrize(
    "line, key, shown",
    [
        ("trials = 40", "sweep.trials", "trials = [40, 80]"),
        ('"errors.settings" = 2', "sweep.errors.settings", '"errors.settings" = [2, 4]'),
        ("[sweep.errors]\nbias_um = 0.5", "sweep.errors.bias_um", '"errors.bias_um" = [0.5, 1.0]'),
    ],
)
def test_a_swept_key_given_one_value_is_refused_naming_it(tmp_path, capsys, line, key, shown):
    study = tmp_path / "s.toml"
    study.write_text(
        f'study = "brown_table1"\ntrials = 40\nchunk = 2\n[sweep]\n{line}\n', encoding="utf-8"
    )
    for cmd in ("check", "run"):
        rc = main([cmd, str(study), *(["--out", str(tmp_path / "o")] if cmd == "run" else [])])
        got = one_line(capsys, rc, f"{key}: a sweep takes a list, e.g. {shown}", prefix=SIM_ERROR)
        assert len(got) < 120, got
    assert not (tmp_path / "o").exists()
    with pytest.raises(sim.ConfigError, match=f"^{key}: a sweep takes a list"):
        sim.load(study)


#: CPU seconds of the region part alone (one core, process_time around the region's function)
#: between two sizes of its keys, measured for this estimate: the estimate's difference must
#: be within 3x of them (the estimate is an order-of-magnitude model)
REGION_SECONDS = [
    (
        "brown_table1",
        {"region.points": 256, "region.rounds": 0},
        {"region.points": 16384, "region.rounds": 8},
        6.2,
    ),
    (
        "brown_dilution",
        {"region.points": 256, "region.rounds": 0},
        {"region.points": 16384, "region.rounds": 8},
        31.5,
    ),
    (
        "brown_design",
        {"region.points": 256, "region.rounds": 0},
        {"region.points": 16384, "region.rounds": 8},
        9.4,
    ),
    (
        "brown_design",
        {"region.plate_points": 256, "unprinted.plates": 100},
        {"region.plate_points": 1024, "unprinted.plates": 400_000},
        102.0,
    ),
    (
        "salsig_encoders",
        {"region.points": 16, "region.trials": 200},
        {"region.points": 1024, "region.trials": 200},
        7.6,
    ),
    (
        "salsig_encoders",
        {"region.points": 128, "region.trials": 200},
        {"region.points": 128, "region.trials": 2000},
        5.6,
    ),
    (
        "agnard_block",
        {"region.points": 4, "region.trials": 20},
        {"region.points": 16, "region.trials": 600},
        45.6,
    ),
]


@pytest.mark.parametrize("study, small, big, seconds", REGION_SECONDS)
def test_the_work_estimate_counts_each_region_part_as_measured(study, small, big, seconds):
    path = ROOT / "studies" / f"{study}.toml"
    a, b = (estimate(load_study(path, values=v)[1]).adjustments for v in (small, big))
    est_s = (b - a) * ADJUSTMENT_S
    assert seconds / 3 < est_s < seconds * 3, (study, big, est_s, seconds)


def test_region_keys_at_their_bounds_are_refused_and_the_study_files_are_not():
    for study in (
        "brown_table1",
        "brown_dilution",
        "brown_design",
        "salsig_encoders",
        "agnard_block",
    ):
        check_limits(estimate(load_study(ROOT / "studies" / f"{study}.toml")[1]))
    for study, bound, words in (
        ("salsig_encoders", {"region.trials": 1_000_000}, "over the 8 GiB limit"),
        ("agnard_block", {"region.points": 64, "region.trials": 1_000_000}, "over the limit of"),
    ):
        cfg = load_study(ROOT / "studies" / f"{study}.toml", values=bound)[1]
        with pytest.raises(sim.ConfigError, match=words):
            check_limits(estimate(cfg), max_memory_gb=8, max_adjustments=5e8)


def test_a_relative_gama_file_beside_the_study_is_named_when_run_from_elsewhere(
    tmp_path, monkeypatch, capsys
):
    (tmp_path / "studies").mkdir()
    (tmp_path / "studies" / "x.xml").write_bytes((GAMA / "one_fixed.xml").read_bytes())
    study = tmp_path / "studies" / "x.toml"
    study.write_text(
        'study = "network"\ntrials = 40\nchunk = 2\n[network]\ngama_xml = "x.xml"\n',
        encoding="utf-8",
    )
    monkeypatch.chdir(tmp_path)
    rc = main(["check", "studies/x.toml"])
    one_line(
        capsys,
        rc,
        f"network.gama_xml: x.xml not found in {tmp_path}",
        "studies/x.xml exists: run from studies or give an absolute path",
        prefix=SIM_ERROR,
    )
    with pytest.raises(sim.ConfigError, match="studies/x.xml exists"):
        sim.load("studies/x.toml")
    monkeypatch.chdir(tmp_path / "studies")  # the documented rule: the working directory
    assert main(["check", "x.toml"]) == 0
    capsys.readouterr()
    # a path that exists nowhere keeps its plain line
    monkeypatch.chdir(tmp_path)
    rc = main(["check", "studies/x.toml", "--set", "network.gama_xml=nosuch.xml"])
    one_line(capsys, rc, "cannot read nosuch.xml: No such file", prefix=SIM_ERROR)


def test_an_out_that_holds_the_working_directory_is_refused_and_left_alone(
    tmp_path, monkeypatch, capsys
):
    out = tmp_path / "o"
    argv = ["run", str(BROWN), "--trials", "40", "--quiet", "--no-figures"]
    assert main([*argv, "--out", str(out)]) == 0
    capsys.readouterr()
    before = sorted(p.name for p in out.iterdir())
    inode = out.stat().st_ino
    (out / "trials").mkdir(exist_ok=True)
    for cwd, given in ((out, "."), (out / "trials", ".."), (out / "trials", str(out))):
        monkeypatch.chdir(cwd)
        rc = main([*argv, "--overwrite", "--out", given])
        one_line(capsys, rc, f"--out: {given} holds the working directory", prefix=SIM_ERROR)
        assert out.stat().st_ino == inode and os.getcwd() == str(cwd)
    assert sorted(p.name for p in out.iterdir()) == sorted(set(before) | {"trials"})
    monkeypatch.chdir(tmp_path)  # from outside: replaced as ever
    assert main([*argv, "--overwrite", "--out", "o"]) == 0


def test_the_plate_region_of_brown_design_counts_its_memory():
    # measured: 211 MB more for 100,000 plates at one input vector (maxrss around the region);
    # the chains of the study's bayes.steps = 8000 (0.57 GiB) are more: 500 steps (37 MB) here
    path = ROOT / "studies" / "brown_design.toml"
    values = {"unprinted.plates": 100_000, "bayes.steps": 500}
    est = estimate(load_study(path, values=values)[1])
    assert 211e6 / 3 < est.bytes < 211e6 * 3 and "plate region" in est.largest, est
