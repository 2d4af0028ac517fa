"""Issue 26, helper R50: a hostile reading of session 48's second-wave merges (the copy check
of run.json's ``written_as``, the export and input checks, the chunk digests, the TOML slips).
Each test names the class of bad input and what was wrong before its fix."""

from __future__ import annotations

import warnings
from pathlib import Path

import pytest
from conftest import TRIANGLE_NETWORK

import sim
from sim.cli import main
from sim.mc.study_source import other_source

RUN = ["--quiet", "--no-figures"]


@pytest.fixture(scope="module")
def done(tmp_path_factory) -> Path:
    """``sim run tri.toml --out r1``: a network run into a directory named by the user."""
    top = tmp_path_factory.mktemp("r50")
    (top / "tri.toml").write_text(TRIANGLE_NETWORK)
    assert main(["run", str(top / "tri.toml"), "--out", str(top / "r1"), *RUN]) == 0
    return top


def test_results_renamed_as_a_whole_are_not_called_another_studys(done, tmp_path, capsys):
    """Unclear message on a legitimate use (J48's copy check): results written with ``--out
    r1`` and then moved or renamed as a whole (``mv r1 2026-11-30``) were noted by ``sim show``
    as "not 2026-11-30's (copied or renamed by hand?): run 2026-11-30's own study file to
    replace them" (no such file ever was) and ``sim.Results`` raised a StaleResultsWarning.
    A name of the user's says no study: no note now. A batch's, or make verify's, name still
    says one (the copy ``cp -r B/alpha B/beta``: tests/test_doors48j.py)."""
    moved = tmp_path / "2026-11-30"
    (done / "r1").rename(moved)
    try:
        capsys.readouterr()
        assert main(["show", str(moved)]) == 0
        assert "holds the results of a run" not in capsys.readouterr().err
        with warnings.catch_warnings():
            warnings.simplefilter("error")
            sim.Results(moved, "network").claims()
        # where the name is taken as a study file's (a batch's B/<stem>), it is still named
        assert "written as r1/" in other_source(moved, "beta")
        assert other_source(moved, "tri") is None
    finally:
        moved.rename(done / "r1")
