"""Figures checked for what a reader relies on, not only that a file exists (issue 28): each
panel has labels, its series and a finite data range, and the plotted data are the numbers
the run wrote to its tables (counts, ranges) -- read back from the Parquet files, not from the
figure code. The figures are caught as they are saved (``Figure.savefig``), in-process."""

from pathlib import Path

import matplotlib.figure as mfig
import numpy as np
import pyarrow.parquet as pq
import pytest

from sim.cli import main

ROOT = Path(__file__).resolve().parent.parent


@pytest.fixture
def figures(monkeypatch):
    """name -> list of panels ``{xlabel, ylabel, title, lines, collections, patches, heights,
    limits}`` of every figure saved while the test runs."""
    saved: dict[str, list[dict]] = {}
    orig = mfig.Figure.savefig

    def savefig(self, fname, *a, **k):
        name = Path(str(fname)).name.lstrip(".").split(".png")[0] + ".png"
        saved[name] = [
            {
                "xlabel": ax.get_xlabel(),
                "ylabel": ax.get_ylabel(),
                "title": ax.get_title(),
                "label": ax.get_label(),
                "lines": len(ax.lines),
                "collections": len(ax.collections),
                "patches": len(ax.patches),
                # the data bars: patches without a legend label (a labelled span marks the paper)
                "heights": [
                    p.get_height()
                    for p in ax.patches
                    if hasattr(p, "get_height") and p.get_label()[:1] in ("", "_")
                ],
                "limits": tuple(ax.dataLim.bounds),
            }
            for ax in self.axes
        ]
        return orig(self, fname, *a, **k)

    monkeypatch.setattr(mfig.Figure, "savefig", savefig)
    return saved


def _run(study: str, out: Path, *sets: str) -> None:
    args = ["run", str(ROOT / "studies" / f"{study}.toml"), "--out", str(out), "--quiet"]
    for s in sets:
        args += ["--set", s]
    assert main(args) == 0


def _panels_are_readable(figs: dict[str, list[dict]]) -> None:
    for name, panels in figs.items():
        data = [p for p in panels if p["lines"] + p["collections"] + p["patches"]]
        assert data, f"{name}: no panel shows data"
        for p in data:
            assert p["xlabel"] or p["ylabel"] or p["title"], f"{name}: a panel without labels"
            assert np.all(np.isfinite(p["limits"])), f"{name}: a panel's data are not finite"


def test_brown_table1_histogram_shows_every_simulated_plate(tmp_path, figures):
    out = tmp_path / "t1"
    _run("brown_table1", out, "trials=40", "chunk=2", "region.points=256", "region.rounds=1")
    assert "table1.png" in figures
    _panels_are_readable(figures)
    s0 = pq.read_table(out / "table1_trials.parquet").column("sigma0_um").to_numpy()
    hist = figures["table1.png"][0]
    assert "σ0" in hist["xlabel"] and "(µm)" in hist["xlabel"]
    assert hist["ylabel"] == "simulated plates"
    # the bars count the 40 simulated plates and span their sigma0 values
    assert sum(hist["heights"]) == pytest.approx(s0.size)
    x0, _, w, _ = hist["limits"]
    assert x0 <= s0.min() and s0.max() <= x0 + w
    field = figures["table1.png"][2]
    assert (field["xlabel"], field["ylabel"]) == ("x (mm)", "y (mm)")
    assert "σ" in field["title"]
    assert any(p["ylabel"] == "σ (µm)" for p in figures["table1.png"][3:])  # the colour bar


def test_network_reliability_has_one_bar_per_observation(tmp_path, figures):
    out = tmp_path / "net"
    _run("network_testfield", out, "trials=100", "chunk=5")
    assert {"network.png", "reliability.png"} <= set(figures)
    _panels_are_readable(figures)
    obs = pq.read_table(out / "observations.parquet").to_pydict()
    red, bnr = figures["reliability.png"]
    n = len(obs["redundancy"])
    assert red["patches"] == bnr["patches"] == n
    assert sorted(red["heights"]) == pytest.approx(sorted(obs["redundancy"]), abs=1e-12)
    assert sorted(bnr["heights"]) == pytest.approx(sorted(obs["bias_noise_ratio"]), abs=1e-12)
    assert all(0.0 <= r <= 1.0 for r in red["heights"])
    assert red["ylabel"] == "redundancy number" and bnr["ylabel"] == "bias-to-noise ratio"
    # the title states the sum of the redundancy numbers, which equals the degrees of freedom
    assert f"{sum(obs['redundancy']):.3f}" in red["title"]
    plan = figures["network.png"][0]
    assert plan["xlabel"].startswith("x (") and plan["ylabel"].startswith("y (")
    assert plan["lines"] + plan["collections"] >= 2  # the observations and the points
