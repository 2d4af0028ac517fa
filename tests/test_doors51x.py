"""Doors of R54 (issue 26, third wave): a hostile reading of the second and third merges --
verify's refusal of a record it did not write, its ``--set`` pre-check, ``sim --version``
alone, the README sha256 list of a run being written, and ``sim.batch --jobs``'s memory gate."""

from __future__ import annotations

import os
import threading

import pytest

from sim.report.verify import cli as verify_cli


@pytest.mark.skipif(not hasattr(os, "mkfifo"), reason="needs FIFOs")
def test_verify_fifo_as_record_refused_not_hung(tmp_path, capsys):
    """A FIFO in the record's place (``results/reproducibility.parquet``: a pipe a user or a
    script left there). Before, make verify's check that the file there is a record of its own
    opened it for reading and hung before any re-run, deaf to Ctrl-C and SIGTERM (both held
    while the open is retried). Now one line names it (not a regular file), exit 2, the FIFO
    kept."""
    res = tmp_path / "results"
    res.mkdir()
    fifo = res / "reproducibility.parquet"
    os.mkfifo(fifo)
    got = {}
    argv = ["--results", str(res), "--scratch", str(tmp_path / "scr")]
    t = threading.Thread(target=lambda: got.setdefault("code", verify_cli.main(argv)), daemon=True)
    t.start()
    t.join(30)  # (returns at once when fixed; the code before this fix never returned)
    if t.is_alive():  # release the hung open (a writer comes and goes), then fail
        fd = os.open(fifo, os.O_WRONLY)
        os.close(fd)
        t.join(30)
        pytest.fail("make verify hung on a FIFO in the record's place")
    err = capsys.readouterr().err.strip().splitlines()
    assert got["code"] == 2
    assert len(err) == 1 and "reproducibility.parquet" in err[0], err
    assert "not a regular file" in err[0] and "Traceback" not in err[0]
    assert fifo.exists() and not fifo.is_file()  # kept, a FIFO still
