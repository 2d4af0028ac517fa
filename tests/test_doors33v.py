"""The classes of the sweep doors33v (brief V33: ``make verify`` of results made with
overrides), one case each; each failed on the code before its fix.

* Results made with overrides (``sim run studies/brown_table1.toml --set plate.grid=4 --seed
  7 --out R/brown_table1``) were re-run from the study file as written and reported "of
  another config" (exit 1) after a full re-run: such results were never verified. ``run.json``
  now records the run's overrides (``overrides``: ``KEY=VALUE`` texts, the value as given
  written as TOML, sorted by key), and verify re-runs the study file with exactly them: "ok",
  deviation 0, "reproduced with the run's overrides: ...". A study file edited since the run
  is still another config, naming only the key the edit changed (it named every override too).
* ``--trials N`` (the Monte-Carlo level) re-ran such results from the file as written with
  verify's own values alone, comparing a grid of 4 points a side with the file's 5 without a
  word; it now keeps the run's other overrides (its trials and chunk are verify's).
* The Python API (``sim.load(path, key=value).run(trials=, seed=)``) and ``python -m sim.batch
  ... -- --set ...`` record the same overrides, byte for byte the ``run.json`` of ``sim run``
  with the same values given in another order.
* Overrides of TOML arrays of inline tables (a network's points), strings with quotes, spaces,
  brackets and an ``=``, and a ``network.gama_xml`` file round-trip exactly: the re-run's
  config is the run's, every table equal.
* An override too long for a command line (a network's observations given to ``sim.load``,
  over 128 KiB) made the re-run "Argument list too long", exit 2: such results could not be
  verified. The re-run now reads such arguments from its standard input, and verify's line
  shows each override cut to 100 characters.
* A ``run.json`` whose overrides were edited by hand (an option such as ``--out=DIR``, text
  after a value, a key the config has not, a key twice, not a list) is not passed on to the
  re-run: the study fails in one line naming the entry and the file, and nothing is re-run.
* An override the re-run refuses (a value the study no longer takes, as a key removed from the
  suite is refused) fails the study in one line naming the refusal (it was "the re-run exited
  with 2"); a relative ``network.gama_xml`` that is not in verify's working directory is said
  to be missing here, not stale.
"""

from __future__ import annotations

import hashlib
import json
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

import sim
from sim.report.verify import main as verify_main

ROOT = Path(__file__).resolve().parent.parent
BROWN = ROOT / "studies" / "brown_table1.toml"
TINY = ["trials=40", "chunk=2", "region.points=256", "region.rounds=0"]
#: the overrides the shared run records: sorted by key, --seed as seed=
RECORDED = [
    "chunk=2",
    "plate.grid=4",
    "region.points=256",
    "region.rounds=0",
    "seed=7",
    "trials=40",
]


def _py(*args, cwd=ROOT):
    return subprocess.run(
        [sys.executable, "-m", *map(str, args)],
        capture_output=True,
        text=True,
        cwd=cwd,
        timeout=300,
    )


def _verify(results, *more, cwd=ROOT):
    return _py("sim.report.verify", "--results", results, "--no-record", *more, cwd=cwd)


@pytest.fixture(scope="module")
def made(tmp_path_factory):
    """brown_table1's tiny run with overrides (the --seed option among them), as ``R``."""
    base = tmp_path_factory.mktemp("v33")
    sets = [x for s in ["plate.grid=4", *TINY] for x in ("--set", s)]
    run = _py(
        "sim",
        "run",
        BROWN,
        "--seed",
        "7",
        *sets,
        "--no-figures",
        f"--out={base / 'R' / 'brown_table1'}",
    )
    assert run.returncode == 0, run.stderr
    return base


def _rec(d: Path) -> dict:
    return json.loads((d / "run.json").read_text(encoding="utf-8"))


@pytest.mark.long
def test_results_made_with_overrides_are_verified_with_them(made, tmp_path):
    assert _rec(made / "R" / "brown_table1")["overrides"] == RECORDED
    out = _verify(made / "R", "--scratch", tmp_path / "S")  # before: "of another config", 1
    assert out.returncode == 0, out.stdout + out.stderr
    assert "brown_table1: ok; 6 files; largest relative deviation 0;" in out.stdout
    assert f"reproduced with the run's overrides: {', '.join(RECORDED)}" in out.stdout
    # the study file edited since the run: still another config, the edit's key alone named
    mine = tmp_path / "mine"
    mine.mkdir()
    text = BROWN.read_text(encoding="utf-8")
    assert "beta_mm = 1.0\n" in text
    (mine / "brown_table1.toml").write_text(text.replace("beta_mm = 1.0\n", "beta_mm = 0.5\n"))
    out = _verify(made / "R", "--scratch", tmp_path / "S", "--studies", mine)
    assert out.returncode == 1, out.stdout + out.stderr
    assert "another config than the re-run with the run's overrides" in out.stdout
    assert "(keys comparator.beta_mm): they are stale against" in out.stdout


@pytest.mark.long
def test_fewer_trials_keep_the_runs_other_overrides(made, tmp_path):
    """``--trials 400`` (the Monte-Carlo level): the run's trials and chunk are verify's, its
    other overrides the run's (they were dropped: a grid of 4 compared with the file's 5)."""
    out = _verify(made / "R", "--scratch", tmp_path / "S", "--trials", "400")
    assert out.returncode == 0, out.stdout + out.stderr
    kept = "plate.grid=4, region.points=256, region.rounds=0, seed=7"
    assert f"reproduced with the run's overrides: {kept}" in out.stdout
    cfg = _rec(tmp_path / "S" / "brown_table1")["config"]
    assert (cfg["plate.grid"], cfg["trials"], cfg["seed"]) == (4, 400, 7)


@pytest.mark.long
def test_the_api_and_the_batch_record_what_sim_run_records(made, tmp_path):
    h = sim.load(BROWN, chunk=2, plate__grid=4, **{"region.points": 256, "region.rounds": 0})
    res = h.run(out=tmp_path / "api" / "brown_table1", trials=40, seed=7, figures=False)
    assert _rec(res.path)["overrides"] == RECORDED  # before: no overrides recorded
    ours = made / "R" / "brown_table1"
    # the same record, but README.md's sha256: the README names its own directory's path
    a, b = _rec(res.path), _rec(ours)
    for rec, d in ((a, res.path), (b, ours)):
        assert (
            rec.pop("readme_sha256") == hashlib.sha256((d / "README.md").read_bytes()).hexdigest()
        )
    assert a == b
    sets = [x for s in [*TINY, "plate.grid=4"] for x in ("--set", s)]
    batch = _py("sim.batch", BROWN, "--results", tmp_path / "B", "--", "--seed", "7", *sets)
    assert batch.returncode == 0, batch.stderr
    assert _rec(tmp_path / "B" / "brown_table1")["overrides"] == RECORDED


POINTS = (
    '[{ name = "A", x_mm = 0.0, y_mm = 0.0, role = "fixed" }, { name = "B", x_mm = 250000.0, '
    'y_mm = 10000.0 }, {name="C", x_mm=240000.0, y_mm=260000.0}, {name="D", x_mm=-15000.5, '
    "y_mm=230000.0}]"
)


@pytest.mark.long
def test_arrays_quoted_strings_and_a_gama_file_round_trip(tmp_path):
    (tmp_path / "studies").mkdir()
    shutil.copy(ROOT / "tests" / "data" / "gama" / "one_fixed.toml", tmp_path / "studies")
    shutil.copy(ROOT / "tests" / "data" / "gama" / "plate.xml", tmp_path)
    (tmp_path / "studies" / "bare.toml").write_text('study = "network"\ntrials = 40\nchunk = 2\n')
    name = 'my "net" [1] = \u00fc'  # bare text: --set reads it as that string
    runs = [
        (
            "one_fixed",
            "--trials",
            "40",
            "--set",
            f"network.name={name}",
            "--set",
            f"network.points={POINTS}",
        ),
        ("bare", "--set", "network.gama_xml=plate.xml"),
    ]
    for study, *sets in runs:
        run = _py("sim", "run", f"studies/{study}.toml", *sets, "--out", f"R/{study}", cwd=tmp_path)
        assert run.returncode == 0, run.stderr
    assert _rec(tmp_path / "R" / "bare")["overrides"] == ['network.gama_xml="plate.xml"']
    assert _rec(tmp_path / "R" / "one_fixed")["overrides"][0] == (
        'network.name="my \\"net\\" [1] = \u00fc"'
    )
    out = _verify("R", "--scratch", "S", cwd=tmp_path)
    assert out.returncode == 0, out.stdout + out.stderr
    for study in ("bare", "one_fixed"):
        assert f"{study}: ok; 7 files; largest relative deviation 0;" in out.stdout
    assert (
        _rec(tmp_path / "S" / "one_fixed")["config"] == _rec(tmp_path / "R" / "one_fixed")["config"]
    )
    # verify elsewhere: the relative file is not there (not "stale")
    elsewhere = _verify(tmp_path / "R", "--studies", tmp_path / "studies", "--study", "bare")
    assert elsewhere.returncode == 1, elsewhere.stdout + elsewhere.stderr
    assert "a file the run's overrides name is not here" in elsewhere.stdout
    assert "run verify where the run was made" in elsewhere.stdout


@pytest.mark.long
def test_an_override_too_long_for_a_command_line_is_re_run(tmp_path):
    """2,500 observations given to ``sim.load`` (150 kB of TOML, over Linux's 128 KiB an
    argument): the re-run was "Argument list too long", exit 2; it now reads its arguments
    from its standard input."""
    pairs = [("A", "B"), ("B", "C"), ("C", "D"), ("A", "C"), ("B", "D")] * 500
    obs = [{"kind": "distance", "from": a, "to": b, "sigma_mm": 2.0} for a, b in pairs]
    one = ROOT / "tests" / "data" / "gama" / "one_fixed.toml"
    sim.load(one, trials=40, network__observations=obs).run(
        out=tmp_path / "R" / "one_fixed", figures=False
    )
    (long,) = [t for t in _rec(tmp_path / "R" / "one_fixed")["overrides"] if len(t) > 1 << 17]
    out = _verify(tmp_path / "R", "--studies", one.parent, "--scratch", tmp_path / "S")
    assert out.returncode == 0, out.stdout + out.stderr
    assert "one_fixed: ok; 7 files; largest relative deviation 0;" in out.stdout
    assert 'network.observations=[{ kind = "distance", from = "A", to = "B", s' in out.stdout
    assert f"... ({len(long):,} characters), trials=40" in out.stdout  # a line, not 150 kB


@pytest.mark.parametrize(
    "given, words",
    [
        (["--out=/tmp/x"], "its override '--out=/tmp/x' does not set a key of its config"),
        (["plate.grid=4 --workers 9"], "is not a value written as a run writes it"),
        (["plate.grid=--help"], "is not a value written as a run writes it"),
        (['study="network"'], "does not set a key of its config"),
        (["plate.grid=4", "plate.grid=4"], "'plate.grid=4' sets a key given before"),
        ("plate.grid=4", "its overrides are not a list of KEY=VALUE texts"),
    ],
)
def test_overrides_edited_by_hand_are_not_passed_on(made, tmp_path, capsys, given, words):
    shutil.copytree(made / "R", tmp_path / "R")
    rec = _rec(tmp_path / "R" / "brown_table1")
    (tmp_path / "R" / "brown_table1" / "run.json").write_text(
        json.dumps({**rec, "overrides": given})
    )
    argv = ["--results", str(tmp_path / "R"), "--scratch", str(tmp_path / "S"), "--no-record"]
    assert verify_main(argv) == 1
    out = capsys.readouterr()
    assert out.out.splitlines()[0] == "brown_table1: FAILED; nothing compared", out
    (line,) = out.out.splitlines()[1:]
    assert words in line and "run.json" in line and "(edited by hand?): not re-run" in line
    assert "re-running" not in out.err and not (tmp_path / "S" / "brown_table1").exists()


def test_an_override_the_rerun_refuses_is_named(made, tmp_path):
    shutil.copytree(made / "R", tmp_path / "R")
    rec = _rec(tmp_path / "R" / "brown_table1")
    given = [t if not t.startswith("plate.grid=") else "plate.grid=-1" for t in RECORDED]
    (tmp_path / "R" / "brown_table1" / "run.json").write_text(
        json.dumps({**rec, "overrides": given})
    )
    out = _verify(tmp_path / "R", "--scratch", tmp_path / "S")  # before: "another config"
    assert out.returncode == 1, out.stdout + out.stderr
    assert "the run's overrides no longer apply" in out.stdout
    assert "(sim: error: plate.grid: must be >= 2 (got -1))" in out.stdout
