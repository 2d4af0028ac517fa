"""BLAS single-threaded in the test processes, as in every ``sim`` process (:mod:`sim.threads`):
the tests compare in-process runs with runs in worker processes bit for bit."""

import os
import resource

import pytest

from sim.threads import single_threaded_blas

single_threaded_blas()

#: SIM_TEST_CPU_LOG=FILE: append each test's CPU seconds (its process and the subprocesses it
#: waited for, setup and teardown included) to FILE as "nodeid<TAB>seconds". CPU time, not
#: wall time: on a shared machine the wall time of a test says more about the load than about
#: the test. Sum per file to see where `make test` spends its time.
CPU_LOG = os.environ.get("SIM_TEST_CPU_LOG")


def _cpu_s() -> float:
    own, kids = (
        resource.getrusage(resource.RUSAGE_SELF),
        resource.getrusage(resource.RUSAGE_CHILDREN),
    )
    return own.ru_utime + own.ru_stime + kids.ru_utime + kids.ru_stime


@pytest.hookimpl(hookwrapper=True)
def pytest_runtest_protocol(item, nextitem):
    t0 = _cpu_s() if CPU_LOG else 0.0
    yield
    if CPU_LOG:
        with open(CPU_LOG, "a") as f:  # one short line per write: safe from several workers
            f.write(f"{item.nodeid}\t{_cpu_s() - t0:.2f}\n")


#: the test files that take longest, slowest first, with their share (%) of the suite's
#: summed test time (measured 2026-11-26 on 2 cores: pytest --durations, per file). Under
#: ``--dist loadfile`` a file runs on one process; handing out the slowest files first keeps
#: one of them from starting last and running alone at the end (the critical path). The
#: Makefile passes --no-loadscope-reorder, or pytest-xdist would hand out the files with
#: the most tests first instead.
SLOW_FIRST = {
    "test_all_studies.py": 21.8,
    "test_verify.py": 16.2,
    "test_docs.py": 15.7,
    "test_bench.py": 5.3,
    "test_no_jit.py": 4.4,
    "test_runner.py": 4.2,
    "test_sparse.py": 3.3,
    "test_design.py": 3.2,
    "test_network.py": 3.1,
    "test_figures.py": 2.8,
    "test_bayes.py": 2.4,
    "test_cli.py": 2.4,
    "test_api.py": 2.2,
    "test_batch.py": 2.1,
}


def pytest_collection_modifyitems(config, items):
    """The slowest files first (SLOW_FIRST), the others after them in their usual order; the
    tests of a file keep their order. Deterministic, so every xdist worker collects the same."""
    rank = {f: i for i, f in enumerate(sorted(SLOW_FIRST, key=lambda f: -SLOW_FIRST[f]))}
    items.sort(key=lambda it: rank.get(it.path.name, len(rank)))
