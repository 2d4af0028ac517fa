"""The classes of the thirteenth fresh sweep of bad inputs (issue 26, doors15: resource
limits, file-system shapes, concurrency, the make targets, clock and identity), one case each;
each failed on the code before its fix.

* a write cut short by the system (``ulimit -f``: EFBIG; a full disk) named no file: "sim:
  error: Error writing bytes to file. Detail: [errno 27] File too large" or "File too large"
  (:func:`sim.mc.storage.atomic_path` now names the file it was writing);
* ``python -m sim.batch`` that cannot start a run (``ulimit -n`` too low: no pipe; ``ulimit
  -u``: no process) ended in a traceback from ``subprocess`` (:func:`sim.batch.run_all`);
* ``--executor dask`` under a low ``ulimit -n`` printed some 1,800 lines of its monitors'
  tracebacks, or spun for minutes without ending (:func:`sim.mc.executors._enough_files`).
"""

from __future__ import annotations

import os
import resource
import signal
import subprocess
import sys
from pathlib import Path

import pytest
from oneline import one_line, one_line_of

from sim import batch, cli, cli_check, threads
from sim.mc import executors, outputs, storage
from sim.mc import publish as publishing
from sim.mc.storage import atomic_path, read_record, write_record

ROOT = Path(__file__).resolve().parent.parent


@pytest.mark.parametrize(
    "error",
    [
        OSError(27, "File too large"),  # Path.write_text under ulimit -f
        OSError("Error writing bytes to file. Detail: [errno 27] File too large"),  # pyarrow
    ],
)
def test_a_write_cut_short_names_its_file(tmp_path, error):
    target = tmp_path / "chunk-000003.parquet"
    with pytest.raises(OSError) as got:
        with atomic_path(target) as tmp:
            tmp.write_bytes(b"part")
            raise error
    assert got.value.filename == str(target)
    assert got.value.errno == 27 and got.value.strerror == "File too large"
    assert list(tmp_path.iterdir()) == []  # no temporary left behind


def test_a_batch_that_cannot_start_its_runs_says_so_in_one_line(tmp_path, monkeypatch, capsys):
    def no_pipes(*args, **kwargs):
        raise OSError(24, "Too many open files")

    monkeypatch.setattr(subprocess, "Popen", no_pipes)
    files = [str(ROOT / "studies" / f) for f in ("salsig_encoders.toml", "wolf_polynomial.toml")]
    assert batch.main(["--results", str(tmp_path / "r"), *files]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 2 and all("cannot start its run: Too many open files" in e for e in err)
    assert {e.split(":")[1].strip() for e in err} == {
        "salsig_encoders.toml",
        "wolf_polynomial.toml",
    }


def test_dask_is_not_started_under_too_few_open_files(monkeypatch):
    started = []
    # imported before getrlimit is patched: distributed fixes its MEMORY_LIMIT at import from
    # the hard ulimit -m, and 1024 bytes there broke every later Dask run of this process
    pytest.importorskip("dask.distributed")
    real = resource.getrlimit
    monkeypatch.setattr(
        resource, "getrlimit", lambda w: (40, 1024) if w == resource.RLIMIT_NOFILE else real(w)
    )
    monkeypatch.setattr("dask.distributed.LocalCluster", lambda *a, **k: started.append(1))
    with pytest.raises(RuntimeError, match="needs at least 64 open files, and ulimit -n is 40"):
        executors.make_executor("dask", 2, None)
    assert not started


def test_a_library_that_cannot_be_mapped_ends_in_one_line_not_a_traceback(tmp_path):
    """``ulimit -v``: a library imported while an entry point loads cannot be mapped
    (ImportError "failed to map segment from shared object", or a MemoryError), which was a
    traceback and then a crash (SIGSEGV) as Python shut down."""
    code = (
        "from sim.threads import interrupt_while_loading\n"
        "interrupt_while_loading('sim')\n"
        "raise ImportError('/x/_sparsetools.so: failed to map segment from shared object')\n"
    )
    limit = 64 * 2**30  # a limit of address space, far above what this needs

    def cap():
        resource.setrlimit(resource.RLIMIT_AS, (limit, limit))

    got = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, preexec_fn=cap, cwd=ROOT
    )
    assert got.returncode == 2, got.stderr
    assert (
        got.stderr
        == f"sim: error: not enough memory to load the suite and its libraries (ulimit -v is {limit // 1024} kB)\n"
    )


def test_a_library_loaded_in_a_run_short_of_memory_is_named_as_such(monkeypatch, capsys):
    """llvmlite, loaded when the first kernel compiles, says "Could not find/load shared object
    file" when it cannot be mapped: that was the one line, blaming a missing file."""

    def no_room(args):
        raise OSError("Could not find/load shared object file 'libllvmlite.so' from resource")

    monkeypatch.setattr(cli_check, "check", no_room)
    # 2 GiB: under 1 GiB sim.cli.main refuses to start, as the sim command does (doors39r)
    real = resource.getrlimit  # ulimit -v only: a library imported now keeps what it reads
    monkeypatch.setattr(
        threads.resource,
        "getrlimit",
        lambda w: (2**31, 2**31) if w == resource.RLIMIT_AS else real(w),
    )
    err = one_line(capsys, cli.main(["check", str(ROOT / "studies" / "salsig_encoders.toml")]))
    assert err == (
        "sim: error: not enough memory to load the suite and its libraries (ulimit -v is 2097152 kB)"
    )


def test_old_results_that_cannot_be_removed_are_named(tmp_path, monkeypatch, capsys):
    """``--overwrite`` by a user who may replace the results directory (its parent is
    writable) but not remove what is in it: the run ended with exit 0 and left the old results
    in a hidden ``.<name>.old.<pid>`` without a word."""
    out, stage = tmp_path / "res", tmp_path / ".res.partial"
    for d, seed in ((out, 1), (stage, 2)):
        (d / "trials").mkdir(parents=True)
        write_record(d, {"config": {"seed": seed}, "code_hash": "x", "files": []})
    (out / "trials" / "chunk-000000.parquet").write_bytes(b"old")
    monkeypatch.setattr(publishing.shutil, "rmtree", lambda p, ignore_errors=False: None)
    publishing.publish(stage, out)
    assert read_record(out)["config"] == {"seed": 2}
    err = capsys.readouterr().err.strip().splitlines()
    old = outputs.swap_dir(out)
    assert old.is_dir() and len(err) == 1
    assert err[0].startswith(f"sim: note: the replaced results are kept in {old} (")
    assert "chunk-000000.parquet could not be removed" in err[0]


def test_a_command_under_too_small_an_address_space_does_not_start():
    """``ulimit -v 500000``: a small network study ran for hours (OpenBLAS retried every
    failed allocation inside SuperLU); the entry points now refuse to start below 1 GiB."""
    code = "from sim.threads import refuse_bad_environment\nrefuse_bad_environment('sim')\n"

    def cap():
        resource.setrlimit(resource.RLIMIT_AS, (500_000 * 1024, 500_000 * 1024))

    got = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, preexec_fn=cap, cwd=ROOT
    )
    one_line_of(got, prefix="sim: error: not enough memory: ulimit -v is 500000 kB")


def test_the_soft_cpu_limit_ends_a_command_in_one_line(monkeypatch, capsys):
    """``ulimit -S -t``: SIGXCPU killed a run ("CPU time limit exceeded", exit 152) with no line
    of its own; it now ends as Ctrl-C does, naming the limit (the chunks finished are kept)."""

    def busy(args):
        os.kill(os.getpid(), signal.SIGXCPU)
        for _ in range(10**7):  # the handler runs between two bytecodes
            pass
        raise AssertionError("SIGXCPU was not handled")

    before = signal.getsignal(signal.SIGXCPU)
    monkeypatch.setattr(cli_check, "check", busy)
    rc = cli.main(["check", str(ROOT / "studies" / "salsig_encoders.toml")])
    assert one_line(capsys, rc, code=130) == "sim: interrupted by the CPU time limit (ulimit -t)"
    assert signal.getsignal(signal.SIGXCPU) == before  # in-process callers get theirs back


@pytest.mark.parametrize("var", ["FUZZ_CASES=0", "FUZZ_CASES=-1", "FUZZ_CASES=abc", "FUZZ_SEED=x"])
def test_make_fuzz_refuses_a_count_that_fuzzes_nothing(var):
    """``make fuzz FUZZ_CASES=0`` (or -1) fuzzed nothing and passed; ``FUZZ_CASES=abc`` was a
    pytest collection error. Checked before pytest starts (``-o`` keeps the venv's stamp)."""
    got = subprocess.run(
        ["make", "-s", "-o", ".venv/.installed", "fuzz", var],
        cwd=ROOT,
        capture_output=True,
        text=True,
        timeout=60,
    )
    assert got.returncode == 2
    name = var.split("=")[0]
    assert got.stderr.splitlines()[0].startswith(f"make fuzz: {name} must be a whole number")


def test_a_git_that_prints_bytes_not_utf8_is_no_commit(tmp_path, monkeypatch):
    """A ``git`` on PATH that prints bytes not UTF-8 (a wrapper; a Latin-1 file name with
    ``core.quotePath=false``) ended every run in "UnicodeDecodeError", exit 2; its words
    (not a commit hash) were the recorded commit otherwise."""
    fake = tmp_path / "git"
    fake.write_text("#!/bin/sh\nprintf '\\377\\376 not a commit\\n'\n")
    fake.chmod(0o755)
    monkeypatch.setenv("PATH", f"{tmp_path}{os.pathsep}{os.environ['PATH']}")
    storage.git_commit.cache_clear()
    try:
        assert storage.git_commit("salsig_encoders") == "unknown"
        assert storage.git_commit() == "unknown"
    finally:
        storage.git_commit.cache_clear()
