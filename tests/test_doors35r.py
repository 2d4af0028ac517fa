"""Review of the session ending 62e2e50b (brief R35: the diff bcd59378..62e2e50b read for
defects); one case each, each failed on the code before its fix.

* A ``run.json`` whose ``overrides`` were edited by hand to hold a lone surrogate in a value
  (``"plate.pattern=\\"\\ud800\\""`` in JSON) passed :func:`sim.mc.overrides.replayable` (it
  reads back as the text a run writes) and ``make verify`` ended in a UnicodeEncodeError
  traceback while building the re-run's command line. Such an override is now refused as
  the other hand-edited ones are: the study fails in one line naming the entry and the
  file, and nothing is re-run.
"""

from __future__ import annotations

import json
import shutil
from pathlib import Path

from sim.report.verify import main as verify_main

ROOT = Path(__file__).resolve().parent.parent
COMMITTED = ROOT / "results" / "brown_table1"


def _results(tmp_path: Path, overrides: list[str]) -> Path:
    """A copy of the committed brown_table1 results whose run.json records ``overrides``."""
    d = tmp_path / "R" / "brown_table1"
    shutil.copytree(COMMITTED, d, ignore=shutil.ignore_patterns("*.png", "trials"))
    rec = json.loads((d / "run.json").read_text(encoding="utf-8"))
    (d / "run.json").write_text(json.dumps({**rec, "overrides": overrides}), encoding="utf-8")
    return d.parent


def test_an_override_with_a_lone_surrogate_is_not_passed_on(tmp_path, capsys):
    results = _results(tmp_path, ['plate.pattern="\ud800"', "trials=40"])
    argv = ["--results", str(results), "--scratch", str(tmp_path / "S"), "--no-record"]
    assert verify_main(argv) == 1  # before: UnicodeEncodeError from the re-run's launcher
    out = capsys.readouterr()
    assert out.out.splitlines()[0] == "brown_table1: FAILED; nothing compared", out
    (line,) = out.out.splitlines()[1:]
    assert "its override 'plate.pattern=\"\\ud800\"' is not a value written as a run" in line
    assert "run.json" in line and "(edited by hand?): not re-run" in line
    assert "re-running" not in out.err and not (tmp_path / "S" / "brown_table1").exists()
