"""The classes of the sweep doors18c (issue 26: the make targets and the setup as a user calls
them, and results that travel between machines), one case each; each failed on the code
before its fix. The make cases run the project's Makefile with its install stamp taken as
current (``make -o .venv/.installed``: nothing is installed) or a copy of it in a temporary
directory with a stand-in Python, so they run no study and touch no network.

* ``make reproduce RUN_JOBS=`` answered "argument --jobs: invalid int value:
  'studies/agnard_block.toml'" (the empty value let the first study file take its place);
  ``make test TEST_WORKERS=abc`` was pytest's four-line usage error; ``make mutation
  MUTATION_WORKERS=abc`` installed the mutation extra first and then failed in mutmut's
  usage: each is now one line naming the variable before anything runs (``whole`` in the
  Makefile);
* ``make bench BENCH_OUT="a b"`` split the directory into two arguments ("unrecognized
  arguments: b"): the value is passed as one shell word;
* ``make -f path/to/Makefile report`` from another directory was "No rule to make target
  'pyproject.toml', needed by '.venv/.installed'" (every path in it is relative): one line
  saying to run it in its own directory;
* a ``.venv`` whose Python no longer starts (``bin/python`` deleted, the Python it was made
  from removed) stopped every target with ".venv/bin/python: No such file or directory", and
  ``make venv`` did nothing (its stamp was newer than pyproject.toml) until ``make clean``:
  such a ``.venv`` is made again;
* a ``.venv`` of a Python older than the project's ``requires-python`` (left by a failed
  ``make venv PYTHON=python3.10``) or made for another directory (the project moved, or
  copied with its ``.venv``: its scripts start the old path's Python and code) stayed as it
  was, every later target failing in pip or in a "bad interpreter": made again too (the
  stamp records the directory it was made for);
* ``copy/.venv/bin/sim`` of a project copied with its ``.venv`` (``cp -a``) silently ran the
  original's code in the copy; it is one line naming both and ``make clean venv``
  (:func:`sim.threads.script_of_another_copy`);
* each install step holds ``.venv.lock`` (flock): a pip still rolling back after Ctrl-C
  raced the next make venv's ``venv --clear``;
* ``make venv PYTHON=python9`` (or a Python without ``venv``) was the shell's or Python's
  line, and Ctrl-C during ``python -m venv`` printed its KeyboardInterrupt traceback: venv's
  output goes to the install's mark, a failure is one line naming PYTHON;
* pip failing in ``make venv`` (no network, no index) printed pip's dozen lines with the
  cause in the middle; it is one line with pip's first error (or its last line: a pip that no
  longer starts) and the log's path, and the next ``make venv`` tries again; an install
  interrupted during pip's own upgrade left a pip that no longer imports, and every later
  ``make venv`` failed in it: an install that did not finish leaves ``.venv.installing``, and
  the next one starts from scratch (a ``.venv`` of the user's own is installed into as it is);
* ``make reproduce`` (``sim.batch --stale-only``) re-ran a study whose results were not
  current without a word: results made by older code, copied from another machine or made
  with other options ran for minutes with nothing printed (the runs are quiet side by side);
  each is now named with the reason, one line per study (:func:`sim.batch.why_stale`);
* ``sim report`` on results whose directories were swapped by hand (``brown_table1/`` holding
  brown_dilution's run and the other way round) labelled each study's claims, region and
  link with the other's name without a word; each such directory is named in a note
  (:func:`sim.report.glance.opening`);
* a library removed from the suite's own ``.venv`` was answered "run the suite with the Python
  it was installed into (make venv; .venv/bin/sim), not .../.venv/bin/python": that is the
  Python it was installed into, and ``make venv`` did nothing; the line now says the
  environment lacks it and that ``make clean venv`` installs it again
  (:func:`sim.threads.import_words`).
"""

import json
import os
import shlex
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

import sim.batch
from sim import threads
from sim.batch import why_stale
from tests.oneline import python_lines

ROOT = Path(__file__).resolve().parents[1]
MAKE = shutil.which("make")
pytestmark = pytest.mark.skipif(MAKE is None, reason="no make on this machine")


#: what an outer make (``make test`` runs pytest) passes down: the make under test would
#: print its lines as ``make[1]:`` and take the outer one's flags
OUTER_MAKE = ("MAKEFLAGS", "MAKELEVEL", "MFLAGS", "MAKEOVERRIDES", "MAKE_TERMOUT", "MAKE_TERMERR")


def user_env(env=None) -> dict:
    """``env`` (default: this process's) without what an outer make passes down."""
    return {k: v for k, v in (os.environ if env is None else env).items() if k not in OUTER_MAKE}


def make(*args, cwd=ROOT, env=None):
    """``make -s ARGS`` in ``cwd`` with the install stamp taken as current, as a user's
    make from a shell (not as a sub-make of the make that runs the tests)."""
    return subprocess.run(
        [MAKE, "-s", "--no-print-directory", "-o", ".venv/.installed", *args],
        cwd=cwd,
        capture_output=True,
        text=True,
        timeout=120,
        env=user_env(env),
    )


def make_line(p: subprocess.CompletedProcess, *needles: str) -> str:
    """Exit 2 and one line of ours on stderr, then only make's own "*** ... Error 2" line
    (README: a failed target ends with it); the line is returned."""
    lines = p.stderr.splitlines()
    assert p.returncode == 2 and "Traceback" not in p.stderr, (p.returncode, p.stderr)
    assert len(lines) == 2 and lines[1].startswith("make: *** ") and "Error 2" in lines[1], p.stderr
    assert all(n in lines[0] for n in needles), lines[0]
    return lines[0]


@pytest.mark.parametrize(
    ("target", "var", "value", "least"),
    [
        ("reproduce", "RUN_JOBS", "", 1),
        ("rerun", "RUN_JOBS", "abc", 1),
        ("reproduce", "RUN_JOBS", "a'b", 1),
        ("test", "TEST_WORKERS", "abc", 0),
        ("mutation", "MUTATION_WORKERS", "0", 1),
    ],
)
def test_a_make_variable_that_is_not_a_whole_number_is_one_line_before_anything_runs(
    target, var, value, least
):
    p = make(target, f"{var}={value}")
    line = make_line(p, f"make {target}: {var} must be a whole number of at least {least}")
    assert line.endswith(f"(got '{value}')"), line
    assert p.stdout == ""  # nothing ran: no batch, no pytest, no pip


def test_make_test_takes_auto_and_zero_workers():
    for value in ("auto", "0"):
        p = make("-n", "test", f"TEST_WORKERS={value}")
        assert p.returncode == 0 and f"pytest -n {value} " in p.stdout, p.stdout + p.stderr


def phony_targets() -> list[str]:
    """The Makefile's .PHONY targets (every command a user is told to run)."""
    line = next(x for x in (ROOT / "Makefile").read_text().splitlines() if x.startswith(".PHONY:"))
    return line.split(":", 1)[1].split()


@pytest.mark.parametrize("target", [t for t in phony_targets() if t != "venv-unusable"])
def test_every_make_target_is_commands_the_shell_can_parse(target):
    """`make -n TARGET` prints what the target would run; each must be valid shell. A comma
    inside ``$(call pip,-e ".[dev,mutation]")`` split the call's argument, and `make mutation`
    died at once in "/bin/sh: Syntax error: Unterminated quoted string" (no test ran it)."""
    p = make("-n", target)
    assert p.returncode == 0, p.stderr
    sh = subprocess.run(["sh", "-n"], input=p.stdout, capture_output=True, text=True, timeout=30)
    assert sh.returncode == 0, (target, sh.stderr, p.stdout)


def test_bench_out_with_a_space_and_a_quote_stays_one_argument():
    out = "/tmp/my bench's dir"
    p = make("-n", "bench", f"BENCH_OUT={out}", "BENCH_FLAGS=--quick")
    assert p.returncode == 0, p.stderr
    argv = shlex.split(p.stdout.strip().splitlines()[-1])
    assert argv[argv.index("--out") + 1] == out and argv[-1] == "--quick", argv


#: what pip prints without a network (its first error is the cause), and a pip left broken
OFFLINE = [
    "  ERROR: Could not find a version that satisfies the requirement setuptools>=61",
    "  ERROR: No matching distribution found for setuptools>=61",
]
BROKEN = "ImportError: cannot import name 'open_rich_spinner' from 'pip._internal.cli.spinners'"


def write_fake(fake: Path, pip_says: list[str] | None) -> None:
    """A stand-in Python: ``-m pip`` prints ``pip_says`` and fails (succeeds when None),
    ``-m venv`` logs its arguments and links ``.venv/bin/python`` to itself, anything else
    is this Python."""
    pip = "exit 0" if pip_says is None else "".join(f"echo {shlex.quote(x)}; " for x in pip_says)
    fake.write_text(
        "#!/bin/sh\n"
        'case "$*" in\n'
        f'  *"-m pip"*) {pip if pip_says is None else pip + "exit 1"};;\n'
        '  *"-m venv"*) echo "venv $*" >> "$(dirname "$0")/venv.log"\n'
        '    ln -sfn "$0" .venv/bin/python; exit 0;;\n'
        "esac\nexec " + shlex.quote(sys.executable) + ' "$@"\n',
        encoding="utf-8",
    )
    fake.chmod(0o755)


def test_make_from_another_directory_says_where_to_run_it(tmp_path):
    p = subprocess.run(
        [MAKE, "-s", "-f", str(ROOT / "Makefile"), "report"],
        cwd=tmp_path,
        capture_output=True,
        text=True,
        timeout=60,
        env=user_env(),
    )
    err = p.stderr.strip()
    assert p.returncode == 2 and "\n" not in err, err
    assert err.endswith(
        f"*** {ROOT / 'Makefile'} runs in its own directory: make -C <its directory> report.  Stop."
    ), err
    assert list(tmp_path.iterdir()) == []  # nothing made here


def fake_project(tmp_path: Path, python: str, pip_fails: bool = False) -> Path:
    """A copy of the Makefile beside a pyproject.toml, a current stamp and ``.venv/bin/python``
    pointing at ``python``; ``PYTHON`` for it is a stand-in whose ``-m venv`` only makes the
    directory and its Python, and whose pip fails (as offline) when ``pip_fails``."""
    d = tmp_path / "proj"
    (d / ".venv" / "bin").mkdir(parents=True)
    shutil.copy(ROOT / "Makefile", d / "Makefile")
    (d / "pyproject.toml").write_text("[project]\nname = 'x'\n", encoding="utf-8")
    write_fake(tmp_path / "fakepython", OFFLINE if pip_fails else None)
    (d / ".venv" / "bin" / "python").symlink_to(python)
    stamp = d / ".venv" / ".installed"
    stamp.touch()
    os.utime(d / "pyproject.toml", (1_000_000_000, 1_000_000_000))  # older than the stamp
    return d


def run_make(d: Path, *args, python: str = ""):
    python = python or str(d.parent / "fakepython")
    return subprocess.run(
        [MAKE, "-s", "--no-print-directory", *args, f"PYTHON={python}"],
        cwd=d,
        capture_output=True,
        text=True,
        timeout=60,
        env=user_env(),
    )


def test_a_venv_whose_python_does_not_start_is_made_again(tmp_path):
    # a dangling .venv/bin/python (the Python it was made from removed): made again, --clear
    d = fake_project(tmp_path, "/nonexistent/python3")
    p = run_make(d, "venv")
    assert p.returncode == 0, p.stderr
    assert "-m venv --clear .venv" in (tmp_path / "venv.log").read_text(encoding="utf-8")
    # a .venv whose Python starts and whose stamp is current is left as it is
    (tmp_path / "venv.log").unlink()
    e = fake_project(tmp_path / "ok", str(tmp_path / "fakepython"))
    p = run_make(e, "venv")
    assert p.returncode == 0 and not (tmp_path / "ok" / "venv.log").exists(), p.stderr


def test_a_venv_made_for_another_directory_or_an_older_python_is_made_again(tmp_path):
    d = fake_project(tmp_path, str(tmp_path / "fakepython"))
    stamp = d / ".venv" / ".installed"
    stamp.write_text("/somewhere/else/proj\n", encoding="utf-8")  # moved or copied here
    p = run_make(d, "venv")
    assert p.returncode == 0, p.stderr
    assert "-m venv --clear .venv" in (tmp_path / "venv.log").read_text(encoding="utf-8")
    assert stamp.read_text(encoding="utf-8").splitlines()[0] == str(d)  # the directory it serves
    (tmp_path / "venv.log").unlink()
    for made_in in (str(d), ""):  # made here, or an empty stamp of an older Makefile: kept
        stamp.write_text(made_in, encoding="utf-8")
        p = run_make(d, "venv")
        assert p.returncode == 0 and not (tmp_path / "venv.log").exists(), (made_in, p.stderr)
    # a Python older than requires-python (a failed make venv PYTHON=python3.10 left it)
    old = tmp_path / "oldpython"
    old.write_text('#!/bin/sh\ncase "$*" in *version_info*) exit 1;; esac\nexit 0\n')
    old.chmod(0o755)
    (d / ".venv" / "bin" / "python").unlink()
    (d / ".venv" / "bin" / "python").symlink_to(old)
    p = run_make(d, "venv")
    assert p.returncode == 0, p.stderr
    assert "-m venv --clear .venv" in (tmp_path / "venv.log").read_text(encoding="utf-8")


def test_the_sim_script_of_a_copied_venv_refuses_to_run_the_originals_code(tmp_path):
    copy = tmp_path / "copy"
    (copy / "sim").mkdir(parents=True)
    (copy / "sim" / "__init__.py").write_text("", encoding="utf-8")
    (copy / ".venv" / "bin").mkdir(parents=True)
    script = copy / ".venv" / "bin" / "sim"
    p = python_lines(
        "import sys",
        f"sys.argv = [{str(script)!r}, '--version']",
        "from sim.__main__ import main",
        "sys.exit(main())",
    )
    err = p.stderr.strip()
    assert p.returncode == 2 and "\n" not in err and "Traceback" not in err, err
    assert err.startswith(f"sim: error: {script} runs the suite in {ROOT}, where its .venv"), err
    assert f"make clean venv in {copy}" in err and p.stdout == "", err
    # python -m sim in the copy (its own code), and a project's own script: nothing to say
    for argv0 in (str(ROOT / "sim" / "__main__.py"), str(ROOT / ".venv" / "bin" / "sim")):
        p = python_lines(
            "import sys",
            f"sys.argv = [{argv0!r}]",
            "from sim.threads import script_of_another_copy",
            "print(script_of_another_copy())",
        )
        assert p.stdout.strip() == "None", (argv0, p.stdout, p.stderr)


def test_a_python_that_cannot_make_a_venv_is_one_line(tmp_path):
    # make venv PYTHON=python9 (a typo), or a Python without the venv module (python2.7)
    d = fake_project(tmp_path, "/nonexistent/python3")
    old = tmp_path / "py27"
    old.write_text('#!/bin/sh\necho "$0: No module named venv" >&2; exit 1\n', encoding="utf-8")
    old.chmod(0o755)
    missing = "not found"  # the shell's word (each step runs in sh -c under the lock)
    for python, why in (
        (str(tmp_path / "python9"), missing),
        (str(old), "No module named venv"),
    ):
        line = make_line(
            run_make(d, "venv", python=python), f"make: PYTHON ({python}) could not make .venv: "
        )
        assert line.endswith(why), line
        assert (d / ".venv.installing").exists()  # the next make venv starts from scratch


def test_an_install_that_failed_or_was_stopped_starts_again_from_scratch(tmp_path):
    d = fake_project(tmp_path, str(tmp_path / "fakepython"))
    # the mark of an install that did not finish (pip failed, Ctrl-C, even inside venv --clear)
    (d / ".venv.installing").touch()
    p = run_make(d, "venv")
    assert p.returncode == 0, p.stderr
    assert "-m venv --clear .venv" in (tmp_path / "venv.log").read_text(encoding="utf-8")
    assert not (d / ".venv.installing").exists()  # removed by the install that finished
    # a .venv of the user's own (no stamp, no mark of this Makefile): installed into as it is
    (tmp_path / "venv.log").unlink()
    (d / ".venv" / ".installed").unlink()
    p = run_make(d, "venv")
    assert p.returncode == 0, p.stderr
    assert "-m venv .venv" in (tmp_path / "venv.log").read_text(encoding="utf-8")


def test_pip_failing_in_make_venv_is_one_line_with_its_first_error(tmp_path):
    d = fake_project(tmp_path, "/nonexistent/python3", pip_fails=True)
    (d / ".venv" / "bin" / "python").unlink()
    (d / ".venv" / "bin" / "python").symlink_to(tmp_path / "fakepython")
    (d / ".venv" / ".installed").unlink()  # as a first install
    p = run_make(d, "venv")
    line = make_line(p, "make: pip could not install into .venv: ", "setuptools>=61")
    assert "Could not find a version" in line and ".venv/pip.log" in line, line
    assert "No matching distribution" in (d / ".venv" / "pip.log").read_text(encoding="utf-8")
    assert not (d / ".venv" / ".installed").exists()  # the next make venv tries again,
    assert (d / ".venv.installing").exists()  # from scratch
    # a pip that does not start (a traceback, no ERROR line): its last line
    write_fake(tmp_path / "fakepython", ["Traceback (most recent call last):", "  File x", BROKEN])
    line = make_line(run_make(d, "venv"), "make: pip could not install into .venv: ")
    assert line.startswith(f"make: pip could not install into .venv: {BROKEN} (all of its"), line


def test_a_library_missing_from_the_suites_own_venv_says_how_to_install_it_again(
    tmp_path, monkeypatch
):
    # a name no module of this process has (a loaded pyarrow outside the patched prefix would
    # read as a file shadowing it)
    missing = ModuleNotFoundError("No module named 'pyarrowx'", name="pyarrowx")
    (tmp_path / "sim").mkdir()
    (tmp_path / ".venv").mkdir()
    monkeypatch.setattr(threads, "__file__", str(tmp_path / "sim" / "threads.py"))
    monkeypatch.setattr(sys, "prefix", str(tmp_path / ".venv"))
    monkeypatch.setattr(sys, "base_prefix", "/usr")
    words = threads.import_words(missing)
    assert words.startswith("cannot load pyarrowx: No module named 'pyarrowx'; ")
    assert f"virtual environment {tmp_path / '.venv'} lacks it: make clean venv" in words
    assert "run the suite with the Python" not in words
    # another Python (not the suite's .venv): as before, run the suite with its own
    monkeypatch.setattr(sys, "prefix", str(tmp_path))
    assert "run the suite with the Python it was installed into" in threads.import_words(missing)


def test_stale_only_names_why_each_study_it_runs_is_out_of_date(tmp_path, capsys):
    study = ROOT / "studies" / "network_plate.toml"
    committed = json.loads((ROOT / "results" / "network_plate" / "run.json").read_text("utf-8"))
    out = tmp_path / "r" / "network_plate"
    assert why_stale(study, out) == "no results yet"
    out.mkdir(parents=True)
    assert why_stale(study, out) == "no run record (run.json)"

    def record(**change):
        (out / "run.json").write_text(json.dumps({**committed, **change}), encoding="utf-8")

    record(code_hash="0" * 64)  # results made by older code (a clone a few commits back)
    assert why_stale(study, out) == ("made by other code: the code the study imports changed since")
    record(config={**committed["config"], "seed": 99, "trials": 3})
    assert why_stale(study, out) == "made with another config: seed, trials"
    record(figures=False)
    assert why_stale(study, out) == "made without figures"
    # the batch says it, one line per study run, before the run's own line
    record()
    small = ["--trials", "40", "--chunk", "2", "--no-figures", "--quiet"]
    assert (
        sim.batch.main(["--stale-only", "--results", str(out.parent), str(study), "--", *small])
        == 0
    )
    said = capsys.readouterr().out.splitlines()
    assert (
        said[0]
        == "network_plate: out of date (made with another config: chunk, trials): running it"
    ), said
    assert json.loads((out / "run.json").read_text("utf-8"))["config"]["trials"] == 40


def test_report_names_results_directories_swapped_by_hand(tmp_path, capsys):
    from sim.cli import main

    res = tmp_path / "R"
    res.mkdir()
    for a, b in (("brown_table1", "brown_dilution"), ("brown_dilution", "brown_table1")):
        shutil.copytree(ROOT / "results" / a, res / b, ignore=shutil.ignore_patterns("trials"))
    assert main(["report", "--results", str(res)]) == 0
    text = (res / "REPORT.md").read_text(encoding="utf-8")
    for name, holds in (("brown_table1", "brown_dilution"), ("brown_dilution", "brown_table1")):
        assert (
            f"- [{name}]({name}/README.md) holds the results of the study `{holds}` (its tables "
            f"say so), not of `{name}`: a directory renamed or swapped by hand"
        ) in text
    # directories renamed to names no study has (as a variant, agnard_block_104): no note
    (res / "brown_dilution").rename(res / "brown_t1")
    (res / "brown_table1").rename(res / "brown_dil2")
    assert main(["report", "--results", str(res)]) == 0
    assert "holds the results" not in (res / "REPORT.md").read_text(encoding="utf-8")


@pytest.mark.skipif(shutil.which("flock") is None, reason="no flock(1) here: steps unlocked")
def test_the_install_steps_hold_a_lock(tmp_path):
    # Ctrl-C during make venv, then make venv again at once: the first pip (still rolling
    # back) and the second's venv --clear raced ("Directory not empty: 'setuptools'")
    d = fake_project(tmp_path, "/nonexistent/python3")
    p = run_make(d, "-n", "venv")
    steps = [x for x in p.stdout.splitlines() if " -m venv --clear " in x or " -m pip in" in x]
    assert len(steps) == 3 and all(x.startswith("flock .venv.lock ") for x in steps), p.stdout
