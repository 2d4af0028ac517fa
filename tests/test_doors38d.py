"""This session's new sentences of the docs, tried as written (brief D38): the Makefile's
refusals (``VENV=``, a setting with a line break), ``SIM_NO_JIT=0`` and the ``NUMBA_``
variables, the did-you-mean of a missing study file, masked values and ``run(None)``, a
damaged ``run.json`` and the Wolf transcription's bytes held as written. One sentence was
false, one case below, failed on the code before its fix.

* "A key or value of more than 200 characters without white space is quoted cut, with its
  length (``'yyyy...yyyy' (100003 characters)``)": the length counted the quotes and
  brackets around the word (a value of 100,003 characters was ``(got 'yyy...yyy') (100006
  characters)``, a key ``yyy...yyy: (100004 characters)``), and an integer key's value was cut
  at 60 characters without a word (``must be an integer (got 'yyy...y)``, its quote left
  open, no length). The length is now the word's, and such a value is cut as the sentence
  says.
"""

from __future__ import annotations

import pytest

import sim

STUDY = "studies/brown_table1.toml"
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
