"""The classes of the sweep doors35n (brief N35: a new user's first hour, done carelessly:
study files copied and run from other directories, commands run from a subdirectory of the
project, from ``/`` and from ``$HOME``), one case each; each failed on the code before its fix.

* ``sim run ../studies/brown_table1.toml`` from a directory inside the project (``docs/``,
  ``studies/``, ``results/``) took its default output in that directory: it made
  ``docs/results/brown_table1/`` (a results directory among the sources) and said "results in
  results/brown_table1/", which the user read as the project's committed results; from
  ``sim/studies/network/`` (reading the code) the run's ``run.json`` landed inside the study's
  package, whose data files are part of its code hash, so every committed network result read
  stale (``sim show``'s note; ``make reproduce`` re-ran them all). The defaults of ``sim run``
  (``results/<name>``, ``scratch/<name>-<hash>``), ``sim report`` and ``python -m sim.batch``
  (``--results``) are now the project's from any directory inside it, shown relative to the
  working directory (:func:`sim.places.base`).
* ``sim run studies/network_plate.toml --no-figures`` (the committed config, for speed)
  replaced the committed results: their PNG files deleted (tracked files; the README shows
  one of brown_dilution's), ``run.json`` saying ``"figures": false``, so ``make reproduce``
  took them as stale. Such a run now goes to ``scratch/`` and says why.
* ``python -m sim.batch mine/my_net.toml`` in the project's root (as the Makefile runs it)
  made a new ``results/my_net`` among the committed results (listed in REPORT.md, never
  checked by ``make verify``), which ``sim run`` of the same file never makes (it goes to
  ``scratch/``): refused before any run, naming ``--results``, as a file named like a
  project study already was.
* ``--out`` (or the API's ``out``) inside the suite's package ``sim/`` was accepted, with the
  same stale code hash: refused in one line naming it (:func:`sim.places.check_place`).
* ``--out moved/x`` where ``moved`` is a symbolic link to a folder moved since said
  "cannot write to moved: File exists": it now names the link and where it points.
* A notebook keeps the ``Results`` of a run whose directory it then deleted (or a temporary
  directory cleaned): reading them said "... is not a results directory" of what was one; it
  now says the directory no longer exists, removed since the run.
* ``sim report`` from a directory without ``results/`` (``/``, ``$HOME``) said "results is not
  a results directory" of a directory that does not exist: it now says it does not exist, and
  where it was looked for.
"""

from __future__ import annotations

import contextlib
import io
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

import sim
import sim.cli
import sim.cli_run
import sim.places
from sim.mc.config import ConfigError
from sim.mc.storage import code_hash
from sim.studies import load_study

ROOT = Path(__file__).resolve().parent.parent
NET = ROOT / "studies" / "network_plate.toml"


def _sim(*args, cwd):
    return subprocess.run(
        [sys.executable, "-m", "sim", *map(str, args)],
        capture_output=True,
        text=True,
        cwd=cwd,
        timeout=300,
    )


def _run_goes_to(monkeypatch, cwd: Path, *argv: str) -> tuple[Path, str, str]:
    """Where ``sim run ARGV`` in ``cwd`` would write (its ``out`` and the path it shows) and
    its standard error; nothing is run (the run itself is stopped)."""
    seen = {}

    def stop(study, cfg, sweep, out, shown, **kw):
        seen.update(out=out, shown=shown)
        raise ConfigError(None, "stopped by the test")

    monkeypatch.setattr(sim.cli_run, "execute", stop)
    monkeypatch.chdir(cwd)
    err = io.StringIO()
    with contextlib.redirect_stderr(err):
        assert sim.cli.main(["run", *argv, "--quiet"]) == 2
    return seen["out"], seen["shown"], err.getvalue()


def _committed_is_current(monkeypatch):
    """``results/network_plate`` read as made by this very config and code (with figures),
    whatever the checkout's results are (stale after a code change, before the re-run)."""
    record = {"config": load_study(NET)[1], "code_hash": code_hash("network")}
    real = sim.places.read_record
    monkeypatch.setattr(
        sim.places,
        "read_record",
        lambda d: record if Path(d).resolve() == ROOT / "results" / "network_plate" else real(d),
    )


def test_default_output_from_inside_the_project_is_the_projects(monkeypatch):
    """From ``docs/`` a run of other values goes to the project's ``scratch/``, and one of
    the committed config to the project's ``results/``, never to ``docs/results/``; from a
    study's package likewise."""
    out, shown, err = _run_goes_to(
        monkeypatch, ROOT / "docs", "../studies/network_plate.toml", "--trials", "40"
    )
    assert out.parent == ROOT / "scratch" and out.name.startswith("network_plate-"), out
    assert shown == f"../scratch/{out.name}", shown
    assert "../results/network_plate/ holds the committed results" in err
    _committed_is_current(monkeypatch)
    out, shown, _ = _run_goes_to(monkeypatch, ROOT / "sim" / "studies" / "network", str(NET))
    assert (out, shown) == (ROOT / "results" / "network_plate", "../../../results/network_plate")
    assert not (ROOT / "docs" / "results").exists()


def test_no_figures_never_replaces_committed_figures(monkeypatch):
    """``sim run studies/network_plate.toml --no-figures``: the committed config, but its
    figures would be deleted (and the results made stale): it goes to ``scratch/``."""
    _committed_is_current(monkeypatch)
    out, shown, err = _run_goes_to(monkeypatch, ROOT, str(NET), "--no-figures")
    assert out.parent == ROOT / "scratch" and shown.startswith("scratch/network_plate-"), out
    assert "a run with --no-figures is not" in err, err  # (V35's words at the merge)
    out, _, _ = _run_goes_to(monkeypatch, ROOT, str(NET))  # with figures: the committed run
    assert out == ROOT / "results" / "network_plate"


def test_batch_and_show_from_inside_the_project(tmp_path):
    """From ``docs/``: ``python -m sim.batch`` of a file of the user's named like a project
    study is refused before any run (it would replace ``../results/brown_table1``: it ran into
    ``docs/results/``), and ``sim show brown_table1`` reads the project's results."""
    mine = tmp_path / "brown_table1.toml"
    mine.write_text((ROOT / "studies" / "brown_table1.toml").read_text() + "\n# mine\n")
    r = subprocess.run(
        [sys.executable, "-m", "sim.batch", str(mine), "--", "--trials", "40", "--no-figures"],
        capture_output=True,
        text=True,
        cwd=ROOT / "docs",
        timeout=300,
    )
    assert r.returncode == 2 and "would replace ../results/brown_table1" in r.stderr, r
    assert not (ROOT / "docs" / "results").exists()
    r = _sim("show", "brown_table1", cwd=ROOT / "docs")
    assert r.returncode == 0 and "brown.table1_closure.dof" in r.stdout, r


def test_batch_of_a_file_of_yours_into_the_projects_results(tmp_path):
    """``python -m sim.batch mine/my_net.toml`` in the root: refused, nothing run or made."""
    mine = tmp_path / "my_net_doors35n.toml"
    mine.write_text(NET.read_text())
    r = subprocess.run(
        [sys.executable, "-m", "sim.batch", str(mine), "--", "--trials", "40", "--no-figures"],
        capture_output=True,
        text=True,
        cwd=ROOT,
        timeout=300,
    )
    assert r.returncode == 2 and r.stdout == "", r
    assert r.stderr == (
        f"sim.batch: {mine} is not a study file of the project's studies: it would make a new "
        "results/my_net_doors35n among the project's results: give your own --results DIR\n"
    )
    assert not (ROOT / "results" / "my_net_doors35n").exists()


def test_out_inside_the_suites_code_is_refused(tmp_path):
    """``--out sim/studies/network/x`` and ``run(out=...)`` there: one line, nothing written."""
    target = ROOT / "sim" / "studies" / "network" / "doors35n-out"
    try:
        r = _sim(
            "run",
            NET,
            "--trials",
            "40",
            "--chunk",
            "2",
            "--quiet",
            "--out",
            "sim/studies/network/doors35n-out",
            cwd=ROOT,
        )
        assert r.returncode == 2 and r.stdout == "", r
        assert r.stderr.count("\n") == 1 and "lies inside the suite's code" in r.stderr, r.stderr
        assert r.stderr.startswith("sim: error: --out: sim/studies/network/doors35n-out ")
        with pytest.raises(sim.ConfigError, match="^out: .* lies inside the suite's code"):
            sim.load(NET, trials=40, chunk=2).run(out=target, quiet=True)
        assert not target.exists() and not target.with_name(".doors35n-out.partial").exists()
    finally:  # before the fix the run wrote there: never leave it in the package
        for p in (target, target.with_name(".doors35n-out.partial")):
            if p.exists():
                subprocess.run(["rm", "-rf", str(p)], check=False)


def test_out_below_a_link_to_nothing(tmp_path):
    """``--out lnk/x`` with ``lnk`` a symbolic link to a folder that was moved away."""
    (tmp_path / "lnk").symlink_to("moved-away")
    r = _sim("run", NET, "--trials", "40", "--quiet", "--out", "lnk/x", cwd=tmp_path)
    assert r.returncode == 2 and r.stdout == "", r
    assert r.stderr == (
        f"sim: error: --out: lnk/x: {tmp_path / 'lnk'} is a symbolic link to moved-away, "
        "which does not exist\n"
    )
    assert sorted(p.name for p in tmp_path.iterdir()) == ["lnk"]


def test_report_where_there_is_no_results_directory(tmp_path):
    """``sim report`` in a directory of the user's without ``results/``: it does not exist."""
    r = _sim("report", cwd=tmp_path)
    assert r.returncode == 2, r
    assert r.stderr == f"sim: error: --results: results does not exist (in {tmp_path})\n"


def test_results_of_a_run_whose_directory_was_deleted(tmp_path):
    """A run's ``Results`` kept after its directory is removed: it no longer exists."""
    res = sim.load(NET, trials=40, chunk=2).run(out=tmp_path / "o", quiet=True, figures=False)
    assert res.claims().num_rows > 0
    shutil.rmtree(tmp_path / "o")
    for read in (res.claims, res.names):
        with pytest.raises(sim.ConfigError) as e:
            read()
        assert str(e.value) == f"path: {tmp_path / 'o'} no longer exists (removed since the run)"
