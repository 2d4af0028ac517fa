"""Every study through the runner: a run on 1 worker and a run on 2 local workers that is killed
with SIGKILL after its first chunks and then resumed on a Dask cluster give the
same tables and trials (issue 12; the second run without figures, ``--no-figures``). So every study shows that the chunks of 2 local pool workers, those of
Dask workers and those of the in-process run are the same, and that a killed run resumes (even
on another executor) to the files of an uninterrupted one.

The Dask cluster is one for the module (a scheduler address given with ``--scheduler``), with
one worker process: the chunks it computes come from a fresh process, not a fork, which is what
this module shows for every study; the path where ``--executor dask`` starts its own
LocalCluster of 2 workers is tested in ``test_runner.py``. (A second worker here cost the
module about 7 s of CPU, its imports and kernels loaded twice per study.)

Each study provides ``tests/data/tiny/<study>.txt``: one ``KEY=VALUE`` override per line for a
run of a few seconds with at least two chunks. The uninterrupted 1-worker run is the session's
shared tiny run (``tiny_run`` in conftest.py), which test_verify.py also compares with a run
on another numerical path.
"""

import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pyarrow.parquet as pq
import pytest
from conftest import ROOT, long_params, tiny_command

from sim.mc.storage import read_provenance
from sim.studies import MODULES

#: the study file that stands for a study kind with several example files
FILES = {"network": "network_testfield"}


def same_table(a: Path, b: Path) -> bool:
    """Equal schema and values, NaN equal to NaN (missing numbers)."""
    import numpy as np
    import pyarrow as pa

    ta, tb = pq.read_table(a), pq.read_table(b)
    if ta.schema.remove_metadata() != tb.schema.remove_metadata() or ta.num_rows != tb.num_rows:
        return False
    for ca, cb in zip(ta.columns, tb.columns):
        if pa.types.is_floating(ca.type):
            x = ca.to_numpy(zero_copy_only=False)
            y = cb.to_numpy(zero_copy_only=False)
            if not np.array_equal(x, y, equal_nan=True):
                return False
        elif ca.to_pylist() != cb.to_pylist():
            return False
    return True


def same_files(a: Path, b: Path) -> None:
    """Every table of ``a`` and ``b`` equal bit for bit, and their trials (``b`` was run
    without figures: the figures of a study are drawn from its tables in the run's own
    process, whatever the executor; test_figures.py shows a PNG is the same when drawn twice)."""
    fa = sorted(
        p.relative_to(a).as_posix()
        for p in a.rglob("*")
        if p.is_file() and p.suffix == ".parquet" and "trials" not in p.parts
    )
    fb = sorted(
        p.relative_to(b).as_posix()
        for p in b.rglob("*")
        if p.is_file() and p.suffix == ".parquet" and "trials" not in p.parts
    )
    assert fa == fb and fa
    for f in fa:
        assert same_table(a / f, b / f), f
        pa_, pb_ = read_provenance(a / f), read_provenance(b / f)
        assert pa_.get("config") == pb_.get("config") and pa_.get("seed") == pb_.get("seed"), f
    ta = (
        sorted(p.relative_to(a).as_posix() for p in (a / "trials").rglob("*.parquet"))
        if (a / "trials").is_dir()
        else []
    )
    tb = (
        sorted(p.relative_to(b).as_posix() for p in (b / "trials").rglob("*.parquet"))
        if (b / "trials").is_dir()
        else []
    )
    assert ta == tb
    for f in ta:
        assert same_table(a / f, b / f), f


CLUSTER = """
import sys
import dask
from dask.distributed import LocalCluster
# no statistical profiler (100 samples a second of every task), slower monitors and event-loop
# ticks, no work stealing (one worker): the cluster idles between the studies, and its CPU is
# the test's (idle, 0.4 s of CPU in 40 s instead of 1.7 s)
dask.config.set({"distributed.worker.profile.enabled": False,
                 "distributed.admin.system-monitor.interval": "5s",
                 "distributed.worker.memory.monitor-interval": "5s",
                 "distributed.admin.tick.interval": "500ms",
                 "distributed.scheduler.work-stealing": False})
with LocalCluster(n_workers=1, threads_per_worker=1, processes=True,
                  dashboard_address=None) as cluster:
    print(cluster.scheduler_address, flush=True)
    sys.stdin.read()                     # until the test module closes our stdin
"""


@pytest.fixture(scope="module")
def scheduler():
    """A Dask LocalCluster with 1 single-threaded worker process, shared by the studies. It
    lives in a process of its own, so nothing the test process does (forks, signals) reaches
    its workers."""
    pytest.importorskip("dask.distributed")
    p = subprocess.Popen(
        [sys.executable, "-c", CLUSTER],
        cwd=ROOT,
        stdin=subprocess.PIPE,
        stdout=subprocess.PIPE,
        stderr=subprocess.DEVNULL,
        text=True,
        start_new_session=True,
    )
    try:
        address = p.stdout.readline().strip()
        assert address.startswith("tcp://"), "the Dask cluster did not start"
        yield address
    finally:
        p.stdin.close()
        try:
            p.wait(timeout=30)
        except subprocess.TimeoutExpired:
            os.killpg(p.pid, signal.SIGKILL)
            p.wait()


# the slowest kinds in make fuzz (10-35 s of CPU each): the runner's machinery is the same
@pytest.mark.parametrize(
    "study",
    long_params(
        sorted(MODULES), {"wolf_polynomial", "agnard_block", "brown_dilution", "brown_design"}
    ),
)
def test_two_workers_and_a_killed_run_give_the_same_files(study, tmp_path, scheduler, tiny_run):
    name = FILES.get(study, study)
    one = tiny_run(name)  # 1 worker, in process
    two = tmp_path / "two"
    stage = tmp_path / ".two.partial"
    p = subprocess.Popen(
        tiny_command(name, two, 2, "--no-figures"),
        cwd=ROOT,
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
        start_new_session=True,
    )
    t0 = time.monotonic()
    while p.poll() is None and time.monotonic() - t0 < 120:
        if list(stage.rglob("chunk-*.parquet")):
            os.killpg(p.pid, signal.SIGKILL)  # the run and its workers, as kill -9 would
            break
        time.sleep(0.05)
    p.wait(timeout=60)
    assert p.returncode == -signal.SIGKILL, "the run finished before it could be killed"
    assert not two.exists() and list(stage.rglob("chunk-*.parquet"))  # killed mid-run
    r = subprocess.run(
        tiny_command(name, two, 2, "--no-figures", "--executor", "dask", "--scheduler", scheduler),
        cwd=ROOT,
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert r.returncode == 0, r.stderr
    assert "resuming" in r.stderr
    same_files(one, two)
    assert list(one.glob("*.png")) and not list(two.rglob("*.png"))
    assert json.loads((two / "run.json").read_text())["figures"] is False
