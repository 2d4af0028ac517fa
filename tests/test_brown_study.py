"""Brown studies (seed 004): claim book, hardware feasibility, sweep of the unprinted station
offset, consistent set, and a report computed from the Parquet files."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from sim.claims.book import ClaimBook
from sim.cli import main
from sim.mc.config import ConfigError
from sim.mc.storage import read_table
from sim.studies import load_study
from sim.studies.brown import values as V
from sim.studies.brown.claims import BOOK, load_book
from sim.studies.brown.consistency import SWEEP_COLUMNS, consistent_set, feasible, sweep_table1
from sim.studies.brown.report import report_dilution, report_table1
from sim.studies.brown.schema import max_offset_mm, setup, sweep_offsets

ROOT = Path(__file__).resolve().parents[1]
DIL = ROOT / "studies" / "brown_dilution.toml"
T1 = ROOT / "studies" / "brown_table1.toml"


def test_claim_book_splits_into_the_two_studies():
    full = ClaimBook.load(BOOK)
    d, t = load_book("brown_dilution"), load_book("brown_table1")
    assert set(d.specs) | set(t.specs) == set(full.specs)
    assert not set(d.specs) & set(t.specs)
    assert len(d.not_reproduced) + len(t.not_reproduced) == len(full.not_reproduced)
    # the paper's "from 5 to 15 percent" is a range; one-plate numbers are one-plate
    assert d.spec("brown.dilution.range_pct")["form"] == "range"
    for c in ("share_1p1_1p3", "points_ge_1p45"):
        assert t.spec(f"brown.table1_point_sigma.{c}")["form"] == "one-plate"
    assert t.spec("brown.table1_closure.typical_range_um")["ref"] == [1.5, 2.0]


def test_study_files_fit_the_papers_scale_and_the_old_geometry_does_not():
    for f in (DIL, T1):
        _, cfg = load_study(f)
        assert cfg["comparator.scale_length_mm"] == 261.0 and cfg["comparator.micrometer_mm"] == 1.0
        pts, th = setup(cfg)
        ok, rmax = feasible(cfg, pts[None], th[None])
        assert ok[0] and rmax[0] <= 262.0
    with pytest.raises(ConfigError, match="comparator.scale_length_mm"):
        load_study(T1, ["comparator.station_offset_mm=45.0"])


def test_largest_offset_is_where_the_longest_range_meets_the_scale():
    _, cfg = load_study(T1)
    h = max_offset_mm(cfg, 90.0)
    assert 33.0 < h < 35.0  # brown_design: about 33.6 mm for a +-90 mm grid
    pts, _ = setup(cfg)
    th = V.thetas(
        cfg["plate.format_mm"],
        [h - 1e-6, h + 1e-3],
        cfg["comparator.alpha_mm"],
        cfg["comparator.beta_mm"],
    )
    ok, rmax = feasible(cfg, np.stack([pts, pts]), th)
    assert ok.tolist() == [True, False]
    assert math.isclose(rmax[0], 262.0, abs_tol=1e-4)


def test_sweep_keys_are_validated():
    with pytest.raises(ConfigError, match="consistency.offset_max_mm"):
        load_study(T1, ["consistency.offset_max_mm=0.2"])
    with pytest.raises(ConfigError, match="consistency.offset_step_mm"):
        load_study(DIL, ["consistency.offset_step_mm=1e-4"])
    with pytest.raises(ConfigError, match="consistency.extents_mm"):
        load_study(DIL, ["consistency.extents_mm=[130.0]"])
    _, cfg = load_study(
        T1,
        [
            "consistency.offset_min_mm=1.0",
            "consistency.offset_max_mm=2.0",
            "consistency.offset_step_mm=0.5",
        ],
    )
    assert sweep_offsets(cfg).tolist() == [1.0, 1.5, 2.0]


def _long(rows):
    """A long sweep table from (offset, claim, verdict, feasible) tuples."""
    t = {c: [] for c in SWEEP_COLUMNS}
    for o, c, v, f in rows:
        for k, x in (
            ("half_extent_mm", 90.0),
            ("offset_mm", o),
            ("feasible", f),
            ("max_range_mm", 0.0),
            ("claim", c),
            ("kind", "prediction"),
            ("value", 0.0),
            ("ci_low", 0.0),
            ("ci_high", 0.0),
            ("p_plate", math.nan),
            ("verdict", v),
        ):
            t[k].append(x)
    return t


def test_consistent_set_intersects_the_holding_offsets_and_names_conflicts():
    v = {
        "a": ["fails", "holds", "holds", "holds", "holds"],
        "b": ["holds", "holds", "holds", "fails", "holds"],
        "c": ["fails"] * 5,
    }
    feas = [True, True, True, True, False]
    rows = [(o, c, v[c][i], feas[i]) for c in v for i, o in enumerate([1.0, 2.0, 3.0, 4.0, 5.0])]
    cs = {r["claim"]: r for r in _rows(consistent_set(_long(rows), {}))}
    assert (cs["a"]["holds_low"], cs["a"]["holds_high"], cs["a"]["contiguous"]) == (2.0, 4.0, True)
    assert (cs["b"]["holds_low"], cs["b"]["holds_high"], cs["b"]["contiguous"]) == (1.0, 3.0, True)
    assert cs["b"]["feasible_high"] == 4.0  # 5 mm is off the scale: never counted
    assert math.isnan(cs["ALL"]["holds_low"]) and "hold nowhere: c" in cs["ALL"]["conflicts"]
    assert (cs["ALL_SATISFIABLE"]["holds_low"], cs["ALL_SATISFIABLE"]["holds_high"]) == (2.0, 3.0)
    rows = [(o, "d", ["holds", "fails", "holds"][i], True) for i, o in enumerate([1.0, 2.0, 3.0])]
    rows += [(o, "e", ["fails", "holds", "fails"][i], True) for i, o in enumerate([1.0, 2.0, 3.0])]
    cs = {r["claim"]: r for r in _rows(consistent_set(_long(rows), {}))}
    assert cs["d"]["contiguous"] is False and "disjoint: d / e" in cs["ALL"]["conflicts"]


def _rows(cols):
    return [dict(zip(cols, vals)) for vals in zip(*cols.values())]


def test_sweep_scores_the_same_rule_as_the_nominal_geometry():
    _, cfg = load_study(T1)
    pts, th = setup(cfg)
    sw = sweep_table1(cfg, load_book("brown_table1"), pts, 1.63)
    # the at-paper-closure share rises as the stations come in (fewer sigmas above 1.35 um)
    s = [
        v
        for c, v, f in zip(sw["claim"], sw["value"], sw["feasible"])
        if c.endswith("share_at_paper_closure") and f
    ]
    assert s[0] > s[-1]
    assert not any(f for f, r in zip(sw["feasible"], sw["max_range_mm"]) if r > 262.0)


@pytest.fixture(scope="module")
def runs(tmp_path_factory):
    out = {}
    for name, f in (("brown_dilution", DIL), ("brown_table1", T1)):
        o = tmp_path_factory.mktemp(name) / name
        tiny = (ROOT / "tests" / "data" / "tiny" / f"{name}.txt").read_text().splitlines()
        sets = [
            x for kv in tiny if not kv.startswith("consistency.offset_step") for x in ("--set", kv)
        ]
        sets += [
            "--set",
            "consistency.offset_min_mm=16.0",
            "--set",
            "consistency.offset_max_mm=18.0",
            "--set",
            "consistency.offset_step_mm=0.5",
        ]
        assert main(["run", str(f), "--out", str(o), "--quiet", *sets]) == 0
        out[name] = o
    return out


def test_nominal_rows_equal_the_sweep_at_the_nominal_offset(runs):
    for name, o in runs.items():
        claims = {r["claim"]: r for r in read_table(o / "claims.parquet").to_pylist()}
        sw = read_table(o / "sweep.parquet").to_pylist()
        e0 = max(r["half_extent_mm"] for r in sw if r["offset_mm"] == 17.0)  # the plate: 90
        at = [r for r in sw if r["offset_mm"] == 17.0 and r["half_extent_mm"] == e0]
        assert at
        for r in at:
            c = claims[r["claim"]]
            if c["form"] == "one-plate":  # nominal: Monte Carlo; sweep: chi-square quantiles
                continue
            assert r["verdict"] == c["verdict"], r["claim"]
            assert math.isclose(r["value"], c["value"], rel_tol=1e-9, abs_tol=1e-12), r["claim"]
        assert (o / "consistent_set.png").stat().st_size > 0


def test_report_prose_comes_from_the_parquet_files(runs, tmp_path):
    import shutil

    import pyarrow.parquet as pq

    for name, rep in (("brown_dilution", report_dilution), ("brown_table1", report_table1)):
        o = tmp_path / name
        shutil.copytree(runs[name], o)
        before = rep(o)
        p = o / "consistent_set.parquet"
        t = pq.read_table(p)
        i = t.column_names.index("holds_low")
        vals = [
            47.77 if c == "ALL" else v
            for c, v in zip(t.column("claim").to_pylist(), t.column("holds_low").to_pylist())
        ]
        import pyarrow as pa

        pq.write_table(t.set_column(i, "holds_low", pa.array(vals, pa.float64())), p)
        after = rep(o)
        assert "47.8" in after and "47.8" not in before
