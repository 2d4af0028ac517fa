"""Helper t43: an order-dependent failure of ``test_doors41m``'s Dask test, and the limit behind
it; one case per class found, each failing on the code before its fix.

* ``distributed`` fixes the machine's memory once, at its import, as the least of the host's
  memory, the cgroup's and the hard ``ulimit -m`` (RLIMIT_RSS), and sizes from it its
  workers' memory limit (paused at 80 %, restarted at 95 %) and its largest message (half of
  it, as a float). Linux does not enforce ``ulimit -m``, so the run would fit, but
  ``sim run --executor dask`` under ``ulimit -m 200`` ended in a 63-line tornado traceback
  ("cannot convert 'float' object to bytearray") before its one line, under ``ulimit -m
  100000`` in "CommClosedError: ... Stream is closed", and under ``ulimit -m 400000`` it
  hung (past 120 s; 3.4 s without the limit). A Python process that lowers the limit after a
  first Dask run hands it to its next LocalCluster's workers all the same. Dask is now
  refused in one line when it would take the limit for the memory (from the limit of the
  moment, :func:`sim.mc.executors._rss_limit_not_taken`). The test run found it because
  ``test_doors15`` imported ``distributed`` first while ``resource.getrlimit`` was patched to
  answer 1024 for every limit: that test now imports it first and patches ``RLIMIT_NOFILE``
  only (and its ``ulimit -v`` test ``RLIMIT_AS`` only, not every limit at 2 GiB).
"""

from __future__ import annotations

import resource
import subprocess
import sys
from pathlib import Path

import pytest
from oneline import one_line_of, python_lines

ROOT = Path(__file__).resolve().parent.parent
STUDY = ROOT / "studies" / "brown_table1.toml"


def _rss(kb: int):
    def cap():
        resource.setrlimit(resource.RLIMIT_RSS, (kb << 10, kb << 10))

    return cap


def test_dask_under_ulimit_m_is_refused_in_one_line(tmp_path):
    # before: 63 lines of tornado's traceback, then "cannot start the dask executor: cannot
    # convert 'float' object to bytearray"
    pytest.importorskip("distributed")
    args = ["run", str(STUDY), "--executor", "dask", "--trials", "40", "--chunk", "2"]
    args += ["--no-figures", "--out", str(tmp_path / "o")]
    proc = subprocess.run(
        [sys.executable, "-m", "sim", *args],
        capture_output=True,
        text=True,
        preexec_fn=_rss(200),
        cwd=ROOT,
        timeout=120,
    )
    one_line_of(proc, "Dask takes ulimit -m (200 kB) for this machine's memory", "--executor local")
    assert not (tmp_path / "o").exists()


def test_the_api_refuses_dask_under_a_limit_set_after_its_import(tmp_path):
    # before: distributed, imported before the limit, did not see it, but the LocalCluster's
    # workers (spawned under it) did: the same failures as above, from the same process
    pytest.importorskip("distributed")
    proc = python_lines(
        "import resource, sim, distributed",
        "resource.setrlimit(resource.RLIMIT_RSS, (200 << 10, 200 << 10))",
        f"st = sim.load({str(STUDY)!r}, trials=40, chunk=2)",
        "try:",
        f"    st.run(executor='dask', out={str(tmp_path / 'o')!r}, figures=False)",
        "except sim.ConfigError as e:",
        "    print(e)",
    )
    assert proc.returncode == 0 and proc.stderr == "", proc.stderr
    assert "Dask takes ulimit -m (200 kB)" in proc.stdout, proc.stdout
