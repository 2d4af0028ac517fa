"""The items left by the session before (brief L44), one case per class found; each failed on
the code before its fix.

* K42: Ctrl-C or SIGTERM while ``python -m sim.batch --report`` rebuilt ``REPORT.md`` printed
  two lines, ``sim report``'s own "sim: interrupted" and the batch's (REPORT.md as it was);
  the report's standard error now passes through the batch, which holds that line back (its
  other lines as they come). A SIGTERM as the batch started ``sim report`` (inside ``Popen``)
  left the batch without its report and with the line "interrupted after every run ended";
  the start is now made with the stop signals held (:func:`sim.held_stops.held_stops`), the
  report stopped then and said, and an interrupt after the runs ended and before the report
  began says that REPORT.md was not rebuilt.
* E42: ``ARROW_USER_SIMD_LEVEL=bogus`` (or empty) was a line of Arrow's own ("cpu_info.cc:393:
  Invalid value for ARROW_USER_SIMD_LEVEL: BOGUS") and a run at the level Arrow detected, exit
  0. Arrow's ``ArchParseUserSimdLevel`` (apache/arrow ``cpp/src/arrow/util/cpu_info.cc``) takes
  NONE, SSE4_2, AVX, AVX2 or AVX512 on x86 and NONE on ARM, upper-casing the value; another is
  now one line naming the variable (``sim.env_vars.arrow_simd_problem``: the commands, the
  benchmarks, ``sim.load``). ``import sim.api`` (``sim.api_helpers``, ``sim.api_tables``)
  directly, not through ``sim.load``, skipped the checks made before NumPy and Arrow load: a
  ``SOURCE_DATE_EPOCH=abc`` was a traceback from ``numpy.f2py``; importing them now raises the
  ``ConfigError`` naming it (:mod:`sim.api_env`). ``python -m benchmarks`` did not check
  ``SIM_NO_JIT``, ``NUMBA_`` or ``ulimit -d`` (``SIM_NO_JIT=0`` timed the Python path): it now
  refuses them as ``sim`` does.
* R41: brown_design's work estimate counted 6 error-budget rows of one unit a trial where its
  trials (the bar) count the 11 rows (``errbudget.BUDGET_ROWS``) at 3 units each: with
  ``budget.max_trials = 1e6`` the estimate said about 7.5e6 adjustments of a run that may take
  3.3e7 (a limit is an upper bound). Now every row is counted at its unit
  (:func:`sim.mc.workunits.design_estimate`): the study's own estimate went from 1.64e6 to
  2.18e6 adjustments (its rows ran 24,500 trials, not 220,000: adaptive, they stop early).
"""

from __future__ import annotations

import os
import platform
import shutil
import signal
import subprocess
import sys
from pathlib import Path

import pytest
from oneline import SIM_ERROR, one_line, one_line_of
from test_doors39s import NETWORK, _file, _sweep_dir

import sim
from sim import batch
from sim.batch_report import rebuild_report
from sim.report.run_summary import terminal_table
from sim.studies import get_study
from sim.studies.network.gama_read import read_gama

ROOT = Path(__file__).resolve().parent.parent


def test_an_interrupted_report_is_one_line_of_the_batch(tmp_path, monkeypatch, capfd):
    import sim.batch_report as br

    real = br.subprocess.Popen  # a sim report ended by Ctrl-C: its own line, exit 130
    code = "import sys; e = sys.stderr; print('a note', file=e); print('sim: interrupted', file=e)"
    monkeypatch.setattr(
        br.subprocess,
        "Popen",
        lambda cmd, **k: real([sys.executable, "-c", code + "; exit(130)"], **k),
    )
    assert rebuild_report(tmp_path / "res") == 130
    err = capfd.readouterr().err.splitlines()
    assert err[0] == "a note" and len(err) == 2, err  # its other lines pass through
    assert err[1].startswith("sim.batch: interrupted while sim report rebuilt"), err


def _batch_up_to_date(tmp_path, monkeypatch) -> list[str]:
    f = tmp_path / "network_plate.toml"
    shutil.copyfile(ROOT / "studies" / f.name, f)
    monkeypatch.setattr(batch, "run_all", lambda *a, **k: {})  # every study up to date
    return ["--report", "--results", str(tmp_path / "res"), str(f)]


def test_sigterm_as_the_report_starts_is_said(tmp_path, monkeypatch, capfd):
    import sim.batch_report as br

    real = br.subprocess.Popen

    def started(cmd, **k):  # SIGTERM to the batch as it starts sim report
        os.kill(os.getpid(), signal.SIGTERM)
        return real([sys.executable, "-c", "import time; time.sleep(60)"], **k)

    monkeypatch.setattr(br.subprocess, "Popen", started)
    assert batch.main(_batch_up_to_date(tmp_path, monkeypatch)) == 130
    err = capfd.readouterr().err
    assert err.count("\n") == 1 and "interrupted while sim report rebuilt" in err, err


def test_an_interrupt_before_the_report_says_it_was_not_rebuilt(tmp_path, monkeypatch, capfd):
    def interrupted(results):  # the interrupt lands on the way into the report
        raise KeyboardInterrupt

    monkeypatch.setattr(batch, "rebuild_report", interrupted)
    assert batch.main(_batch_up_to_date(tmp_path, monkeypatch)) == 130
    err = capfd.readouterr().err
    assert err.count("\n") == 1 and "REPORT.md was not rebuilt: sim report --results" in err, err


def _python(env: dict, *args: str) -> subprocess.CompletedProcess:
    env = {**os.environ, **env}
    return subprocess.run(
        [sys.executable, *args], capture_output=True, text=True, timeout=120, cwd=ROOT, env=env
    )


@pytest.mark.skipif(platform.machine() != "x86_64", reason="Arrow's x86 levels")
@pytest.mark.parametrize("value", ["bogus", ""])
def test_an_arrow_simd_level_arrow_does_not_know_is_one_line(value):
    p = _python(
        {"ARROW_USER_SIMD_LEVEL": value}, "-m", "sim", "check", "studies/wolf_polynomial.toml"
    )
    one_line_of(p, "ARROW_USER_SIMD_LEVEL", "avx2", prefix=SIM_ERROR)


@pytest.mark.parametrize("module", ["sim.api", "sim.api_helpers"])
def test_importing_an_api_module_directly_checks_the_environment(module):
    code = f"from sim.mc.config import ConfigError\ntry:\n    import {module}\nexcept ConfigError as e:\n    print(e)"
    p = _python({"SOURCE_DATE_EPOCH": "abc"}, "-c", code)
    assert p.returncode == 0 and p.stderr == "" and "SOURCE_DATE_EPOCH" in p.stdout, p


def test_the_benchmarks_refuse_what_sim_refuses():
    p = _python({"SIM_NO_JIT": "0"}, "-m", "benchmarks", "--help")
    one_line_of(p, "SIM_NO_JIT", prefix="benchmarks: error: ")


def _work(capsys, *sets: str) -> tuple[int, float]:
    from sim.cli import main

    argv = ["check", str(ROOT / "studies" / "brown_design.toml")]
    assert main([*argv, *(w for kv in sets for w in ("--set", kv))]) == 0
    line = next(x for x in capsys.readouterr().out.splitlines() if x.startswith("# work: "))
    trials, _, rest = line.removeprefix("# work: ").partition(" trials")
    return int(trials.replace(",", "")), float(rest.split("about ")[1].split(" ")[0])


def test_the_design_estimate_counts_a_budget_trial_as_its_trials_do(capsys):
    t0, a0 = _work(capsys, "budget.max_trials=1000")
    t1, a1 = _work(capsys, "budget.max_trials=1000000")
    assert t1 - t0 == 11 * 999_000, (t0, t1)  # every budget row up to max_trials
    # a budget trial costs 3 units, as its bar counts it, and its chunk's 100 units over the
    # study's 500 trials a chunk (before: 6/11 of a unit and 0.2)
    assert abs((a1 - a0) / (t1 - t0) - 3.2) < 0.05, (a0, a1, t0, t1)


def test_a_sweep_over_a_list_that_differs_in_three_places_shows_each_cell_apart(tmp_path):
    def grids(*n):
        return [{"prefix": p, "nx": k, "ny": k} for p, k in zip("ABC", n)]

    table = [grids(3, 3, 3), grids(4, 4, 4), grids(4, 3, 4)]  # the last two: their middle
    net = sim.load(_file(tmp_path, "n.toml", NETWORK)).config
    values = {"network.grids": [repr(g) for g in table]}  # as sweep.parquet holds a list
    d = _sweep_dir(tmp_path / "g", net, {"network.grids": table}, ["network.grids"], values)
    rows = terminal_table(d, get_study=get_study).splitlines()[2:5]
    shown = [r.split(None, 1)[1] for r in rows]  # each cell's grids, as sim show cuts them
    assert len(set(shown)) == 3, rows


@pytest.mark.parametrize("link", [os.symlink, os.link])
def test_one_study_file_under_two_names_in_a_batch_is_refused(tmp_path, capsys, link):
    a, b = tmp_path / "a.toml", tmp_path / "b.toml"
    a.write_text(NETWORK, encoding="utf-8")
    link("a.toml" if link is os.symlink else a, b)
    res = tmp_path / "res"
    rc = batch.main(["--results", str(res), str(a), str(b), "--", "--trials", "40"])
    one_line(capsys, rc, "a.toml and ", "b.toml are one file", "list it once")
    assert not res.exists()  # before any run


GAMA = """<?xml version="1.0" ?>
<gama-local xmlns="http://www.gnu.org/software/gama/gama-local">
  <network axes-xy="ne" angles="left-handed">
    <parameters sigma-apr="1" sigma-act="apriori" />
    <points-observations>
      <point id="A" x="0.0" y="0.0" fix="xy" />
      <point id="B" x="250.0" y="10.0" fix="xy" />
      <point id="C" x="240.0" y="260.0" adj="xy" />
      <point id="D" x="-15.0" y="230.0" adj="xy" />
      EXTRA
      <obs from="A">
        <distance to="C" val="353.836" stdev="2.0" /><distance to="D" val="230.489" stdev="2.0" />
      </obs>
      <obs from="B">
        <distance to="C" val="250.200" stdev="2.0" /><distance to="D" val="344.420" stdev="2.0" />
      </obs>
      <obs from="C"><distance to="D" val="256.759" stdev="2.0" /></obs>
      COORDS
    </points-observations>
  </network>
</gama-local>
"""


def _gama(tmp_path: Path, extra: str = "", coords: str = "") -> Path:
    (tmp_path / "n.xml").write_text(GAMA.replace("EXTRA", extra).replace("COORDS", coords))
    f = tmp_path / "n.toml"
    xml = tmp_path / "n.xml"
    f.write_text(f'study = "network"\ntrials = 40\nchunk = 2\n[network]\ngama_xml = "{xml}"\n')
    return f


@pytest.mark.parametrize("adj", ["xy", "XY"])
def test_an_adj_point_nothing_observes_is_left_out_as_gama_local_does(tmp_path, adj):
    f = _gama(tmp_path, f'<point id="E" x="100.0" y="100.0" adj="{adj}" />')
    sim.load(f)  # before: ConfigError, "no observation reaches it"
    net = read_gama(tmp_path / "n.xml")  # as the run reads it
    assert [p["name"] for p in net["network.points"]] == ["A", "B", "C", "D"], net
    assert net["datum.points"] == [] and "left out, as gama-local leaves them: 'E'" in net["note"]


COORDINATES = '<coordinates><point id="{}" x="{}" y="{}" /><cov-mat dim="2" band="0">1 1</cov-mat></coordinates>'


@pytest.mark.parametrize(
    ("extra", "coords", "said"),
    [
        ("", COORDINATES.format("A", "0.0", "0.0"), "gama-local keeps its observed coordinates"),
        ('<point id="E" x="9.0" y="9.0" fix="xy" adj="xy" />', "", "gama-local holds it fixed"),
    ],
)
def test_a_fixed_point_gama_local_reads_otherwise_is_one_line_naming_it(
    tmp_path, capsys, extra, coords, said
):
    from sim.cli import main

    f = _gama(tmp_path, extra, coords)
    one_line(capsys, main(["check", str(f)]), "network.gama_xml", "n.xml", said)
