"""Doors, session 50, helper L51: the left items of the session's first helpers.

Each test names the class of bad input and what the suite did with it before.
"""

from __future__ import annotations

import json

import pytest

from sim.long_words import clipped
from sim.mc.config import ConfigError
from sim.mc.study_source import other_source
from tests.conftest import TRIANGLE_NETWORK

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


def test_sweep_range_wider_than_a_float_is_counted():
    """Class: a ``[sweep]`` range whose span overflows a float (start 1e308, stop -1e308).
    Its count ``(stop - start) / step`` was inf: three values (step -1e308) were refused as
    "more than 10000 values", and ``num = 3`` as "the range's values are not finite". Now
    reckoned in halves (exact): the values the user wrote, the count a true one."""
    from sim.mc.sweep import _values

    assert _values("k", {"start": 1e308, "stop": -1e308, "step": -1e308}) == [1e308, 0.0, -1e308]
    assert _values("k", {"start": 1e308, "stop": -1e308, "num": 3}) == [1e308, 0.0, -1e308]
    # a range of that span with a small step still has too many values, and says so
    with pytest.raises(ConfigError, match="more than 10000 values"):
        _values("k", {"start": -1.7e308, "stop": 1.7e308, "step": 1e300})


@pytest.mark.parametrize("index", ["[99999999999999999999999]", "[-1]"])
def test_list_item_key_echoed_as_written_and_hinted(tmp_path, capsys, index):
    """Class: ``--set`` of a list's item by an index no list has. A 23-digit index was echoed
    as ``points[1e+23]`` (a key the user never wrote: the message's long-number shortening
    reached the key), and ``points[-1]`` (Python's last item) had no word that a list's items
    are given whole. Now the key as written, and the list's hint for any index."""
    from sim.cli import main

    st = tmp_path / "t.toml"
    st.write_text(TRIANGLE_NETWORK)
    assert main(["check", str(st), "--set", f"network.points{index}.x_mm=1"]) == 2
    err = capsys.readouterr().err.strip()
    assert err.startswith(f"sim: error: network.points{index}.x_mm: unknown key"), err
    assert "network.points is a list" in err and "--set 'network.points=[...]'" in err
    assert len(err.splitlines()) == 1


@pytest.mark.parametrize(
    ("line", "said"),
    [
        ("trials = NaN", "in lower case, nan and inf: trials = nan"),
        ("trials = -Inf", "in lower case, nan and inf: trials = -inf"),
        ("trials = None", "TOML has no null: leave trials out"),
    ],
)
def test_python_words_for_toml_values_hinted(tmp_path, capsys, line, said):
    """Class: a study file written as Python or NumPy would (``NaN``, ``Inf``, ``None``).
    ``NaN`` and ``Inf`` got tomllib's bare "Invalid value", no word that TOML writes ``nan``
    and ``inf``; ``None`` was hinted as a text to quote (``trials = "None"``), where a
    Python user means no value: TOML has no null, the key is left out."""
    from sim.cli import main

    st = tmp_path / "t.toml"
    st.write_text(TRIANGLE_NETWORK.replace("trials = 40", line))
    assert main(["check", str(st)]) == 2
    err = capsys.readouterr().err.strip()
    assert "malformed TOML" in err and said in err and len(err.splitlines()) == 1, err


def _one_fixed(tmp_path, enc: str | None = None, stdev: str | None = None):
    """tests/data/gama/one_fixed.xml, its stdevs replaced, saved as UTF-16 declaring ``enc``."""
    import re
    from pathlib import Path

    text = (Path(__file__).parent / "data" / "gama" / "one_fixed.xml").read_text()
    if stdev is not None:
        text = re.sub(r'stdev="[^"]*"', f'stdev="{stdev}"', text)
    p = tmp_path / "net.xml"
    if enc is None:
        p.write_text(text)
    else:
        text = re.sub(r"^<\?xml[^>]*\?>", f'<?xml version="1.0" encoding="{enc}"?>', text)
        p.write_bytes(text.encode("utf-16"))
    return p


def test_gama_utf16_file_declaring_another_encoding_named(tmp_path):
    """Class: a GNU Gama file saved as UTF-16 by an editor that kept its declaration of
    iso-8859-2. Refused with the parser's bare "not well-formed (invalid token): line 2"
    (gama-local refuses it too): now the disagreement and what to do are said; a UTF-16 file
    declaring UTF-16 is still read."""
    from sim.studies.network.gama_read import read_gama

    with pytest.raises(ConfigError) as e:
        read_gama(_one_fixed(tmp_path, "iso-8859-2"))
    assert "a UTF-16 file" in str(e.value) and "declare UTF-16" in str(e.value)
    assert read_gama(_one_fixed(tmp_path, "UTF-16"))["network.points"]


def test_gama_stdev_out_of_range_quoted_as_written(tmp_path):
    """Class: a GNU Gama stdev far out of range, written subnormal (``stdev="1e-320"``). The
    refusal printed the float's nearest representation, ``9.99989e-321``, a number the file
    does not hold, and "(0 arcsec)": now the attribute's text and "under 1e-300 arcsec"."""
    from sim.studies.network.gama_read import read_gama

    with pytest.raises(ConfigError) as e:
        read_gama(_one_fixed(tmp_path, stdev="1e-320"))
    assert "a standard deviation of 1e-320 (under 1e-300 arcsec)" in str(e.value)


def test_sim_check_builds_the_network_once(tmp_path, capsys, monkeypatch):
    """Class: ``sim check`` of a large network (work, not input). It built the network three
    times (the study's checks, the keys it does not read, the notes on its biases): 0.74 s of
    CPU each at 10,000 points, a sixth of the command. Now once: an equal config gives the
    network built last."""
    import sim.studies.network.definition as definition
    from sim.cli import main

    made = []
    points = definition._points
    monkeypatch.setattr(definition, "_points", lambda *a: made.append(1) or points(*a))
    st = tmp_path / "t.toml"
    st.write_text(TRIANGLE_NETWORK.replace("trials = 40", "trials = 41"))  # (no memo of before)
    assert main(["check", str(st)]) == 0
    assert "network.points" in capsys.readouterr().out
    assert len(made) == 1
