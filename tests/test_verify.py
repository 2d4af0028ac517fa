"""`sim verify`: a re-run within tolerance passes; a number or verdict edited by hand fails."""

from pathlib import Path

import pyarrow as pa
import pyarrow.parquet as pq
import pytest

from sim.cli import main
from sim.report.verify import compare_dirs, markdown, write_record

ROOT = Path(__file__).resolve().parent.parent
BROWN = ROOT / "studies" / "brown_table1.toml"


@pytest.fixture(scope="module")
def two_runs(tmp_path_factory):
    d = tmp_path_factory.mktemp("verify")
    for name in ("committed", "rerun"):
        assert (
            main(
                [
                    "run",
                    str(BROWN),
                    "--out",
                    str(d / name),
                    "--trials",
                    "40",
                    "--quiet",
                    "--set",
                    "chunk=2",
                ]
            )
            == 0
        )
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
    import shutil

    edited = tmp_path / "edited"
    shutil.copytree(two_runs / "committed", edited)
    t = pq.read_table(edited / "points.parquet")
    v = t.column("sigma_x_um")[0].as_py()
    _edit(edited / "points.parquet", "sigma_x_um", 0, v * (1 + 1e-5))  # beyond rounding level
    c = compare_dirs(edited, two_runs / "rerun")
    assert not c.ok and any("sigma_x_um" in f for f in c.failures)
    _edit(edited / "points.parquet", "sigma_x_um", 0, v * (1 + 1e-12))  # rounding level: passes
    assert compare_dirs(edited, two_runs / "rerun").ok


def test_a_changed_verdict_fails(two_runs, tmp_path):
    import shutil

    edited = tmp_path / "edited"
    shutil.copytree(two_runs / "committed", edited)
    v = pq.read_table(edited / "claims.parquet").column("verdict").to_pylist()
    i = next(k for k, x in enumerate(v) if x in ("holds", "fails", "inconclusive"))
    _edit(edited / "claims.parquet", "verdict", i, "fails" if v[i] != "fails" else "holds")
    c = compare_dirs(edited, two_runs / "rerun")
    assert not c.ok and any("verdict" in f for f in c.failures)


def test_declared_tolerance_is_used(tmp_path):
    from sim.mc.storage import write_table

    a, b = tmp_path / "a", tmp_path / "b"
    prov = {"study": "x", "tolerances": {"t.parquet": {"chain_mean": 0.05}}}
    write_table(a / "t.parquet", {"chain_mean": [1.0, 2.0], "exact": [3.0, 4.0]}, prov)
    write_table(b / "t.parquet", {"chain_mean": [1.03, 2.0], "exact": [3.0, 4.0]}, prov)
    assert compare_dirs(a, b).ok
    write_table(b / "t.parquet", {"chain_mean": [1.0, 2.0], "exact": [3.0, 4.001]}, prov)
    assert not compare_dirs(a, b).ok
