"""Review of the session of 2026-11-28 (brief R30: the diff 7f102c07..9e65f66f read as its next
maintainer); one case each, each failed on the code before its fix.

* A failed or interrupted run dropped from ``sys.modules`` every module whose parent package
  was not there (:func:`sim.execute.drop_half_imported`), the caller's too: a stub a
  notebook or a test put in by hand (``sys.modules["mine.plugin"] = ...``) was gone after any
  refused ``run()``. Only the modules the failed run imported itself are dropped now (the
  names held when it started are recorded).
* ``SIM_MAX_ADJUSTMENTS=1e-400`` (or ``SIM_MAX_MEMORY_GB``, ``--max-adjustments 1e-400``) was
  refused "must be a positive number (got 0.0)", of digits that are no zero; it now names the
  digits in the words of a study file's ``1e-400`` (:func:`sim.mc.numtext.float_text`).
* ``sim.load(..., errors__bias_um=np.longdouble("1e-4000"))`` (a NumPy long double no double
  holds, on a machine whose long double is wider) was a bias of 0.0 without a word, and
  ``np.longdouble("1e4000")`` "must be finite (got inf)", where ``Decimal("1e-999")`` and a
  study file's ``1e-400`` are refused naming the value (:mod:`sim.mc.pyvalue`).
* The two refusals of a number no double holds were worded twice, in
  :mod:`sim.mc.numtext` (a study file, ``--set``, a Gama file) and :mod:`sim.mc.pyvalue` (a
  Python value): one wording now (:func:`sim.mc.numtext.unheld`).
* ``python -m sim.batch --jobs x a.toml -- --set k=b.toml`` added "study files come before
  --, not after it (k=b.toml)" to argparse's line about ``--jobs``: the hint is for a batch
  given no study file, and names a word of its own, not an option's value.
* ``--set trials=.5`` was refused "must be an integer (got the text '.5': write 0.5)", and
  0.5 is refused next: an integer key gets no such advice for a fraction.
* A mistyped command's guess (``sim rn``: did you mean run?) read the choices in quotes, as
  Python up to 3.12.7 prints them; 3.12.8 and 3.13 print them bare, and the guess was lost.
* ``run(out=None)`` whose temporary directory was removed under it (a cleaner of /tmp) added
  a note "the finished chunks are kept in <that directory>: run(out=...) resumes the run".
"""

from __future__ import annotations

import decimal
import inspect
import sys
import types
from pathlib import Path

import numpy as np
import pytest
from oneline import SIM_ERROR, one_line

import sim
import sim.mc.pyvalue
from sim.api_state import anonymous_dir
from sim.batch import main as batch_main
from sim.cli import main
from sim.cli_args import parser
from sim.mc.config import ConfigError

ROOT = Path(__file__).resolve().parents[1]
TABLE1 = str(ROOT / "studies" / "brown_table1.toml")
PLATE = str(ROOT / "studies" / "network_plate.toml")


def test_a_failed_run_leaves_the_callers_own_modules(monkeypatch):
    stub = types.ModuleType("review30_mine.plugin")  # no parent package, by the caller's hand
    monkeypatch.setitem(sys.modules, "review30_mine.plugin", stub)
    st = sim.load(PLATE, trials=40, chunk=2)
    with pytest.raises(ConfigError, match="^workers: "):
        st.run(workers=999)
    assert sys.modules.get("review30_mine.plugin") is stub


@pytest.mark.parametrize(
    "env, args",
    [
        ({"SIM_MAX_ADJUSTMENTS": "1e-400"}, ["check", TABLE1]),
        ({"SIM_MAX_MEMORY_GB": "1e-400"}, ["check", TABLE1]),
        ({}, ["run", TABLE1, "--max-adjustments", "1e-400"]),
    ],
    ids=["SIM_MAX_ADJUSTMENTS", "SIM_MAX_MEMORY_GB", "--max-adjustments"],
)
def test_a_limit_no_double_holds_is_named_as_written(env, args, monkeypatch, capsys, tmp_path):
    for k, v in env.items():
        monkeypatch.setenv(k, v)
    monkeypatch.chdir(tmp_path)
    rc = main(args)
    line = one_line(
        capsys,
        rc,
        "1e-400 is too small for a 64-bit float (it would be read as 0)",
        prefix=SIM_ERROR,
    )
    assert "got 0.0" not in line, line


def test_a_limit_that_is_no_number_keeps_argparses_words(capsys):
    rc = main(["run", TABLE1, "--max-memory-gb", "abc"])
    one_line(capsys, rc, "argument --max-memory-gb: invalid float value: 'abc'", prefix=SIM_ERROR)


def test_a_number_no_double_holds_is_worded_once():
    with pytest.raises(ConfigError) as info:
        sim.load(TABLE1, bias_um=decimal.Decimal("1e-999"))
    assert str(info.value).endswith(
        "Decimal('1E-999') is too small for a 64-bit float (it would be read as 0)"
    )
    assert "64-bit float" not in inspect.getsource(sim.mc.pyvalue)  # sim.mc.numtext's words


@pytest.mark.skipif(np.longdouble("1e-4000") == 0, reason="no long double wider than a double")
@pytest.mark.parametrize("digits, words", [("1e-4000", "too small"), ("1e4000", "beyond")])
def test_a_long_double_no_double_holds_is_refused(digits, words):
    v = np.longdouble(digits)
    for given in (v, np.array([v])):
        with pytest.raises(ConfigError, match=rf"^errors\.bias_um: np\.longdouble\(.* is {words}"):
            sim.load(TABLE1, errors__bias_um=given)


def test_the_batch_names_no_study_file_after_dashes_for_another_mistake(capsys):
    rc = batch_main(["--jobs", "x", TABLE1, "--", "--set", "network.include=b.toml"])
    line = one_line(capsys, rc, "argument --jobs: must be an integer (got 'x')")
    assert "come before --" not in line, line
    rc = batch_main(["--", "b.toml"])  # the case the hint is for (doors29b) still has it
    one_line(capsys, rc, "required: files", "study files come before --, not after it (b.toml)")


def test_an_integer_key_gets_no_advice_to_write_a_fraction(capsys):
    rc = main(["check", TABLE1, "--set", "trials=.5"])
    line = one_line(capsys, rc, "trials: must be an integer", prefix=SIM_ERROR)
    assert "write" not in line, line
    rc = main(["check", TABLE1, "--set", "trials=07"])  # an integer's text still gets it
    one_line(capsys, rc, "trials: must be an integer (got the text '07': write 7)")


def test_a_mistyped_command_is_guessed_with_the_choices_printed_bare():
    said = parser("sim").explain(
        "argument COMMAND: invalid choice: 'rn' (choose from run, show, check, report)"
    )
    assert said.endswith("(did you mean run?)"), said


def test_a_temporary_directory_removed_under_the_run_is_not_named(tmp_path):
    base = tmp_path / "sim-network-x"
    base.mkdir()
    with pytest.raises(KeyboardInterrupt) as info:
        with anonymous_dir(base, base / "network"):
            base.rmdir()  # a cleaner of /tmp
            raise KeyboardInterrupt
    assert not getattr(info.value, "__notes__", None), info.value.__notes__
