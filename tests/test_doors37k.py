"""The classes of the sweep doors37k (brief K37: the Makefile and the virtual environment as
doors), one case each; each failed on the code before its fix. The make cases run ``make -n``
(nothing runs) or a copy of the Makefile in a temporary directory with a stand-in Python, so
they build no virtual environment, run no study and touch no network.

* a name of the Makefile's own on make's command line (it reads only its settings) replaced
  its paths without a word: ``make clean VENV=results`` ran ``rm -rf results ...`` (the
  committed results), ``make test STAMP=x`` or ``STUDY_FILES=...`` misread the install and
  the studies. One line naming it and the settings, exit 2, before anything runs.
* a setting holding a line break (``RUN_FLAGS=$'--seed 3\\n--trials 40'``, from a script or a
  pasted line): the recipe's command was split in two at it, "/bin/sh: 1: Syntax error:
  Unterminated quoted string", naming no variable (``make -n`` printed a command of two
  lines). One line naming the setting, exit 2.
* a ``.venv`` that lacks what ``pyproject.toml`` asks for: an install that pip finished with
  exit 0 and that installed nothing (``PIP_DRY_RUN``, ``PIP_NO_DEPS``, ``PIP_TARGET`` or a
  ``pip.conf``) was stamped as whole, every later target failing in it (``.venv/bin/ruff: No
  such file or directory``); a library removed from a finished ``.venv`` (``pip uninstall
  pyarrow``) left ``make venv`` doing nothing. The install now ends with the check
  (:mod:`sim.venv_check`): one line naming what is missing, the next ``make venv`` starting
  from scratch; and a ``.venv`` whose libraries changed after its stamp is checked before any
  target and installed into again.
* a ``.venv`` that is a file or a link to nothing (not the suite's): ``make venv`` said
  "PYTHON (python3) could not make .venv: Error: [Errno 20] Not a directory", blaming
  ``PYTHON``, and for a link ``python -m venv`` made the missing target's directory outside
  the project; it is named in one line, and nothing is made or removed.
* ``sim show``, ``sim report`` and a run's README.md over results of an older version of the
  suite (``git archive 00dbae17 results``: a run record made before ``plate.layout_seed``
  existed) named the key the record lacks with a blank value, "`plate.layout_seed` =  (the
  file: 1)", as if the run had set it empty: it is "not in its record"
  (:func:`sim.report.config_diff.changes_text`).

Held (found right): ``make -n`` of every target runs nothing; ``make -C`` from another
directory; ``RUN_FLAGS`` with quotes, ``;``, ``$(...)`` and an open quote (one line);
``--out`` in ``BENCH_FLAGS``; ``PYTHON`` missing or not a Python (one line); results of older
commits without ``table_shape`` or ``overrides`` (``sim show`` and ``sim report`` with their note
that another version made them; an older claims table without ``verdict``: one line, re-run).
"""

from __future__ import annotations

import os
import shlex
import shutil
import subprocess
import sys
from pathlib import Path

import pytest
from test_doors18c import MAKE, ROOT, user_env

pytestmark = pytest.mark.skipif(MAKE is None, reason="no make on this machine")


def make_n(*args: str) -> subprocess.CompletedProcess:
    """``make -n ARGS`` in the project with its install stamp taken as current (runs nothing)."""
    return subprocess.run(
        [MAKE, "-s", "-n", "--no-print-directory", "-o", ".venv/.installed", *args],
        cwd=ROOT,
        capture_output=True,
        text=True,
        timeout=60,
        env=user_env(),
    )


def refused(p: subprocess.CompletedProcess, needle: str) -> None:
    """Exit 2, one line holding ``needle``, nothing printed (make -n: no command shown)."""
    err = p.stderr.removesuffix("\n")
    assert p.returncode == 2 and "\n" not in err and needle in err, (p.returncode, p.stderr)
    assert p.stdout == "", p.stdout


@pytest.mark.parametrize(
    "args", [("clean", "VENV=results"), ("test", "STAMP=x"), ("reproduce", "STUDY_FILES=a.toml")]
)
def test_the_makefiles_own_names_on_its_command_line_are_refused(args):
    name = args[1].split("=")[0]
    refused(make_n(*args), f"make: {name} is this Makefile's own name and not a setting")


@pytest.mark.parametrize(
    ("target", "setting"),
    [
        ("reproduce", "RUN_FLAGS=--seed 3\n--trials 40"),
        ("verify", "VERIFY_FLAGS=--study brown_table1\n"),
        ("bench", "BENCH_FLAGS=--quick\n--only engines"),
        ("venv", "PYTHON=python3\n"),
    ],
)
def test_a_setting_with_a_line_break_is_one_line(target, setting):
    name = setting.split("=")[0]
    refused(make_n(target, setting), f"make: {name} holds a line break")


def venv_project(tmp_path: Path, dependencies: list[str]) -> Path:
    """A copy of the Makefile and sim/venv_check.py beside a pyproject.toml of the project
    ``sim`` asking for ``dependencies``, with a ``.venv`` whose Python is a stand-in: ``-m pip``
    and ``-m venv`` log their arguments to ``calls.log`` and succeed doing nothing (as pip
    with PIP_DRY_RUN), anything else is this test's Python (which holds the project)."""
    d = tmp_path / "proj"
    (d / "sim").mkdir(parents=True)
    shutil.copy(ROOT / "Makefile", d / "Makefile")
    shutil.copy(ROOT / "sim" / "venv_check.py", d / "sim" / "venv_check.py")
    (d / "sim" / "__init__.py").write_text("", encoding="utf-8")
    deps = ", ".join(f'"{x}"' for x in dependencies)
    (d / "pyproject.toml").write_text(
        f'[project]\nname = "sim"\ndependencies = [{deps}]\n', encoding="utf-8"
    )
    fake = tmp_path / "python"
    fake.write_text(
        '#!/bin/sh\ncase "$*" in\n'
        f'  *"-m pip"*|*"-m venv"*) echo "$*" >> {shlex.quote(str(tmp_path / "calls.log"))}'
        "; exit 0;;\nesac\nexec " + shlex.quote(sys.executable) + ' "$@"\n',
        encoding="utf-8",
    )
    fake.chmod(0o755)
    (d / ".venv" / "bin").mkdir(parents=True)
    (d / ".venv" / "bin" / "python").symlink_to(fake)
    return d


def run_make(d: Path, *args: str) -> subprocess.CompletedProcess:
    python = str(d.parent / "python")
    return subprocess.run(
        [MAKE, "-s", "--no-print-directory", *args, f"PYTHON={python}"],
        cwd=d,
        capture_output=True,
        text=True,
        timeout=60,
        env=user_env(),
    )


def test_an_install_that_left_the_venv_lacking_a_library_is_not_stamped(tmp_path):
    d = venv_project(tmp_path, ["numpy", "no-such-lib-k37>=1"])
    p = run_make(d, "venv")  # a first install: pip exits 0 and installs nothing
    err = p.stderr.splitlines()
    assert p.returncode == 2 and len(err) == 2 and "Traceback" not in p.stderr, p.stderr
    assert err[0].startswith("make: pip could not install into .venv: "), err
    assert "lacks no-such-lib-k37, where pyproject.toml asks for no-such-lib-k37>=1" in err[0]
    assert "PIP_DRY_RUN" in err[0] and ".venv/pip.log" in err[0], err
    assert not (d / ".venv" / ".installed").exists()  # the next make venv tries again,
    assert (d / ".venv.installing").exists()  # from scratch
    # what the project asks for all there: stamped, and the next make does nothing
    e = venv_project(tmp_path / "whole", ["numpy>=1"])
    assert run_make(e, "venv").returncode == 0
    assert (e / ".venv" / ".installed").exists() and not (e / ".venv.installing").exists()
    (tmp_path / "whole" / "calls.log").unlink()
    p = run_make(e, "venv")
    assert p.returncode == 0 and p.stdout == "" and p.stderr == "", (p.stdout, p.stderr)
    assert not (tmp_path / "whole" / "calls.log").exists()


def test_a_venv_whose_libraries_changed_after_its_stamp_is_checked_and_installed_again(
    tmp_path,
):
    d = venv_project(tmp_path, ["numpy"])
    assert run_make(d, "venv").returncode == 0
    stamp = d / ".venv" / ".installed"
    os.utime(stamp, (1_000_000_000, 1_000_000_000))
    site = d / ".venv" / "lib" / "python3.11" / "site-packages"
    site.mkdir(parents=True)  # pip uninstall touches site-packages: newer than the stamp
    (tmp_path / "calls.log").unlink()
    assert run_make(d, "venv").returncode == 0  # still whole: nothing installed
    assert not (tmp_path / "calls.log").exists()
    # the library removed (here: asked for and absent): named, and installed again
    pyproject = d / "pyproject.toml"
    text = pyproject.read_text(encoding="utf-8").replace('"numpy"', '"numpy", "no-such-lib-k37"')
    pyproject.write_text(text, encoding="utf-8")
    stamp.write_text(f"{d}\n{cksum(pyproject)}\n", encoding="utf-8")
    os.utime(stamp, (1_000_000_000, 1_000_000_000))
    p = run_make(d, "venv")
    assert "lacks no-such-lib-k37, where pyproject.toml asks for no-such-lib-k37" in p.stdout
    assert "installing the project again" in p.stdout
    assert "-m pip install" in (tmp_path / "calls.log").read_text(encoding="utf-8")
    # the stand-in pip installs nothing: the check after it names the library again
    assert p.returncode == 2 and "lacks no-such-lib-k37" in p.stderr, p.stderr


def cksum(path: Path) -> str:
    """The checksum the Makefile's stamp records for ``path`` (``cksum < FILE | tr ' ' -``)."""
    out = subprocess.run(["cksum"], stdin=path.open("rb"), capture_output=True, check=True)
    return out.stdout.decode().strip().replace(" ", "-")


@pytest.mark.parametrize("shape", ["file", "dangling link"])
def test_a_venv_that_is_a_file_or_a_dangling_link_is_named_and_left_alone(tmp_path, shape):
    d = venv_project(tmp_path, ["numpy"])
    shutil.rmtree(d / ".venv")
    if shape == "file":
        (d / ".venv").write_text("mine\n", encoding="utf-8")
    else:  # python -m venv made the missing target's directory (outside the project)
        (d / ".venv").symlink_to(tmp_path / "gone" / "venv")
    p = run_make(d, "venv")
    err = p.stderr.splitlines()
    assert p.returncode == 2 and len(err) == 2, p.stderr
    assert err[0] == (
        "make: .venv is not a directory (a file, or a link to nothing), not a virtual "
        "environment: remove or rename it, then make venv"
    ), err
    assert not (tmp_path / "calls.log").exists() and not (tmp_path / "gone").exists()
    assert (d / ".venv").is_symlink() or (d / ".venv").read_text(encoding="utf-8") == "mine\n"


def test_a_key_the_run_record_of_an_older_version_lacks_is_said_to_be_missing():
    from sim.report.config_diff import changes_text

    older = {"study": "brown", "plate.random_half_extent_mm": 110.0}  # before layout_seed
    today = {"study": "brown", "plate.random_half_extent_mm": 100.0, "plate.layout_seed": 1}
    assert changes_text(older, today) == (
        "`plate.layout_seed` not in its record (the file: 1), "
        "`plate.random_half_extent_mm` = 110.0 (the file: 100.0)"
    )
    assert changes_text(today, older).startswith("`plate.layout_seed` = 1 (not in the file), ")
