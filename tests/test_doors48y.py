"""The classes of the sweep doors48y (brief X49: the network export a user edited, kept), one
case each; each failed on the code before its fix.

* A network run's GNU Gama export (``network.xml``) edited by hand in its results directory
  (docs/gama.md shows it as the way into ``gama-local``), then the same command again, with or
  without ``--overwrite``: the edit was replaced by the new export, exit 0, without a word (the
  suite took the file for its own by its name). The run records the export's sha256 now
  (``export_sha256``), and such a run is refused before any work, naming the file; the edited
  file is the user's (a publish carries it, and refuses a new export of its name).
* A FIFO (or a symbolic link, a device) put in the export's place: removed by ``--overwrite``
  as the run's own file, without a word. Named now, never opened or followed, and kept. A
  directory of its name, refused only when every chunk was done, is refused before any work.
* (Held, not tested here: an edited export with ``--overwrite`` and another study is carried
  into the new results as the user's, ``carried`` in its record.)
* A record of an older version, without ``export_sha256``: its regular export is the run's,
  as before (replaced, no refusal).
"""

from __future__ import annotations

import json
import os
import stat
from pathlib import Path

import pytest
from conftest import TRIANGLE_NETWORK

from sim.cli import main
from sim.mc.export_edits import EXPORT_KEY, changed_exports
from sim.mc.publish import _foreign

RUN = ["run", "tri.toml", "--out", "r1", "--no-figures", "--quiet"]


@pytest.fixture(scope="module")
def done(tmp_path_factory) -> Path:
    """A finished run of the triangle network (its export ``network.xml``), run twice: the
    second run over its own untouched export is not refused."""
    d = tmp_path_factory.mktemp("y")
    (d / "tri.toml").write_text(TRIANGLE_NETWORK, encoding="utf-8")
    here = os.getcwd()
    os.chdir(d)
    try:
        assert main(RUN) == 0
        assert EXPORT_KEY in json.loads((d / "r1" / "run.json").read_text())
        assert main(RUN) == 0  # the export as its run wrote it: replaced without a word
    finally:
        os.chdir(here)
    return d


def _rerun(d: Path, capsys, *extra: str) -> tuple[int, str]:
    here = os.getcwd()
    os.chdir(d)
    try:
        capsys.readouterr()
        rc = main([*RUN, *extra])
    finally:
        os.chdir(here)
    return rc, capsys.readouterr().err


def test_edited_export_is_kept_and_named(done: Path, capsys) -> None:
    """An export edited by hand, re-run the same config with and without ``--overwrite``:
    before, exit 0 and the edit gone; now exit 2 before any work, one line naming the file,
    which is left as the user made it, and a publish counts it as the user's."""
    xml = done / "r1" / "network.xml"
    original = xml.read_bytes()
    edited = original.replace(b"</gama-local>", b"<!-- mine -->\n</gama-local>")
    xml.write_bytes(edited)
    try:
        for extra in ((), ("--overwrite",)):
            rc, err = _rerun(done, capsys, *extra)
            assert rc == 2, err
            assert len(err.strip().splitlines()) == 1 and "Traceback" not in err
            assert "network.xml was changed after the run that wrote it" in err
            assert xml.read_bytes() == edited
        assert "network.xml" in _foreign(done / "r1")  # carried, or refused, by a publish
    finally:
        xml.write_bytes(original)
    assert changed_exports(done / "r1") == {}


def test_fifo_in_place_of_export_is_named_not_removed(done: Path, capsys) -> None:
    """A FIFO named ``network.xml`` in the results, re-run with ``--overwrite``: before, it was
    removed as the run's file (exit 0); now it is named as a FIFO (never opened: no hang) and
    kept. A directory of that name was refused only at the run's end: now before any work."""
    xml = done / "r1" / "network.xml"
    original = xml.read_bytes()
    xml.unlink()
    for make, what, kept in (
        (os.mkfifo, "a FIFO (named pipe)", stat.S_ISFIFO),
        (os.mkdir, "a directory", stat.S_ISDIR),
    ):
        make(xml)
        try:
            rc, err = _rerun(done, capsys, "--overwrite")
            assert rc == 2, err
            assert f"network.xml is {what}, not the export its run wrote" in err
            assert kept(os.lstat(xml).st_mode)
        finally:
            xml.rmdir() if xml.is_dir() else xml.unlink()
    xml.write_bytes(original)


def test_older_record_without_export_sums_reads_as_before(done: Path) -> None:
    """A record of a version that kept no export sha256 (``export_sha256`` removed): its
    regular export, whatever its bytes, is the run's, as before (no refusal, not carried)."""
    rec_path = done / "r1" / "run.json"
    text = rec_path.read_text()
    rec = json.loads(text)
    rec.pop(EXPORT_KEY)
    rec_path.write_text(json.dumps(rec))
    xml = done / "r1" / "network.xml"
    original = xml.read_bytes()
    xml.write_bytes(original + b"<!-- mine -->\n")
    try:
        assert changed_exports(done / "r1") == {}
        assert "network.xml" not in _foreign(done / "r1")
    finally:
        rec_path.write_text(text)
        xml.write_bytes(original)
