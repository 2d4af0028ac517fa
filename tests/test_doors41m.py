"""Helper m41: real sizes with workers, Dask and repeated loads (the memory of the whole
process tree against the estimate, the API loading and running in one process); one case per
class found, each failing on the code before its fix (small sizes here, the measured ones in
the docstrings).

* a run whose memory fits with 1 worker and not with 2 was refused before it started (the
  estimate of a chunk times the workers against ``--max-memory-gb``), but its one line sent
  the user to "reduce chunk, trials or the sizes in the study file" and did not name the
  workers at all: a 10,000-point network (0.264 GiB a process) with ``--workers 2`` under
  ``--max-memory-gb 0.4``. The line now says what each worker process needs and the most
  workers that fit, "use --workers 1, or reduce ..." (the API's "use workers=1").
* ``--executor dask`` sent the chunk function with every task: a network's holds the network
  and its factor (37 MiB pickled at 10,000 points), and sent with each of its 20 chunks it
  took the run's own process from 0.48 GiB (1 worker) to 1.2 GiB (the estimate 0.26 GiB a
  process) and the tree to 2.2 GiB (PSS), and Dask printed its six-line UserWarning "Sending
  large graph of size 37.19 MiB ..." in the middle of the run. The function is now scattered
  to the workers once a part (:meth:`sim.mc.executors._Dask.run`).
* under ``ulimit -v`` Arrow's default allocator (mimalloc) mapped up to 1 GiB of the address
  space at a run's first table, whatever the table: a 10,000-point network (0.264 GiB
  estimated, 0.93 GiB mapped at its peak with the system's allocator) peaked at 1,999,916 kB
  under ``ulimit -v 2000000``, 84 kB from the limit, so the room the check saw before the run
  was not there. With no room left for Arrow's threads a Parquet read hung for good (seen once
  at that limit: every thread on a futex in ``AsyncScanner::ToTable``; alone, with 8 to 16 MiB
  left it hangs, with 32 MiB glibc aborts "cannot allocate memory for thread-local data"), and
  the API's next ``sim.load`` of the study in the process was refused ("leaves this process
  about 0.076 GiB beside the 1.83 GiB it maps already") after a first run that had fit.
  Importing ``sim`` under ``ulimit -v`` or ``-d`` now sets ``ARROW_DEFAULT_MEMORY_POOL=system``
  (unless set): that run peaks at 977,032 kB and the next loads and runs.
"""

from __future__ import annotations

import functools
import pickle
import warnings
from pathlib import Path

import numpy as np
import pytest
from conftest import grid_network

import sim
from sim.cli import main
from sim.mc.config import ConfigError
from sim.mc.runner import RunContext, make_executor, run_chunks
from tests.oneline import one_line, python_lines

SIDE = 12


def _network(tmp_path: Path) -> tuple[Path, float]:
    """A 12 x 12 trilateration grid (nearest 8, inner datum; about 3.6 MiB a process): its
    study file and the bytes a process of its run needs (tests/conftest.py)."""
    return grid_network(tmp_path, SIDE)


def _limit_for(need: float, workers: float) -> str:
    """A memory limit in GiB that ``workers`` processes needing ``need`` bytes each fit (the
    next whole number does not)."""
    return f"{need * (workers + 0.5) / 2**30:.6g}"


@pytest.mark.parametrize("workers,fit", [(2, 1), (3, 2)])
def test_a_memory_refusal_with_workers_names_the_workers_that_fit(workers, fit, tmp_path, capsys):
    # before: "...; reduce chunk, trials or the sizes in the study file", no word of workers
    st, need = _network(tmp_path)
    args = ["run", str(st), "--no-figures", "--out", str(tmp_path / "o"), "--quiet"]
    args += ["--workers", str(workers), "--max-memory-gb", _limit_for(need, fit)]
    line = one_line(capsys, main(args), f"each of {workers} worker processes", "GiB limit")
    assert f"; use --workers {fit}, or reduce " in line, line
    assert not (tmp_path / "o").exists()


def test_the_api_names_its_workers_argument(tmp_path, monkeypatch):
    st, need = _network(tmp_path)
    monkeypatch.setenv("SIM_MAX_MEMORY_GB", _limit_for(need, 1))
    with pytest.raises(ConfigError) as e:
        sim.load(st).run(out=tmp_path / "o", workers=2, figures=False)
    words = str(e.value)
    assert "; use workers=1, or reduce " in words and "--" not in words, words


def test_a_memory_refusal_with_one_worker_is_as_before(tmp_path, capsys):
    # held: one worker over the limit is refused before the build, naming the network's size
    st, need = _network(tmp_path)
    args = ["run", str(st), "--no-figures", "--out", str(tmp_path / "o")]
    args += ["--max-memory-gb", _limit_for(need, 0)]
    line = one_line(capsys, main(args), "network.grids: ", "GiB memory limit")
    assert "worker" not in line and line.endswith("use fewer points or observations"), line


#: pickles of :class:`_Held` in this process
PICKLED: list = []


class _Held:
    """What a network's chunk function holds (its network and factor), counted as pickled."""

    def __init__(self, n: int):
        self.a = np.arange(n, dtype=float)

    def __reduce__(self):
        PICKLED.append(1)
        return (_Held._of, (self.a,))

    @staticmethod
    def _of(a):
        h = _Held.__new__(_Held)
        h.a = a
        return h


def _chunk(rng, n, held):
    return {"x": rng.normal(size=n) + held.a[:n]}


@pytest.mark.long
def test_dask_sends_the_chunk_function_once(tmp_path):
    # before: the function with every task: pickled once a chunk, and Dask's "Sending large
    # graph of size 48.8 MiB" warning (6 lines) for four chunks of a 12 MiB function
    pytest.importorskip("distributed")
    fn = functools.partial(_chunk, held=_Held(1_600_000))  # 12.2 MiB pickled
    assert len(pickle.dumps(fn)) > 12 * 2**20
    want = run_chunks(fn, 8, 3, 2, quiet=True)
    ex = make_executor("dask", 1)
    try:
        PICKLED.clear()
        with warnings.catch_warnings():
            warnings.simplefilter("error")  # the large graph's UserWarning fails the test
            got = run_chunks(fn, 8, 3, 2, ctx=RunContext(quiet=True, executor=ex))
    finally:
        ex.close()
    assert np.array_equal(want["x"], got["x"])
    assert len(PICKLED) <= 2, len(PICKLED)  # the check that it pickles, and the scatter


@pytest.mark.long
def test_under_ulimit_v_arrow_does_not_map_the_room(tmp_path):
    # before: the address space grew by 1.3 GiB in the run (mimalloc's reservation), the
    # pool "mimalloc"
    st, need = _network(tmp_path)
    proc = python_lines(
        "import resource",
        "resource.setrlimit(resource.RLIMIT_AS, (6 << 30, resource.RLIM_INFINITY))",
        "import sim, pyarrow as pa",
        "from sim.room import mapped_bytes",
        f"h = sim.load({str(st)!r})",
        "before = mapped_bytes()",
        f"h.run(out={str(tmp_path / 'o')!r}, figures=False)",
        "peak = int(open('/proc/self/status').read().split('VmPeak:')[1].split()[0]) << 10",
        "print(pa.default_memory_pool().backend_name, (peak - before) / 2**30)",
    )
    assert proc.returncode == 0, proc.stderr
    pool, grew = proc.stdout.split()
    assert pool == "system" and float(grew) < 0.5, proc.stdout
