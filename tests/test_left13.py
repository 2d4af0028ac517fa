"""The items issue 26's last note left open (left12's and review27's, agnard27's; brief L13).

1. ``sim check``'s note on brown_table1's ``plate.pattern`` said "printed by the paper:
   another value is off its setup" also for a ``plate.pattern = "list"`` of exactly Table 1's
   25 points, which the run (and the check's own last line) treats as the paper's plate
   (:func:`sim.studies.brown.schema.as_printed`). The note now says the value spells the
   paper's setup another way; a list that is not Table 1's keeps the old note.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from sim.cli import main

ROOT = Path(__file__).resolve().parents[1]
OFF = "printed by the paper: another value is off its setup"


# ------------------------------------------------------------- 1. the check's note on a list
def _listing(capsys, pts) -> dict[str, str]:
    """``sim check`` of brown_table1 with ``pts`` as its listed plate: {key: its line}."""
    study = str(ROOT / "studies" / "brown_table1.toml")
    sets = ["--set", 'plate.pattern="list"', "--set", f"plate.points={np.asarray(pts).tolist()}"]
    assert main(["check", study, *sets]) == 0
    out = capsys.readouterr().out.splitlines()
    return {ln.lstrip("# ").split(" = ")[0]: ln for ln in out if " = " in ln}, out


def test_the_check_note_on_the_papers_points_as_a_list_agrees_with_the_run(capsys):
    from sim.instruments.plates import grid_points

    paper = grid_points(5, 45.0)
    lines, out = _listing(capsys, paper[::-1])
    said = lines["plate.pattern"]
    assert OFF not in said, said
    assert "printed by the paper: the paper's setup spelled another way" in said, said
    assert not any("off the paper's setup" in ln for ln in out)
    assert OFF in lines["plate.format_mm"]  # the keys at the paper's value keep their note
    moved = paper.copy()
    moved[7, 0] += 1e-3  # a point a micron off: not the paper's plate, the note as before
    lines, out = _listing(capsys, moved)
    assert OFF in lines["plate.pattern"], lines["plate.pattern"]
    assert out[-2].startswith("# off the paper's setup (plate.pattern = 'list' (paper: 'grid'))")
