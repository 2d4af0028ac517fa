"""The classes of the sweep doors22b (every command's output as other programs and terminals
consume it: pipes, a full disk, closed streams, a terminal of no size), one case each; each
failed on the code before its fix.

* standard output that fails only when Python flushes it at exit (a user's default: block
  buffered, ``PYTHONUNBUFFERED`` unset; the earlier tests wrote through a line-buffered file):
  ``sim check STUDY > /dev/full``, ``sim show DIR > /dev/full``, ``--help > /dev/full`` of every
  program and ``make verify > /dev/full`` printed Python's "Exception ignored in: <_io.TextIOWrapper
  name='<stdout>'> OSError: [Errno 28]" and exited 120; a reader that left (``| head -1``)
  printed the same with BrokenPipeError. Now one line naming standard output and exit 2, or
  (a reader that left) nothing and 141 (:func:`sim.ends.flush_stdout`); with
  ``PYTHONUNBUFFERED=1`` argparse dropped the failed write of ``--help``: exit 0, no word
  (:class:`sim.mc.argv.BoundedParser`);
* ``sim run ... --out DIR > DIR/log.txt`` over earlier results in DIR: the user's log was
  carried into the new results as a copy made before the run printed a word, and the run's
  lines went into the old file, removed with the old results: an empty log and exit 0. A
  user's regular file is now carried by a hard link, the same file (:func:`sim.mc.publish._carry`);
* ``python -m sim.batch --jobs 1`` passed its standard output to the runs: a full one was a
  line per run, and a reader that left ended the batch with the first run's 141, where
  ``--jobs 2`` said a full output once and ended with 0 on a reader that left; both now as
  ``sim``: one line, or quietly 141 (:func:`sim.batch.run_all`, :func:`sim.batch.main`);
* a directory name that begins with "-" (``python -m sim.batch --results=-r``, ``make verify``
  ``--scratch=-s``) reached each run as ``--out -r/<study>``, which sim run read as an option
  ("argument --out: expected one argument"); ``--out -`` and ``--timings -`` made a directory
  and a file named "-" where "-" reads as standard output: refused by name;
* standard error closed (``2>&-``): Python's ``print(..., file=sys.stderr)`` wrote to standard
  output (an error line into a saved ``sim check`` listing), and ``python -m sim.batch`` ended
  with exit 1 and no timings after its runs (:func:`sim.ends.open_standard_streams`);
* ``make verify`` that failed broadly prints ~30 KB: into a full disk or to a reader that left
  it was a traceback from ``print``, and its record was not written
  (:func:`sim.report.verify.cli._main`, :func:`sim.ends.stdout_failed`);
* ``make verify``'s standard output held its re-runs' "results in /tmp/sim-verify-.../" lines
  (a directory removed at its end) between its own (:func:`sim.report.verify.rerun.rerun_study`);
"""

import os
import subprocess
import sys
from pathlib import Path

import pytest
from oneline import one_line, one_line_of

ROOT = Path(__file__).resolve().parent.parent
STUDY = ROOT / "studies" / "network_plate.toml"
FULL = Path("/dev/full")


def _env(**more: str) -> dict:
    """The environment of a user's shell: standard output block-buffered."""
    env = {k: v for k, v in os.environ.items() if k != "PYTHONUNBUFFERED"}
    env["PYTHONIOENCODING"] = "utf-8"
    return {**env, **more}


def _into_full(*argv: str, **env: str) -> subprocess.CompletedProcess:
    with open(FULL, "w") as full:
        return subprocess.run(
            [sys.executable, *argv],
            stdout=full,
            stderr=subprocess.PIPE,
            text=True,
            env=_env(**env),
            cwd=ROOT,
        )


def _into_left_pipe(*argv: str) -> subprocess.CompletedProcess:
    """``argv`` with its standard output a pipe whose reader has left (``| head -c 0``)."""
    r, w = os.pipe()
    os.close(r)
    try:
        return subprocess.run(
            [sys.executable, *argv],
            stdout=w,
            stderr=subprocess.PIPE,
            text=True,
            env=_env(),
            cwd=ROOT,
        )
    finally:
        os.close(w)


SMALL_OUTPUTS = [
    ("-m", "sim", "check", str(STUDY)),
    ("-m", "sim", "show", str(ROOT / "results" / "network_plate")),
    ("-m", "sim", "--help"),
    ("-m", "sim", "--version"),
    ("-m", "sim.batch", "--help"),
    ("-m", "sim.report.verify", "--help"),
    ("-m", "benchmarks", "--help"),
]


@pytest.mark.skipif(not FULL.exists(), reason="needs /dev/full")
@pytest.mark.parametrize("argv", SMALL_OUTPUTS, ids=lambda a: " ".join(a[1:3]))
def test_a_full_standard_output_flushed_at_exit_is_one_line(argv):
    if "show" in argv and not (ROOT / "results" / "network_plate" / "claims.parquet").is_file():
        pytest.skip("needs the committed results of network_plate")
    p = _into_full(*argv)
    line = one_line_of(p, "No space left on device", "standard output")
    assert "Exception ignored" not in line


@pytest.mark.skipif(not FULL.exists(), reason="needs /dev/full")
@pytest.mark.parametrize("prog", ["sim", "sim.batch", "sim.report.verify", "benchmarks"])
def test_help_into_a_full_output_unbuffered_is_one_line(prog):
    """argparse drops an OSError of its --help: with PYTHONUNBUFFERED=1 (many containers) every
    program's ``--help > /dev/full`` ended with exit 0 and no word."""
    one_line_of(_into_full("-m", prog, "--help", PYTHONUNBUFFERED="1"), "standard output")


@pytest.mark.parametrize("argv", SMALL_OUTPUTS, ids=lambda a: " ".join(a[1:3]))
def test_a_reader_that_left_ends_the_output_quietly(argv):
    if "show" in argv and not (ROOT / "results" / "network_plate" / "claims.parquet").is_file():
        pytest.skip("needs the committed results of network_plate")
    p = _into_left_pipe(*argv)
    assert (p.returncode, p.stderr) == (141, ""), (p.returncode, p.stderr)


def test_verify_prints_only_its_own_lines(tmp_path):
    """``make verify``'s standard output held each re-run's own "network: results in
    /tmp/sim-verify-.../network_plate/" (a directory removed when verify ends) between its
    comparison lines, and a full standard output failed the re-runs themselves."""
    if not (ROOT / "results" / "network_plate" / "claims.parquet").is_file():
        pytest.skip("needs the committed results of network_plate")
    argv = ["-m", "sim.report.verify", "--results", "results", "--study", "network_plate"]
    argv += ["--trials", "400", "--workers", "1", "--scratch", str(tmp_path / "s")]
    p = subprocess.run(
        [sys.executable, *argv], capture_output=True, text=True, env=_env(), cwd=ROOT
    )
    assert p.returncode == 0, p.stderr
    assert p.stdout.startswith("network_plate: ok; ") and p.stdout.count("\n") == 1, p.stdout


@pytest.mark.long
def test_output_redirected_into_the_results_directory_is_kept(tmp_path):
    """``sim run ... --out DIR > DIR/log.txt`` over an earlier run into DIR: the user's log was
    carried into the new results as a copy made before the run printed a word, and what it
    printed went into the old file, removed with the old results: an empty log, exit 0."""
    out = tmp_path / "o"
    run = [sys.executable, "-m", "sim", "run", str(STUDY), "--no-figures", "--out", str(out)]
    first = subprocess.run([*run, "--trials", "40"], capture_output=True, env=_env(), cwd=ROOT)
    assert first.returncode == 0, first.stderr
    for trials in ("40", "60"):  # the same run again, and one of another config
        with open(out / "log.txt", "w") as log:
            p = subprocess.run(
                [*run, "--trials", trials, "--overwrite"],
                stdout=log,
                stderr=subprocess.STDOUT,
                env=_env(),
                cwd=ROOT,
            )
        text = (out / "log.txt").read_text()
        assert p.returncode == 0, text
        assert f"results in {out}/" in text, (trials, text)


@pytest.mark.long
@pytest.mark.skipif(not FULL.exists(), reason="needs /dev/full")
def test_batch_of_one_job_says_a_full_output_once(tmp_path):
    """``python -m sim.batch --jobs 1`` passed its standard output to the runs: a full one was
    one line per run (each run's own), where ``--jobs 2`` says it once for the driver."""
    files = [str(STUDY), str(ROOT / "studies" / "network_testfield.toml")]
    argv = ["-m", "sim.batch", *files, "--jobs", "1", "--results", str(tmp_path / "r")]
    p = _into_full(*argv, "--", "--trials", "40", "--no-figures")
    assert one_line_of(p) == "sim.batch: standard output: No space left on device"
    assert (tmp_path / "r" / "network_testfield" / "run.json").is_file()


@pytest.mark.parametrize("jobs", ["1", "2"])
def test_batch_whose_reader_left_ends_as_sim_does(tmp_path, jobs):
    """A reader that left (``| head -c 0``): ``--jobs 1`` ended with the first run's 141,
    ``--jobs 2`` with 0; both as ``sim``: quietly, 141."""
    argv = ["-m", "sim.batch", str(STUDY), "--jobs", jobs, "--results", str(tmp_path / "r")]
    p = _into_left_pipe(*argv, "--", "--trials", "40", "--no-figures")
    assert (p.returncode, p.stderr) == (141, ""), (p.returncode, p.stderr)
    assert (tmp_path / "r" / "network_plate" / "run.json").is_file()


def _failed_comparisons(*args, **kwargs):
    """What verify found, as a broad failure does: 20 lines for each of 12 studies (~30 KB)."""
    from sim.report.verify.rules import Comparison

    lines = [f"points.parquet:col{j}: deviation beyond its tolerance {'.' * 80}" for j in range(20)]
    return [Comparison(study=f"s{i}", files=3, max_ratio=9.0, failures=lines) for i in range(12)]


@pytest.mark.skipif(not FULL.exists(), reason="needs /dev/full")
@pytest.mark.parametrize("reader_left", [False, True])
def test_verify_long_output_that_cannot_be_written(tmp_path, capsys, monkeypatch, reader_left):
    """A verify that failed broadly prints ~30 KB: into a full disk or to a reader that left it
    was a traceback from ``print`` (exit 1 by the traceback), before the record was written."""
    from sim.report.verify import cli as verify_cli

    monkeypatch.setattr(verify_cli, "verify", _failed_comparisons)
    monkeypatch.setattr(verify_cli, "write_record", lambda results, comps: written.append(comps))
    written: list = []
    if reader_left:
        r, w = os.pipe()
        os.close(r)
        out = os.fdopen(w, "w", buffering=1024)
    else:
        out = open(FULL, "w", buffering=1024)  # noqa: SIM115 - closed below
    try:
        monkeypatch.setattr(sys, "stdout", out)
        rc = verify_cli.main(["--results", str(ROOT / "results"), "--scratch", str(tmp_path)])
    finally:
        monkeypatch.undo()
        try:
            out.close()
        except OSError:
            pass
    assert written, "the record was not written"
    if reader_left:
        assert (rc, capsys.readouterr().err) == (1, "")
    else:
        line = one_line(capsys, rc, "standard output", code=1)
        assert line == "sim verify: error: No space left on device: standard output"


@pytest.mark.long
def test_a_directory_name_that_begins_with_a_dash_reaches_the_runs(tmp_path):
    """``python -m sim.batch --results=-r`` (and ``make verify`` ``--scratch=-s``) handed each
    run ``--out -r/<study>``, which sim run read as an option: "argument --out: expected one
    argument", naming an option the user never gave."""
    argv = ["-m", "sim.batch", str(STUDY), "--results=-r", "--", "--trials", "40", "--no-figures"]
    p = subprocess.run(
        [sys.executable, *argv], capture_output=True, text=True, env=_env(), cwd=tmp_path
    )
    assert p.returncode == 0, p.stderr
    assert (tmp_path / "-r" / "network_plate" / "run.json").is_file()
    if not (ROOT / "results" / "network_plate" / "claims.parquet").is_file():
        return
    for d in ("studies", "results"):
        (tmp_path / d).symlink_to(ROOT / d)
    argv = ["-m", "sim.report.verify", "--results", "results", "--study", "network_plate"]
    argv += ["--trials", "400", "--workers", "1", "--scratch=-s"]
    p = subprocess.run(
        [sys.executable, *argv], capture_output=True, text=True, env=_env(), cwd=tmp_path
    )
    assert p.returncode == 0 and p.stdout.startswith("network_plate: ok; "), p.stderr


def test_a_dash_for_an_output_is_not_taken_as_a_name(tmp_path, capsys, monkeypatch):
    """``--out -`` made a results directory named "-" and ``--timings -`` a file named "-" (in
    the working directory), where many programs read "-" as standard output."""
    from sim import batch, cli

    monkeypatch.chdir(tmp_path)
    run = ["run", str(STUDY), "--trials", "40", "--no-figures", "--out", "-"]
    one_line(capsys, cli.main(run), "'-' is not standard output", prefix="sim: error: --out: ")
    argv = [str(STUDY), "--stale-only", "--results", str(tmp_path / "r"), "--timings", "-"]
    one_line(capsys, batch.main(argv), "'-' is not standard output", prefix="sim.batch: --timings")
    assert not (tmp_path / "-").exists()


def _closed_stderr(*argv: str, cwd=ROOT) -> subprocess.CompletedProcess:
    """``argv`` run with its standard error closed (``2>&-``)."""
    script = '"$0" "$@" 2>&-'
    return subprocess.run(
        ["sh", "-c", script, sys.executable, *argv],
        capture_output=True,
        text=True,
        env=_env(),
        cwd=cwd,
    )


@pytest.mark.long
def test_a_closed_standard_error_keeps_errors_out_of_standard_output(tmp_path):
    """With standard error closed Python leaves ``sys.stderr`` None, and ``print(...,
    file=sys.stderr)`` wrote to standard output: ``sim check STUDY --set trials=-1 2>&- >
    saved.toml`` put its error line into the saved listing; ``python -m sim.batch 2>&-``
    ended with exit 1 and no timings after its runs had finished."""
    p = _closed_stderr("-m", "sim", "check", str(STUDY), "--set", "trials=-1")
    assert (p.returncode, p.stdout) == (2, ""), (p.returncode, p.stdout)
    timings = tmp_path / "t.json"
    argv = ["-m", "sim.batch", str(STUDY), "--results", str(tmp_path / "r")]
    argv += ["--timings", str(timings), "--", "--trials", "40", "--no-figures"]
    p = _closed_stderr(*argv)
    assert p.returncode == 0 and timings.is_file(), (p.returncode, p.stdout)
