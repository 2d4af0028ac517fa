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


def test_table1_figure_counts_the_runs_sigmas(monkeypatch):
    """The middle panel's share is over the run's 2n σ (core.py: x and y of each point), so
    a 4 x 4 plate's label says 32, not the paper's 50 (doors29f's case 2)."""
    import numpy as np

    import sim.studies.brown.figures as F

    seen = []
    monkeypatch.setattr(F, "_plate_axes", lambda *a, **k: None)
    monkeypatch.setattr(F, "save", lambda fig, path: seen.append(fig))
    g = np.arange(4) * 45.0
    pts = np.stack(np.meshgrid(g, g), -1).reshape(-1, 2)
    t1 = {"sigma0_um": np.linspace(1.4, 1.9, 12), "share_1p1_1p3": np.linspace(0.6, 0.9, 12)}
    F.fig_table1({}, pts, None, np.full((16, 2), 1.2), t1, None)
    labels = [ax.get_xlabel() for ax in seen[0].axes]
    assert "share of the 32 σ printing 1.1–1.3 µm (%)" in labels


def test_table1_intro_on_the_papers_plate_says_it_once(monkeypatch):
    text = _intro(monkeypatch)
    assert text.startswith("The paper's production test: a 5 x 5 array at 45 mm, 2 settings")
