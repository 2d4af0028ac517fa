"""doors29f: a number an output prints is the run's, not the paper's default."""

import sim.studies.brown.report as R


def _intro(monkeypatch, **over):
    cfg = {
        "plate.pattern": "grid",
        "plate.grid": 5,
        "plate.spacing_mm": 45.0,
        "errors.settings": 2,
        "errors.setting_sigma_um": 1.7,
        "errors.comparator_sigma_um": 1.1,
        "comparator.station_offset_mm": 17.0,
        **over,
    }
    monkeypatch.setattr(R, "config", lambda out: {"config": cfg, "range_sigma_um": 1.63})
    return R._table1_intro(None)


def test_table1_intro_prints_the_runs_grid(monkeypatch):
    text = _intro(monkeypatch, **{"plate.grid": 4, "plate.spacing_mm": 60.0})
    assert "this run: a 4 x 4 array at 60 mm" in text


def test_table1_intro_names_a_non_grid_pattern(monkeypatch):
    text = _intro(monkeypatch, **{"plate.pattern": "random"})
    assert "this run: a random pattern" in text
