"""BLAS single-threaded in the test processes, as in every ``sim`` process (:mod:`sim.threads`):
the tests compare in-process runs with runs in worker processes bit for bit.

:func:`tiny_run`: each study file run once per test session at its tiny size, shared by the
tests that read a whole study's output (test_all_studies, test_verify, test_docs and the
studies' own end-to-end tests), across the processes of ``pytest -n``."""

import fcntl
import os
import re
import resource
import signal
import subprocess
import sys
import threading
import tomllib
from pathlib import Path

import pytest

from sim.threads import single_threaded_blas

single_threaded_blas()

# A shell without job control starts a background job (`make test &`, a CI step's `&`) with
# SIGINT ignored, and every child inherits that: the tests of what a command does on Ctrl-C
# (a terminal's foreground process) would then see a SIGINT the caller ignores. The tests run
# as from a terminal, however they were started.
if signal.getsignal(signal.SIGINT) is signal.SIG_IGN:
    signal.signal(signal.SIGINT, signal.default_int_handler)
# The same for SIGHUP under `nohup make test`: the commands keep a SIGHUP their caller ignores
# ignored (as they should), and the tests of what a closed terminal does saw no signal at all.
if signal.getsignal(signal.SIGHUP) is signal.SIG_IGN:
    signal.signal(signal.SIGHUP, signal.SIG_DFL)

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


#: the handlers a test must give back: a test process whose SIGINT is left ignored passes that
#: on to every child it starts, and a later test of Ctrl-C in a child then fails
SIGNALS = (signal.SIGINT, signal.SIGTERM, signal.SIGHUP)


@pytest.fixture(autouse=True)
def _gives_signal_handlers_back():
    """Every test leaves the process's signal handlers as it found them (a command called in
    process restores its own); one that does not fails, naming the signal, and they are put
    back so that the tests after it are not affected."""
    before = {s: signal.getsignal(s) for s in SIGNALS}
    yield
    changed = [s for s in SIGNALS if signal.getsignal(s) is not before[s]]
    for s in changed:
        signal.signal(s, before[s])
    if changed:
        pytest.fail(
            f"the test left the handler of {', '.join(signal.Signals(s).name for s in changed)} changed"
        )


@pytest.hookimpl(hookwrapper=True)
def pytest_runtest_protocol(item, nextitem):
    t0 = _cpu_s() if CPU_LOG else 0.0
    yield
    if CPU_LOG:
        with open(CPU_LOG, "a") as f:  # one short line per write: safe from several workers
            f.write(f"{item.nodeid}\t{_cpu_s() - t0:.2f}\n")


#: the test files that take longest, slowest first, with their share (%) of the suite's
#: summed test CPU time (measured 2026-11-30 on 2 cores: SIM_TEST_CPU_LOG, per file, the tests
#: marked long left out; a shared tiny run counts for the file that asks for it first). Under ``--dist loadfile`` a file runs
#: on one process; handing out the slowest files first keeps one of them from starting last
#: and running alone at the end (the critical path). The Makefile passes
#: --no-loadscope-reorder, or pytest-xdist would hand out the files with the most tests first
#: instead.
SLOW_FIRST = {
    "test_docs.py": 11.5,
    "test_fuzz.py": 5.0,
    "test_verify.py": 3.7,
    "test_doors22b.py": 3.6,
    "test_left12.py": 2.7,
    "test_cli_manners.py": 2.6,
    "test_cli.py": 2.5,
    "test_all_studies.py": 2.1,
    "test_batch.py": 1.9,
    "test_network.py": 1.9,
    "test_doors28a.py": 1.6,
    "test_doors_sweep.py": 1.6,
    "test_runner.py": 1.6,
    "test_left8.py": 1.5,
}


#: ``SIM_LONG_TESTS=1`` (``make fuzz`` sets it) runs the tests marked ``long``: hostile-input
#: cases of many seconds each (a file-size limit hit mid-run, a Dask cluster signalled while it
#: starts, grids of thousands of points) whose class a faster test of ``make test`` also guards.
#: Without it they are skipped, naming ``make fuzz``, so that ``make test`` stays in its budget.
LONG_TESTS = os.environ.get("SIM_LONG_TESTS", "") not in ("", "0")


def long_params(values, long) -> list:
    """``values`` for ``pytest.mark.parametrize``, those in ``long`` marked ``long`` (make fuzz
    runs them): the cheaper values guard the same property in ``make test``."""
    return [pytest.param(v, marks=pytest.mark.long) if v in long else v for v in values]


def pytest_configure(config):
    config.addinivalue_line(
        "markers", "long: a slow hostile-input test, run by make fuzz (SIM_LONG_TESTS=1)"
    )


def pytest_collection_modifyitems(config, items):
    """The slowest files first (SLOW_FIRST), the others after them in their usual order; the
    tests of a file keep their order. Deterministic, so every xdist worker collects the same.
    Tests marked ``long`` are skipped unless ``SIM_LONG_TESTS=1`` (:data:`LONG_TESTS`)."""
    rank = {f: i for i, f in enumerate(sorted(SLOW_FIRST, key=lambda f: -SLOW_FIRST[f]))}
    items.sort(key=lambda it: rank.get(it.path.name, len(rank)))
    if not LONG_TESTS:
        skip = pytest.mark.skip(reason="long: make fuzz runs it (SIM_LONG_TESTS=1)")
        for it in items:
            if it.get_closest_marker("long"):
                it.add_marker(skip)


ROOT = Path(__file__).resolve().parent.parent
TINY = ROOT / "tests" / "data" / "tiny"


def tiny_overrides(study: str) -> list[str]:
    """The ``--set`` arguments of a study kind's tiny configuration (``tests/data/tiny/``):
    a run of a few seconds with at least two chunks."""
    f = TINY / f"{study}.txt"
    assert f.is_file(), f"{f} is missing: every study needs a tiny configuration"
    lines = [ln.strip() for ln in f.read_text().splitlines()]
    return [a for ln in lines if ln and not ln.startswith("#") for a in ("--set", ln)]


# A network of three points (two fixed), 40 trials in chunks of 2: the smallest study a sweep or
# a publish can be tried on in a second (tests/test_doors37s.py, 39s.py, 41c.py).
TRIANGLE_NETWORK = """\
study = "network"
trials = 40
chunk = 2
[network]
points = [ { name = "A", x_mm = 0.0, y_mm = 0.0, role = "fixed" },
           { name = "B", x_mm = 1000.0, y_mm = 0.0, role = "fixed" },
           { name = "C", x_mm = 400.0, y_mm = 700.0 } ]
generate = [ { kind = "distance", from = "*", to = "*", sigma_mm = 0.01 } ]
"""


def grid_network(tmp_path: Path, side: int = 20) -> tuple[Path, float]:
    """A side x side trilateration grid (nearest 8, inner datum): its study file and the bytes
    its run's estimate needs (tests/test_doors39m.py, 40m.py)."""
    from sim.mc.config import validate
    from sim.mc.network_size import network_estimate
    from sim.studies import get_study

    st = tmp_path / "grid.toml"
    st.write_text(
        'study = "network"\ntrials = 40\nchunk = 2\n[network]\ngrids = [ { prefix = "G", '
        f'nx = {side}, ny = {side}, spacing_m = 100.0 }} ]\ngenerate = [ {{ kind = "distance", '
        'from = "G*", to = "G*", nearest = 8, sigma_mm = 2.0 } ]\n[datum]\nkind = "inner"\n'
    )
    flat = {
        "trials": 40,
        "chunk": 2,
        "network.grids": [{"prefix": "G", "nx": side, "ny": side, "spacing_m": 100.0}],
        "network.generate": [
            {"kind": "distance", "from": "G*", "to": "G*", "nearest": 8, "sigma_mm": 2.0}
        ],
        "datum.kind": "inner",
    }
    return st, network_estimate(validate(flat, get_study("network").schema, None))[3]


def on_a_terminal(
    args: list[str], timeout: float, rows_cols: tuple[int, int] | None = None
) -> tuple[int, bytes, list[tuple[float, bytes]]]:
    """Run ``python -m sim ARGS`` with standard error on a pseudo-terminal (the progress bar
    draws there; ``rows_cols``: its size, as ``stty rows R cols C``); its exit code, what it
    drew, and each read with its time since the start (tests/test_doors41l.py, 42b.py)."""
    import pty
    import struct
    import termios
    import time

    m, s = pty.openpty()
    if rows_cols is not None:
        fcntl.ioctl(s, termios.TIOCSWINSZ, struct.pack("HHHH", *rows_cols, 0, 0))
    t0 = time.monotonic()
    proc = subprocess.Popen(
        [sys.executable, "-m", "sim", *args], stdin=s, stdout=subprocess.DEVNULL, stderr=s, cwd=ROOT
    )
    os.close(s)
    seen, got = b"", []
    while True:
        try:
            data = os.read(m, 65536)
        except OSError:  # the terminal's other end closed: the run ended
            break
        if not data:
            break
        seen += data
        got.append((time.monotonic() - t0, data))
    os.close(m)
    return proc.wait(timeout=timeout), seen, got


def study_of(path: Path) -> str:
    """The study kind a study file runs (its ``study`` key)."""
    return tomllib.loads(path.read_text()).get("study", "")


def tiny_command(name: str, out: Path, workers: int = 1, *extra: str) -> list[str]:
    """``sim run studies/<name>.toml`` at its study's tiny size into ``out``."""
    f = ROOT / "studies" / f"{name}.toml"
    return [sys.executable, "-m", "sim", "run", str(f), "--out", str(out), "--quiet"] + [
        "--workers",
        str(workers),
        *extra,
        *tiny_overrides(study_of(f)),
    ]


#: another numerical path: OpenBLAS's AVX kernels (no AVX2/AVX-512), NumPy instead of numba
ELSEWHERE = {"OPENBLAS_CORETYPE": "Sandybridge", "SIM_NO_JIT": "1"}


def tiny_cache(base: Path) -> Path:
    """The directory of the session's shared tiny runs: under the controller's base temporary
    directory, which every ``pytest -n`` process shares (a worker's base lies inside it)."""
    cache = (base.parent if os.environ.get("PYTEST_XDIST_WORKER") else base) / "tiny-runs"
    cache.mkdir(exist_ok=True)
    return cache


def shared_tiny_run(cache: Path, name: str, *options: str, elsewhere: bool = False) -> Path:
    """The shared tiny run of ``studies/<name>.toml`` with ``options`` in ``cache``, made by
    the first process that asks for it (a lock per run; a failure recorded once): see
    :func:`tiny_run`."""
    key = "_".join([name, *(o.strip("-").replace("=", "-") for o in options)])
    key = f"{key}-elsewhere" if elsewhere else key
    assert re.fullmatch(r"[\w.-]+", key), f"options {options} make no directory name"
    out, failed = cache / key, cache / f"{key}.failed"
    env = dict(os.environ)
    if elsewhere:
        env.update(ELSEWHERE)
    if elsewhere or options:  # tables only: the figures are the plain run's
        options = (*options, "--no-figures")
    else:
        env.update(SIM_FIGURE_CHECK=str(cache / f"{key}.figures.jsonl"))
    with open(cache / f"{key}.lock", "w") as lock:
        fcntl.flock(lock, fcntl.LOCK_EX)  # released when the file closes
        if not out.exists() and not failed.exists():
            cmd = tiny_command(name, out, 2 if elsewhere else 1, *options)
            r = subprocess.run(cmd, cwd=ROOT, env=env, capture_output=True, text=True, timeout=600)
            if r.returncode != 0:
                failed.write_text(f"exit {r.returncode}\n{r.stderr[-3000:]}")
    if failed.exists():
        pytest.fail(f"the shared tiny run {key} failed: {failed.read_text()}")
    return out


@pytest.fixture(scope="session")
def tiny_run(tmp_path_factory):
    """``tiny_run(name, *options)``: the output directory of ``studies/<name>.toml`` run at
    its tiny size on 1 worker with ``options`` (more ``sim run`` options, e.g. ``--executor
    dask --workers 2``; :func:`tiny_command`), run once per session and shared by every test
    (and every ``pytest -n`` process: a directory of the session's base, a lock per run, a
    failure recorded once). Without options, every figure's layout check and facts are
    written to ``<dir>.figures.jsonl`` (``SIM_FIGURE_CHECK``, :func:`sim.report.plotting.save`:
    the check runs after the PNG is written and leaves it as it is). With options, and with
    ``elsewhere=True`` (on 2 workers on another numerical path, :data:`ELSEWHERE`), the run
    draws no figures (``--no-figures``): its tables are compared, and the figures are drawn by
    the plain run.
    READ ONLY: a test that edits a file copies it first."""
    cache = tiny_cache(tmp_path_factory.getbasetemp())

    def run(name: str, *options: str, elsewhere: bool = False) -> Path:
        return shared_tiny_run(cache, name, *options, elsewhere=elsewhere)

    return run


#: the shared tiny runs that compile the suite's numba kernels (on a fresh clone no kernel is
#: in numba's cache yet): Brown's multilateration kernel (about 11 s of CPU), Wolf's error
#: field and polynomial fit, Agnard's group kernels. ``make test`` (``pytest -n``, the whole
#: suite) makes them first, two lines side by side in its controlling process, so that each
#: kernel is compiled once, and not by several processes that start before its cache is
#: written. The test processes start meanwhile and wait for a run they need (its lock).
FIRST_RUNS = (("brown_table1", "brown_design"), ("wolf_polynomial", "agnard_block"))
_FIRST: list = []


def pytest_sessionstart(session):
    config = session.config
    whole = config.args_source is pytest.Config.ArgsSource.TESTPATHS
    if hasattr(config, "workerinput") or not whole or not config.getoption("numprocesses", 0):
        return
    cache = tiny_cache(config._tmp_path_factory.getbasetemp())

    def make(names):
        for name in names:
            try:
                shared_tiny_run(cache, name)
            except BaseException:  # recorded in <run>.failed; the test that needs it says so
                pass

    for names in FIRST_RUNS:
        t = threading.Thread(target=make, args=(names,), daemon=True)
        t.start()
        _FIRST.append(t)


def pytest_sessionfinish(session):
    for t in _FIRST:
        t.join()
