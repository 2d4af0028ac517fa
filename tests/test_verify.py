"""`make verify` (issue 27): each column compared by the rule of the kind of number it holds; a
number or verdict edited by hand fails; bad requests are one line; and another machine inside
CI: every study kind re-run under another numerical path (another OpenBLAS kernel, the
compiled paths off, another worker count) agrees with a run on the usual path by the same
rules, and fast studies re-run with fewer trials agree with the committed results at the
Monte-Carlo level.

The runs on the usual path are the session's shared tiny runs (``tiny_run`` in conftest.py;
test_all_studies.py shows that they are reproduced bit for bit by other executors and by a
killed and resumed run)."""

import os
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pyarrow as pa
import pyarrow.parquet as pq
import pytest
from conftest import ELSEWHERE, long_params, tiny_overrides
from oneline import VERIFY_ERROR, one_line

import sim
from sim.batch import is_current
from sim.instruments import transforms2d as t2
from sim.instruments.ranges import positions as po
from sim.mc import tolerance as tl
from sim.mc.storage import write_table
from sim.report.verify import compare_dirs, markdown, verify, write_record
from sim.report.verify import main as verify_main
from sim.studies import MODULES
from sim.studies.design import external as ex
from sim.studies.design.cells import pareto_front

ROOT = Path(__file__).resolve().parent.parent
#: the study file that stands for a study kind with several example files
FILES = {"network": "network_testfield"}


@pytest.fixture(scope="module")
def two_runs(tmp_path_factory, tiny_run):
    """Two copies of brown_table1's tiny run, "committed" and "rerun" (that a re-run gives
    the same files bit for bit is test_all_studies.py's)."""
    d = tmp_path_factory.mktemp("verify")
    for name in ("committed", "rerun"):
        shutil.copytree(tiny_run("brown_table1"), d / name)
    return d


def _edit(path: Path, column: str, row: int, value) -> None:
    """Rewrite one cell of a Parquet file, keeping its metadata (a hand edit)."""
    t = pq.read_table(path)
    col = t.column(column).to_pylist()
    col[row] = value
    t = t.set_column(
        t.column_names.index(column), column, pa.array(col, t.schema.field(column).type)
    )
    pq.write_table(t, path)


def test_identical_rerun_passes_and_is_recorded(two_runs):
    c = compare_dirs(two_runs / "committed", two_runs / "rerun", "brown_table1")
    assert c.ok and c.files >= 3 and c.max_rel == 0.0
    write_record(two_runs, [c])
    text = markdown(two_runs)
    assert "## Reproducibility" in text and "brown_table1" in text


def test_a_number_edited_by_hand_fails(two_runs, tmp_path):
    edited = tmp_path / "edited"
    shutil.copytree(two_runs / "committed", edited)
    t = pq.read_table(edited / "points.parquet")
    v = t.column("sigma_x_um")[0].as_py()
    _edit(edited / "points.parquet", "sigma_x_um", 0, v * (1 + 1e-5))  # beyond rounding level
    c = compare_dirs(edited, two_runs / "rerun")
    assert not c.ok and any("sigma_x_um" in f for f in c.failures)
    _edit(edited / "points.parquet", "sigma_x_um", 0, v * (1 + 1e-12))  # rounding level: passes
    assert compare_dirs(edited, two_runs / "rerun").ok


def test_a_changed_verdict_fails_and_a_value_within_its_mc_error_passes(two_runs, tmp_path):
    edited = tmp_path / "edited"
    shutil.copytree(two_runs / "committed", edited)
    t = pq.read_table(edited / "claims.parquet").to_pydict()
    i = next(k for k, x in enumerate(t["verdict"]) if x in ("holds", "fails", "inconclusive"))
    _edit(
        edited / "claims.parquet", "verdict", i, "fails" if t["verdict"][i] != "fails" else "holds"
    )
    c = compare_dirs(edited, two_runs / "rerun")
    assert not c.ok and any("verdict" in f for f in c.failures)
    # a Monte-Carlo value: 5 % of its standard error passes, 50 % fails (the rule: 10 %)
    shutil.rmtree(edited)
    shutil.copytree(two_runs / "committed", edited)
    j = next(
        k
        for k, (lo, hi) in enumerate(zip(t["ci_low"], t["ci_high"]))
        if lo is not None and hi is not None and hi > lo
    )
    se = (t["ci_high"][j] - t["ci_low"][j]) / 3.92
    _edit(edited / "claims.parquet", "value", j, t["value"][j] + 0.05 * se)
    assert compare_dirs(edited, two_runs / "rerun").ok
    _edit(edited / "claims.parquet", "value", j, t["value"][j] + 0.5 * se)
    c = compare_dirs(edited, two_runs / "rerun")
    assert not c.ok and any("claims.parquet:value" in f and "mc" in f for f in c.failures)


def _pair(tmp_path, a: dict, b: dict, tol: dict):
    write_table(tmp_path / "a" / "t.parquet", a, {"study": "x"}, tol)
    write_table(tmp_path / "b" / "t.parquet", b, {"study": "x"}, tol)
    return compare_dirs(tmp_path / "a", tmp_path / "b")


def test_axial_and_undefined_values(tmp_path):
    tol = {"bearing_deg": tl.axial(180.0, null_reason="why")}
    why = ["", "a circle", ""]
    a = {"bearing_deg": [90.0, None, 30.0], "why": why}
    assert _pair(tmp_path, a, {"bearing_deg": [-90.0, None, 30.0], "why": why}, tol).ok
    assert _pair(tmp_path, a, {"bearing_deg": [89.9999999999, None, -150.0], "why": why}, tol).ok
    assert not _pair(tmp_path, a, {"bearing_deg": [90.0, None, 31.0], "why": why}, tol).ok
    c = _pair(tmp_path, a, {"bearing_deg": [90.0, 12.0, 30.0], "why": ["", "", ""]}, tol)
    assert not c.ok and "a circle" in c.failures[0]  # a null against a number: with its reason


def test_chain_and_arithmetic_bounds(tmp_path):
    tol = {"post": tl.chain(rtol=0.05), "solve": tl.arithmetic(cond=1e4, atol=0.0)}
    a = {"post": [1.0, 2.0], "solve": [3.0, 4.0]}
    assert _pair(tmp_path, a, {"post": [1.04, 2.0], "solve": [3.0, 4.0 * (1 + 1e-12)]}, tol).ok
    assert not _pair(tmp_path, a, {"post": [1.0, 2.0], "solve": [3.0, 4.0 * (1 + 1e-11)]}, tol).ok
    assert not _pair(tmp_path, a, {"post": [1.2, 2.0], "solve": [3.0, 4.0]}, tol).ok
    # undeclared: floats at the default 1e-7, booleans (decisions) exactly
    b = {"x": [1.0], "flag": [True]}
    assert _pair(tmp_path, b, {"x": [1.0 + 1e-9], "flag": [True]}, {}).ok
    assert not _pair(tmp_path, b, {"x": [1.0 + 1e-6], "flag": [True]}, {}).ok
    assert not _pair(tmp_path, b, {"x": [1.0], "flag": [False]}, {}).ok


def test_legacy_tolerances_in_the_provenance_are_read(tmp_path):
    a, b = tmp_path / "a", tmp_path / "b"
    prov = {"study": "x", "tolerances": {"t.parquet": {"chain_mean": 0.05}}}
    write_table(a / "t.parquet", {"chain_mean": [1.0, 2.0], "exact": [3.0, 4.0]}, prov)
    write_table(b / "t.parquet", {"chain_mean": [1.03, 2.0], "exact": [3.0, 4.0]}, prov)
    assert compare_dirs(a, b).ok
    write_table(b / "t.parquet", {"chain_mean": [1.0, 2.0], "exact": [3.0, 4.001]}, prov)
    assert not compare_dirs(a, b).ok


@pytest.mark.parametrize(
    "tol, match",
    [
        ({"nosuch": tl.arithmetic()}, "nosuch: no such column"),
        ({"x": {"kind": "fuzzy"}}, "kind must be one of"),
        ({"x": {"kind": "mc", "fraction": 0.1}}, "needs se or ci"),
        ({"x": tl.mc(se="x_se")}, "'x_se' is not in the table"),
        ({"x": tl.arithmetic(cond=-1.0)}, "cond must be a finite number"),
        ({"x": {"kind": "axial", "period": 180.0, "rtol": 1.0}}, "unknown key"),
        ({"x": tl.axial(null_reason="why")}, "row 1 is null and why empty"),
    ],
)
def test_a_bad_declaration_is_refused_naming_the_column(tmp_path, tol, match):
    with pytest.raises(ValueError, match=match):
        write_table(tmp_path / "t.parquet", {"x": [1.0, None], "why": ["", ""]}, {}, tol)
    assert not (tmp_path / "t.parquet").exists()


# --- the command line: one line for a bad request, nothing deleted that the suite did not write


def test_unknown_study_and_empty_results_are_one_line(capsys, tmp_path, two_runs):
    results = tmp_path / "results"
    shutil.copytree(two_runs / "committed", results / "brown_table1")
    assert "nosuch" in one_line(
        capsys, verify_main(["--results", str(results), "--study", "nosuch"]), prefix=VERIFY_ERROR
    )
    (tmp_path / "empty").mkdir()
    assert "no study results" in one_line(
        capsys, verify_main(["--results", str(tmp_path / "empty")]), prefix=VERIFY_ERROR
    )
    assert "--workers" in one_line(
        capsys, verify_main(["--results", str(results), "--workers", "0"]), prefix=VERIFY_ERROR
    )
    assert "error" in one_line(
        capsys, verify_main(["--results", str(results), "--bogus"]), prefix=VERIFY_ERROR
    )


def test_a_truncated_file_is_one_failure_line(capsys, tmp_path, two_runs):
    results, scratch = tmp_path / "results", tmp_path / "scratch"
    shutil.copytree(two_runs / "committed", results / "brown_table1")
    shutil.copytree(two_runs / "rerun", scratch / "brown_table1")
    p = results / "brown_table1" / "points.parquet"
    p.write_bytes(p.read_bytes()[: p.stat().st_size // 2])
    argv = ["--results", str(results), "--scratch", str(scratch), "--no-rerun", "--no-record"]
    assert verify_main(argv) == 1
    out = capsys.readouterr()
    assert "Traceback" not in out.out + out.err
    assert "points.parquet: the committed file cannot be read" in out.out


def test_scratch_keeps_what_the_suite_did_not_write(capsys, tmp_path, two_runs):
    results, scratch = tmp_path / "results", tmp_path / "scratch"
    shutil.copytree(two_runs / "committed", results / "brown_table1")
    mine = scratch / "brown_table1" / "notes.txt"  # the user's directory named like a study
    mine.parent.mkdir(parents=True)
    mine.write_text("mine")
    line = one_line(
        capsys,
        verify_main(["--results", str(results), "--scratch", str(scratch)]),
        prefix=VERIFY_ERROR,
    )
    assert "not a results directory of the suite" in line and mine.read_text() == "mine"
    before = sorted(p.name for p in (results / "brown_table1").iterdir())
    line = one_line(
        capsys,
        verify_main(["--results", str(results), "--scratch", str(results)]),
        prefix=VERIFY_ERROR,
    )
    assert "inside) the committed results" in line
    assert sorted(p.name for p in (results / "brown_table1").iterdir()) == before
    # an earlier re-run (its run.json) with the user's note in it: refused too, note kept
    shutil.copytree(two_runs / "rerun", scratch / "brown_table1", dirs_exist_ok=True)
    line = one_line(
        capsys,
        verify_main(["--results", str(results), "--scratch", str(scratch)]),
        prefix=VERIFY_ERROR,
    )
    assert "'notes.txt', which the suite did not write" in line and mine.read_text() == "mine"
    # without it, the earlier re-run is replaced (the same tiny run: every column compared)
    mine.unlink()
    tiny = tiny_overrides("brown_table1")
    assert tiny[:4] == ["--set", "trials=40", "--set", "chunk=2"]
    argv = ["--results", str(results), "--scratch", str(scratch), "--trials", "40", *tiny[2:]]
    assert "--trials: must be at least 400" in one_line(
        capsys, verify_main(argv), prefix=VERIFY_ERROR
    )  # too few
    argv[argv.index("40")] = "400"
    argv[argv.index("chunk=2")] = "chunk=20"  # a key given twice by --set is refused
    assert verify_main([*argv, "--study", "brown_table1"]) == 0
    assert "brown_table1: ok" in capsys.readouterr().out


# --- another machine inside CI ----------------------------------------------------------------


def _run(study: str, out: Path, workers: int, env: dict, *extra: str) -> None:
    cmd = [sys.executable, "-m", "sim", "run", str(ROOT / "studies" / f"{study}.toml")]
    cmd += ["--out", str(out), "--quiet", "--workers", str(workers), *extra]
    r = subprocess.run(
        cmd, cwd=ROOT, env={**os.environ, **env}, capture_output=True, text=True, timeout=600
    )
    assert r.returncode == 0, r.stderr


# test_all_studies: forward; the four slowest kinds (7-17 s of CPU) in make fuzz
@pytest.mark.parametrize(
    "kind",
    long_params(
        sorted(MODULES, reverse=True),
        {"agnard_block", "brown_design", "gridplate_two_plates", "salsig_encoders"},
    ),
)
def test_another_numerical_path_agrees_by_the_same_rules(kind, tiny_run):
    """Every study kind at its tiny size: the shared 1-worker run on the usual path against
    the shared run on 2 workers with OpenBLAS's Sandybridge kernels and the compiled paths
    off (``SIM_NO_JIT=1``: every compiled kernel's NumPy twin; issue 22's whole-study check
    of the compiled paths); every column by its rule, every verdict equal."""
    if any(k in os.environ for k in ELSEWHERE):
        pytest.skip("the environment already sets OPENBLAS_CORETYPE or SIM_NO_JIT")
    study = FILES.get(kind, kind)
    usual, other = tiny_run(study), tiny_run(study, elsewhere=True)
    c = compare_dirs(usual, other, study)
    assert c.files >= 2 and c.ok, c.failures
    # the run elsewhere drew no figures (--no-figures): the same tables without them
    assert list(usual.glob("*.png")) and not list(other.rglob("*.png"))


#: the committed results (SIM_VERIFY_RESULTS: another results directory, e.g. a fresh make rerun)
RESULTS = Path(os.environ.get("SIM_VERIFY_RESULTS", ROOT / "results"))
#: fast studies re-run with fewer trials against the committed results: (study, sim run args)
REDUCED = {
    "brown_table1": ["--trials", "400"],
    "network_brown": ["--trials", "400"],
    "gridplate_two_plates": ["--trials", "400", "--set", "chunk=100"],
}


@pytest.mark.parametrize("study", sorted(REDUCED))
def test_fewer_trials_elsewhere_agree_with_the_committed_results(study, tmp_path):
    """The committed results against a re-run with fewer trials on another numerical path, at
    the Monte-Carlo level (``--trials``): the claim book's columns and the analytic columns by
    their rules, Monte-Carlo values within 4 combined standard errors; skipped while the
    committed results are not current (``make reproduce`` re-runs them)."""
    committed = RESULTS / study
    if not is_current(ROOT / "studies" / f"{study}.toml", committed):
        pytest.skip(f"the committed results of {study} are not current: make reproduce")
    scratch = tmp_path / "scratch"
    _run(study, scratch / study, 2, ELSEWHERE, "--no-figures", *REDUCED[study])
    results = tmp_path / "results"
    results.mkdir()
    (results / study).symlink_to(committed)
    (c,) = verify(results, scratch, rerun=False, mode="mc")  # the rules of fewer trials
    assert c.ok, c.failures
    assert c.files >= 3 and not any("claims.parquet" in n for n in c.not_compared)
    assert 0 < c.max_ratio <= 1  # Monte-Carlo values were compared, within their errors


# --- no result that flips on the last bit -----------------------------------------------------


def test_design_plates_do_not_turn_with_the_last_bits(monkeypatch):
    """brown_design's Gaussian plates: a last-bit change of the covariance (as another BLAS
    kernel leaves) moves the plates' rms by rounding only; drawn along the eigenvectors of the
    symmetric grid's repeated eigenvalues, it moved them by a percent."""
    cfg = sim.load(ROOT / "studies" / "brown_design.toml", **{"unprinted.plates": 400}).config
    sr, grid = ex.range_sigma_um(cfg), cfg["zeiss.grid_sigma_um"]
    off = cfg["paper.offset_mm"]

    def zeiss():  # the Zeiss comparison at beta 0 (a sweep value): plates plus the grid's error
        return np.concatenate(
            [
                ex.plate_rms(cfg, ex.zeiss_points(cfg, h), off, 0.0, sr, grid, 92)[1]
                for h in (60, 80)
            ]
        )

    base = zeiss()
    F0 = po.full_point_covariance
    rng = np.random.default_rng(27)

    def nudged(*a, **k):
        F = F0(*a, **k)
        d = rng.uniform(-4, 4, F.shape) * np.finfo(float).eps
        return F * (1 + (d + np.swapaxes(d, -1, -2)) / 2)

    monkeypatch.setattr(po, "full_point_covariance", nudged)
    np.testing.assert_allclose(zeiss(), base, rtol=1e-9)


def test_salsig_sd_e_keeps_its_digits():
    """Salsig's sd of E from the analytic Jacobian: a last-bit change of the fitted parameters
    moves it by rounding only (the central difference it replaced moved it by ~1e-7)."""
    rng = np.random.default_rng(2)
    p = t2.affine_from_columns(0.0127, 0.012702, -59.2 * t2.ARCSEC, 0.01, (-115.0, -118.0))
    p = p + rng.normal(0, 1e-9, (200, 6))
    cov = np.broadcast_to(np.diag([1e-16, 1e-16, 1e-9, 1e-16, 1e-16, 1e-9]), (200, 6, 6))
    a = np.sqrt(t2.inverse_decomposition(p, cov)["cov"][:, 2, 2])
    q = p * (1 + rng.uniform(-2, 2, p.shape) * np.finfo(float).eps)
    b = np.sqrt(t2.inverse_decomposition(q, cov)["cov"][:, 2, 2])
    np.testing.assert_allclose(b, a, rtol=1e-12)


def test_pareto_ties_are_not_decided_by_the_last_bit():
    cost = np.array([60.0, 60.0, 90.0])
    ok = np.ones(3, bool)
    for d in (1e-15, -1e-15):  # two designs equal but for rounding: both on the front
        acc = np.array([1.0, 1.0 + d, 0.9])
        assert pareto_front(cost, acc, ok).tolist() == [True, True, True]
    assert pareto_front(cost, np.array([1.0, 1.001, 0.9]), ok).tolist() == [True, False, True]
