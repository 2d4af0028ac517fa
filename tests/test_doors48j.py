"""Issue 26, helper J48: the items the first wave of session 48 left. Each test names the class
of bad input and what was wrong before."""

from __future__ import annotations

import json
import shutil
import warnings
from pathlib import Path

import pyarrow.parquet as pq
import pytest
from conftest import TRIANGLE_NETWORK

import sim
from sim.batch_checks import why_stale
from sim.cli import main
from sim.report.verify.rerun import verify

RUN = ["--quiet", "--no-figures"]


@pytest.fixture(scope="module")
def batch(tmp_path_factory) -> Path:
    """A batch's results of two network study files, ``alpha.toml`` and ``beta.toml`` (another
    sigma), as ``python -m sim.batch --results B`` writes them: ``B/alpha``, ``B/beta``."""
    top = tmp_path_factory.mktemp("j48")
    (top / "alpha.toml").write_text(TRIANGLE_NETWORK)
    (top / "beta.toml").write_text(TRIANGLE_NETWORK.replace("0.01", "0.05"))
    for name in ("alpha", "beta"):
        out = top / "B" / name
        assert main(["run", str(top / f"{name}.toml"), "--out", str(out), *RUN]) == 0
    return top


def test_a_study_directory_copied_over_another_is_named_by_every_reader(batch, tmp_path, capsys):
    """A results directory copied by hand over another study's (``cp -r B/alpha B/beta``): it
    was shown, reported, read by ``sim.Results``, verified and taken as up to date as beta
    with alpha's numbers (run.json did not record its study file). Now the record names its
    study file (path, sha256) and the directory it was written as, and each reader says so;
    a record without the fields (an older version's) is read as before."""
    b = tmp_path / "B"
    shutil.copytree(batch / "B", b)
    rec = json.loads((b / "alpha" / "run.json").read_text())
    assert rec["written_as"] == "alpha" and rec["study_file"]["path"].endswith("alpha.toml")
    assert len(rec["study_file"]["sha256"]) == 64
    shutil.rmtree(b / "beta")
    shutil.copytree(b / "alpha", b / "beta")
    capsys.readouterr()
    needle = "holds the results of a run of"
    assert main(["show", str(b / "beta")]) == 0
    err = capsys.readouterr().err
    assert needle in err and "alpha.toml written as alpha/" in err and "not beta's" in err
    assert main(["show", str(b / "alpha")]) == 0 and needle not in capsys.readouterr().err
    assert main(["report", "--results", str(b)]) == 0
    err = capsys.readouterr().err
    assert needle in err and str(b / "beta") in err and str(b / "alpha ") not in err
    with pytest.warns(sim.StaleResultsWarning, match="written as alpha/"):
        sim.Results(b / "beta", "network").claims()
    assert "written as alpha/" in why_stale(batch / "beta.toml", b / "beta", RUN)
    # the same study file's content under beta's name: its config is beta's, its record not
    (tmp_path / "beta.toml").write_text(TRIANGLE_NETWORK)
    assert "written as alpha/" in why_stale(tmp_path / "beta.toml", b / "beta", RUN)
    (tmp_path / "scratch" / "beta").mkdir(parents=True)
    (comp,) = verify(b, tmp_path / "scratch", only=["beta"], rerun=False)
    assert comp.failures and "written as alpha/" in comp.failures[0]
    # an older version's record (no study file, no name): read as before, without a note
    old = {k: v for k, v in rec.items() if k not in ("written_as", "study_file")}
    (b / "beta" / "run.json").write_text(json.dumps(old))
    assert main(["show", str(b / "beta")]) == 0 and needle not in capsys.readouterr().err
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        sim.Results(b / "beta", "network").claims()


def test_a_resume_says_how_many_chunks_it_keeps_and_computes_again(batch, tmp_path, capsys):
    """A staging directory whose chunk files were swapped or copied by hand: "resuming
    network: 20 finished chunks found" counted every file, also those the run then computed
    again (not what their names say). Now it says how many are kept and computed again."""
    out = tmp_path / "res" / "alpha"
    stage = tmp_path / "res" / ".alpha.partial"
    shutil.copytree(batch / "B" / "alpha", stage)  # as a run killed before it published
    part = stage / "trials" / "part-0"
    shutil.copy(part / "chunk-000004.parquet", part / "chunk-000003.parquet")  # chunk 4's
    shutil.copy(part / "chunk-000005.parquet", part / "chunk-000099.parquet")  # beyond the run
    capsys.readouterr()
    assert main(["run", str(batch / "alpha.toml"), "--out", str(out), *RUN]) == 0
    err = capsys.readouterr().err
    assert "resuming network: 19 finished chunks kept, 2 computed again" in err, err
    first = pq.read_table(batch / "B" / "alpha" / "claims.parquet").column("value")
    assert pq.read_table(out / "claims.parquet").column("value") == first  # the same trials
