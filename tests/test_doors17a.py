"""The classes of the sweep doors17a (issue 26: the process environment, streams and
invocation contexts a user's shell or notebook brings), one case each; each failed on the
code before its fix.

* a run of the Python API in a user's process took matplotlib over: ``matplotlib.use("Agg")``
  switched the caller's pyplot backend (closing every figure the caller had open) and the
  suite's style stayed in the caller's ``rcParams`` (a notebook's next plot in 9 pt with a
  grid); the suite now draws on Agg canvases of its own without pyplot, and
  :func:`sim.report.mpl.kept` puts the caller's ``rcParams`` back (the PNGs are the same);
* a network whose point names are not ASCII, run under a locale that is not UTF-8 (``LC_ALL=C``
  with ``PYTHONUTF8=0``, or a Latin-1 locale), computed every trial and then failed writing
  ``network.xml`` (UnicodeEncodeError; under Latin-1 it would write an XML file in Latin-1
  without saying so): the file is written in UTF-8 (:func:`sim.studies.network.gama.write_gama`),
  as is every text file the suite writes;
* ``python -m sim.batch`` and ``make verify`` read their child runs' output in the locale's
  encoding, not the one the child writes in (``PYTHONIOENCODING=utf-16``: every character of a
  run's error line came out with NULs between): :func:`sim.mc.children.child_text`;
* 50,000 options (``--set`` or ``--study``) kept ``sim``, ``python -m sim.batch`` and ``make
  verify`` busy for minutes (argparse's time grows with their square) before "unknown key":
  at most :data:`sim.mc.argv.MAX_OPTIONS` are read (:class:`sim.mc.argv.BoundedParser`);
* ``sim.cli.main`` called from a thread that is not the main one (a notebook's worker) ended
  in "ValueError: signal only works in main thread": it sets signal handlers in the main
  thread only;
* a library missing (``python3 -m sim`` with a Python the suite is not installed into) or
  shadowed (an empty ``tqdm.py``, ``numpy.py`` or ``pyarrow.py`` on ``PYTHONPATH`` or in the
  working directory) while an entry point loads ended in a traceback, and one first used later
  (``tomllib.py`` in ``sim check``, ``matplotlib.py`` after every trial) in an "internal
  error", exit 3: one line naming the file that shadows it, or the Python, exit 2
  (:func:`sim.threads.import_words`, :func:`sim.threads.shadowed`);
* a ``--set`` value the locale could not decode (``LC_ALL=C`` without UTF-8 mode, or Latin-1
  bytes) was refused as "must be printable on one line"; now as bytes that are not UTF-8;
* ``sim check`` or ``sim show`` with standard output closed (``>&-``) printed nowhere and
  exited 0;
* ``TQDM_NCOLS=abc`` (any ``TQDM_`` variable tqdm cannot convert) and a ``SOURCE_DATE_EPOCH``
  beyond the system's dates ended every entry point in a traceback while loading
  (:func:`sim.threads.refuse_bad_environment`);
* ``run(workers=2)`` of the Python API inside a worker of the caller's ``multiprocessing.Pool``
  (a daemonic process) ended in multiprocessing's bare AssertionError: one line saying to use
  one worker (:func:`sim.mc.executors._may_start_processes`);
* ``--workers 2`` (or ``run(workers=2)``) in a process whose start method is ``forkserver``
  (set by the caller, and Python 3.14's default on Linux) failed at once: the pool's workers,
  children of the fork server, took the run's process for their dead parent and quit
  (:class:`sim.mc.executors._Pool`).
"""

import os
import subprocess
import sys
import threading
from pathlib import Path

import pytest
from oneline import one_line, python_lines

import sim.batch
from sim.cli import main
from sim.mc.argv import MAX_OPTIONS
from sim.mc.config import ConfigError, parse_override
from sim.report.verify import main as verify_main

ROOT = Path(__file__).resolve().parent.parent
STUDY = ROOT / "studies" / "network_plate.toml"
SMALL = ["--trials", "40", "--chunk", "2"]


@pytest.mark.long
def test_an_api_run_leaves_the_callers_matplotlib_alone(tmp_path):
    p = python_lines(
        "import matplotlib",
        "matplotlib.use('svg')",
        "import matplotlib.pyplot as plt",
        "plt.rcParams['font.size'] = 14.0",
        "mine = plt.figure()",
        "import sim",
        f"sim.load({str(STUDY)!r}, trials=40, chunk=2).run(out={str(tmp_path / 'api')!r})",
        "print(matplotlib.get_backend(), plt.get_fignums(), plt.rcParams['font.size'],",
        "      plt.rcParams['axes.grid'])",
    )
    assert p.returncode == 0, p.stderr
    assert p.stdout.split() == ["svg", "[1]", "14.0", "False"], p.stdout
    cli = subprocess.run(
        [sys.executable, "-m", "sim", "run", str(STUDY), *SMALL, "--out", str(tmp_path / "cli")],
        capture_output=True,
        text=True,
    )
    assert cli.returncode == 0, cli.stderr
    for png in ("network.png", "reliability.png"):  # drawn as sim run draws them
        assert (tmp_path / "api" / png).read_bytes() == (tmp_path / "cli" / png).read_bytes()


def test_a_network_of_non_ascii_names_runs_in_a_locale_that_is_not_utf8(tmp_path):
    text = STUDY.read_text(encoding="utf-8").replace('"G', '"É')
    assert "É13" in text
    study = tmp_path / "names.toml"
    study.write_text(text, encoding="utf-8")
    env = {**os.environ, "LC_ALL": "C", "PYTHONUTF8": "0", "PYTHONCOERCECLOCALE": "0"}
    out = tmp_path / "o"
    p = subprocess.run(
        [sys.executable, "-m", "sim", "run", str(study), *SMALL, "--no-figures", "--out", str(out)],
        capture_output=True,
        text=True,
        env=env,
    )
    assert p.returncode == 0, p.stderr
    assert '<point id="É1"' in (out / "network.xml").read_bytes().decode("utf-8")


def test_batch_reads_its_runs_lines_in_the_encoding_they_are_written_in(tmp_path):
    bad = tmp_path / "bad.toml"  # its run refuses the umask (a bad config, or a results
    bad.write_text(STUDY.read_text(encoding="utf-8"), encoding="utf-8")  # directory it would
    p = subprocess.run(  # not replace, the driver refuses itself: tests/test_doors28b.py)
        [sys.executable, "-m", "sim.batch", str(bad), "--results", "res", "--", *SMALL],
        capture_output=True,
        cwd=tmp_path,
        env={**os.environ, "PYTHONIOENCODING": "utf-16"},
        preexec_fn=lambda: os.umask(0o277),
    )
    err = p.stderr.decode("utf-16").strip()
    assert p.returncode == 2 and "\n" not in err and "\x00" not in err, (p.returncode, err)
    assert err.startswith("bad.toml: sim: error: umask 0277") and "denies" in err, err


def test_too_many_options_are_refused_before_argparse_reads_them(capsys):
    def sets(n):
        return [x for i in range(n) for x in ("--set", f"a{i}=1")]

    one_line(
        capsys, main(["check", str(STUDY), *sets(MAX_OPTIONS + 1)]), f"at most {MAX_OPTIONS:,}"
    )
    one_line(capsys, sim.batch.main([str(STUDY), "--", *sets(MAX_OPTIONS + 1)]), f"{MAX_OPTIONS:,}")
    studies = [x for i in range(MAX_OPTIONS + 1) for x in ("--study", f"a{i}")]
    one_line(capsys, verify_main(studies), f"at most {MAX_OPTIONS:,}")
    # at the bound, the options are read (and the first unknown key named)
    one_line(capsys, main(["check", str(STUDY), *sets(MAX_OPTIONS)]), "a0: unknown key")


def test_the_command_line_runs_in_a_thread_that_is_not_the_main_one(capsys):
    # main() from a notebook's or a test runner's thread: "sim: error: ValueError: signal
    # only works in main thread", and the same ValueError again from restoring the handlers
    done = {}

    def check():
        try:
            done["rc"] = main(["check", str(STUDY)])
        except BaseException as e:  # noqa: BLE001 - what the thread met is the finding
            done["rc"] = repr(e)

    t = threading.Thread(target=check)
    t.start()
    t.join()
    assert done["rc"] == 0, (done, capsys.readouterr().err)


@pytest.mark.long
def test_a_library_shadowed_or_missing_is_one_line(tmp_path):
    # a file of a library's name on PYTHONPATH (or in the working directory): a traceback at
    # load (tqdm.py: "cannot import name 'tqdm'"; numpy.py: pyarrow's AttributeError), an
    # "internal error" exit 3 in sim check (tomllib.py) or after every trial (matplotlib.py)
    out = str(tmp_path / "o")
    cases = [
        ("tqdm", ["-m", "sim", "check", str(STUDY)]),
        ("tqdm", ["-m", "sim.batch", str(STUDY)]),
        ("numpy", ["-m", "sim", "check", str(STUDY)]),
        ("tomllib", ["-m", "sim", "check", str(STUDY)]),
        ("matplotlib", ["-m", "sim", "run", str(STUDY), *SMALL, "--quiet", "--out", out]),
    ]
    for name, args in cases:
        shadow = tmp_path / name
        shadow.mkdir(exist_ok=True)
        (shadow / f"{name}.py").write_text("", encoding="utf-8")
        env = {**os.environ, "PYTHONPATH": str(shadow)}
        p = subprocess.run([sys.executable, *args], capture_output=True, text=True, env=env)
        err = p.stderr.strip()
        assert p.returncode == 2 and "\n" not in err and "Traceback" not in err, (args, err)
        assert f"{shadow / name}.py shadows the library {name}" in err, err
    # a Python the suite is not installed into: "No module named ..." named in one line
    p = python_lines(
        "import sys",
        "from sim.threads import import_words",
        "print(import_words(ModuleNotFoundError(\"No module named 'pyarrow'\", name='pyarrow')))",
        "print(import_words(ValueError('x')))",
    )
    lines = p.stdout.splitlines()
    # doors18c: in the suite's own .venv the rest says to make it again (test_doors18c)
    assert lines[0].startswith("cannot load pyarrow: No module named 'pyarrow'; ")
    assert lines[1] == "None"


def test_a_set_value_the_locale_could_not_decode_is_named_as_such():
    # LC_ALL=C without UTF-8 mode: --set network.name="café" reached the schema as
    # 'caf\udcc3\udca9' and was refused as "must be printable on one line"
    with pytest.raises(ConfigError, match="network.name: --set holds bytes that are not UTF-8"):
        parse_override('network.name="caf\udcc3\udca9"')
    assert parse_override('network.name="café"') == ("network.name", "café")


def test_check_and_show_with_standard_output_closed_say_so():
    # sim check STUDY >&- printed nowhere and exited 0: what was asked for went nowhere
    for args in (["check", str(STUDY)], ["show", str(ROOT / "results" / "network_plate")]):
        p = subprocess.run(
            [sys.executable, "-m", "sim", *args],
            stderr=subprocess.PIPE,
            text=True,
            preexec_fn=lambda: os.close(1),  # noqa: PLW1509 - the shell's >&-
        )
        err = p.stderr.strip()
        assert p.returncode == 2 and err == (
            "sim: error: standard output is closed (>&-): nothing to print to"
        ), (args, p.returncode, err)


def test_variables_a_library_reads_while_loading_are_one_line():
    # TQDM_NCOLS=abc: a traceback from tqdm.utils at import; SOURCE_DATE_EPOCH beyond the
    # system's dates: "OverflowError: timestamp out of range" from numpy.f2py
    cases = [
        ({"TQDM_NCOLS": "abc"}, "sim: error: TQDM_NCOLS: tqdm cannot read it"),
        ({"SOURCE_DATE_EPOCH": "9" * 20}, "sim: error: SOURCE_DATE_EPOCH: must be an integer"),
    ]
    for env, start in cases:
        p = subprocess.run(
            [sys.executable, "-m", "sim", "check", str(STUDY)],
            capture_output=True,
            text=True,
            env={**os.environ, **env},
        )
        err = p.stderr.strip()
        assert p.returncode == 2 and "\n" not in err and err.startswith(start), (env, err)


def test_workers_from_a_daemonic_process_are_one_line_and_nothing_written(tmp_path):
    # run(workers=2) inside a worker of the caller's multiprocessing.Pool: multiprocessing's
    # bare "AssertionError: daemonic processes are not allowed to have children"
    out = tmp_path / "o"
    p = python_lines(
        "from multiprocessing import get_context",
        "import sim",
        "def f(_):",
        "    try:",
        f"        sim.load({str(STUDY)!r}, trials=40, chunk=2).run(out={str(out)!r}, workers=2)",
        "    except sim.ConfigError as e:",
        "        return str(e)",
        "if __name__ == '__main__':",
        "    with get_context('fork').Pool(1) as pool:",
        "        print(pool.map(f, [0])[0])",
    )
    assert p.returncode == 0, p.stderr
    assert "from a daemonic process" in p.stdout and "use 1 worker" in p.stdout, p.stdout
    assert list(tmp_path.iterdir()) == []


def test_workers_start_under_the_callers_forkserver_method(tmp_path):
    # multiprocessing.set_start_method("forkserver") (Python 3.14's default on Linux): the
    # workers, children of the fork server, took their parent for dead and quit at once:
    # "cannot start the local executor: A process in the process pool was terminated abruptly"
    p = python_lines(
        "import multiprocessing as mp",
        "import sim",
        "if __name__ == '__main__':",
        "    mp.set_start_method('forkserver', force=True)",
        f"    st = sim.load({str(STUDY)!r}, trials=40, chunk=2)",
        f"    two = st.run(out={str(tmp_path / 'two')!r}, workers=2, figures=False)",
        f"    one = st.run(out={str(tmp_path / 'one')!r}, figures=False)",
        "    print(two.claims().select(['value']).equals(one.claims().select(['value'])))",
    )
    assert p.returncode == 0 and p.stdout.split() == ["True"], (p.stdout, p.stderr)
