"""The failure classes of the seventh sweep of bad inputs (issue 26), one case per class;
each failed on the code before its fix.

* a chunk file dropped by hand into a run's ``trials/`` (named like the run's own) survives
  every re-run, ``--overwrite`` included (no run removes a file it did not write), yet
  ``Results.table("trials")`` refused it with "run the study again", which never helped;
* ``sim.Results`` of a directory that does not exist said "network has no table 'claims';
  it has " (an empty list): the table was blamed for a wrong path;
* the Python API's ``trials`` (``sim.load(f, trials=N)``, ``.run(trials=N)``) did not pick
  the chunk as ``sim run --trials N`` does: ``trials=40`` on a file of ``chunk = 100`` was
  refused, and a smaller count ran other chunks (other intervals) than the command;
  ``sim check --set trials=40`` refused what ``sim run --set trials=40`` runs;
* Brown's ranges overflowing from a huge ``plate.format_mm`` were blamed on
  ``comparator.station_offset_mm``;
* salsig's scales had no upper bound: ``comparator.sx = 1e308`` ran and recovered nonsense
  without a word, ``zscale.s_mm_per_digit = 1e300`` (with the B8 scales) ran, printed a
  NumPy overflow warning and failed only after the run;
* an output whose encoding cannot show a name (``PYTHONIOENCODING=ascii``, a network named
  'café') gave "UnicodeEncodeError: 'ascii' codec can't encode ..." without saying that the
  output was the matter;
* ``sim run --trials 40 --set trials=60`` (or ``--seed`` with ``--set seed=``) dropped one of
  the two silently, and so did ``make verify --trials 400 --set trials=40``;
* ``python -m sim.batch --results out a/x.toml b/x.toml`` said they "would both write
  results/x", not out/x;
* a file of the run (a figure, a table) replaced by a directory holding a user's file made the
  re-run fail at its very end with "File exists: .../.<out>.partial/network.png": the clash
  with a foreign file was checked for the file's own name only.
"""

import io
import shutil
import sys
from pathlib import Path

import pytest
from oneline import one_line

import sim
from sim.batch import main as batch_main
from sim.cli import main
from sim.mc.config import ConfigError

ROOT = Path(__file__).resolve().parent.parent
NETWORK = ROOT / "studies" / "network_brown.toml"


def test_a_chunk_added_by_hand_is_named_with_a_remedy_that_works(tmp_path, capsys):
    d = tmp_path / "r"
    run = ["run", str(NETWORK), "--trials", "40", "--no-figures", "--quiet", "--out", str(d)]
    assert main(run) == 0
    part = d / "trials" / "part-0"
    shutil.copy(part / "chunk-000001.parquet", part / "chunk-000099.parquet")
    assert main(run) == 0  # the re-run keeps the file it did not write
    assert (part / "chunk-000099.parquet").is_file()
    with pytest.raises(ConfigError) as e:
        sim.Results(d, "network").table("trials")
    msg = str(e.value)
    assert "chunk-000099.parquet is not one of the run's chunk files" in msg
    assert "move it away" in msg and "run the study again" not in msg
    (part / "chunk-000099.parquet").unlink()
    assert sim.Results(d, "network").table("trials").num_rows == 40


def test_results_of_a_missing_directory_name_the_path(tmp_path):
    with pytest.raises(ConfigError, match=r"^path: .*nowhere does not exist$"):
        sim.Results(tmp_path / "nowhere", "network").claims()
    with pytest.raises(ConfigError, match=r"^path: .*nowhere does not exist$"):
        sim.Results(tmp_path / "nowhere", "network").names()  # was []


def test_api_trials_picks_the_chunk_as_sim_run_trials_does(capsys):
    """``sim run --trials 40`` on a file of chunk = 100 picks chunks of 2 (at least
    MIN_CHUNKS chunks); ``sim.load(f, trials=40)`` and ``.run(trials=40)`` refused it."""
    assert sim.load(NETWORK, trials=40).config["chunk"] == 2
    assert sim.load(NETWORK, trials=400).config["chunk"] == 20
    assert sim.load(NETWORK, trials=40, chunk=1).config["chunk"] == 1
    assert sim.load(NETWORK, trials=4000).config["chunk"] == 100  # the file's, small enough
    assert main(["check", str(NETWORK), "--set", "trials=40"]) == 0
    assert "\nchunk = 2 " in capsys.readouterr().out


def test_a_format_so_large_that_ranges_overflow_names_the_format(capsys):
    """Brown's stations stand half the format plus the offset from the centre; a format of
    1e300 mm was blamed on the 17 mm ``comparator.station_offset_mm`` (refused now at the
    format's bound for the comparator, brown_design's, before any range is reckoned)."""
    argv = ["check", str(ROOT / "studies" / "brown_table1.toml"), "--set", "plate.format_mm=1e300"]
    one_line(capsys, main(argv), "must be <= 2000", prefix="sim: error: plate.format_mm: ")


@pytest.mark.parametrize(
    "setting, key",
    [
        ("comparator.sx=1e308", "comparator.sx"),
        ("zscale.s_mm_per_digit=1e300", "zscale.s_mm_per_digit"),
    ],
)
def test_salsig_scales_that_overflow_are_refused_on_load(capsys, setting, key):
    """A comparator scale of 1e308 ran and recovered nonsense (SX 1000 digits); a z scale
    (and B8 scales) of 1e300 ran, printed a NumPy warning and failed after the run."""
    argv = ["check", str(ROOT / "studies" / "salsig_encoders.toml"), "--set", setting]
    one_line(capsys, main(argv), prefix=f"sim: error: {key}: ")


def test_an_output_that_cannot_show_a_name_is_named(capsys, monkeypatch):
    """``PYTHONIOENCODING=ascii sim check`` of a network named 'café' said only
    "UnicodeEncodeError: 'ascii' codec can't encode ...", not that the output was the matter."""
    monkeypatch.setattr(sys, "stdout", io.TextIOWrapper(io.BytesIO(), encoding="ascii"))
    err = one_line(capsys, main(["check", str(NETWORK), "--set", 'network.name="café"']))
    assert err == (
        "sim: error: the output (encoding ascii) cannot show '\\xe9': set PYTHONIOENCODING=utf-8"
    )


@pytest.mark.parametrize(
    "opts", [["--trials", "40", "--set", "trials=60"], ["--seed", "3", "--set", "seed=4"]]
)
def test_a_key_given_by_its_option_and_by_set_is_refused(tmp_path, capsys, opts):
    """``sim run --trials 40 --set trials=60`` ran 40 trials without a word (and ``make
    verify --trials 400 --set trials=40`` dropped the user's --set the same way)."""
    argv = ["run", str(NETWORK), *opts, "--no-figures", "--quiet", "--out", str(tmp_path / "o")]
    one_line(capsys, main(argv), prefix=f"sim: error: {opts[0]}: given twice")
    assert not (tmp_path / "o").exists()


def test_batch_names_the_results_directory_two_files_would_share(tmp_path, capsys):
    """``--results out`` with a/x.toml and b/x.toml said "would both write results/x"."""
    for d in "ab":
        (tmp_path / d).mkdir()
        shutil.copy(NETWORK, tmp_path / d / "x.toml")
    files = [str(tmp_path / d / "x.toml") for d in "ab"]
    err = one_line(capsys, batch_main(["--results", str(tmp_path / "out"), *files]))
    assert err.endswith(f"would both write {tmp_path / 'out' / 'x'}"), err


def test_a_user_directory_named_like_a_file_of_the_run_is_named(tmp_path, capsys):
    """A table replaced by a directory holding a user's file (``claims.parquet/notes.txt``):
    the re-run failed at the end with "File exists: .../.r.partial/claims.parquet"."""
    d = tmp_path / "r"
    run = ["run", str(NETWORK), "--trials", "40", "--no-figures", "--quiet", "--out", str(d)]
    assert main(run) == 0
    (d / "claims.parquet").unlink()
    (d / "claims.parquet").mkdir()
    (d / "claims.parquet" / "notes.txt").write_text("mine")
    capsys.readouterr()
    prefix = f"sim: error: --out: {d / 'claims.parquet'} was not written by sim"
    one_line(capsys, main([*run, "--overwrite", "--seed", "5"]), prefix=prefix)
    assert (d / "claims.parquet" / "notes.txt").read_text() == "mine"


def test_a_block_too_large_to_build_is_refused_before_it_is_built(capsys):
    """(lead, after the sixth sweep) 50 x 200 models: the block's visibility table asked for
    12 GB in `sim check` (a kill by the system without a memory limit); now one line naming
    the key, for the block and for the trade-off's blocks."""
    f = str(ROOT / "studies" / "agnard_block.toml")
    block = ["block.strips=50", "block.models=200"]
    trade = ["tradeoff.block_strips=[50,1,1,1,1,1]", "tradeoff.block_models=[200,1,1,1,1,1]"]
    for key, sets in (("block.models", block), ("tradeoff.block_models", trade)):
        one_line(
            capsys,
            main(["check", f, *(a for s in sets for a in ("--set", s))]),
            f"{key}: a block of 50 x 200 = 10000 models",
        )
