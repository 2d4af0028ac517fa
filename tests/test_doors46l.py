"""Doors sweep 46l: the items session 45 left (stop 55), each a class of bad input with a test
that failed on the code before its fix.

* R45: ``--out`` naming a directory with files but no run record (a home directory, ``/usr``)
  was walked in full, every entry of every subdirectory, before its refusal (1-4 s on ``/usr``,
  minutes on a home directory of millions of files), looking for a running run's lock to name.
  It now looks at no more than :data:`sim.mc.swap.LOOK_AT` entries, breadth first, and the
  refusal names one of the entries it holds (a directory holding only ``.DS_Store`` looked
  empty to ``ls`` and was refused for holding "files").
* F44/C45: ``make verify`` while a study's only directory is its run's staging directory (a
  first run in progress, or one killed before it published) said "no study results in
  RESULTS" (or "no results of 'NAME'" for ``--study NAME``) and nothing of the run; it now says
  so in its one line, as ``sim show`` and ``sim report`` do (:mod:`sim.mc.unfinished`).
* N45: ``sim check`` of a network whose bias the adjustment will not absorb (``bias_mm = 10``
  on the README network's distances) printed the work and nothing else, exit 0; the run then
  counted its three self-checks "not applicable". It now says so before the run, in a note
  line naming the bias (:func:`sim.studies.network.bias_checks.bias_notes`); an absorbed bias
  (each station's orientation) gets no note.
* E45: ``OPENBLAS_NUM_THREADS`` that OpenBLAS reads as no count (``abc``, ``-1``, ``0``, empty:
  C's ``atoi`` gives 0 or less) was kept as given: OpenBLAS then read ``OMP_NUM_THREADS``, and
  with that unreadable too ran on every core where the suite runs one thread a process
  (measured: two threads, and a 300 x 300 solve's last bits another's), without a word;
  ``1.5`` was read as 1. It is now one line naming the variable, exit 2, at every door
  (``sim check`` the same line as ``sim run``). Held, measured: ``OMP_NUM_THREADS=abc`` alone
  (OpenBLAS reads the suite's ``OPENBLAS_NUM_THREADS=1`` first; Arrow's pool takes it for
  unset), ``MKL_NUM_THREADS=1.5`` (no MKL: OpenBLAS), ``NUMBA_NUM_THREADS=0``/``abc``/``1.5``
  (refused already, by numba's own reading).
* brown_design's memory refusal advised "reduce chunk, trials or the sizes in the study file"
  whichever part held the memory: with ``bayes.steps = 200000`` its chains are 14 GiB of it, and
  neither chunk nor trials changes them. Each part names its keys now (the chains
  ``bayes.steps, bayes.walkers or bayes.chains``, the design grid ``design.grids, ...``), the
  same line from ``sim check`` and ``sim run``.
* F44/C45: ``kill -9`` of ``python -m sim.batch --report`` while its ``sim report`` ran (which
  then stops too) left the old ``REPORT.md`` beside the newly published results, and no
  command ever said so. The batch marks the report due before it starts ``sim report``
  (``<results>/.report-due``, :mod:`sim.report_due`), ``sim report`` clears the mark once
  ``REPORT.md`` is written, and ``make verify`` (and a batch without ``--report``) names it.
"""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
import time

import pytest

import sim.mc.swap as swap_mod
from sim.cli import main
from sim.mc.storage import StageLock
from sim.report.verify.cli import main as verify_main
from tests.oneline import SIM_ERROR, VERIFY_ERROR, one_line

STUDY = "studies/brown_table1.toml"
ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def _tree(root, dirs: int, files: int) -> None:
    for i in range(dirs):
        d = root / f"d{i:03d}"
        d.mkdir(parents=True)
        for j in range(files):
            (d / f"f{j}").touch()


def test_a_full_out_without_a_record_is_refused_after_a_bounded_look(tmp_path, capsys, monkeypatch):
    """A non-empty ``--out`` with no run record: before, every entry under it was looked at
    (here 2,040; a home directory's millions took minutes) before the one-line refusal."""
    out = tmp_path / "home"
    _tree(out, 40, 50)
    monkeypatch.setattr(swap_mod, "LOOK_AT", 200, raising=False)
    seen, scandir = [], os.scandir

    class Counted:
        def __init__(self, path):
            self.it = scandir(path)

        def __enter__(self):
            return self

        def __exit__(self, *a):
            self.it.close()

        def __iter__(self):
            for e in self.it:
                seen.append(e.path)
                yield e

        def __next__(self):
            e = next(self.it)
            seen.append(e.path)
            return e

        def close(self):
            self.it.close()

    monkeypatch.setattr(os, "scandir", Counted)
    argv = ["run", os.path.join(ROOT, STUDY), "--quiet", "--no-figures", "--out", str(out)]
    line = one_line(capsys, main(argv), "holds files but no sim run record", prefix=SIM_ERROR)
    assert len([p for p in seen if p.startswith(str(out))]) <= 250, len(seen)  # before: 2,040
    assert "it holds 'd000' and more" in line


def test_a_directory_holding_only_a_hidden_file_names_it(tmp_path, capsys):
    """``ls`` shows it empty: the refusal said "holds files" and named none."""
    out = tmp_path / "res"
    out.mkdir()
    (out / ".DS_Store").write_bytes(b"\0")
    argv = ["run", os.path.join(ROOT, STUDY), "--quiet", "--no-figures", "--out", str(out)]
    line = one_line(capsys, main(argv), "no sim run record", prefix=SIM_ERROR)
    assert line.endswith("(it holds '.DS_Store')")


def test_a_running_run_near_the_top_is_still_named(tmp_path, capsys):
    """The bounded look still finds a running run's lock one level down (held: as before)."""
    out = tmp_path / "home"
    _tree(out, 3, 5)
    lock = StageLock(out / "res" / ".net.partial").acquire()
    try:
        argv = ["run", os.path.join(ROOT, STUDY), "--quiet", "--no-figures", "--out", str(out)]
        line = one_line(capsys, main(argv), "is being written by a running sim", prefix=SIM_ERROR)
    finally:
        lock.release()
    assert "holds res/.net.partial, which" in line


def test_verify_of_results_whose_only_study_is_being_written_says_so(tmp_path, capsys):
    """A first run into ``res/brown_table1`` holds ``res/.brown_table1.partial`` locked: before,
    "no study results in res (no */claims.parquet)" and no word of it."""
    res = tmp_path / "res"
    lock = StageLock(res / ".brown_table1.partial").acquire()
    try:
        argv = ["--results", str(res), "--scratch", str(tmp_path / "v")]
        line = one_line(capsys, verify_main(argv), "no study results", prefix=VERIFY_ERROR)
    finally:
        lock.release()
    assert f"{res / 'brown_table1'}: a run is writing it now" in line


def test_verify_of_a_study_whose_run_was_killed_before_it_published_says_so(tmp_path, capsys):
    """``--study brown_table1`` of results holding brown_dilution and the staging directory a
    killed run of brown_table1 left: before, "no results of 'brown_table1' ... (there are:
    brown_dilution)" alone."""
    res = tmp_path / "res"
    shutil.copytree(os.path.join(ROOT, "results", "brown_dilution"), res / "brown_dilution")
    (res / ".brown_table1.partial").mkdir()
    argv = ["--results", str(res), "--scratch", str(tmp_path / "v"), "--study", "brown_table1"]
    line = one_line(capsys, verify_main(argv), "no results of 'brown_table1'", prefix=VERIFY_ERROR)
    assert "its run did not finish" in line and "the same command again finishes it" in line


NETWORK = """study = "network"
trials = 400
chunk = 20
[network]
points = [ {{ name = "A", x_mm = 0.0, y_mm = 0.0, role = "fixed" }},
           {{ name = "B", x_mm = 400.0, y_mm = 0.0, role = "fixed" }},
           {{ name = "C", x_mm = 400.0, y_mm = 300.0, role = "fixed" }},
           {{ name = "D", x_mm = 0.0, y_mm = 300.0, role = "fixed" }},
           {{ name = "P", x_mm = 150.0, y_mm = 120.0 }} ]
generate = [ {{ kind = "distance", from = ["A", "B", "C", "D"], to = "P", sigma_mm = 0.002{d} }},
             {{ kind = "direction", from = ["A", "B", "C", "D"], to = "*", sigma_arcsec = 2.0{a} }} ]
"""


def test_sim_check_of_a_network_whose_bias_is_not_absorbed_says_the_checks_are_not_applicable(
    tmp_path, capsys
):
    """Before: the listing and the work line, no word of the three checks the run would count
    "not applicable"."""
    p = tmp_path / "net.toml"
    p.write_text(NETWORK.format(d=", bias_mm = 10.0", a=""))
    assert main(["check", str(p)]) == 0
    notes = [x for x in capsys.readouterr().out.splitlines() if x.startswith("# note: ")]
    assert len(notes) == 1, notes
    assert "network.coverage95.mean" in notes[0] and "will be not applicable" in notes[0]
    assert "bias_mm = 10 on the distance at 'A' to 'P'" in notes[0]
    p.write_text(NETWORK.format(d="", a=", bias_arcsec = 30.0"))  # absorbed: no note
    assert main(["check", str(p)]) == 0
    assert "# note: " not in capsys.readouterr().out


@pytest.mark.parametrize("value", ["abc", "-1", "0", "", "1.5"])
def test_an_openblas_thread_count_openblas_cannot_read_is_refused(
    value, tmp_path, capsys, monkeypatch
):
    """Before: ``sim check`` exit 0 and ``sim run`` ran (on every core with ``OMP_NUM_THREADS``
    unreadable as well)."""
    monkeypatch.setenv("OPENBLAS_NUM_THREADS", value)
    monkeypatch.setenv("OMP_NUM_THREADS", "abc")
    study = os.path.join(ROOT, STUDY)
    need = ("OPENBLAS_NUM_THREADS: must be a whole number of threads", repr(value))
    check = one_line(capsys, main(["check", study]), *need, prefix=SIM_ERROR)
    run = one_line(capsys, main(["run", study, "--out", str(tmp_path / "x")]), prefix=SIM_ERROR)
    assert check == run


@pytest.mark.parametrize(
    "variable, value", [("OMP_NUM_THREADS", "abc"), ("MKL_NUM_THREADS", "1.5")]
)
def test_thread_variables_no_library_acts_on_stay(variable, value, monkeypatch):
    """Held: OpenBLAS reads the suite's own ``OPENBLAS_NUM_THREADS`` first; no MKL."""
    from sim.env_vars import environment_problem

    monkeypatch.delenv("OPENBLAS_NUM_THREADS", raising=False)
    monkeypatch.setenv(variable, value)
    assert environment_problem() is None


@pytest.mark.parametrize(
    "sets, keys",
    [
        (["bayes.steps=200000"], "reduce bayes.steps, bayes.walkers or bayes.chains"),
        (["design.grids=[5, 7, 29]"], "reduce design.grids, design.offsets_mm or design.beta_mm"),
    ],
)
def test_brown_designs_memory_refusal_names_the_keys_of_the_part_that_holds_it(
    sets, keys, tmp_path, capsys
):
    """Before: "...; reduce chunk, trials or the sizes in the study file"."""
    study = os.path.join(ROOT, "studies", "brown_design.toml")
    argv = [x for k in sets for x in ("--set", k)] + ["--max-memory-gb", "0.4"]
    check = one_line(capsys, main(["check", study, *argv]), "GiB limit", prefix=SIM_ERROR)
    assert check.endswith(keys), check
    out = ["--out", str(tmp_path / "x"), "--quiet", "--no-figures"]
    assert one_line(capsys, main(["run", study, *argv, *out]), prefix=SIM_ERROR) == check


def _children(pid: int) -> list[int]:
    try:
        tasks = os.listdir(f"/proc/{pid}/task")
    except OSError:
        return []
    out = []
    for t in tasks:
        try:
            with open(f"/proc/{pid}/task/{t}/children") as f:
                out += [int(x) for x in f.read().split()]
        except OSError:
            pass
    return out


def _await(cond, what: str, limit: float = 120.0) -> None:
    end = time.monotonic() + limit  # (a bound on a wait for an event, not a timing assert)
    while not cond():
        assert time.monotonic() < end, what
        time.sleep(0.05)


def test_a_batch_killed_while_its_report_ran_is_named_by_the_next_verify(tmp_path, capsys):
    """The batch's report step in a process of its own, killed (SIGKILL) as soon as its ``sim
    report`` has started: before, ``make verify`` said nothing of the report left as it was."""
    res = tmp_path / "res"
    shutil.copytree(os.path.join(ROOT, "results", "brown_dilution"), res / "brown_dilution")
    code = "import sys; from pathlib import Path; from sim.batch_report import rebuild_report; "
    code += "rebuild_report(Path(sys.argv[1]))"
    batch = subprocess.Popen([sys.executable, "-c", code, str(res)], cwd=ROOT)
    _await(lambda: _children(batch.pid) or batch.poll() is not None, "no sim report started")
    report = _children(batch.pid)
    batch.kill()
    batch.wait()
    assert report, "the batch ended before its sim report started"
    _await(lambda: not os.path.exists(f"/proc/{report[0]}"), "sim report did not stop with it")
    assert not (res / "REPORT.md").exists()
    argv = ["--results", str(res), "--scratch", str(tmp_path / "v"), "--no-rerun"]
    assert verify_main(argv) == 2  # (no re-run in the scratch: nothing to compare)
    err = capsys.readouterr().err
    assert f"sim verify: note: {res / 'REPORT.md'} was not rebuilt" in err, err
    assert f"sim report --results {res} rebuilds it" in err
    assert main(["report", "--results", str(res)]) == 0  # rebuilt: the mark goes with it
    capsys.readouterr()
    assert verify_main(argv) == 2 and "not rebuilt" not in capsys.readouterr().err
