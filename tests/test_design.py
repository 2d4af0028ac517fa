"""brown_design: sweeps, adaptive trial counts, error budget, design constraints, coverage."""
import numpy as np
import pytest

from sim import budget, coverage as cv, datum as dm, positions as po
from sim.cli import main
from sim.config import ConfigError, validate
from sim.plate import grid_points
from sim.runner import run_chunks
from sim.storage import read_provenance, read_table
from sim.studies import design
from sim.sweep import cell_seed, expand, run_adaptive

TABLE1 = """study = "brown_table1"
trials = {trials}
seed = 77
chunk = 10
"""


def _claims(path):
    t = read_table(path).to_pydict()
    return dict(zip(t["claim"], t["value"]))


def test_sweep_of_one_cell_equals_the_single_run_with_the_same_seed(tmp_path):
    single = tmp_path / "single.toml"
    single.write_text(TABLE1.format(trials=20))
    for mode in ("common", "spawn"):
        sw = tmp_path / f"sweep_{mode}.toml"
        sw.write_text(TABLE1.format(trials=20) + f'\n[sweep]\nseed_mode = "{mode}"\n'
                      '"errors.settings" = [2]\n')
        assert main(["run", str(sw), "--out", str(tmp_path / f"sw_{mode}"), "--quiet"]) == 0
        rows = read_table(tmp_path / f"sw_{mode}" / "sweep.parquet").to_pydict()
        assert rows["cell"] == [0] and rows["feasible"] == [True]
        seed = rows["seed"][0]
        assert seed == (77 if mode == "common" else cell_seed(77, 0, 0))
        assert main(["run", str(single), "--out", str(tmp_path / f"one_{mode}"), "--seed",
                     str(seed), "--quiet"]) == 0
        a = _claims(tmp_path / f"sw_{mode}" / "cells" / "cell0000_r0" / "claims.parquet")
        b = _claims(tmp_path / f"one_{mode}" / "claims.parquet")
        assert a == b
        assert rows["brown.table1_closure.rms_um"][0] == b["brown.table1_closure.rms_um"]


def test_sweep_records_infeasible_cells_with_the_reason(tmp_path):
    sw = tmp_path / "sw.toml"
    sw.write_text(TABLE1.format(trials=20) + '\n[sweep]\nreplicates = 2\n[sweep.plate]\n'
                  'spacing_mm = [45.0, 80.0]\n')
    assert main(["run", str(sw), "--out", str(tmp_path / "o"), "--quiet"]) == 0
    rows = read_table(tmp_path / "o" / "sweep.parquet").to_pydict()
    assert rows["plate.spacing_mm"] == [45.0, 45.0, 80.0, 80.0]
    assert rows["feasible"] == [True, True, False, False]
    assert "outside the 245 mm format" in rows["reason"][2]
    assert rows["seed"][0] != rows["seed"][1]          # replicates: independent streams
    assert not (tmp_path / "o" / "cells" / "cell0001_r0").exists()
    assert read_provenance(tmp_path / "o" / "sweep.parquet")["sweep_keys"] == ["plate.spacing_mm"]


def test_sweep_table_errors_name_the_key(tmp_path, capsys):
    sw = tmp_path / "sw.toml"
    sw.write_text(TABLE1.format(trials=20) + '\n[sweep]\n"plate.bogus" = [1, 2]\n')
    assert main(["run", str(sw), "--out", str(tmp_path / "o"), "--quiet"]) == 2
    assert "sweep.plate.bogus" in capsys.readouterr().err
    assert not (tmp_path / "o").exists()
    with pytest.raises(ConfigError, match="sweep.x"):
        expand({"x": {"start": 0, "stop": 1}})
    keys, cells, reps, mode = expand({"a": {"start": 1, "stop": 2, "num": 3},
                                      "b": {"start": 2, "stop": 8, "step": 3}, "replicates": 2})
    assert keys == ["a", "b"] and reps == 2 and mode == "spawn"
    assert [c["a"] for c in cells] == [1.0, 1.0, 1.0, 1.5, 1.5, 1.5, 2.0, 2.0, 2.0]
    assert [c["b"] for c in cells[:3]] == [2, 5, 8]


def test_adaptive_trials_stop_at_the_target_and_reuse_the_chunk_streams():
    def fn(rng, n):
        return {"x": rng.normal(0.0, 1.0, n)}

    def stat(res):
        x = res["x"]
        return {"mean": (float(x.mean()), float(x.std(ddof=1) / np.sqrt(len(x))))}

    res, st = run_adaptive(fn, stat, 0.02, seed=5, chunk=500, quiet=True)
    n = len(res["x"])
    assert st["mean"][1] < 0.02 and n % 500 == 0
    assert 1 / np.sqrt(n) < 0.02 * 1.1 and 1 / np.sqrt(n - 500) > 0.02 * 0.9  # stopped at once
    fixed = run_chunks(fn, n, 5, 500, quiet=True)
    assert np.array_equal(fixed["x"], res["x"])


def test_first_harmonic_wobble_is_absorbed_but_not_the_second():
    pts = grid_points(5, 45.0)
    th = po.design_theta(4, 152.5, 0.5, 1.0)
    T = 40
    P = np.broadcast_to(pts, (T, 25, 2))
    TH = np.broadcast_to(th, (T, 10))
    r = po.ranges(P, TH)
    psi = po.arm_angles(P, TH)
    S = dm.inner(pts)
    t0 = th.copy()
    t0[-2:] = 0.0
    out = {}
    for h in (1, 2):
        e = budget.wobble_error(psi, np.random.default_rng(1), 2.0, h)
        assert np.abs(e).max() <= 2.0 + 1e-12 and np.abs(e).max() > 1.5
        res = po.adjust(r + e * 1e-3, "pivot", t0, "inner")
        out[h] = np.abs(((res.points - P) * 1e3).reshape(T, -1) @ S.T).max()
    assert out[1] < 1e-3 < 0.05 < out[2]


def test_graduation_error_is_shared_by_readings_on_one_graduation():
    r = np.array([[10.2, 10.9, 11.1, 200.5]])
    e = budget.graduation_error(r, np.random.default_rng(0), 0.54)
    assert e[0, 0] == e[0, 1] and e[0, 1] != e[0, 2]
    r = np.random.default_rng(1).uniform(0, 261, (400, 50))
    big = budget.graduation_error(r, np.random.default_rng(2), 0.54)
    # one draw per (trial, graduation): those are the independent samples of the std
    first = np.unique(np.floor(r).astype(int) + 1000 * np.arange(400)[:, None], return_index=True)[1]
    g = big.ravel()[first]
    assert abs(g.std() / 0.54 - 1) < 4 / np.sqrt(2 * (g.size - 1))


def test_time_model_reproduces_the_papers_timings_and_pareto_front():
    cfg = validate({}, design.SCHEMA, design.check)
    assert design.measuring_time(cfg, 4, 30, 1) == pytest.approx(60.0)
    assert design.measuring_time(cfg, 4, 30, 2) == pytest.approx(90.0)
    cost = np.array([1.0, 2.0, 2.0, 3.0, 0.5])
    acc = np.array([3.0, 2.0, 2.5, 1.0, 9.0])
    ok = np.array([True, True, True, True, False])
    assert design.pareto_front(cost, acc, ok).tolist() == [True, True, False, True, False]


def test_scale_length_makes_browns_dilution_geometry_infeasible():
    cfg = validate({}, design.SCHEMA, design.check)
    g = design.geometry_eval(cfg, 4, 5, 110.0, [45.0, 5.0], [1.0])
    assert "exceeds the 262 mm" in g["reason"][0]
    assert g["reason"][1] == ""
    g8 = design.geometry_eval(cfg, 8, 5, 90.0, [10.0], [1.0])
    assert "pivot over the plate" in g8["reason"][0]


def test_paper_design_must_be_in_the_grid():
    with pytest.raises(ConfigError, match="paper.offset_mm"):
        validate({"paper.offset_mm": 33.0}, design.SCHEMA, design.check)
    with pytest.raises(ConfigError, match="time.double_min"):
        validate({"time.double_min": 50.0}, design.SCHEMA, design.check)


def test_coverage_of_a_linear_models_ellipses_is_95_percent():
    rng = np.random.default_rng(2026)
    grid = grid_points(4, 60.0)
    aff = np.array([[1.0001, 2e-4, 0.3], [-1e-4, 0.9998, -0.1]])
    T = 20000
    r = cv.affine_trials(rng, T, grid, 1.5, aff)
    Q = r["leverage"][:, None, None] * np.eye(2)
    inside = cv.ellipse_inside(r["err_um"], np.broadcast_to(Q, (16, 2, 2)), sigma=1.5)
    # points of one trial share the fit: use the trial (not the point) as the sampling unit
    per_trial = inside.mean(1)
    se = per_trial.std(ddof=1) / np.sqrt(T)
    assert abs(per_trial.mean() - 0.95) < 4 * se
    inside_f = cv.ellipse_inside(r["err_um"], np.broadcast_to(Q, (16, 2, 2)), s0=r["s0_um"],
                                 dof=r["dof"]).mean(1)
    assert abs(inside_f.mean() - 0.95) < 4 * inside_f.std(ddof=1) / np.sqrt(T)
    rej = cv.chi2_reject(r["s0_um"], 1.5, r["dof"], 0.05)
    assert abs(rej.mean() - 0.05) < 4 * np.sqrt(0.05 * 0.95 / T)
    assert abs(r["s0_um"].mean() / 1.5 - cv.c4(r["dof"] + 1)) < 4 * r["s0_um"].std() / 1.5 / np.sqrt(T)
    # a wrong (too small) sigma is detected: coverage falls well below 95 %
    assert cv.ellipse_inside(r["err_um"], np.broadcast_to(Q, (16, 2, 2)), sigma=1.0).mean() < 0.85


def test_sweep_rows_draw_and_tabulate(tmp_path):
    from sim.sweep import sweep_markdown

    sw = tmp_path / "sw.toml"
    sw.write_text(TABLE1.format(trials=20) + '\n[sweep]\n"errors.settings" = [1, 2]\n'
                  '"plate.spacing_mm" = [45.0, 80.0]\n')
    assert main(["run", str(sw), "--out", str(tmp_path / "o"), "--quiet"]) == 0
    assert (tmp_path / "o" / "sweep.png").is_file()
    md = sweep_markdown(tmp_path / "o")
    assert md.count("\n") >= 5 and "no: plate.spacing_mm" in md and "sweep.png" in md
