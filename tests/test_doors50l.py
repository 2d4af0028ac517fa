"""Doors, session 50, helper L51: the left items of the session's first helpers.

Each test names the class of bad input and what the suite did with it before.
"""

from __future__ import annotations

import json

from sim.long_words import clipped
from sim.mc.study_source import other_source

#: what a hostile run.json holds: a window title, a screen clear, a carriage return, a bidi
#: override
FORGED = "x\x1b]0;PWNED\x07y\x1b[2J\rz\u202eevil"


def test_forged_record_strings_are_shown_escaped(tmp_path):
    """Class: a run.json forged by hand (terminal escape sequences). Its ``written_as`` and
    study file path were quoted as they were in the note of ``sim show``, ``sim report``,
    ``sim.Results``, ``make verify`` and the batch: the terminal obeyed them (retitled,
    cleared, the line overwritten or reversed). Now written escaped, one plain line."""
    d = tmp_path / "beta"
    d.mkdir()
    record = {"config": {}, "code_hash": "0", "written_as": FORGED}
    record["study_file"] = {"path": FORGED + ".toml", "sha256": None}
    (d / "run.json").write_text(json.dumps(record))
    why = other_source(d)
    assert why is not None and "beta's" in why
    assert why.isprintable(), why
    assert "\\x1b]0;PWNED\\x07" in why and "\\u202e" in why and "\\x0d" in why
    # the command line's error line, and the API's one-line refusal, the same way
    line = clipped(f"sim: error: --set: {FORGED}")
    assert line.isprintable() and line.endswith("\\u202eevil")
