"""The lead's own sweep of the session of 2026-11-28, 20:55 UTC (issue 26): fresh bad input
tried as a new user, door by door, while the helpers were cut off. Each test failed on the
code before its fix."""

from __future__ import annotations

from pathlib import Path

import pytest

from sim.cli import main

STUDIES = Path(__file__).resolve().parents[1] / "studies"


def _edited(tmp_path: Path, study: str, old: str, new: str) -> Path:
    text = (STUDIES / study).read_text(encoding="utf-8")
    assert old in text
    p = tmp_path / study
    p.write_text(text.replace(old, new, 1), encoding="utf-8")
    return p


def _refused(capsys, args) -> str:
    assert main(args) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1, err
    return err


@pytest.mark.parametrize(
    ("old", "new", "words"),
    [
        ("spacing_m = 25.0", "spacing_m = -25.0", "grids[0].spacing_m: must be > 0 (got -25 m)"),
        ("spacing_m = 25.0", "spacing_m = 0.0", "grids[0].spacing_m: must be > 0 (got 0 m)"),
    ],
)
def test_a_field_networks_length_in_metres_is_refused_by_the_key_written(
    tmp_path, capsys, old, new, words
):
    # before: "network.grids[0].spacing_mm: must be > 0 (got -25000 mm)", a key the file
    # does not have and a value it does not hold
    err = _refused(capsys, ["check", str(_edited(tmp_path, "network_testfield.toml", old, new))])
    assert words in err and "spacing_mm" not in err, err
