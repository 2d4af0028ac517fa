"""Tests of the Agnard, Nolette & Gagnon study: block geometry, scanner model, independent-
model block adjustment (reduced normals), data snooping, study config and a tiny run."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest
from verdict_check import region_verdict

from sim.claims.region import REGION_VERDICTS
from sim.instruments.block import data_snooping as ds
from sim.instruments.block import independent_models as im
from sim.instruments.block import scanner as sc
from sim.instruments.block.layout import CONTROL_PATTERNS, make_block, select_control
from sim.instruments.geometry import similarity_fit
from sim.mc.config import ConfigError
from sim.studies import load_study
from sim.studies.agnard.region import REJECTED, SCANNER_KEYS

STUDY = "studies/agnard_block.toml"


@pytest.fixture(scope="module")
def small():
    """A 2 x 3 block with 40 signalised points."""
    return make_block(2, 3, n_ground=40, pass_rows=3)


def _start(block, st, xm, rng, T):
    X0 = block.points + rng.normal(0, 2.0, (T,) + block.points.shape)
    return im.initial_values(st, xm, X0) + (X0,)


# ----------------------------------------------------------------------------- geometry


def test_block_counts_and_incidence(small):
    b = make_block()
    assert b.n_ground == 178
    assert b.strips * b.models == 16
    # every pass point is seen by at least two models, every ground point by at least one
    seen = np.bincount(b.obs_point, minlength=b.n_points)
    assert seen[b.is_pass].min() >= 2 and seen[~b.is_pass].min() >= 1
    assert np.all(np.diff(b.obs_model) >= 0)
    assert select_control(b, "five").size == 5 and select_control(b, "full").size == 21
    for p in CONTROL_PATTERNS:
        c = select_control(b, p)
        assert np.unique(c).size == c.size and c.max() < b.n_ground


def test_parallax_intersection_is_exact(small):
    b = small
    xl = b.image_coords(b.obs_left, b.obs_point)
    xr = b.image_coords(b.obs_right, b.obs_point)
    G = im.form_models(xl, xr, b.focal_mm, b.base_m) + b.photos.reshape(-1, 3)[b.obs_left]
    assert np.allclose(G, b.points[b.obs_point], atol=1e-9)


def test_height_error_matches_parallax_propagation(small):
    """MC std of the model Z error equals (H - Z)^2 / (f B) * sigma_p (std within sampling)."""
    b = small
    rng = np.random.default_rng(3)
    k = 0
    xl = b.image_coords(b.obs_left[[k]], b.obs_point[[k]])[0]
    xr = b.image_coords(b.obs_right[[k]], b.obs_point[[k]])[0]
    N, sp = 20000, 0.02  # mm of x-parallax
    d = rng.normal(0, sp, N)
    Z = im.form_models(
        np.column_stack([xl[0] + d, np.full(N, xl[1])]),
        np.broadcast_to(xr, (N, 2)),
        b.focal_mm,
        b.base_m,
    )[:, 2]
    hz = b.H_m - b.points[b.obs_point[k], 2]
    expect = hz**2 / (b.focal_mm * b.base_m) * sp
    assert abs(Z.std(ddof=1) / expect - 1) < 4 / math.sqrt(2 * (N - 1))


# ----------------------------------------------------------------------------- scanner


def test_scanner_field_peaks_and_calibration():
    rng = np.random.default_rng(1)
    f = sc.random_field(rng, 20, max_x_um=20.0, max_y_um=40.0, n_eval=47)
    g = np.linspace(-115, 115, 47)
    d = sc.evaluate(f, np.stack(np.meshgrid(g, g), -1).reshape(-1, 2))
    assert np.allclose(np.abs(d[..., 0]).max(1), 20.0) and np.allclose(
        np.abs(d[..., 1]).max(1), 40.0
    )
    nodes, disp = sc.scan_grid(f, rng, 5.0, 0.0)
    xy = rng.uniform(-115, 115, (500, 2))
    r = sc.evaluate(f, xy) - sc.interpolate(nodes, disp, xy)
    # a noise-free 5 mm grid removes the smooth field to a few per cent
    assert np.sqrt((r**2).mean()) < 0.03 * np.sqrt((sc.evaluate(f, xy) ** 2).mean())
    # nodes are reproduced exactly
    nn = np.stack(np.meshgrid(nodes, nodes), -1).reshape(-1, 2)
    assert np.allclose(sc.interpolate(nodes, disp, nn), disp.reshape(20, -1, 2))


def test_fiducial_affine_removes_affine_errors():
    fid = sc.corner_fiducials(110.0)
    A = np.array([[3.0, 2e-3, -1e-3], [-2.0, 5e-4, 4e-3]])  # um, um/mm
    xy = np.random.default_rng(0).uniform(-110, 110, (30, 2))
    lin = lambda p: np.column_stack([np.ones(len(p)), p]) @ A.T  # noqa: E731
    beta = sc.fiducial_affine(lin(fid)[None], fid)[0]
    fitted = np.column_stack([np.ones(30), xy]) @ beta
    assert np.allclose(fitted, lin(xy), atol=1e-12)


# ----------------------------------------------------------------------------- adjustment


def test_noise_free_gives_zero_residuals_and_true_parameters(small):
    rng = np.random.default_rng(7)
    T = 3
    xm, (s, R, t) = im.noisy_models(small, rng, T)
    ctrl = select_control(small, "five")
    st = im.BlockStructure(small.obs_model, small.obs_point, ctrl, small.n_models, small.n_points)
    s0, R0, t0, X0 = _start(small, st, xm, rng, T)
    res = im.adjust_block(
        st,
        xm,
        np.ones(3),
        np.broadcast_to(small.points[ctrl], (T, 5, 3)),
        np.full((5, 3), 10.0),
        s0,
        R0,
        t0,
        X0,
        tol_m=1e-9,
    )
    assert res.converged.all()
    assert np.abs(res.v_obs).max() < 1e-7 and np.abs(res.v_ctrl).max() < 1e-7
    assert np.allclose(res.X, small.points, atol=1e-7)
    assert np.allclose(res.s, s, rtol=1e-10) and np.allclose(res.R, R, atol=1e-10)
    assert np.allclose(res.t, t, atol=1e-6)


def test_all_control_reproduces_each_model_similarity(small):
    """With every point a (near-fixed) control point the block splits into one independent
    7-parameter fit per model: the closed-form (Horn/Umeyama) similarity."""
    rng = np.random.default_rng(11)
    T = 2
    xm, _ = im.noisy_models(small, rng, T, 0.3)
    ctrl = np.arange(small.n_points)
    ctrl_xyz = small.points + rng.normal(0, 0.1, (T,) + small.points.shape)
    st = im.BlockStructure(small.obs_model, small.obs_point, ctrl, small.n_models, small.n_points)
    s0, R0, t0, X0 = _start(small, st, xm, rng, T)
    res = im.adjust_block(
        st, xm, np.ones(3), ctrl_xyz, np.full((ctrl.size, 3), 1e9), s0, R0, t0, X0, tol_m=1e-10
    )
    for m in range(small.n_models):
        k = small.obs_model == m
        f = similarity_fit(xm[:, k], ctrl_xyz[:, small.obs_point[k]])
        s, R, t = f.scale, f.R, f.t
        assert np.allclose(res.s[:, m], s, rtol=1e-6)
        assert np.allclose(res.R[:, m], R, atol=1e-6)
        assert np.allclose(res.t[:, m], t, atol=1e-3)


def test_reduced_normals_equal_dense_solve(small):
    rng = np.random.default_rng(5)
    T = 2
    xm, _ = im.noisy_models(small, rng, T, 0.2)
    ctrl = select_control(small, "full")
    st = im.BlockStructure(small.obs_model, small.obs_point, ctrl, small.n_models, small.n_points)
    s0, R0, t0, X0 = _start(small, st, xm, rng, T)
    K = small.obs_model.size
    w = rng.uniform(0.5, 2.0, (T, K, 3))
    wc = np.broadcast_to([30.0, 30.0, 20.0], (ctrl.size, 3))
    cx = np.broadcast_to(small.points[ctrl], (T, ctrl.size, 3))
    c = np.zeros((T, small.n_models, 3))
    args = (st, xm, c, s0, R0, t0, X0, w, cx, np.broadcast_to(wc, (T,) + wc.shape))
    dg, dX = im.normal_step(*args)
    dg2, dX2 = im.normal_step(*args, dense=True)
    assert np.allclose(dg, dg2, rtol=1e-7, atol=1e-9 * np.abs(dg2).max())
    assert np.allclose(dX, dX2, rtol=1e-7, atol=1e-9 * np.abs(dX2).max())


def test_residual_cofactors_equal_dense(small):
    rng = np.random.default_rng(9)
    T = 2
    xm, _ = im.noisy_models(small, rng, T, 0.1)
    ctrl = select_control(small, "full")
    P, M, K, C = small.n_points, small.n_models, small.obs_model.size, ctrl.size
    st = im.BlockStructure(small.obs_model, small.obs_point, ctrl, M, P)
    s0, R0, t0, X0 = _start(small, st, xm, rng, T)
    w = rng.uniform(0.5, 2.0, (T, K, 3))
    wc = np.full((C, 3), 25.0)
    res = im.adjust_block(
        st,
        xm,
        w,
        np.broadcast_to(small.points[ctrl], (T, C, 3)),
        wc,
        s0,
        R0,
        t0,
        X0,
        keep_normals=True,
    )
    q = ds.residual_cofactors(st, res, w)
    J = res.J
    A = np.zeros((T, 3 * K + 3 * C, 7 * M + 3 * P))
    for k in range(K):
        A[:, 3 * k : 3 * k + 3, 7 * st.obs_model[k] : 7 * st.obs_model[k] + 7] = J[:, k]
        A[:, 3 * k : 3 * k + 3, 7 * M + 3 * st.obs_point[k] + np.arange(3)] = -np.eye(3)
    for i, j in enumerate(ctrl):
        A[:, 3 * K + 3 * i : 3 * K + 3 * i + 3, 7 * M + 3 * j + np.arange(3)] = np.eye(3)
    W = np.concatenate([w.reshape(T, -1), np.broadcast_to(wc, (T, C, 3)).reshape(T, -1)], 1)
    Qx = np.linalg.inv(np.einsum("toi,to,toj->tij", A, W, A))
    Qv = 1 / W - np.einsum("toi,tij,toj->to", A, Qx, A)
    assert np.allclose(q, Qv[:, : 3 * K].reshape(T, K, 3), atol=1e-9)


def test_chol_solve_matches_numpy():
    rng = np.random.default_rng(2)
    a = rng.normal(size=(4, 30, 30))
    N = a @ a.transpose(0, 2, 1) + 30 * np.eye(30)
    b = rng.normal(size=(4, 30, 2))
    assert np.allclose(im.chol_solve(N, b), np.linalg.solve(N, b))


def test_similarity_fit_recovers_transform():
    rng = np.random.default_rng(4)
    src = rng.normal(0, 100, (3, 12, 3))
    s, R, t = im.random_similarities(rng, (3,))
    dst = s[:, None, None] * np.einsum("tij,tnj->tni", R, src) + t[:, None]
    f = similarity_fit(src, dst)
    s2, R2, t2 = f.scale, f.R, f.t
    assert np.allclose(s2, s) and np.allclose(R2, R) and np.allclose(t2, t)


# ----------------------------------------------------------------------------- pugging, snooping


def test_digital_pugging_shares_image_coordinates(small):
    b = small
    rng = np.random.default_rng(6)
    F = b.models + 1
    el, er, _ = im.pointing_errors(
        rng,
        4,
        b.obs_left,
        b.obs_right,
        b.obs_point,
        F,
        b.strips,
        b.n_points,
        mark_um=21.0,
        parallax_um=21.0,
        digital=b.is_pass,
    )
    ml, mr, _ = im.pointing_errors(
        rng,
        4,
        b.obs_left,
        b.obs_right,
        b.obs_point,
        F,
        b.strips,
        b.n_points,
        mark_um=21.0,
        parallax_um=21.0,
        mechanical=b.is_pass,
        transfer_um=10.0,
        recentre_um=21.0,
    )
    # a pass point on the photo that is the right of model m and the left of model m + 1
    found = 0
    for k1 in np.flatnonzero(b.is_pass[b.obs_point]):
        k2 = np.flatnonzero((b.obs_point == b.obs_point[k1]) & (b.obs_left == b.obs_right[k1]))
        for k in k2:
            found += 1
            assert np.array_equal(er[:, k1], el[:, k])  # digital: the very same pixel
            assert not np.allclose(mr[:, k1], ml[:, k])  # mechanical: re-centred
    assert found > 0


def test_parallax_error_statistics(small):
    """Signalised points: x-parallax error std = parallax_um (within the sampling error)."""
    b = small
    rng = np.random.default_rng(8)
    el, er, _ = im.pointing_errors(
        rng,
        400,
        b.obs_left,
        b.obs_right,
        b.obs_point,
        b.models + 1,
        b.strips,
        b.n_points,
        mark_um=21.0,
        parallax_um=15.0,
    )
    p = (el[..., 0] - er[..., 0]).ravel()
    assert abs(p.std(ddof=1) / 15.0 - 1) < 4 / math.sqrt(2 * (p.size - 1))


def test_snooping_finds_a_planted_blunder(small):
    b = small
    rng = np.random.default_rng(12)
    T = 4
    sxy, sz = 0.13, 0.22
    xl = b.image_coords(b.obs_left, b.obs_point)
    xr = b.image_coords(b.obs_right, b.obs_point)
    G = im.form_models(xl, xr, b.focal_mm, b.base_m) + b.photos.reshape(-1, 3)[b.obs_left]
    G = G + rng.normal(0, 1, (T,) + G.shape) * [sxy, sxy, sz]
    k_bad = int(
        np.flatnonzero(b.is_pass[b.obs_point] & (np.bincount(b.obs_point)[b.obs_point] >= 3))[0]
    )
    G[:, k_bad, 2] += 20 * sz  # a 20-sigma height blunder
    s, R, t = im.random_similarities(rng, (T, b.n_models))
    xm = im.to_model_frame(G, b.obs_model, s, R, t)
    ctrl = select_control(b, "full")
    st = im.BlockStructure(b.obs_model, b.obs_point, ctrl, b.n_models, b.n_points)
    s0, R0, t0, X0 = _start(b, st, xm, rng, T)
    w = np.array([1 / sxy**2, 1 / sxy**2, 1 / sz**2])
    rej, _, wmax, rounds = ds.snoop(
        st,
        xm,
        w,
        np.broadcast_to(b.points[ctrl], (T, ctrl.size, 3)),
        np.full((ctrl.size, 3), 1e4),
        s0,
        R0,
        t0,
        X0,
        b.is_pass,
        crit=3.29,
        max_reject=10,
    )
    assert rej[:, b.obs_point[k_bad]].all() and (rounds >= 1).all()
    assert (wmax <= 3.29).all()


# ----------------------------------------------------------------------------- study


def test_bad_config_names_the_key():
    with pytest.raises(ConfigError, match="pugging.gross_px"):
        load_study(STUDY, ["pugging.gross_px=[5.0, 1.0]"])
    with pytest.raises(ConfigError, match="tradeoff.block_models"):
        load_study(STUDY, ["tradeoff.block_models=[8]"])
    with pytest.raises(ConfigError, match="block.base_mm"):
        load_study(STUDY, ["block.base_mm=120.0"])
    with pytest.raises(ConfigError, match="control.few"):
        load_study(STUDY, ["control.few=everywhere"])
    with pytest.raises(ConfigError, match="block.ground_points"):
        load_study(STUDY, ["block.ground_points=12"])
    with pytest.raises(ConfigError, match="region.points"):
        load_study(STUDY, ["region.points=1"])
    with pytest.raises(ConfigError, match="table1.points"):
        load_study(STUDY, ["table1.points=1"])
    with pytest.raises(ConfigError, match="chunk"):
        load_study(STUDY, ["chunk=1000000"])


def _tiny_overrides():
    from pathlib import Path

    lines = (Path(__file__).parent / "data" / "tiny" / "agnard_block.txt").read_text().split()
    return [ln for ln in lines if not ln.startswith("trials=")]


@pytest.fixture(scope="module")
def tiny_run(tiny_run):
    """The session's shared tiny run of agnard_block (conftest.py: its tables are read here,
    its figures were checked as they were drawn), with the study and its config."""
    from sim.mc.storage import read_provenance

    study, cfg = load_study(STUDY, _tiny_overrides(), trials=4)
    out = tiny_run("agnard_block")
    assert read_provenance(out / "claims.parquet")["config"] == json.loads(json.dumps(cfg))
    return study, cfg, out


def test_tiny_run_writes_claims_and_report(tiny_run):
    from sim.claims.book import KINDS
    from sim.mc.storage import read_table
    from sim.studies.agnard.claims import load_book

    study, cfg, out = tiny_run
    rows = read_table(out / "claims.parquet").to_pylist()
    names = [r["claim"] for r in rows]
    # each claim scored once; a resolution not in tradeoff.dpis has no gain row (doors24d)
    absent = {
        f"agnard.scanner.gain_{d}dpi_pct" for d in (300, 600) if d not in cfg["tradeoff.dpis"]
    }
    assert absent and not absent & set(names)
    assert len(names) == len(set(names)) == len(load_book().specs) - len(absent)
    assert all(r["kind"] in KINDS for r in rows)
    nr = read_table(out / "not_reproduced.parquet").to_pylist()
    assert nr and all(r["why"] for r in nr)
    text = study.report(out)
    assert f"{out.name}/block_layout.png" in text and "w-test" in text
    assert f"{out.name}/consistent_region.png" in text and "Consistent region" in text
    for f in (
        "scanner_field.png",
        "block_layout.png",
        "check_residuals.png",
        "tradeoffs.png",
        "consistent_region.png",
        "trials.parquet",
        "consistent_region.parquet",
        "scanner_region.png",
        "scanner_region.parquet",
    ):
        assert (out / f).is_file()


def test_five_control_rows_decided_over_the_region(tiny_run):
    """The lost five-point layout is explored over its possible insets; every 5-control row
    is decided over them (no printed statement constrains the layout: every inset stays)."""
    from sim.mc.storage import read_table

    _, cfg, out = tiny_run
    reg = read_table(out / "consistent_region.parquet").to_pydict()
    n = cfg["region.points"]  # each layout without and with the projection centres
    assert len(reg["five_inset_1"]) == 2 * n
    assert all(0.0 <= u <= 0.45 for u in reg["five_inset_1"])
    assert reg["centres_1"] == [0.0] * n + [1.0] * n
    assert reg["five_inset_1"][:n] == reg["five_inset_1"][n:]
    rows = {r["claim"]: r for r in read_table(out / "claims.parquet").to_pylist()}
    for c in ("ctrl", "check"):
        r = rows[f"agnard.control_5.{c}_x_cm"]
        assert r["interval"] == "region"
        assert r["verdict"] in REGION_VERDICTS
        assert r["value"] <= r["value_high"]
    # 8 rows of region.toml and the joint X, Y row over the joint (layout, scanner) points
    # with the projection centres, the check-Z finding over those without, each with its
    # per-point column; of scanner.toml over the scanner's vectors the same 9,
    # the first pass's two and the digital rejections
    assert _check_region_rows(out) == (10, 12)
    joint = read_table(out / "joint_region.parquet").to_pydict()
    assert len(joint["five_inset_1"]) == 2 * cfg["table1.points"]  # each vector at 2 layouts
    assert set(joint["centres_1"]) == {0.0, 1.0} and set(SCANNER_KEYS) <= set(joint)
    assert (
        "of the lost layout and the scanner's inputs" in rows["agnard.control_5.check_z_cm"]["note"]
    )


def test_five_control_predictions_over_the_papers_program_the_rest_a_finding(tiny_run):
    """The paper names its program (SPACE-M), which carries the models' projection centres:
    every 5-control prediction is decided over the joint points with them only (its note says
    how many: half the joint points), and check Z without them is a finding row decided over
    the other half, counted apart from the predictions."""
    from sim.mc.storage import read_table
    from sim.studies.agnard.claims import WITHOUT_CENTRES
    from sim.studies.agnard.leads import _five

    _, cfg, out = tiny_run
    rows = {r["claim"]: r for r in read_table(out / "claims.parquet").to_pylist()}
    joint = read_table(out / "joint_region.parquet").to_pydict()
    half = int(np.sum(np.asarray(joint["centres_1"]) > 0.5))
    assert 2 * half == len(joint["centres_1"]) == 2 * cfg["table1.points"]
    for cid in (*region_predictions(), "agnard.control_5.check_xy_holm"):
        assert rows[cid]["interval"] == "region"  # max_residual.control_5_*: findings
        note = rows[cid]["note"]
        assert f"the {half} joint points of the lost layout" in note
        assert "inputs with the projection centres (the paper's program SPACE-M" in note
    assert WITHOUT_CENTRES == {
        "agnard.control_5.check_z_cm": "agnard.finding.control_5_check_z_without_centres_cm"
    }
    f = rows["agnard.finding.control_5_check_z_without_centres_cm"]
    assert f["kind"] == "finding" and f["interval"] == "region"
    assert f["verdict"] == "finding"
    assert f"the {half} joint points of the lost layout" in f["note"]
    assert "inputs without the projection centres (" in f["note"]
    assert joint[f["claim"]] == joint["agnard.control_5.check_z_cm"]  # the same evidence
    assert _five(f["claim"])  # reported with the 5-control rows, not the scanner's


def region_predictions() -> list[str]:
    """The 5-control predictions of region.toml."""
    from sim.claims.book_region import load_declaration
    from sim.studies.agnard.claims import load_book
    from sim.studies.agnard.region import DECLARATION

    return list(load_declaration(DECLARATION, load_book()).predictions)


def _check_region_rows(out) -> tuple[int, int]:
    """Every row decided over a region has the verdict its per-point outcomes give: the
    5-control rows' in joint_region.parquet (the layout and the scanner together), the
    others' in scanner_region.parquet (every explored vector: Table 1, which empties it, is
    set aside); the two counts."""
    from sim.mc.storage import read_table

    joint = read_table(out / "joint_region.parquet").to_pydict()
    scan = read_table(out / "scanner_region.parquet").to_pydict()
    claims = read_table(out / "claims.parquet").to_pylist()
    n = [0, 0]
    centres = np.asarray(joint["centres_1"]) > 0.5
    for c in (c for c in claims if c["interval"] == "region"):
        in_scan = c["claim"] not in joint
        table = scan if in_scan else joint
        assert c["claim"] in table, c["claim"]
        col = table[c["claim"]]
        if not in_scan:  # a prediction over the points with centres, a finding without
            col = [o for o, w in zip(col, centres) if w == (c["kind"] != "finding")]
        assert c["outcome"] == region_verdict(col), c["claim"]
        n[in_scan] += 1
    return n[0], n[1]


def test_joint_xy_rows_and_xy_paper_checks(tiny_run):
    """The XY columns are paper-checks (exact, not simulated); each check-point block's
    headline is the Holm test of its X and Y rows (the 21-control one from the two rows'
    p, the 5-control one over the layout region); the 5-control check Z is decided over the
    layouts with and without projection centres; the Y/X ratio is a finding."""
    from sim.mc.storage import read_table
    from sim.studies.agnard.claims import JOINT, MEMBERS

    study, _, out = tiny_run
    rows = {r["claim"]: r for r in read_table(out / "claims.parquet").to_pylist()}
    for b in ("control_5", "control_21"):
        for w in ("ctrl", "check"):
            r = rows[f"agnard.{b}.{w}_xy_cm"]
            assert r["kind"] == "paper-check" and r["interval"] == "exact"
            assert r["verdict"] == "holds" and not r["headline"]
    j21 = rows[JOINT["control_21"]]  # over the scanner's vectors, from its members' p
    assert j21["headline"] and j21["interval"] == "region" and j21["verdict"] in REGION_VERDICTS
    shift = read_table(out / "scanner_shift.parquet").to_pydict()
    for m in MEMBERS[JOINT["control_21"]]:
        assert rows[m]["interval"] == "region" and "common random numbers" in rows[m]["note"]
        assert m in shift["claim"]
    j5 = rows[JOINT["control_5"]]
    assert j5["headline"] and j5["interval"] == "region" and j5["verdict"] in REGION_VERDICTS
    z = rows["agnard.control_5.check_z_cm"]
    assert z["kind"] == "prediction" and z["headline"] and z["interval"] == "region"
    assert rows["agnard.anisotropy.y_over_x"]["verdict"] == "finding"
    text = study.report(out)
    assert text.index("**Consistent region.**") < text.index("Verdicts over the region:")
    five = text[text.index("Verdicts over the region:") : text.index("**Scanner region")]
    assert "agnard.control_5.check_z_cm" in five and "agnard.control_21." not in five
    scanner = text[text.index("**Predictions over the scanner's inputs**") :]
    assert "`agnard.control_21.check_z_cm`" in scanner and "common random numbers" in scanner
    assert f"`{JOINT['control_5']}` (headline)" in text
    assert "check X and Y as one Holm test" in text


def test_digital_rejections_decided_over_the_scanner(tiny_run):
    """'Not a single pass point had to be removed' is decided over the scanner's vectors by
    the count's own estimator (not the log shift): one row per vector in
    scanner_rejections.parquet, its outcome column the row's per-vector outcomes, the
    share of blocks losing none a probability inside its interval, and the note says how."""
    from sim.mc.storage import read_table

    study, cfg, out = tiny_run
    rows = {r["claim"]: r for r in read_table(out / "claims.parquet").to_pylist()}
    r = rows[REJECTED]
    assert r["interval"] == "region" and r["verdict"] in REGION_VERDICTS
    assert "control variate" in r["note"] and "share of blocks that lose none" in r["note"]
    t = read_table(out / "scanner_rejections.parquet").to_pydict()
    assert len(t["share_zero"]) == cfg["table1.points"]
    assert t["outcome"] == read_table(out / "scanner_region.parquet").to_pydict()[REJECTED]
    for lo, z, hi in zip(t["share_zero_low"], t["share_zero"], t["share_zero_high"]):
        assert 0.0 <= lo <= z <= hi <= 1.0
    assert REJECTED not in read_table(out / "scanner_shift.parquet").to_pydict()["claim"]
    assert "pass points per block over the scanner's" in study.report(out)
    assert "names 82 pass points" in r["note"] and "82 is not buildable" in r["note"]


def test_the_papers_82_pass_points_are_not_a_whole_row_pattern():
    """The paper's first pass names 82 pass points; on its 2 x 8 block the regular pattern
    (whole rows per strip) gives 62, 76 (the study's 4 rows) or 90, as the digital
    rejections' note says: 82 is none of them."""
    counts = [int(make_block(2, 8, pass_rows=r).is_pass.sum()) for r in (3, 4, 5)]
    assert counts == [62, 76, 90] and 82 not in counts


def test_table1_rows_are_not_comparable_because_the_scanner_region_is_empty(tiny_run):
    """The scanner's unprinted inputs (scanner.toml) explored under Table 1: no vector
    reproduces its 'without' rms (the printed +-40 um peak is 0.25 m on the ground), so the
    region is empty, the conflicting statements are named, and every Table 1 row (with,
    without, ratio) is 'not comparable' because of that, none an erratum."""
    from sim.mc.storage import read_table

    _, cfg, out = tiny_run
    reg = read_table(out / "scanner_region.parquet").to_pydict()
    assert len(reg["accepted"]) == cfg["table1.points"] and not any(reg["accepted"])
    for w in ("ctrl", "check"):
        for c in ("x", "y"):
            cid = f"agnard.table1.without_{w}_{c}_m"
            assert set(reg[cid]) == {"fails"}, cid
            assert max(reg[f"{cid}__value"]) < 0.5  # far below Table 1's 0.99-1.53 m
    inp = read_table(out / "scanner_region_inputs.parquet").to_pydict()
    assert inp["input"] == list(SCANNER_KEYS) and inp["n_region"] == [0] * len(SCANNER_KEYS)
    rows = {r["claim"]: r for r in read_table(out / "claims.parquet").to_pylist()}
    t1 = [k for k in rows if k.startswith("agnard.table1.")]
    assert len(t1) == 12
    for k in t1:
        assert rows[k]["verdict"] == "not comparable", k
        assert "empty, no vector reproduces Table 1 (conflicting: " in rows[k]["note"], k
        assert "without_ctrl_y_m" in rows[k]["note"], k


def test_scanner_inputs_set_the_config_keys_they_name():
    """Every input of scanner.toml sets an existing scan.* key, inside the key's own bounds."""
    from sim.claims.book_region import load_declaration
    from sim.studies.agnard.claims import load_book
    from sim.studies.agnard.region import SCANNER
    from sim.studies.agnard.schema import SCHEMA

    book = load_book()
    dec = load_declaration(SCANNER, book)
    assert [i.name for i in dec.inputs] == list(SCANNER_KEYS)
    for i in dec.inputs:
        f = SCHEMA[SCANNER_KEYS[i.name]]
        assert f.lo <= i.low < i.high <= f.hi, i.name
    assert {s.id for s in dec.statements} == {
        f"agnard.table1.{t}_{w}_{c}_m"
        for t in ("with", "without")
        for w in ("ctrl", "check")
        for c in ("x", "y")
    }
    assert all(book.spec(s.id)["kind"] == "not comparable" for s in dec.statements)
    assert all(i.why for i in dec.inputs)
    # every simulated 21-control prediction (not the XY paper-checks, not the Holm row, which
    # is decided from its members): Tables 2-3's and the acceptance limits'; and the first
    # pass's two rows (the same blocks with weak control); and the digital rejections (a count)
    assert set(dec.predictions) == {
        c
        for c, spec in book.specs.items()
        if c.startswith(("agnard.control_21.", "agnard.max_residual.control_21_"))
        and spec["kind"] == "prediction"
        and spec["form"] in ("one-plate", "upper")
    } | {"agnard.first_pass.pass_xy_cm", "agnard.first_pass.pass_z_cm", REJECTED}
    assert len(dec.predictions) == 11


def test_budget_recomputation_and_pointing_model():
    from sim.studies.agnard.schema import model_sigmas

    _, cfg = load_study(STUDY)
    pix_cm = 25.4e-3 / cfg["scan.dpi"] * cfg["block.scale"] * 100
    sxy, sz = model_sigmas(cfg)
    assert math.isclose(100 * sxy, pix_cm * math.hypot(0.5, 0.25))  # 14.7 cm
    assert math.isclose(100 * sz, 0.5 * pix_cm * 152 / 90)  # 22.2 cm


def test_chunk_functions_pickle():
    import pickle
    from functools import partial

    from sim.studies.agnard import chunks as ch
    from sim.studies.agnard.schema import block_of

    _, cfg = load_study(STUDY)
    b = block_of(cfg)
    for fn in (
        partial(ch.main_chunk, cfg, b),
        partial(ch.sweep_chunk, cfg, b, (0.0, 0.17)),
        partial(ch.pugging_chunk, cfg, b, 0.5),
        partial(ch.scanner_chunk, cfg, b, 300.0),
        partial(ch.table1_chunk, cfg, b, ({"scan.stepper_share": 0.5},)),
    ):
        assert pickle.loads(pickle.dumps(fn)).func is fn.func


def test_table1_chunk_pairs_the_first_pass_with_the_configured_scanner():
    """The scanner region's first pass (brief P): at a vector equal to the configured scanner
    the same blocks give the configured first pass (common random numbers; the vector's
    21-control pass is reached through Table 1's passes, so to the solver's tolerance)."""
    from sim.studies.agnard import chunks as ch
    from sim.studies.agnard.region import first_samples
    from sim.studies.agnard.schema import block_of

    _, cfg = load_study(STUDY)
    out = ch.table1_chunk(cfg, block_of(cfg), ({},), np.random.default_rng(5), 2)
    v, c = first_samples(out, "s0"), first_samples(out, "cfg")
    assert sorted(v) == ["agnard.first_pass.pass_xy_cm", "agnard.first_pass.pass_z_cm"]
    for cid in v:
        assert v[cid].shape == (2,) and np.all(v[cid] > 1.0)  # cm: a tenth of a pixel or more
        assert np.allclose(v[cid], c[cid], rtol=1e-6), cid


def test_sparse_and_dense_reduced_solutions_agree(small):
    rng = np.random.default_rng(13)
    T = 2
    xm, _ = im.noisy_models(small, rng, T, 0.2)
    ctrl = select_control(small, "perimeter")
    st = im.BlockStructure(small.obs_model, small.obs_point, ctrl, small.n_models, small.n_points)
    s0, R0, t0, X0 = _start(small, st, xm, rng, T)
    cx = np.broadcast_to(small.points[ctrl], (T, ctrl.size, 3))
    wc = np.full((ctrl.size, 3), 30.0)
    a = im.adjust_block(st, xm, np.ones(3), cx, wc, s0, R0, t0, X0, solver="dense")
    b = im.adjust_block(st, xm, np.ones(3), cx, wc, s0, R0, t0, X0, solver="sparse")
    assert np.allclose(a.X, b.X, atol=1e-8) and np.allclose(a.s, b.s, rtol=1e-12)


def test_monte_carlo_point_errors_match_adjustment_covariance(small):
    """Model coordinates with Gaussian errors of known sigma, weights 1/sigma^2: the MC std of
    the adjusted ground coordinates equals sqrt of the point cofactors (within sampling)."""
    b = small
    rng = np.random.default_rng(21)
    T = 600
    sig = np.array([0.13, 0.13, 0.22])
    xm, (s, R, t) = im.noisy_models(b, rng, T, sig)
    ctrl = select_control(b, "full")
    st = im.BlockStructure(b.obs_model, b.obs_point, ctrl, b.n_models, b.n_points)
    sc_ = 0.05
    cx = b.points[ctrl] + rng.normal(0, sc_, (T, ctrl.size, 3))
    X0 = np.broadcast_to(b.points, (T,) + b.points.shape)
    res = im.adjust_block(
        st, xm, 1 / sig**2, cx, np.full((ctrl.size, 3), 1 / sc_**2), s, R, t, X0, keep_normals=True
    )
    q = im.point_cofactors(st, res)
    err = (res.X - b.points)[:, ~np.isin(np.arange(b.n_points), ctrl)]
    expect = np.sqrt(q[0])[~np.isin(np.arange(b.n_points), ctrl)]
    ratio = np.sqrt((err**2).mean(0)) / expect  # true errors: mean is zero
    tol = 4 / math.sqrt(2 * T)
    # every coordinate within 4 standard errors of the std; the mean ratio within the bound
    # that holds even for fully correlated coordinates
    assert np.all(np.abs(ratio - 1) < tol)
    assert abs(ratio.mean() - 1) < tol


def test_input_rows_follow_the_config():
    """An input row reports the run's value (here changed by an override), never a typed one."""
    from sim.claims.table import claim_rows
    from sim.studies.agnard.claims import input_rows, load_book
    from sim.studies.agnard.schema import block_of

    _, cfg = load_study(STUDY, ["scan.max_y_um=30.0"])
    b = block_of(cfg)
    book = load_book()
    table = input_rows(book, cfg, b, select_control(b, "five"), select_control(b, "full"))
    rows = {r["claim"]: r for r in claim_rows(book, table)}
    assert rows["agnard.input.scan.max_y_um"]["value"] == 30.0
    assert rows["agnard.input.scan.max_y_um"]["verdict"] == "input"
    assert rows["agnard.scanner.pixel_um"]["verdict"] == "holds"  # 25.4 mm / 600


@pytest.mark.parametrize("scale, empty", [(1.0, False), (0.15, True)])
def test_table1_note_follows_the_region(scale, empty):
    """Blocks at Table 1's own values leave a region, and the notes say the book's reason
    (an empty region) fails for that run; blocks at 15 % of them empty it, every statement
    named as conflicting."""
    from sim.claims.book_region import load_declaration, sample_evidence
    from sim.claims.inference import explore
    from sim.studies.agnard.claims import load_book, table1_rows
    from sim.studies.agnard.region import SCANNER

    book = load_book()
    dec = load_declaration(SCANNER, book)
    rng = np.random.default_rng(3)
    stats: list[dict] = []

    def model(x):
        n = len(x["grid_mm"])
        per = [
            {s.id: scale * s.ref[0] * (1 + 0.02 * rng.standard_normal(40)) for s in dec.statements}
            for _ in range(n)
        ]
        stats.extend(per)
        return {
            s.id: sample_evidence(np.stack([p[s.id] for p in per]), s.ref[0])
            for s in dec.statements
        }

    region = explore(dec.inputs, dec.statements, model, rng, n=4, rounds=0)
    assert region.empty == empty
    rows = table1_rows(book, region, stats)
    assert len(rows) == 12 and all(r["verdict"] == "not comparable" for r in rows)
    for r in rows:
        if empty:
            assert "empty, no vector reproduces Table 1 (conflicting: " in r["note"]
        else:
            assert "does not hold in this run" in r["note"]
