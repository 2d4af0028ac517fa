"""A user's first hour with the command line (issue 25): usage, --version, plain help,
did-you-mean, sim check's documentation, no Broken pipe, --trials at any size, the verdicts
on screen, sim show, and the committed results/ left alone by a different run."""

import json
import re
import socket
import subprocess
import sys
import warnings
from pathlib import Path

import pyarrow.parquet as pq
import pytest

from sim.cli import main
from sim.mc.runner import MIN_CHUNKS, make_executor
from sim.mc.storage import write_record, write_table
from sim.report.claimtext import interval_text, sim_text
from sim.report.run_summary import region_line, verdict_line

ROOT = Path(__file__).resolve().parent.parent
# brown_table1 at a tiny size: a few seconds
TINY = 'study = "brown_table1"\ntrials = 40\nchunk = 2\n[region]\npoints = 256\nrounds = 1\n'


def _study(tmp_path, text=TINY, name="t1.toml"):
    p = tmp_path / name
    p.write_text(text)
    return p


def test_no_arguments_prints_usage(capsys):
    assert main([]) == 2
    out = capsys.readouterr().out
    assert out.startswith("usage: sim") and "sim run STUDY.toml" in out


def test_version(capsys):  # returned, not raised: main() called in a notebook goes on
    assert main(["--version"]) == 0
    assert capsys.readouterr().out.startswith("sim 0.")


@pytest.mark.parametrize("cmd", [[], ["run"], ["show"], ["check"], ["report"]])
def test_help_is_plain_text(cmd, capsys):
    assert main([*cmd, "--help"]) == 0
    out = capsys.readouterr().out
    assert out.startswith("usage: sim") and "``" not in out and ":class:" not in out


@pytest.mark.parametrize(
    "override, hint",
    [
        ("comparator.beta=0.5", "comparator.beta_mm"),
        ("plate.grd=5", "plate.grid"),
        ("errors.setting_sigma=1.0", "errors.setting_sigma_um"),
    ],
)
def test_unknown_key_suggests_the_key(override, hint, capsys):
    assert main(["check", str(ROOT / "studies/brown_dilution.toml"), "--set", override]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1
    assert f"did you mean {hint}" in err


def test_an_unknown_key_with_nothing_near_has_no_guess(capsys):
    assert main(["check", str(ROOT / "studies/brown_dilution.toml"), "--set", "zzz=1"]) == 2
    assert "did you mean" not in capsys.readouterr().err


def test_check_prints_doc_unit_bounds_and_work(capsys):
    assert main(["check", str(ROOT / "studies/brown_dilution.toml")]) == 0
    out = capsys.readouterr().out.splitlines()
    spacing = next(line for line in out if line.startswith("plate.spacing_mm = "))
    assert "#" in spacing and "unit mm" in spacing and ">" in spacing
    assert out[-1].startswith("# work: ") and "trials" in out[-1] and "memory" in out[-1]


def test_check_into_a_closed_pipe_says_nothing():
    p = subprocess.Popen(
        [sys.executable, "-m", "sim", "check", str(ROOT / "studies/brown_design.toml")],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        cwd=ROOT,
    )
    p.stdout.readline()
    p.stdout.close()  # what `| head -1` does
    err = p.stderr.read().decode()
    p.wait(timeout=60)
    assert "Broken pipe" not in err and "Traceback" not in err and err == ""


def _chunks(out: Path) -> int:
    return sum(1 for _ in (out / "trials").rglob("chunk-*.parquet"))


def test_trials_picks_a_chunk_size_giving_enough_chunks(tmp_path, capsys):
    study = _study(tmp_path)
    out = tmp_path / "out"
    assert main(["run", str(study), "--trials", "60", "--out", str(out)]) == 0
    cfg = json.loads((out / "run.json").read_text())["config"]
    assert cfg["trials"] == 60 and -(-60 // cfg["chunk"]) >= MIN_CHUNKS
    assert _chunks(out) >= MIN_CHUNKS
    # the verdicts on screen: the counts, the headline rows, the per-run report
    text = capsys.readouterr().out
    assert "claims:" in text and "brown." in text
    assert f"report: {out}/README.md" in text
    readme = (out / "README.md").read_text()
    assert readme.splitlines()[1].startswith("# out: Brown") and "**Verdicts:**" in readme
    assert "README.md" in json.loads((out / "run.json").read_text())["files"]
    # --chunk chooses; the study file's own chunk stays without --trials
    out2 = tmp_path / "out2"
    more = ["--quiet", "--no-figures"]  # the config is read, not the figures
    assert (
        main(["run", str(study), "--trials", "60", "--chunk", "3", "--out", str(out2), *more]) == 0
    )
    assert json.loads((out2 / "run.json").read_text())["config"]["chunk"] == 3
    out3 = tmp_path / "out3"
    assert main(["run", str(study), "--out", str(out3), *more]) == 0
    assert json.loads((out3 / "run.json").read_text())["config"]["chunk"] == 2


def test_show_prints_a_results_directory(tmp_path, capsys):
    out = tmp_path / "out"
    assert main(["run", str(_study(tmp_path)), "--out", str(out), "--quiet"]) == 0
    capsys.readouterr()
    claims = pq.read_table(out / "claims.parquet").column("claim").to_pylist()
    assert main(["show", str(out)]) == 0
    text = capsys.readouterr().out
    assert text.startswith("claim") and claims[0] in text and "claims:" in text
    assert main(["show", str(out), "--markdown"]) == 0
    readme = (out / "README.md").read_text()
    assert capsys.readouterr().out == readme.split("\n", 1)[1]  # the file without its mark
    # a README.md of the user's is never replaced, by a run or by sim report
    (out / "README.md").write_text("my notes\n")
    assert main(["report", "--results", str(tmp_path)]) == 0
    assert (out / "README.md").read_text() == "my notes\n"
    assert "kept as yours" in capsys.readouterr().err  # said, in a note line
    assert main(["show", str(tmp_path)]) == 2  # not a results directory: one line
    err = capsys.readouterr().err
    assert len(err.strip().splitlines()) == 1 and "not a results directory" in err


def test_a_different_run_goes_to_scratch_and_leaves_results_alone(tmp_path, capsys, monkeypatch):
    monkeypatch.chdir(tmp_path)
    study = _study(tmp_path)
    committed = Path("results") / "brown_table1"
    assert main(["run", str(study), "--out", str(committed), "--quiet"]) == 0
    before = (committed / "run.json").read_text()
    capsys.readouterr()
    assert main(["run", str(study), "--seed", "5", "--quiet", "--no-figures"]) == 0
    err = capsys.readouterr().err
    assert "writing to scratch/brown_table1-" in err and "seed = 20261122 (this run 5)" in err
    assert (committed / "run.json").read_text() == before
    (scratch,) = Path("scratch").iterdir()
    assert json.loads((scratch / "run.json").read_text())["config"]["seed"] == 5
    # the same command again reuses its scratch directory; the committed run's own config
    # (same code) goes to results/ as before
    assert main(["run", str(study), "--seed", "5", "--quiet", "--no-figures"]) == 0
    assert len(list(Path("scratch").iterdir())) == 1
    capsys.readouterr()
    assert main(["run", str(study), "--quiet"]) == 0
    assert "scratch" not in capsys.readouterr().err
    # the same record, byte for byte: the sha256 of the run.json it replaced is dropped
    # once the old results are removed (docs/outputs.md)
    assert (committed / "run.json").read_text() == before


def test_the_dask_cluster_starts_without_a_dashboard_warning():
    pytest.importorskip("dask.distributed")
    s = socket.socket()
    try:
        s.bind(("127.0.0.1", 8787))  # the dashboard's default port, taken
        s.listen()
    except OSError:
        pass  # already taken by someone else: the same situation
    try:
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            ex = make_executor("dask", 1)
            ex.close()
        assert not [w for w in caught if "already in use" in str(w.message)]
    finally:
        s.close()


# --- the suite report and the numbers in it --------------------------------------------------


@pytest.mark.parametrize(
    "value, lo, hi, text",
    [
        (0.707123, 0.7065, 0.7078, "0.70712 [0.70650, 0.70780]"),  # half-width 6.5e-4: 5 decimals
        (82.5, 39.3, 168.0, "82 [39, 168]"),  # half-width 64: units
        (1.03, 0.86, 1.33, "1.03 [0.86, 1.33]"),
        (1.0, 1.0, 1.0, "1.00 [1.00, 1.00]"),  # no width: 3 significant digits
    ],
)
def test_numbers_at_the_precision_their_interval_supports(value, lo, hi, text):
    r = {"value": value, "ci_low": lo, "ci_high": hi, "interval": "ci", "verdict": "holds"}
    assert f"{sim_text(r)} {interval_text(r)}" == text


def test_exact_numbers_keep_the_digits_that_decide():
    r = {"value": 0.70708861, "interval": "exact", "zone_low": 0.7, "zone_high": 0.72}
    assert sim_text(r) == "0.7071"
    r = {"value": 1.0000000006, "interval": "exact", "zone_low": 1.0000000005, "zone_high": 1.1}
    assert sim_text(r) == "1.000000001"  # inside by 1e-10: the digits that show it


def test_region_line_and_new_verdicts_are_counted(tmp_path):
    write_record(tmp_path, {"config": {"study": "brown_table1"}, "code_hash": "0" * 16})
    write_table(
        tmp_path / "consistent_region.parquet",
        {
            "offset_mm": [1.0, 2.0, 4.0],
            "confirmed": [True, False, True],
            "brown.x": ["holds", "fails", "holds"],
        },
        {"study": "brown_table1"},
    )
    assert (
        region_line(tmp_path) == "consistent region: 3 accepted input vectors (offset_mm 1.00–4.00)"
    )
    claims = [{"verdict": v} for v in ("holds", "depends", "undecidable", "depends")]
    assert verdict_line(claims) == "4 claims: 1 holds, 2 depends, 1 undecidable"


def test_the_suite_report_opens_with_one_screen_per_paper(tmp_path):
    results = tmp_path / "results"
    out = results / "brown_table1"
    assert main(["run", str(_study(tmp_path)), "--out", str(out), "--quiet"]) == 0
    (out / "README.md").unlink()
    assert main(["report", "--results", str(results)]) == 0
    text = (results / "REPORT.md").read_text()
    opening = text.split("## Every headline claim")[0]
    assert "## The verdicts at a glance" in opening and len(opening.splitlines()) < 40
    assert "**Brown 1968** ([brown_table1](brown_table1/README.md))" in opening
    assert not re.search(r"00\d_[0-9a-f]{16}", text)  # papers by authors and year
    assert (out / "README.md").is_file()  # sim report writes each directory's README.md
