"""The items issue 26's last sessions left open (brief D30d).

1. ``sim run --trials 1e3`` was refused ("invalid int value: '1e3'") while ``--set
   trials=1e3`` and ``sim.load(..., trials=1e3)`` ran 1,000 trials. ``--trials``, ``--chunk``,
   ``--seed`` (and ``make verify``'s ``--trials``) now read their value as ``--set`` reads it
   (:func:`sim.mc.argv.integer`): a float without a fraction is that integer, anything else
   is refused in ``--set``'s words.
2. ``--set trials=abc`` (any key that takes a number) was told to "write 2748.0": the hint at
   a number the text spells (:func:`sim.mc.numtext.number_text`) read "abc" (or "add",
   "cafe") as a hexadecimal float without its ``0x``. Only a text with its ``0x`` is one now.
3. ``python -m benchmarks --out A --out B`` wrote into B alone, without a word (so did a
   repeated ``--only``, ``--rerun-files`` or ``--rerun-workers``); now one line naming the
   option, as ``sim`` and ``make verify`` say of theirs. ``make bench`` passes ``BENCH_OUT``
   as ``--out``: an ``--out`` in ``BENCH_FLAGS`` is named with ``BENCH_OUT`` instead.
4. :class:`sim.mc.storage.StageLock` took the ``flock`` before it recorded the descriptor:
   an interrupt (Ctrl-C) between the two, or a failed write of the pid after it, kept the
   lock (and the descriptor) for the process's life, and every later run of that process
   (a notebook's ``sim.load(...).run(...)``) into the same ``--out`` was "being written by a
   running sim" (itself). The descriptor is recorded first and closed on any exception.
5. wolf_polynomial's Table 1 figure said its scale "10 µm = 20 mm" in its title and drew it
   as 0.5 µm/mm apart: one constant of the module now gives both.
6. The Makefile's names it does not read but a user tries covered a few spellings
   (``JOBS``, ``WORKERS``, ...): ``make reproduce jobs=4``, ``RUN_JOB=4``, ``make test
   test_workers=1``, ``make bench OUT=x``, ``make fuzz FUZZ_CASE=5``, ``make venv PY=...``
   were dropped without a word (PY replaced the virtual environment's Python in every
   command). Every setting's singular, unprefixed and lower-case spellings are now named.
7. ``sim report`` over the project's own ``results/`` showed a results directory without
   its study file in ``studies/`` like any other, though nothing can re-run it; it is now
   marked, below the opening screen and in the list of studies (a results directory of the
   user's is not compared with ``studies/``).
"""

from __future__ import annotations

import errno
import fcntl
import os
import re
import shutil

import pytest
from conftest import ROOT
from oneline import SIM_ERROR, one_line
from test_doors18c import MAKE, fake_project, make_line, run_make
from test_doors29b import _bench

from sim import cli_read
from sim.cli import DOC, main
from sim.cli_args import parser
from sim.mc import storage
from sim.mc.storage import StageLock
from sim.report.verify.cli import _parser as verify_parser
from sim.studies.wolf import figures as wolf_figures

BROWN = str(ROOT / "studies" / "brown_table1.toml")


# ------------------------------------------------------------- 1. --trials 1e3 as --set reads it
def test_an_integer_option_reads_its_value_as_set_does(capsys):
    a = parser(DOC).parse_args(["run", BROWN, "--trials", "1e3", "--chunk", "5e1", "--seed", "7.0"])
    assert (a.trials, a.chunk, a.seed) == (1000, 50, 7) and type(a.trials) is int
    assert verify_parser().parse_args(["--trials", "4e2"]).trials == 400
    for value, words in (
        ("1000.5", "must be an integer (got 1000.5)"),
        ("inf", "must be finite (got inf)"),
        (".5e3", "must be an integer (got the text '.5e3': write 500.0)"),
    ):
        by_set = one_line(capsys, main(["check", BROWN, "--set", f"trials={value}"]))
        by_option = one_line(capsys, main(["run", BROWN, "--trials", value]), prefix=SIM_ERROR)
        assert by_set == f"{SIM_ERROR}trials: {words}", by_set  # the same words
        assert f"argument --trials: {words} (see sim run --help)" in by_option, by_option


# ------------------------------------------------------------- 2. "abc" is no hexadecimal float
@pytest.mark.parametrize("text", ["abc", "add", "cafe"])
def test_a_word_is_not_read_as_a_hexadecimal_number(capsys, text):
    line = one_line(capsys, main(["check", BROWN, "--set", f"trials={text}"]), prefix=SIM_ERROR)
    assert line.endswith(f"trials: must be an integer (got {text!r})"), line  # no "write 2748.0"
    hint = one_line(capsys, main(["check", BROWN, "--set", "trials=0x1p9"]))
    assert "write 512.0" in hint  # a hexadecimal float with its 0x is still one


# ------------------------------------------------------------- 3. benchmarks' once-options


@pytest.mark.parametrize(
    "argv, opt",
    [
        (["--out", "A", "--out", "B"], "--out"),
        (["--out=A", "--out", "B"], "--out"),
        (["--only", "engines", "--only", "brown"], "--only"),
        (["--rerun-workers", "1", "--rerun-workers", "2"], "--rerun-workers"),
    ],
)
def test_benchmarks_refuses_an_option_given_twice(tmp_path, capsys, argv, opt):
    argv = [re.sub(r"^(--out=)?([AB])$", rf"\g<1>{tmp_path}/\2", a) for a in argv]
    one_line(capsys, _bench(argv), f"argument {opt}: given twice", prefix="benchmarks: error: ")
    assert list(tmp_path.iterdir()) == []


@pytest.mark.skipif(MAKE is None, reason="no make on this machine")
def test_make_bench_names_bench_out_for_an_out_in_bench_flags(tmp_path):
    log, fake = tmp_path / "calls.log", tmp_path / "python"
    fake.write_text(f'#!/bin/sh\necho "$*" >> {log}\n', encoding="utf-8")
    fake.chmod(0o755)
    d = fake_project(tmp_path, str(fake))
    p = run_make(d, "bench", "BENCH_FLAGS=--quick --out elsewhere")
    make_line(p, "make bench: BENCH_FLAGS holds --out: give the directory as BENCH_OUT=DIR")
    assert "-m benchmarks" not in (log.read_text(encoding="utf-8") if log.exists() else "")
    assert run_make(d, "bench", "BENCH_FLAGS=--quick").returncode == 0
    # a smoke run's default directory (doors35v: it replaced the committed results/bench)
    assert "-m benchmarks --out scratch/bench-quick --quick\n" in log.read_text(encoding="utf-8")


# ------------------------------------------------------------- 4. the lock and an interrupt
def _open_fds() -> set[str]:
    return set(os.listdir("/proc/self/fd")) if os.path.isdir("/proc/self/fd") else set()


@pytest.mark.parametrize("where", ["flock", "ftruncate", "write"])
def test_an_interrupt_while_locking_keeps_no_lock(tmp_path, monkeypatch, where):
    stage = tmp_path / "out.partial"
    pid_line = f"{os.getpid()}\n".encode()
    real = {"flock": fcntl.flock, "ftruncate": os.ftruncate, "write": os.write}

    def flock(fd, op):  # the lock taken, then Ctrl-C before the descriptor was recorded
        real["flock"](fd, op)
        raise KeyboardInterrupt

    def ftruncate(fd, n):
        real["ftruncate"](fd, n)
        raise KeyboardInterrupt

    def write(fd, data):  # a full disk under the pid (only the lock file's write fails)
        if data == pid_line:
            raise OSError(errno.ENOSPC, "No space left on device")
        return real["write"](fd, data)

    fds = _open_fds()
    with monkeypatch.context() as m:
        if where == "flock":
            m.setattr(storage.fcntl, "flock", flock)
        else:
            m.setattr(storage.os, where, {"ftruncate": ftruncate, "write": write}[where])
        with pytest.raises(KeyboardInterrupt if where != "write" else OSError):
            StageLock(stage).acquire()
    assert _open_fds() == fds  # no descriptor left open
    lock = StageLock(stage).acquire()  # was Locked(pid): this very process held it
    lock.release()


# ------------------------------------------------------------- 5. wolf's Table 1 scale, once
def test_wolf_table1_figure_says_the_scale_it_draws(tmp_path, monkeypatch):
    import pyarrow as pa

    rows = {
        "plate": ["003", "003", "005"],
        "point": [1, 2, 1],
        "x_set1_mm": [0.0, 20.0, 0.0],
        "y_set1_mm": [0.0, 0.0, 20.0],
        "dx_sets_um": [1.0, -2.0, 0.5],
        "dy_sets_um": [0.5, 1.0, -1.0],
    }
    monkeypatch.setattr(wolf_figures, "read_table", lambda p: pa.table(rows))
    monkeypatch.setattr(wolf_figures, "save", lambda fig, p: wolf_figures.plt.close(fig))
    drawn = []
    monkeypatch.setattr(wolf_figures, "_quiver", lambda *a: drawn.append(a[5:]))
    monkeypatch.setattr(wolf_figures, "_TABLE1_KEY_UM", 10.0)
    monkeypatch.setattr(wolf_figures, "_TABLE1_KEY_MM", 40.0)  # a scale changed in one place
    wolf_figures.table1_figure(tmp_path)
    assert len(drawn) == 2
    for title, key_um, um_per_mm in drawn:
        assert "10 µm = 40 mm" in title and key_um == 10.0 and um_per_mm == 0.25, title


# ------------------------------------------------------------- 6. the Makefile's other spellings
def _named() -> set[str]:
    text = (ROOT / "Makefile").read_text(encoding="utf-8")
    names = set(re.findall(r"^\$\(call not_read,(\w+),", text, re.M))
    for group in re.findall(r"^\$\(call not_read_any,([\w ]+),", text, re.M):
        names |= set(group.split())
    return names


def test_every_settings_likely_spellings_are_named():
    text = (ROOT / "Makefile").read_text(encoding="utf-8")
    settings = set(re.findall(r"^([A-Z][A-Z_]*) \?=", text, re.M))
    settings |= {"FUZZ_CASES", "FUZZ_SEED", "FUZZ_SAVE"}  # read by make fuzz from its command line
    assert {"RUN_JOBS", "TEST_WORKERS", "BENCH_OUT", "PYTHON"} <= settings
    want = set()
    for s in settings:
        short = s.split("_", 1)[-1]
        want |= {s.lower(), short, short.lower()} - {s}
        if s.endswith("S"):
            want.add(s[:-1])
    assert not want - _named() - settings, sorted(want - _named() - settings)
    assert not _named() & settings  # no setting is refused


# the other spellings refused before any command: cases of
# test_doors29b.test_make_names_a_setting_it_does_not_read_before_any_command


# ------------------------------------------------------------- 7. results without a study file
def test_the_report_marks_project_results_without_their_study_file(tmp_path, capsys, monkeypatch):
    project = tmp_path / "project"
    (project / "studies").mkdir(parents=True)
    shutil.copy(ROOT / "studies" / "network_plate.toml", project / "studies")
    for name in ("network_plate", "network_old"):  # network_old: its file deleted since
        shutil.copytree(ROOT / "results" / "network_plate", project / "results" / name)
    monkeypatch.setattr(cli_read, "STUDY_FILES", project / "studies")
    shutil.copytree(project / "results", tmp_path / "mine")  # a directory of the user's
    mark = "(no study file `studies/network_old.toml`: these results cannot be re-run)"
    for results, times in ((project / "results", 2), (tmp_path / "mine", 0)):
        assert main(["report", "--results", str(results)]) == 0, capsys.readouterr().err
        capsys.readouterr()
        text = (results / "REPORT.md").read_text(encoding="utf-8")
        assert text.count(mark) == times, text[:3000]  # below the opening and in the list
        assert "`studies/network_plate.toml`" not in text  # it has its file
    assert "- `network_old` " + mark in (project / "results" / "REPORT.md").read_text()
