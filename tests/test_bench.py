"""The benchmark at smoke size (``python -m benchmarks --quick``): every engine row is present
with its compiled, NumPy and loop times, and both sides of each agree; the study rows time a
study in each variant; the page names every compiled module of the suite; the rerun rows time
the study files as ``make rerun`` runs them; a disagreement or bad input stops it with one
line. No timings are asserted."""

import re
from pathlib import Path

import numpy as np
import pyarrow.parquet as pq
import pytest

from benchmarks import cli, engines, studies
from benchmarks.engines_linear import polynomial

ROOT = Path(__file__).resolve().parent.parent
ENGINES = {
    "multilateration",
    "pposition",
    "gridplate",
    "block",
    "polynomial",
    "polynomial_shared",
    "stress_field",
    "stress_sincos",
    "selinv",
    "sparse_solve",
    "block_sparse",
    "network_gradient",
}
#: every compiled module of the suite (a file whose kernels sim.lsq.compile compiles)
COMPILED = {
    "sim/lsq/group_kernel.py",
    "sim/lsq/group_kernel_solve.py",
    "sim/lsq/linear_kernel.py",
    "sim/instruments/ranges/multilateration_jit.py",
    "sim/instruments/plotter/polynomial_kernel.py",
    "sim/instruments/plotter/errorfield_kernel.py",
    "sim/lsq/selinv.py",
    "sim/lsq/sparse_batch.py",
    "sim/studies/network/kernel.py",
}
#: compiled modules that have no engine row yet (issue 22 item 3): none left
NO_ROW_YET: set[str] = set()


def compiles_through_sim_lsq_compile(text: str) -> bool:
    """True if the source calls ``compiled`` of :mod:`sim.lsq.compile` under any name: the
    module imported as ``compile`` or an alias (``from sim.lsq import compile as jit``) and
    ``<alias>.compiled(`` called, or ``compiled`` imported from it (under any alias) and called."""
    names = set()
    for m in re.finditer(r"^from sim\.lsq import (.+)$", text, re.M):
        for part in m.group(1).strip("()").split(","):
            w = part.split()
            if w and w[0] == "compile":
                names.add(w[-1])
    if re.search(r"^import sim\.lsq\.compile\b", text, re.M):
        names.add(r"sim\.lsq\.compile")
    if any(re.search(rf"\b{n}\.compiled\(", text) for n in names):
        return True
    for m in re.finditer(r"^from sim\.lsq\.compile import (.+)$", text, re.M):
        for part in m.group(1).strip("()").split(","):
            w = part.split()
            if w and w[0] == "compiled" and re.search(rf"\b{w[-1]}\(", text):
                return True
    return False


def test_scan_finds_compiled_modules_under_any_alias():
    assert compiles_through_sim_lsq_compile(
        "from sim.lsq import compile as jit\nf = jit.compiled(g)\n"
    )
    assert compiles_through_sim_lsq_compile(
        "from sim.lsq import compile\nf = compile.compiled(g)\n"
    )
    assert compiles_through_sim_lsq_compile("from sim.lsq.compile import compiled as c\nf = c(g)\n")
    assert not compiles_through_sim_lsq_compile(
        "from sim.lsq import compile as jit\njit.available()\n"
    )
    assert not compiles_through_sim_lsq_compile("f = other.compiled(g)\n")


@pytest.mark.long
def test_engines_and_rerun_rows_at_smoke_size(tmp_path, monkeypatch):
    monkeypatch.chdir(ROOT)
    monkeypatch.setattr(studies, "STUDIES", ("network_testfield",))
    out = tmp_path / "bench"
    assert (
        cli.main(
            [
                "--quick",
                "--only",
                "engines,studies,rerun",
                "--out",
                str(out),
                "--rerun-files",
                "studies/network_testfield.toml",
                "--rerun-workers",
                "2",  # one worker count: the rows of each are made by the same code
            ]
        )
        == 0
    )
    eng = pq.read_table(out / "engines.parquet").to_pydict()
    assert set(eng["engine"]) == ENGINES == set(engines.cases())
    # the agreement itself is checked against SciPy in the tests below (a disagreement stops
    # the bench); here only that each row was measured
    for i, name in enumerate(eng["engine"]):
        assert 0 <= eng["max_abs_diff"][i] <= eng["tolerance"][i], name
        assert eng["compiled_s"][i] > 0 and eng["numpy_s"][i] > 0 and eng["scipy_s"][i] > 0
        assert (eng["speedup"][i] < eng["target_speedup"][i]) == eng["note"][i].startswith("below")
    # every compiled module of the suite has a row, and the page names it with a verdict
    named = {m.split(" ")[0].rstrip(",") for m in eng["compiled_module"] if m}
    named |= {m.split(", ")[1] for m in eng["compiled_module"] if ", " in m}
    assert {f[:-3].replace("/", ".") for f in COMPILED - NO_ROW_YET} == named
    on_disk = {
        p.relative_to(ROOT).as_posix()
        for p in (ROOT / "sim").rglob("*.py")
        if compiles_through_sim_lsq_compile(p.read_text())
    }
    assert on_disk == COMPILED
    page = (out / "README.md").read_text()
    for m in named:
        assert m in page, m
    st = pq.read_table(out / "studies.parquet").to_pydict()
    assert st["study"] == ["network_testfield"] * 2
    assert st["variant"] == list(studies.VARIANTS)
    assert all(x > 0 for x in st["seconds"])
    rr = pq.read_table(out / "rerun.parquet").to_pydict()
    assert rr["study"] == ["network_testfield", "report", "total"]
    assert rr["workers"] == [2, 2, 2]
    assert rr["jobs"] == [2] * 3  # make rerun's studies side by side
    wall, start, target = rr["wall_s"], rr["start_s"], rr["target_s"]
    # one study file: the total spans its run and the report (and the driver's own time)
    assert wall[2] >= wall[0] + wall[1]
    assert start[0] >= 0.0 and start[1] >= start[0] + wall[0]  # the study, then the report
    assert target[2] == 90.0 and np.isnan(target[0])
    assert (out / "engines.png").stat().st_size > 0
    assert not (out / "bench.parquet").exists()  # a section left out is not written


def test_the_polynomial_engine_is_the_study_fit_and_agrees_with_scipy():
    case = polynomial(6)
    coef = case.engine()
    assert coef.shape == (6, 10, 2)  # ten terms per axis, per trial
    assert engines.agreement(case, 6) <= case.tol


def test_a_disagreement_stops_the_bench(monkeypatch, capsys):
    def wrong(T):
        c = polynomial(T)
        return engines.Case(c.n_points, c.engine, lambda t: c.one(t) + 1e-6, c.tol, c.unit, c.scipy)

    monkeypatch.setattr(engines, "cases", lambda: {"polynomial": (wrong, 40, 5)})
    with pytest.raises(RuntimeError, match="differ by"):
        engines.engine_rows(quick=True)
    assert cli.main(["--quick", "--only", "engines", "--out", "/nonexistent/never"]) == 2
    assert "differ by" in capsys.readouterr().err


def test_bad_input_is_one_line_and_exit_2(tmp_path, capsys):
    assert (
        cli.main(
            ["--only", "rerun", "--rerun-files", str(tmp_path / "*.toml"), "--out", str(tmp_path)]
        )
        == 2
    )
    assert "no study file matches" in capsys.readouterr().err
    for bad in (["--only", "nothing"], ["--rerun-workers", "0"], ["--rerun-workers", "a"]):
        with pytest.raises(SystemExit) as e:
            cli.main(bad)
        assert e.value.code == 2
