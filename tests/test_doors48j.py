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
from oneline import SIM_ERROR, one_line

import sim
from sim.batch_checks import why_stale
from sim.cli import main
from sim.mc.config import ConfigError
from sim.report.config_diff import _values_text
from sim.report.labels import middle
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


def _whole_words(text: str, label: str, dots: str) -> bool:
    """Whether ``label`` is ``text`` cut at word boundaries: its start ends, and its end
    starts, where a word or number of ``text`` does."""
    head, tail = label.split(dots)
    w = lambda c: c.isalnum() or c in "_.-"  # noqa: E731
    at = len(text) - len(tail)
    return (
        text.startswith(head)
        and text.endswith(tail)
        and not (w(text[len(head) - 1]) and w(text[len(head)]))
        and not (w(text[at - 1]) and w(text[at]))
    )


def test_a_sweeps_configuration_line_cuts_its_values_between_words():
    """Silent nonsense in a sweep's README: its configuration line gave a swept grid's value
    cut mid-word (``[{ prefix = "G", n...sigma_mm = 0.001 }]``, ``...pacing_mm = 40.0``): the
    shortening kept both ends by count. Now it cuts where a word ends and another starts."""

    def grid(n: int, sigma: float) -> list[dict]:
        keys = {"prefix": "G", "nx": n, "ny": n, "spacing_mm": 40.0, "role": "observed"}
        return [{**keys, "sigma_mm": sigma}]

    line = _values_text([grid(3, 0.001), grid(5, 0.002)])
    assert (
        line
        == '[[{ prefix = "G", ... sigma_mm = 0.001 }], [{ prefix = "G", ... sigma_mm = 0.002 }]]'
    )
    text = '[{ prefix = "G", nx = 3, ny = 3, spacing_mm = 40.0, role = "observed", sigma_mm = 0.0012 }]'
    for n in (20, 30, 40, 50, 60):
        label = middle(text, n, "...")
        assert len(label) <= n and _whole_words(text, label, "..."), label
    assert middle("a" * 60, 10) == "aaaa\u2026aaaaa"  # one word: cut in its middle, as before


def test_an_emptied_key_of_points_is_named_as_the_user_set_it(capsys):
    """Unclear message: `--set network.grids=[]` on a grid plate (its only points) was refused
    as "network.points: a network needs at least two points", a key the user never named.
    The key the user set is named now (by sim check and sim.load alike)."""
    plate = str(Path(__file__).resolve().parent.parent / "studies" / "network_plate.toml")
    rc = main(["check", plate, "--set", "network.grids=[]"])
    one_line(capsys, rc, "network.grids: a network needs at least two points", prefix=SIM_ERROR)
    with pytest.raises(ConfigError) as e:
        sim.load(plate, network__random=[], network__grids=[])
    assert e.value.key == "network.grids" and "give 0" in str(e.value)


def test_a_readme_gives_the_consistent_region_once(tmp_path):
    """A README.md said the consistent region twice at its top, "Consistent region: N
    accepted input vectors (...)" and then the study's own "**Consistent region.** ..."
    section (whose table gives each input's range of the region again): the line is left out
    where the study's section gives the region."""
    from sim.report.run_summary import write_run_readme
    from sim.studies import design_config, get_study

    d = tmp_path / "brown_table1"
    shutil.copytree(Path(__file__).resolve().parent.parent / "results" / "brown_table1", d)
    assert write_run_readme(d, get_study, d.name, d, design_config) is not None
    text = (d / "README.md").read_text()
    assert text.count("**Consistent region.**") == 1 and "accepted input vectors" not in text
