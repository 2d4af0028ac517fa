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

import resource
import subprocess
from pathlib import Path

import pytest

from sim import batch
from sim.mc import executors
from sim.mc.storage import atomic_path

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
    monkeypatch.setattr(resource, "getrlimit", lambda what: (40, 1024))
    pytest.importorskip("dask.distributed")
    monkeypatch.setattr("dask.distributed.LocalCluster", lambda *a, **k: started.append(1))
    with pytest.raises(RuntimeError, match="needs at least 64 open files, and ulimit -n is 40"):
        executors.make_executor("dask", 2, None)
    assert not started
