"""The classes of the sweep doors28c (brief D28c: ``make verify`` and ``sim report`` during a
``make reproduce`` that really re-runs studies, and results that travel: copied, renamed,
moved under a link, read-only, made at another commit), one case each; each failed on the code
before its fix. Copies (``cp -a``, ``tar`` without times, a ``git clone``), a renamed or
linked results directory, an extra directory, a figure deleted and a table of another seed
were all right already.

* a results tree on a read-only mount (a clone checked out read-only, a bind mount): ``sim
  report`` (and the report step of ``make verify``) said "Read-only file system:
  results/agnard_block/.README.md.22149.tmp", a file the user never saw: removing the
  temporary that could not be made failed too there (EROFS, not ENOENT), and that error
  replaced the one being reported (:class:`sim.mc.storage.atomic_path`).
"""

import errno
import os
import pathlib
import shutil
from pathlib import Path

from oneline import SIM_ERROR, one_line

from sim.cli import main


def _read_only(monkeypatch, top: Path) -> None:
    """Everything under ``top`` as on a read-only mount (``mount -o remount,ro,bind``): writing
    a file there and removing one, even one that is not there, is EROFS (root writes through
    every mode bit, and a test may not mount, so the test says it)."""

    def under(p) -> bool:
        return Path(os.fsdecode(p)).resolve().is_relative_to(top.resolve())

    real_unlink, real_write_text = os.unlink, pathlib.Path.write_text

    def unlink(p, *a, **k):
        if under(p):
            raise OSError(errno.EROFS, "Read-only file system", os.fsdecode(p))
        return real_unlink(p, *a, **k)

    def write_text(self, *a, **k):
        if under(self):
            raise OSError(errno.EROFS, "Read-only file system", str(self))
        return real_write_text(self, *a, **k)

    monkeypatch.setattr(os, "unlink", unlink)
    monkeypatch.setattr(pathlib.Path, "write_text", write_text)


def test_sim_report_on_a_read_only_mount_names_the_readme_not_its_temporary(
    tiny_run, tmp_path, monkeypatch, capsys
):
    results = tmp_path / "results"
    shutil.copytree(tiny_run("network_plate"), results / "network_plate")
    before = {p: p.read_bytes() for p in results.rglob("*") if p.is_file()}
    _read_only(monkeypatch, results)
    rc = main(["report", "--results", str(results)])
    line = one_line(capsys, rc, "Read-only file system", prefix=SIM_ERROR)
    assert line.endswith(str(results / "network_plate" / "README.md")), line
    assert ".tmp" not in line
    assert {p: p.read_bytes() for p in results.rglob("*") if p.is_file()} == before
