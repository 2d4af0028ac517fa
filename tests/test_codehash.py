"""Staleness per study: a study's code hash covers the modules it imports, and only those."""
from pathlib import Path

from sim.codehash import study_files

ROOT = Path(__file__).resolve().parent.parent


def names(study):
    return {f.relative_to(ROOT / "sim").as_posix() for f in study_files(study)}


def test_closure_follows_imports_and_stops_there():
    brown, wolf = names("brown_table1"), names("wolf_polynomial")
    assert "multilateration.py" in brown and "polynomial.py" in wolf
    assert "polynomial.py" not in brown        # Brown does not import the Wolf model
    assert not any(f.startswith("bench/") for f in brown | wolf)  # the benchmark is not study code
    assert "claims.py" in brown and "storage.py" in wolf


def test_every_study_has_its_own_closure():
    from sim.studies import MODULES

    for study in MODULES:
        assert any(f.startswith("studies/") for f in names(study)), study


def test_results_are_current_until_the_config_changes(tmp_path):
    from sim.cli import main
    from sim.codehash import is_current

    text = (ROOT / "studies" / "brown_table1.toml").read_text()
    study = tmp_path / "brown_table1.toml"
    study.write_text(text.replace("trials = ", "trials = 40 # ", 1).replace("chunk = ", "chunk = 20 # ", 1))
    out = tmp_path / "out"
    assert not is_current(study, out)                       # nothing there yet
    assert main(["run", str(study), "--out", str(out), "--quiet"]) == 0
    assert is_current(study, out)
    study.write_text(study.read_text().replace("seed = ", "seed = 11 # ", 1))
    assert not is_current(study, out)
