"""The lead's own sweep of 2026-11-29 (issue 26): the network kind's refusal of a gross bias kept
(a tiny one is doors33r's, which the merge took); a w-test power not above its level (a
negative MDB printed as a finding); a trade-off's list of settings with one twice (two rows of
one setting) or out of order (a zigzag line); the benchmark's lists (a worker count given
twice); ``sim report`` over results of another version of the code, and over a study some of
whose trials did not converge (said by ``sim show``, not by the report); gridplate's second
memory model. Each test failed on the code before its fix."""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest

from sim.cli import main
from tests.test_lead32 import STUDIES, _trilateration  # 300 random points, 8 nearest distances


def _with_bias(tmp_path: Path, half_extent_mm: float, bias_mm: float) -> Path:
    """The trilateration of test_lead32 with a bias on its generated distances."""
    f = _trilateration(tmp_path, half_extent_mm)
    text = f.read_text(encoding="utf-8").replace(
        "sigma_mm = 1.0", f"sigma_mm = 1.0, bias_mm = {bias_mm}", 1
    )
    f.write_text(text, encoding="utf-8")
    return f


def test_a_gross_bias_is_still_named_when_it_is_the_cause(tmp_path, capsys):
    # the rule kept: the same network with a bias of 40 sigma is refused at the probe for it
    f = _with_bias(tmp_path, 7000.0, 40.0)
    assert main(["check", str(f)]) == 2
    err = capsys.readouterr().err.strip()
    assert "the bias of 40 mm on the distance" in err, err


def test_a_bench_setting_given_twice_in_one_list_is_refused(tmp_path, capsys):
    # before: `--rerun-workers 1,1` timed make rerun with one worker twice and wrote two rows
    # of one key into rerun.parquet (and its figure), exit 0; `--only store,store` passed
    from benchmarks import cli

    for bad, named in (
        (["--rerun-workers", "1,01"], "1 given twice"),
        (["--only", "store,store"], "store given twice"),
    ):
        with pytest.raises(SystemExit) as e:
            cli.main([*bad, "--quick", "--out", str(tmp_path / "b")])
        assert e.value.code == 2
        err = capsys.readouterr().err.strip()
        assert len(err.splitlines()) == 1 and named in err, err
    assert not (tmp_path / "b").exists()


def test_sim_report_says_which_results_were_made_by_other_code(
    tiny_run, tmp_path, capsys, monkeypatch
):
    # before: `sim show DIR` noted results made by another version of the study's code, while
    # `sim report` rebuilt REPORT.md from them without a word (after a change of code, a
    # report of the old verdicts read as current)
    d = tmp_path / "results" / "salsig_encoders"
    shutil.copytree(tiny_run("salsig_encoders"), d)
    assert main(["report", "--results", str(d.parent)]) == 0
    assert "note" not in capsys.readouterr().err
    monkeypatch.setattr("sim.stale.study_code_hash", lambda study: "0" * 16)
    assert main(["report", "--results", str(d.parent)]) == 0
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1, err
    assert "1 of the reported results directories (salsig_encoders) was made by another" in err


def test_the_report_says_how_many_trials_of_a_study_did_not_converge(tmp_path, capsys):
    # before: `sim run` and `sim show` said "not converged: 29 of 40 trials", REPORT.md
    # listed the study with "3 self-check undecided" and not a word of why
    out = tmp_path / "r" / "tri"
    args = ["run", str(_trilateration(tmp_path, 8000.0)), "--out", str(out), "--no-figures"]
    assert main([*args, "--quiet"]) == 0
    assert main(["report", "--results", str(out.parent)]) == 0
    text = (out.parent / "REPORT.md").read_text(encoding="utf-8")
    assert "(your own instrument as data). Not converged: 29 of 40 trials" in text, text


def test_a_w_test_power_not_above_its_level_is_refused(tmp_path, capsys):
    # before: reliability.alpha0 = 0.5 with reliability.power = 0.05 printed the finding
    # network.design.mdb_max_mm = -0.002325 (a negative minimal detectable bias), and 0.1 with
    # 0.05 printed -1.6e-18 (Baarda's delta0 = z(1 - alpha0/2) + z(power) at or below zero)
    f = STUDIES / "network_plate.toml"
    for a0, pw in (("0.5", "0.05"), ("0.1", "0.05"), ("0.3", "0.3")):
        args = [
            "check",
            str(f),
            "--set",
            f"reliability.alpha0={a0}",
            "--set",
            f"reliability.power={pw}",
        ]
        assert main(args) == 2
        err = capsys.readouterr().err.strip()
        assert len(err.splitlines()) == 1, err
        assert err.startswith(
            f"sim: error: reliability.power: {pw} is not above reliability.alpha0"
        ), err
    assert (
        main(
            ["check", str(f), "--set", "reliability.alpha0=0.3", "--set", "reliability.power=0.31"]
        )
        == 0
    )


def test_a_list_of_settings_compared_takes_each_once_in_increasing_order(tmp_path, capsys):
    # before: `power.marks = [3, 3, 5]` ran and wrote two rows of one setting (their values
    # differed: two streams) into power.parquet, drawn as two lines of one label; `[7, 3, 5]`
    # was drawn as a zigzag line (49, 9, 25 marks); every trade-off list of every study alike
    f = STUDIES / "salsig_encoders.toml"
    for bad, named in (("[3, 3, 5]", "3"), ("[5.0, 3, 5]", "5")):
        assert main(["check", str(f), "--set", f"power.marks={bad}"]) == 2
        err = capsys.readouterr().err.strip()
        assert err == f"sim: error: power.marks: {named} is given twice: give each setting once", (
            err
        )
    assert (
        main(
            [
                "check",
                str(STUDIES / "wolf_polynomial.toml"),
                "--set",
                "trade.drift_fractions=[0.5, 0.50]",
            ]
        )
        == 2
    )
    assert "trade.drift_fractions: 0.5 is given twice" in capsys.readouterr().err
    assert main(["check", str(f), "--set", "power.marks=[7, 3, 5]"]) == 0
    out = capsys.readouterr().out
    assert "power.marks = [3, 5, 7]  # " in out and "settings compared: each once" in out, out
    # a list of names keeps its order (a table's rows), a name given twice is refused
    layouts = 'tradeoff.layouts=["full", "corners", "full"]'
    assert main(["check", str(STUDIES / "agnard_block.toml"), "--set", layouts]) == 2
    assert "tradeoff.layouts: 'full' is given twice" in capsys.readouterr().err


def test_gridplates_chunk_check_uses_the_estimates_memory_model(capsys):
    # before: gridplate's own chunk check counted 96 bytes a reading (a second memory model,
    # 3 times the measured one: doors33m) and refused a chunk of 1,000 trials of 4 plates of
    # 15 x 15 points read 50 times, "about 4.3 GB", that sim check's estimate put at 1.6 GiB
    big = ["--set", "plate.count=4", "--set", "plate.grid=15", "--set", "readings.count=50"]
    f = str(STUDIES / "gridplate_two_plates.toml")
    assert main(["check", f, *big, "--set", "chunk=1000", "--set", "trials=20000"]) == 0
    assert "about 1.59 GiB of memory" in capsys.readouterr().out
    assert main(["check", f, *big, "--set", "chunk=5000", "--set", "trials=100000"]) == 2
    err = capsys.readouterr().err.strip()
    assert (
        err == "sim: error: chunk: a chunk of 5000 trials needs about 8.6 GB; use a smaller chunk"
    )


def test_wolfs_printed_approach_and_format_mark_a_run_off_the_papers_setup(capsys):
    # before: the schema said the approach side and the P-30 format were "not in the text"
    # (the paper: "always by approaching grid intersections from the lower right side",
    # "100-by-150-mm format") and left them unmarked: a run from either side, or of another
    # format, had its predictions scored as tests of the paper (S33's left item)
    f = str(STUDIES / "wolf_polynomial.toml")
    for setting in ("reading.approach=random", "repeat.format_mm=[120.0, 80.0]"):
        assert main(["check", f, "--set", setting]) == 0
        out = capsys.readouterr().out
        assert f"# off the paper's setup ({setting.split('=')[0]} = " in out, out
