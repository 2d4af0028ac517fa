"""The failure classes of the second sweep of bad inputs over every door (issue 26), one
parametrised case per class: each is refused with exit 2 and one line naming the key or the
argument, and nothing is written.

* a ``--set`` value that carries a line break (a second key smuggled in with the first);
* a value written as an empty table ``{}`` (it vanished when the file was flattened, and the
  default was used); an empty section stays allowed;
* ``sim report --results DIR`` on a directory of the user's without study results (it wrote
  ``REPORT.md`` into it);
* a datum constraint whose coefficients are all zero (it was dropped, and the rank defect
  blamed).
"""

from pathlib import Path

import pytest

from sim.cli import main

ROOT = Path(__file__).resolve().parent.parent
BROWN = ROOT / "studies" / "brown_table1.toml"

NETWORK = """study = "network"
trials = 40
chunk = 2
[network]
name = "n"
points = [
  { name = "A", x_mm = 0.0, y_mm = 0.0 },
  { name = "B", x_mm = 1000.0, y_mm = 0.0 },
  { name = "C", x_mm = 400.0, y_mm = 700.0 },
]
generate = [ { kind = "distance", from = "*", to = "*", sigma_mm = 0.01 },
             { kind = "direction", from = "*", to = "*", sigma_arcsec = 1.0 } ]
[datum]
kind = "constraints"
constraints = [ { "A.x" = COEF }, { "A.y" = 1.0 }, { "B.y" = 1.0 } ]
"""


def _one_line(capsys, code: int, *names: str) -> str:
    err = capsys.readouterr().err
    assert code == 2 and err.count("\n") == 1 and err.startswith("sim: error: "), err
    assert "Traceback" not in err and all(n in err for n in names), err
    return err


@pytest.mark.parametrize(
    "value, key",
    [("40\nchunk=2", "trials"), ("40\rseed=3", "trials"), ("[3,\n5]", "dilution.grids")],
)
def test_a_set_value_is_one_line(capsys, value, key):
    _one_line(capsys, main(["check", str(BROWN), "--set", f"{key}={value}"]), key, "one line")


@pytest.mark.parametrize(
    "text, key", [("[plate]\ngrid = {}\n", "plate.grid"), ("trials = {}\n", "trials")]
)
def test_an_empty_table_is_not_a_value(tmp_path, capsys, text, key):
    f = tmp_path / "s.toml"
    f.write_text('study = "brown_table1"\n' + text)
    _one_line(capsys, main(["check", str(f)]), key, "{}")
    f.write_text('study = "brown_table1"\n[plate]\n[errors]\nsettings = 2\n')  # empty section
    assert main(["check", str(f)]) == 0
    capsys.readouterr()
    _one_line(capsys, main(["check", str(BROWN), "--set", "plate={}"]), "plate", "unknown key")


def test_report_refuses_a_directory_without_study_results(tmp_path, capsys):
    (tmp_path / "mine").mkdir()
    (tmp_path / "mine" / "notes.txt").write_text("mine\n")
    _one_line(capsys, main(["report", "--results", str(tmp_path / "mine")]), "no study results")
    assert [p.name for p in (tmp_path / "mine").iterdir()] == ["notes.txt"]


@pytest.mark.parametrize("coef", ["0.0", "0"])
def test_an_all_zero_datum_constraint_is_named(tmp_path, capsys, coef):
    f = tmp_path / "n.toml"
    f.write_text(NETWORK.replace("COEF", coef))
    _one_line(capsys, main(["check", str(f)]), "datum.constraints[0]", "zero")
    f.write_text(NETWORK.replace("COEF", "1.0"))
    assert main(["check", str(f)]) == 0
