"""T50: what a command costs before it reads its arguments.

* ``sim --version``, ``sim --help``, a refused option (``sim check --bad-option``) and a study
  file name refused as a name (``sim check '~x.toml'``) loaded the whole suite first: the
  runner, ``sim.lsq`` (SciPy's sparse and linear algebra), pyarrow, every study kind and
  tqdm, 1.1 to 1.4 s of CPU in every process (the test suite starts hundreds). The command
  line now loads a command's module when the command runs (:data:`sim.cli.COMMANDS`); the
  property held here is which modules such a command loads, not its time (``make bench``'s
  ``startup`` rows time it).
* ``sim --version`` read the installed package's metadata (``importlib.metadata``, 0.1 s);
  it prints :data:`sim.__version__`, which must be pyproject.toml's version.
"""

import importlib
import subprocess
import sys
import tomllib

import pytest
from conftest import ROOT

import sim
from sim import cli

#: what a command that loads no study must not load
HEAVY = ("sim.mc.runner", "scipy.sparse", "sim.lsq", "pyarrow", "sim.studies", "tqdm")

CODE = """
import contextlib, io, sys
from sim.cli import main
codes = []
for argv in {argvs!r}:
    with contextlib.redirect_stdout(io.StringIO()), contextlib.redirect_stderr(io.StringIO()):
        codes.append(main(argv))
print(codes)
print(' '.join(m for m in {heavy!r} if m in sys.modules))
"""


def test_version_help_and_refused_arguments_load_no_study_runner_or_scipy():
    """Class: a command that ends before it loads a study (``--version``, ``--help``, an
    unknown option, a study file name refused as a name). Before: each loaded
    sim.mc.runner, scipy.sparse, pyarrow and every study kind (about 1.2 s of CPU)."""
    argvs = [["--version"], ["--help"], ["check", "--bad-option", "x.toml"], ["check", "~x.toml"]]
    r = subprocess.run(
        [sys.executable, "-c", CODE.format(argvs=argvs, heavy=HEAVY)],
        cwd=ROOT,
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert r.returncode == 0, r.stderr
    codes, loaded = (r.stdout.splitlines() + ["", ""])[:2]
    assert codes == "[0, 0, 2, 2]", r.stdout
    assert loaded.split() == [], f"loaded before any study: {loaded}"


def test_version_is_pyproject_s(capsys):
    """Class: the version a command prints. Before: read from the installed metadata
    (``importlib.metadata``, a tenth of a second in every process); now sim.__version__,
    held here to pyproject.toml's so the two cannot drift apart."""
    project = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]["version"]
    assert sim.__version__ == project
    assert cli.main(["--version"]) == 0
    assert capsys.readouterr().out == f"sim {project}\n"


@pytest.mark.parametrize("cmd", sorted(cli.COMMANDS))
def test_every_command_of_the_parser_has_its_module_and_function(cmd):
    """Class: a command the parser takes but the dispatch table lacks (or names a function
    its module does not have): it would end in exit 1 or an internal error. Every command
    module is imported here once."""
    module, name = cli.COMMANDS[cmd]
    assert callable(getattr(importlib.import_module(module), name))


def test_the_parser_s_commands_are_the_dispatch_table_s():
    """Class: a command added to the parser and not to :data:`sim.cli.COMMANDS` (it would
    exit 1 without a word)."""
    p = cli.parser(cli.DOC)
    sub = next(a for a in p._actions if a.dest == "cmd")
    assert set(sub.choices) == set(cli.COMMANDS)


def test_a_library_a_command_cannot_load_is_one_line(monkeypatch, capsys):
    """Class: a command whose module cannot be imported (a library missing or shadowed,
    loaded now when the command runs rather than at start-up, where
    :func:`sim.threads.interrupt_while_loading` named it). One line naming it, exit 2,
    no traceback and no "internal error"."""
    monkeypatch.setitem(cli.COMMANDS, "report", ("sim.no_such_module_t50", "report"))
    assert cli.main(["report", "--results", str(ROOT / "results")]) == 2
    err = capsys.readouterr().err
    assert err.startswith("sim: error: cannot load sim: ") and err.count("\n") == 1, err
