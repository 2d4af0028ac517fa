"""This session's new sentences of the docs, tried as written (brief D38): the Makefile's
refusals (``VENV=``, a setting with a line break), ``SIM_NO_JIT=0`` and the ``NUMBA_``
variables, the did-you-mean of a missing study file, masked values and ``run(None)``, a
damaged ``run.json`` and the Wolf transcription's bytes held as written. Three sentences were
false: one fixed in docs/sweeps.md (a sweep over the work limit names its cells, not its
largest cell), two in code, a case each below, each failed on the code before its fix.

* "A key or value of more than 200 characters without white space is quoted cut, with its
  length (``'yyyy...yyyy' (100003 characters)``)": the length counted the quotes and
  brackets around the word (a value of 100,003 characters was ``(got 'yyy...yyy') (100006
  characters)``, a key ``yyy...yyy: (100004 characters)``), and an integer key's value was cut
  at 60 characters without a word (``must be an integer (got 'yyy...y)``, its quote left
  open, no length). The length is now the word's, and such a value is cut as the sentence
  says.
* "standard output whose encoding cannot show the en dash of an interval gets ``-``":
  ``sim show DIR --markdown`` of every paper study was refused there, "the output (encoding
  ascii) cannot show '\\u2014'", the em dash of its verdict lines (the suite's own, not a
  name of the user's). The suite's em dash, ``±``, ``≤`` and ``≥`` are now written in ASCII.
"""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

import sim

ROOT = Path(__file__).resolve().parents[1]
STUDY = str(ROOT / "studies/brown_table1.toml")
LONG = "y" * 100_003


@pytest.mark.parametrize(
    ("kwargs", "key"),
    [
        ({"plate__grid": LONG}, "plate.grid"),
        ({"plate__pattern": LONG}, "plate.pattern"),
        ({LONG: 3}, LONG[:60]),
    ],
    ids=["integer", "choice", "key"],
)
def test_a_long_word_is_quoted_cut_with_its_own_length(kwargs, key):
    with pytest.raises(sim.ConfigError) as e:
        sim.load(STUDY, **kwargs)
    text = str(e.value)
    assert text.startswith(key) and len(text) < 300, text
    assert "(100003 characters)" in text, text
    if key != LONG[:60]:
        assert "yyy'" in text, text  # the quote closed, not cut open


def test_sim_show_markdown_on_an_ascii_output_writes_its_dashes_in_ascii():
    """``PYTHONIOENCODING=ascii sim show results/brown_table1 --markdown`` was refused: "the
    output (encoding ascii) cannot show '\\u2014'", the em dash of the suite's own verdict
    lines, as a name of the user's would be; cli.md says such an output gets ASCII."""
    env = {**os.environ, "PYTHONIOENCODING": "ascii"}
    cmd = [sys.executable, "-m", "sim", "show", "results/brown_table1", "--markdown"]
    proc = subprocess.run(cmd, env=env, cwd=ROOT, capture_output=True, text=True, timeout=120)
    assert proc.returncode == 0 and "cannot show" not in proc.stderr, proc.stderr
    assert "** -- " in proc.stdout and proc.stdout.isascii()
