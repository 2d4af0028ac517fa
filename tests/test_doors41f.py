"""Fuzz, seeds 4101.. and the doors fuzzer's 41001126/7 and 41011126/7 (brief F41), and a new
mutation kind, SEQUENCE (tests/fuzz_sequence.py): orders of operations on one small study and
one output directory -- runs, runs with ``--overwrite``, ``--set``, ``--trials`` or ``--seed``,
runs interrupted by SIGINT, SIGTERM or SIGKILL at a marker (the ``k``-th rename of a file) and
the same command again, the study file or its GNU Gama file edited between steps or saved anew
while a run runs, ``sim show``, ``sim report``, verify (interrupted too), a sweep, ``python -m
sim.batch --stale-only``, a figure deleted, a table touched, a file of the user's added, the
API's ``run()`` and ``Results.table``; after each step the results are one whole run of a
config a step asked for, equal to its clean run, or the step was refused in one line. The
seeds' cases of the earlier kinds found no new class (seed 4101: 300 cases and 100; 4102,
4103, 4110-4112: 40 each; the doors fuzzer: 40 cases a seed). One case each, each failed on
the code before its fix.

* A run killed, its GNU Gama file (or a Wolf table) edited, then the same command again, was
  refused "holds an unfinished run of a different config: network.gama_sha256 = ... (this
  run ...); run again with its values to finish it, or use --overwrite": followed literally
  there is no value to give (the digest is filled in on load, and one given by hand must be
  the file's own: refused again). It now says the file changed since the unfinished run
  started and to put back its contents of then (with the other keys, "run again with its
  values and net.xml as it was then"); doing so resumes the run. The two digests were cut at
  40 characters with their closing quotes (``'d6ede3... (this run '923d4...)``): a value
  cut is now ended by ``...`` and its quote or bracket.

Held (about 250 sequences of 4-8 steps, seeds 13 and 4101-4111): every run, resume, batch and
API call that ended with exit 0 left the config it was asked for, complete, its tables and
chunks byte for byte a clean run's, no staging or swap directory beside it; every interrupt
(SIGINT, SIGTERM, SIGKILL at each rename of a run, a sweep, the API, ``sim report`` and
verify) left the old results or the new ones, never a mixture, and the same command again
finished the run; a Gama or study file saved anew while a run ran gave the results of the
file as loaded, or one line; ``--stale-only`` re-ran results of another config, of no figures
or with a figure deleted (a sweep cell's too) and called no others current; verify passed only
results of the study file's config; ``sim show`` and ``Results.table`` read only the run the
directory records; a file of the user's (in the results or a cell) was never lost; no worker
outlived its run. The API's run in a process that ignores SIGINT (started by ``nohup ... &``)
goes on when sent one, as Python does: not a class.
"""

from __future__ import annotations

from pathlib import Path

from sim.cli import main
from sim.mc.record_text import finish_words
from tests.oneline import SIM_ERROR, one_line

ROOT = Path(__file__).resolve().parent.parent
GAMA = ROOT / "tests" / "data" / "gama" / "one_fixed.xml"
STUDY = 'study = "network"\ntrials = 40\nchunk = 2\n[network]\ngama_xml = "{x}"\n'


def test_an_unfinished_run_of_an_edited_gama_file_says_to_put_it_back(tmp_path, capsys):
    x, study, out = tmp_path / "net.xml", tmp_path / "net.toml", tmp_path / "res" / "net"
    x.write_bytes(GAMA.read_bytes())
    study.write_text(STUDY.format(x=x))
    run = ["run", str(study), "--quiet", "--no-figures", "--out", str(out)]
    assert main(run) == 0, capsys.readouterr().err
    out.rename(out.parent / ".net.partial")  # as a run killed before it published
    x.write_bytes(GAMA.read_bytes().replace(b'stdev="2.0"', b'stdev="2.5"'))  # edited since
    capsys.readouterr()
    # before: "...; run again with its values to finish it, or use --overwrite to replace it"
    line = one_line(capsys, main(run), "network.gama_sha256 = '", prefix=SIM_ERROR)
    assert line.count("'") == 4 and "...' (this run '" in line  # each sha256 cut, then quoted
    assert f"{x} changed since it started: put back its contents of then to finish it" in line
    assert "run again with its values" not in line and "--overwrite" in line
    line = one_line(capsys, main([*run, "--trials", "60"]), prefix=SIM_ERROR)
    assert f"run again with its values and {x} as it was then to finish it" in line
    x.write_bytes(GAMA.read_bytes())  # the advice followed: the run is finished
    assert main(run) == 0 and "resuming network: 20 finished" in capsys.readouterr().err
    assert (out / "run.json").is_file() and not (out.parent / ".net.partial").exists()


def test_an_unfinished_run_of_an_edited_wolf_table_says_to_put_it_back():
    old = {"table1.file": "t1.csv", "table1.sha256": "a" * 64, "trials": 8}
    words = finish_words(old, {**old, "table1.sha256": "b" * 64})
    assert words.startswith("t1.csv changed since it started: put back its contents of then")
    assert finish_words(old, {**old, "trials": 16}).startswith("run again with its values to")
