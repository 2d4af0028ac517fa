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


def test_verify_set_checked_at_the_reruns_trials():
    """``make verify --trials N --set K=V`` (``--set`` is only allowed with ``--trials``): the
    pre-check of R53 asked ``sim check`` with the study file's trials, not the re-runs' N.
    Before, ``--trials 40000 --set chunk=1000`` of brown_dilution (40 chunks, as its re-run
    takes it) was refused before any re-run ("4,000 trials in chunks of 1,000 give 4 chunks"),
    and ``--trials 400 --set chunk=100`` (4 chunks: its re-run refuses it) passed the check.
    Now the check takes ``--trials`` as the re-run does: the first passes, the second is
    refused naming ``chunk``, the re-runs' 400 trials and the study file."""
    from pathlib import Path

    from sim.report.verify.child import set_refusal

    files = [("brown_dilution", Path("studies/brown_dilution.toml"))]
    assert set_refusal(files, ["--trials", "40000", "--set", "chunk=1000"]) is None
    why = set_refusal(files, ["--trials", "400", "--set", "chunk=100"])
    assert why is not None and "\n" not in why
    assert "chunk: 400 trials" in why and "brown_dilution.toml" in why
    assert "--trials 400" in why
