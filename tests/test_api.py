"""The Python API (sim.api): the README's worked example, validation and the output rules."""

from pathlib import Path

import numpy as np
import pyarrow as pa
import pytest

import sim

ROOT = Path(__file__).resolve().parent.parent
STUDY = ROOT / "studies" / "brown_table1.toml"


def test_readme_worked_example(tmp_path):
    # --- README: Python API --------------------------------------------------------------
    import sim

    # the region of unprinted inputs at its smallest (docs/python.md runs it at full size)
    small = {"region.points": 256, "region.rounds": 0}
    st = sim.load(STUDY, trials=200, chunk=10, **{"errors.settings": 3}, **small)  # dotted keys
    st = st.replace(comparator__beta_mm=0.5)  # keyword form: __ stands for the dot
    print(st.estimate().describe())  # trials, adjustments, unknowns, memory
    res = st.run(out=tmp_path / "t1", workers=2, figures=False)  # out=None: a temp dir
    claims = res.claims()  # pyarrow.Table
    print(claims.select(["claim", "value", "ci_low", "ci_high", "holds"]).to_pylist()[:2])
    points = res.table("points")  # any table by name; "trials" per trial
    # ----------------------------------------------------------------------------------------
    assert isinstance(claims, pa.Table) and isinstance(points, pa.Table)
    assert res.table("trials").num_rows == 200
    assert np.isfinite(claims.column("value").to_numpy()).all()
    assert "trials" in res.names() and "claims" in res.names()
    # the same run from the command line gives the same tables
    from sim.cli import main

    assert (
        main(
            [
                "run",
                str(STUDY),
                "--out",
                str(tmp_path / "cli"),
                "--quiet",
                "--no-figures",  # tables compared; figures are test_figures.py's
                "--trials",
                "200",
                "--set",
                "chunk=10",
                "--set",
                "errors.settings=3",
                "--set",
                "comparator.beta_mm=0.5",
                *(a for k, v in small.items() for a in ("--set", f"{k}={v}")),
            ]
        )
        == 0
    )
    from sim.mc.storage import read_table

    assert (
        read_table(tmp_path / "cli" / "claims.parquet")
        .select(["value"])
        .equals(claims.select(["value"]))
    )


def test_api_errors_name_the_key(tmp_path):
    with pytest.raises(sim.ConfigError, match="plate.grid"):
        sim.load(STUDY, plate__grid="five")
    with pytest.raises(sim.ConfigError, match="plate.gird"):
        sim.load(STUDY, **{"plate.gird": 5})
    st = sim.load(STUDY, trials=20, chunk=1)
    f = tmp_path / "mine.txt"
    f.write_text("mine")
    with pytest.raises(sim.ConfigError, match="is a file"):
        st.run(out=f, overwrite=True)
    assert f.read_text() == "mine"
    with pytest.raises(sim.ConfigError, match="figures"):
        st.run(out=tmp_path / "o", figures="no")
    r = st.run(out=tmp_path / "o", figures=False)  # the tables, no PNG
    assert r.table("claims").num_rows and not list((tmp_path / "o").glob("*.png"))
    with pytest.raises(sim.ConfigError, match="no table"):
        r.table("nope")
