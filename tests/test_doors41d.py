"""A new user's first hour, the docs tried as written (sweep doors41d): README.md and every
page docs/index.md links, their commands run in a fresh clone, their examples copied and
edited. Each class was found false and fixed; each test fails on the code or page before its
fix:

* docs/python.md: ``table("trials")`` is "else the chunk dataset", and "a table the run wrote
  and that was removed since is named as removed, not as one the study has not". Of the
  committed results (``sim.Results("results/brown_table1", "brown_table1")``, whose run wrote
  20 chunks and recorded their sha256; the clone holds none: ``results/*/trials/`` is not
  committed) ``table("trials")`` and ``table("chunks")`` said "brown_table1 has no table
  'trials'; it has claims, ...", a table the study writes. They now say the run wrote it and
  the committed results hold no chunks: run the study again.
* REPORT.md's line on a second run of a study ("``t2`` is the study ``brown_table1`` again at
  another configuration (...)") names what its config changes. It compared the run with the
  directory named as its study (``results/brown_table1``); over a results directory of yours
  (``sim report --results runs`` of ``runs/t1`` and ``runs/t2``: the cli.md runs) there is
  none, and the line listed the first four keys of the config (``comparator.alpha_mm`` =
  0.500, ...), which both runs share. It now compares with the run shown in the row above.

* ``sim.Results(path, study)`` with the study named wrong (``sim.Results("results/brown_table1",
  "brown_dilution").claims()``, a slip between Brown's two studies) was refused "... is a table
  of 'brown_table1', not of 'brown_dilution'; run the study again": no run helps. When the
  directory's run is that table's study, the line now says to give ``study='brown_table1'``.

* ``res.claims()`` of a sweep run through the API (docs/python.md's call on docs/sweeps.md's
  example) said "brown_table1 has no table 'claims'; it has sweep", and not where the claims
  are: the line now names the sweep's ``cells/<label>`` directories.

* ``sim show results`` (the directory ``make reproduce`` writes, typed for a run's) was "results
  is not a results directory (no claims.parquet or sweep.parquet)", a dead end; so was ``sim
  show`` of a sweep's ``cells/``. The line now names how many results directories it holds
  and the command that shows the first, which works as typed.

And docs/cli.md: in the project's root "a study file of yours kept outside ``studies/`` ... goes
to ``scratch/my_net-<config hash>/``", ``<name>`` "the study file's" (and ``sim run --help``
alike). A copy of a project's study file under another name (``my_table1.toml``, copied from
``studies/brown_table1.toml`` with ``trials = 400``) went to ``scratch/brown_table1-<hash>/``:
it stands for the study whose results it is compared with. The page and the help say so.

And one in docs/sweeps.md: its example sweep's configuration line was quoted "spawned from seed
1967 ... trials = 400 (the file: 4000)", where the page's example (no ``seed``, ``trials = 200``)
says "spawned from seed 20261122" and names ``chunk``, ``seed`` and ``trials``: the page now
quotes its own example's line, and says that a sweep file without ``seed`` takes the default,
not the study file's.
"""

from __future__ import annotations

import re
import shutil

import pytest
from conftest import ROOT

import sim
from sim.cli import main
from sim.mc.config import ConfigError
from sim.mc.storage import read_provenance
from sim.places import default_out
from sim.report.config_diff import sweep_config_line
from sim.studies import design_config


@pytest.mark.parametrize("name", ["trials", "chunks"])
def test_the_chunk_dataset_of_the_committed_results_is_named_as_written_by_its_run(name, tmp_path):
    # as committed: results/ of a checkout where the studies were re-run hold trials/ too
    held = tmp_path / "brown_table1"
    shutil.copytree(
        ROOT / "results" / "brown_table1", held, ignore=shutil.ignore_patterns("trials")
    )
    res = sim.Results(held, "brown_table1")
    with pytest.raises(ConfigError) as e:
        res.table(name)
    msg = str(e.value)
    assert "has no table" not in msg, msg
    assert "trials is missing: its run wrote it" in msg and "hold no chunks" in msg, msg
    assert "run the study again" in msg and "\n" not in msg, msg


def test_a_second_runs_line_names_the_keys_it_changes_from_the_run_shown(tmp_path, capsys):
    # two runs of agnard_block, neither in a directory named agnard_block (a user's runs)
    shutil.copytree(ROOT / "results" / "agnard_block", tmp_path / "ab_paper")
    shutil.copytree(ROOT / "results" / "agnard_block_104", tmp_path / "ab_real")
    assert main(["report", "--results", str(tmp_path)]) == 0
    line = next(s for s in (tmp_path / "REPORT.md").read_text().splitlines() if "again at" in s)
    assert line.startswith("- [ab_real](ab_real/README.md) is the study `agnard_block`"), line
    shown = re.findall(r"`([a-z_0-9.]+)` = ", line)
    assert shown, line
    mine, main_run = (
        read_provenance(tmp_path / d / "claims.parquet")["config"] for d in ("ab_real", "ab_paper")
    )
    assert all(mine[k] != main_run[k] for k in shown), line


def test_the_sweep_page_quotes_its_examples_configuration_line(tmp_path):
    page = (ROOT / "docs" / "sweeps.md").read_text()
    block = re.search(r"```toml\n# (\S+): .*?```", page, re.S)
    quoted = re.search(r'"(A sweep of .*?) \.\.\."\)', " ".join(page.split()))
    assert block and quoted, "the page's example or its quoted line is gone"
    (tmp_path / block.group(1)).write_text(block.group(0).strip("`").removeprefix("toml\n"))
    st = sim.load(tmp_path / block.group(1))
    prov = {"config": st.config, "sweep": st.sweep, "sweep_keys": list(st.sweep)}
    line = sweep_config_line(prov, block.group(1).removesuffix(".toml"), design_config)
    assert line.startswith(quoted.group(1)), (quoted.group(1), line)


@pytest.mark.parametrize("study", ["brown_dilution", "nosuch"])
def test_results_of_a_study_named_wrong_say_which_study_to_give(study):
    res = sim.Results(ROOT / "results" / "brown_table1", study)
    with pytest.raises(ConfigError) as e:
        res.claims()
    msg = str(e.value)
    assert f"is a table of 'brown_table1', not of '{study}'" in msg, msg
    assert "run the study again" not in msg and "give study='brown_table1'" in msg, msg


def test_claims_of_a_sweep_name_where_its_cells_tables_are(tmp_path):
    f = tmp_path / "sweep.toml"
    net = (ROOT / "tests" / "data" / "gama" / "one_fixed.toml").read_text()
    f.write_text(net + '\n[sweep]\n"test.alpha" = [0.05, 0.01]\n')
    res = sim.load(f, trials=40, chunk=2).run(out=tmp_path / "o", figures=False)
    with pytest.raises(ConfigError) as e:
        res.claims()
    msg = str(e.value)
    assert "has no table 'claims'; it has sweep" in msg, msg
    assert f"each cell's in {tmp_path / 'o' / 'cells'}/<label>" in msg, msg
    sim.Results(tmp_path / "o" / "cells" / "cell0000_r0", "network").claims()  # there it is


def test_a_renamed_copy_of_a_study_file_goes_where_the_page_says(tmp_path, monkeypatch, capsys):
    (tmp_path / "studies").mkdir()  # a project's root: its studies/ and committed results
    shutil.copytree(ROOT / "results" / "brown_table1", tmp_path / "results" / "brown_table1")
    text = (ROOT / "studies" / "brown_table1.toml").read_text()
    mine = re.sub(
        r"(?m)^trials = .*$", "trials = 400", re.sub(r"(?m)^chunk = .*$", "chunk = 20", text)
    )
    (tmp_path / "my_table1.toml").write_text(mine)
    monkeypatch.chdir(tmp_path)
    st = sim.load("my_table1.toml")
    where = default_out(st.config, st.sweep, tmp_path / "my_table1.toml")[1]
    assert where.startswith("scratch/brown_table1-"), where
    assert main(["run", "--help"]) == 0
    helped = " ".join(capsys.readouterr().out.split())
    assert (
        "(of a copy of a project's study file, kept under another name outside studies/: the study's)"
        in helped
    )
    page = " ".join((ROOT / "docs" / "cli.md").read_text().split())
    assert "its `<name>` is the study's (`scratch/brown_table1-<config hash>/`" in page


def test_show_of_a_directory_of_results_names_a_command_that_shows_one(capsys):
    assert main(["show", str(ROOT / "results")]) == 2
    err = capsys.readouterr().err.strip()
    hint = re.search(r"; it holds (\d+): sim show (\S+), \.\.\.$", err)
    assert hint and int(hint.group(1)) >= 10 and "\n" not in err, err
    assert main(["show", hint.group(2)]) == 0, capsys.readouterr().err
