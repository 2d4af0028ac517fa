"""The items issue 26's last session left open (brief L32).

1. A cell's or a run's "Not the configuration of studies/X.toml" line
   (:func:`sim.report.config_diff.changed_keys`) compared values with ``!=``, while the
   README's inputs table and ``printed_differs`` compare them as 12 significant digits show
   them: a swept 1.1 + 0.6 was named as changed from the file's 1.7 ("`k` = 1.7000000000000002
   (the file: 1.7)"). The three now share one rule, :func:`sim.mc.numtext.shown`.
2. ``--workers 1e1`` was refused ("invalid int value") while ``--trials 1e1`` ran 10 trials;
   ``sim run --workers``, ``make verify --workers`` and ``python -m sim.batch --jobs`` now read
   their value as ``--set`` reads an integer (:func:`sim.mc.argv.integer`), and refuse one out
   of range in its words ("must be <= 64 (got 65)"; they said "must be between 1 and 64 (got
   65)", "must be between 1 and 16, not 17"). ``--max-memory-gb inf`` said "must be a positive
   number (got inf)": it now says the number must be finite.
3. Two ``make verify`` given the same ``--scratch``: the second said "the re-run refused its
   options", naming the sim run's pid in its quoted line. It now says another verify (its
   pid) or a running sim (its pid) re-runs into that ``--scratch``, and names the directory.
4. Two ``python -m sim.batch`` given the same ``--timings`` file each wrote their timings at
   their end: the last write won, the other's studies were lost from the file without a word.
   A batch now holds the file (:class:`sim.batch_timings.TimingsLock`, an ``flock`` on
   ``.<name>.lock`` beside it); the second is refused before it runs anything, naming the
   other's pid.
"""

from __future__ import annotations

import subprocess
import sys

from conftest import ROOT
from oneline import one_line

from sim.batch import main as batch_main
from sim.batch_timings import TimingsLock
from sim.cli import DOC, main
from sim.cli_args import parser
from sim.mc.argv import most_workers
from sim.mc.outputs import stage_dir
from sim.mc.storage import StageLock
from sim.report.config_diff import changed_keys
from sim.report.verify.child import busy_words
from sim.report.verify.cli import _parser as verify_parser
from sim.report.verify.cli import main as verify_main

BROWN = str(ROOT / "studies" / "brown_table1.toml")


# ------------------------------------------- 1. one rule for "another value" (12 digits shown)
def test_a_swept_value_that_shows_as_the_files_is_no_change():
    base = {"study": "s", "a": 1.7, "b": [1.7, 2.0], "c": "x"}
    mine = {"study": "s", "a": 1.1 + 0.6, "b": [1.1 + 0.6, 2], "c": "x"}
    assert changed_keys(mine, base) == []
    mine = {"study": "s", "a": 1.7000001, "b": [1.7, 2.5], "c": "y", "d": 1}
    assert changed_keys(mine, base) == ["a", "b", "c", "d"]


# ------------------------------------------- 2. integer options read as --set reads an integer
def test_workers_and_jobs_read_their_value_as_trials_does(capsys):
    assert parser(DOC).parse_args(["run", BROWN, "--workers", "2e0"]).workers == 2
    assert verify_parser().parse_args(["--workers", "1e0"]).workers == 1
    top = most_workers()
    rc = main(["run", BROWN, "--workers", str(top + 1)])
    one_line(capsys, rc, f"--workers: must be <= {top} (got {top + 1})")
    rc = verify_main(["--workers", "0"])
    one_line(capsys, rc, "--workers: must be >= 1 (got 0)")
    rc = batch_main(["--jobs", "65", BROWN])
    one_line(capsys, rc, "--jobs: must be <= 64 (got 65)")
    rc = batch_main(["--jobs", "1.5", BROWN])
    one_line(capsys, rc, "--jobs: must be an integer (got 1.5)")
    rc = main(["run", BROWN, "--max-memory-gb", "inf", "--out", "/nonexistent/x"])
    one_line(capsys, rc, "--max-memory-gb: must be a finite positive number (got inf)")


# ------------------------------------------- 3. a --scratch another verify re-runs into
def test_a_scratch_another_verify_writes_is_named_with_its_pid(tmp_path):
    holder = "import sys; sys.stdin.read()"
    verify = (  # a process named like a verify, whose child holds the re-run's directory
        "import subprocess, sys  # sim.report.verify\n"
        f"p = subprocess.Popen([sys.executable, '-c', {holder!r}], stdin=subprocess.PIPE)\n"
        "print(p.pid, flush=True); sys.stdin.read(); p.stdin.close(); p.wait()\n"
    )
    proc = subprocess.Popen(
        [sys.executable, "-c", verify], stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True
    )
    try:
        child = int(proc.stdout.readline())
        target = tmp_path / "brown_table1"
        line = f"sim: error: --out: {target} is being written by a running sim (pid {child}); wait"
        said = busy_words(line, target)
    finally:
        proc.stdin.close()
        proc.wait()
    assert said == (
        f"another verify (pid {proc.pid}) re-runs into the same --scratch {tmp_path} "
        "(brown_table1); wait for it to finish or choose another --scratch"
    )
    assert busy_words("sim: error: --trials: must be >= 1 (got 0)", target) is None


def test_a_scratch_a_running_sim_writes_is_named(tmp_path, capsys):
    lock = StageLock(stage_dir(tmp_path / "brown_table1")).acquire()  # as a re-run holds it
    try:
        rc = verify_main(["--study", "brown_table1", "--scratch", str(tmp_path)])
    finally:
        lock.release()
    err = capsys.readouterr().err  # its progress line "re-running brown_table1", then one
    assert rc == 2 and err.count("\n") == 2 and "Traceback" not in err, err
    line = err.splitlines()[-1]
    assert line.startswith("sim verify: error: brown_table1: a running sim (pid "), line
    assert f"writes into the same --scratch {tmp_path} (brown_table1)" in line, line
    assert "refused its options" not in line, line


# ------------------------------------------- 4. one batch at a time writes a --timings file
def test_a_timings_file_another_batch_writes_is_refused_naming_its_pid(tmp_path, capsys):
    timings = tmp_path / "t.json"
    hold = (
        "import sys\nfrom sim.batch_timings import TimingsLock\n"
        f"assert TimingsLock({str(timings)!r}).acquire() is None\n"
        "print('held', flush=True); sys.stdin.read()\n"
    )
    other = subprocess.Popen(
        [sys.executable, "-c", hold], stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True
    )
    try:
        assert other.stdout.readline() == "held\n"
        rc = batch_main(["--timings", str(timings), BROWN])
    finally:
        other.stdin.close()
        other.wait()
    one_line(capsys, rc, f"--timings: another sim.batch (pid {other.pid}) writes {timings}")
    lock = TimingsLock(timings)  # the holder gone, the lock is free; released, no file left
    assert lock.acquire() is None
    lock.release()
    assert sorted(tmp_path.iterdir()) == []
    (tmp_path / ".t.json.lock").write_text("notes\n")  # a file of the user's of that name
    assert "is not a lock file of sim.batch" in TimingsLock(timings).acquire()
    assert (tmp_path / ".t.json.lock").read_text() == "notes\n"
