"""Doors, session 48, helper K: the readers, the API and the option words left by D46/R47.

* A TOML slip in a study file (``study = brown_table1`` unquoted, ``trials = 4,000``,
  ``setting_sigma_um = 1.7um``, ``[errors`` without its bracket) was refused in tomllib's words
  alone ("Invalid value (at line 5, column 9)"): the line as probably meant is said now
  (:mod:`sim.mc.toml_slips`).
* Names differing only in case: ``sim check Studies/Brown_Table1.toml`` (no directory
  ``Studies``), ``study = "Brown_Table1"``, ``sim check --Trials 40`` got no guess.
* The list-item hint (``--set design.positions.0=3``) was given by ``sim run``/``sim check``
  only: ``sim.load(..., design__positions__0=3)`` said "unknown key" alone, ``python -m
  sim.batch -- --set`` "unknown key (the study has no such key)", without even the guess
  ``--set Trials=40`` gets from ``sim run`` (:mod:`sim.mc.unknown_key`: one wording).
* ``sim.run``, ``res.claims.num_rows``, ``res.trials``: Python's bare AttributeError.
* A results directory touched by hand: a figure made a FIFO was named in the report but
  ``sim show``/``sim report`` exited 0; a run record of this code with ``table_sha256`` and
  ``table_shape`` removed was read as an older version's (tables unchecked); a sweep's top
  directory without ``run.json`` was read unchecked.
"""

from __future__ import annotations

import json
import os
import pickle
import shutil
from pathlib import Path

import pytest

import sim
from sim.batch import main as batch_main
from sim.cli import main
from sim.mc.config import ConfigError
from tests.conftest import TRIANGLE_NETWORK
from tests.hand_edits import edit_first_value
from tests.oneline import SIM_ERROR, one_line
from tests.within import within

ROOT = Path(__file__).resolve().parents[1]
BROWN = ROOT / "studies" / "brown_table1.toml"
DESIGN = ROOT / "studies" / "brown_design.toml"


@pytest.mark.parametrize(
    "old, new, meant",
    [
        ('study = "brown_table1"', "study = brown_table1", 'study = "brown_table1"'),
        ("trials = 4000", "trials = 4,000", "no thousands separator: trials = 4000"),
        ("setting_sigma_um = 1.7", "setting_sigma_um = 1.7um", "setting_sigma_um = 1.7)"),
        ("[errors]", "[errors", "closed by ]: [errors]"),
        ("format_mm = 245.0", "format_mm = 245,0", "not a comma: format_mm = 245.0"),
        ("bias_um = 0.0", "bias_um = True", "lower case: bias_um = true"),
        ("trials = 4000", "trials: 4000", "with =: trials = 4000"),
    ],
)
def test_a_toml_slip_in_a_study_file_says_what_was_meant(tmp_path, capsys, old, new, meant):
    """Class: a TOML slip a new user makes in a study file. Before: tomllib's words alone
    ("Invalid value (at line 5, column 9)", "Expected newline or end of document after a
    statement"), nothing of what TOML wanted there."""
    text = BROWN.read_text(encoding="utf-8")
    assert old in text
    (f := tmp_path / "slip.toml").write_text(text.replace(old, new, 1), encoding="utf-8")
    one_line(capsys, main(["check", str(f)]), "malformed TOML", "(at line", meant)


@pytest.mark.parametrize("value", ["1/2", "0" + "1" * 5000])
def test_a_toml_line_with_no_known_slip_gets_no_guess(tmp_path, capsys, value):
    """A control of the above: a line none of the slips fits (``trials = 1/2``), or one too
    long to be a slip (5,000 digits after a leading zero: no integer of them is made), is
    refused in tomllib's words with no guess made up."""
    text = BROWN.read_text(encoding="utf-8").replace("trials = 4000", f"trials = {value}", 1)
    (f := tmp_path / "slip.toml").write_text(text, encoding="utf-8")
    line = one_line(capsys, main(["check", str(f)]), "malformed TOML")
    assert line.endswith("(at line 6, column 11)"), line


def test_names_differing_only_in_case_are_guessed(tmp_path, capsys):
    """Class: a name typed in another case. Before: ``Studies/Brown_Table1.toml`` (the
    directory ``Studies`` is none) "no such study file" with no guess; ``study =
    "Brown_Table1"`` "unknown study" with the list alone; ``sim check --Trials 40``
    "unrecognized arguments" alone."""
    typed = ROOT / "Studies" / "Brown_Table1.toml"
    one_line(capsys, main(["check", str(typed)]), f"did you mean {BROWN}?", prefix=SIM_ERROR)
    text = BROWN.read_text(encoding="utf-8").replace('"brown_table1"', '"Brown_Table1"', 1)
    (f := tmp_path / "case.toml").write_text(text, encoding="utf-8")
    one_line(capsys, main(["check", str(f)]), "(did you mean brown_table1?)")
    rc = main(["check", str(BROWN), "--Trials", "40"])
    one_line(capsys, rc, "--trials: an option of sim run", "sim check --set trials=40")


LIST_WORDS = "design.positions is a list: its items have no keys of their own"


def test_a_list_item_set_by_index_gets_the_same_words_at_every_door(tmp_path, capsys):
    """Class: a list's item set by its index at the API and the batch. Before: ``sim.load``
    said "unknown key" alone; the batch "unknown key (the study has no such key)", without
    the guess or the list named (``sim run``/``sim check`` only)."""
    with pytest.raises(ConfigError) as e:
        sim.load(DESIGN, design__positions__0=3)
    assert LIST_WORDS in str(e.value) and "design__positions=[...]" in str(e.value)
    argv = ["check", str(DESIGN), "--set", "design.positions.0=3"]
    cli = one_line(capsys, main(argv), LIST_WORDS).removeprefix(SIM_ERROR)
    assert cli == str(e.value)
    res = tmp_path / "res"
    rc = batch_main([str(DESIGN), "--results", str(res), "--", "--set", "design.positions.0=3"])
    assert one_line(capsys, rc, LIST_WORDS).endswith(cli)
    rc = batch_main([str(BROWN), "--results", str(res), "--", "--set", "Trials=40"])
    one_line(capsys, rc, "--set Trials: unknown key (did you mean trials?)")
    assert not res.exists()


def test_likely_slips_of_the_api_say_what_to_use():
    """Class: a likely slip of the Python API. Before: ``sim.run(...)`` "module 'sim' has no
    attribute 'run'", ``res.claims.num_rows`` "'function' object has no attribute 'num_rows'",
    ``res.trials`` Python's bare words. Each is still an AttributeError (hasattr works)."""
    with pytest.raises(AttributeError, match=r"sim\.load\(STUDY_FILE\)\.run\(\) runs a study"):
        sim.run  # noqa: B018
    with pytest.raises(AttributeError, match=r"did you mean sim\.Results\?"):
        sim.results  # noqa: B018
    assert not hasattr(sim, "run") and not hasattr(sim, "nosuch")
    res = sim.Results(ROOT / "results" / "brown_table1", "brown_table1")
    with pytest.raises(AttributeError, match=r"call it, res\.claims\(\)\.num_rows"):
        res.claims.num_rows  # noqa: B018
    with pytest.raises(AttributeError, match=r"res\.table\('trials'\) reads a table"):
        res.trials  # noqa: B018
    assert not hasattr(res, "tables") and getattr(res, "__deepcopy__", None) is None
    assert res.claims.__doc__ == sim.Results.claims.__doc__ and res.claims == res.claims
    assert pickle.loads(pickle.dumps(res.claims)).__self__ == res  # a Pool's task, as before


def _copy(tiny_run, tmp_path: Path) -> Path:
    d = tmp_path / "res" / "network_plate"
    shutil.copytree(tiny_run("network_plate"), d, symlinks=True)
    return d


def test_a_figure_made_a_fifo_stops_show_and_report(tiny_run, tmp_path, capsys):
    """Class: a figure of a run replaced by a FIFO. Before: ``sim show`` and ``sim report``
    exited 0 (the report said "not shown"), where a table so replaced is refused."""
    d = _copy(tiny_run, tmp_path)
    fig = next(d.glob("*.png"))
    fig.unlink()
    os.mkfifo(fig)
    one_line(capsys, within(60, main, ["show", str(d)]), f"{fig} is a FIFO", "run its study")
    one_line(capsys, within(60, main, ["report", "--results", str(d.parent)]), f"{fig} is a FIFO")
    fig.unlink()  # a figure missing is let be, as before
    assert within(60, main, ["show", str(d)]) == 0


def test_a_record_of_this_code_without_table_sums_and_shapes_is_refused(tiny_run, tmp_path, capsys):
    """Class: a run record whose ``table_sha256`` and ``table_shape`` were both removed (a
    claim's value edited too). Before: read as the oldest versions' records, the edited value
    shown as the run's; a record of this code's run (which writes both) is refused now."""
    d = _copy(tiny_run, tmp_path)
    rec = json.loads((d / "run.json").read_text(encoding="utf-8"))
    del rec["table_sha256"], rec["table_shape"]
    (d / "run.json").write_text(json.dumps(rec), encoding="utf-8")
    edited = edit_first_value(d)
    words = "holds neither table_sha256 nor table_shape"
    assert str(edited) not in one_line(capsys, within(60, main, ["show", str(d)]), words)
    with pytest.raises(ConfigError, match=words):
        sim.Results(d, "network").claims()


def test_a_sweeps_top_directory_without_its_run_record_is_refused(tmp_path, capsys):
    """Class: a sweep's ``run.json`` deleted. Before: ``sim show`` read its ``sweep.parquet``
    unchecked, exit 0 (a run's directory so touched is refused, as ``Results`` refused it)."""
    (f := tmp_path / "sw.toml").write_text(
        TRIANGLE_NETWORK + '[sweep]\n"datum.kind" = ["fixed", "inner"]\n', encoding="utf-8"
    )
    out = tmp_path / "sw"
    assert main(["run", str(f), "--out", str(out), "--quiet", "--no-figures"]) == 0
    capsys.readouterr()
    (out / "run.json").unlink()
    one_line(capsys, main(["show", str(out)]), f"{out / 'run.json'} is missing")


def test_a_users_table_written_into_a_runs_directory_is_left_out_by_every_reader(
    tiny_run, tmp_path, capsys
):
    """Class: ``sim.write_table`` of the same study into a run's directory. Before: ``sim
    show`` refused the whole directory ("mixes results of two runs") where ``Results`` and
    verify left the table out; all leave it out now, and it is kept."""
    d = _copy(tiny_run, tmp_path)
    mine = sim.write_table(d / "mine.parquet", {"x": [1.0, 2.0]}, {"study": "network"})
    assert within(60, main, ["show", str(d)]) == 0
    assert within(60, main, ["report", "--results", str(d.parent)]) == 0
    capsys.readouterr()
    assert "mine" not in sim.Results(d, "network").names() and mine.is_file()
