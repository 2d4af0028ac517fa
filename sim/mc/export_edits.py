"""A network run's GNU Gama export (``network.xml``, a sweep's ``cells/<label>/network.xml``)
that the user changed after the run wrote it. The export is an input to ``gama-local``, and
docs/gama.md shows it as the way there: editing it in place is a natural step. The suite
decided which of a results directory's files it owns by name only, so a re-run of the same
config (even without ``--overwrite``) replaced an edited export without a word, and a FIFO or
a symbolic link put in its place was removed as the run's own file.

:func:`export_sums` records each export's sha256 in ``run.json`` (``export_sha256``) when the
run is sealed; :func:`changed_exports` names the exports of a results directory that are not
the ones its run wrote (their sha256 differs, or something other than a regular file stands
there: looked at with ``lstat``, never opened or followed). A publish keeps such a file as
the user's (:func:`sim.mc.publish._foreign`) and a run that would write a file of its name is
refused, before any work (:func:`refuse_changed_export`) and at its end, naming it: as for
any file of the user's in the way of one the run writes. A record of an older version, with
no ``export_sha256``, has its regular files taken as the run's, as before.

So is a results directory's ``README.md`` edited by hand (its sha256 is not the
``readme_sha256`` that ``sim run`` and ``sim report`` record when they write it): the user's
notes were replaced by a re-run, or by ``sim report``, without a word (the mark on its first
line said "edits are overwritten", hidden where Markdown is shown).
"""

from __future__ import annotations

import hashlib
import os
import re
import stat
from pathlib import Path

from sim.mc.config import ConfigError
from sim.mc.file_kind import mode_kind
from sim.mc.storage import read_record

__all__ = ["EXPORT_KEY", "README_KEY", "export_sums", "changed_exports", "refuse_changed_export"]

#: the run record's key of the exports' sha256
EXPORT_KEY = "export_sha256"
#: the run record's key of the sha256 of the README.md the suite wrote last
README_KEY = "readme_sha256"
#: the name of an export as a run record lists it: a run's, or a sweep's cell's
_EXPORT = re.compile(r"(?:cells/[^/\\\x00]+/)?[^/\\\x00]+\.xml")


def _sha256(p: Path) -> str:
    h = hashlib.sha256()
    with open(p, "rb") as f:
        while block := f.read(1 << 20):
            h.update(block)
    return h.hexdigest()


def export_sums(stage: Path, files: list[str]) -> dict[str, str]:
    """The sha256 of each export among the run's ``files`` (relative to ``stage``)."""
    return {f: _sha256(stage / f) for f in files if _EXPORT.fullmatch(f)}


def changed_exports(out: Path, rec: dict | None = None, dirs: bool = False) -> dict[str, str]:
    """The exports the run record of ``out`` (or ``rec``) lists among its files that are there
    but are not the ones its run wrote, each with what it is now (``"changed after the run
    that wrote it (edited by hand?)"``, ``"a FIFO (named pipe)"``, ...). A directory of that
    name is named only with ``dirs`` (a publish refuses it as any entry of the user's in the
    way, whose files it lists one by one)."""
    rec = read_record(out) if rec is None else rec
    files = rec.get("files") if isinstance(rec, dict) else None
    sums = rec.get(EXPORT_KEY) if isinstance(rec, dict) else None
    sums = sums if isinstance(sums, dict) else {}
    readme = rec.get(README_KEY) if isinstance(rec, dict) else None
    if isinstance(readme, (str, list)):  # (a record without it: the README is the suite's, as
        sums = {**sums, "README.md": readme}  # before; a list: either, one being written)
    found = {}
    for name in files if isinstance(files, list) else []:
        if not isinstance(name, str) or not (_EXPORT.fullmatch(name) or name in sums):
            continue
        p = Path(out) / name
        try:
            mode = os.lstat(p).st_mode
        except OSError:  # gone (the run writes it again) or not to be looked at
            continue
        if stat.S_ISDIR(mode):
            if dirs:
                found[name] = "a directory"
            continue
        if not stat.S_ISREG(mode):
            found[name] = mode_kind(mode)
            continue
        want = sums.get(name)
        try:
            wants = [want] if isinstance(want, str) else want if isinstance(want, list) else None
            same = wants is None or _sha256(p) in wants
        except OSError:
            same = False
        if not same:
            found[name] = "changed after the run that wrote it (edited by hand?)"
    return found


def changed_words(out: Path, name: str, what: str) -> str:
    """The refusal of a run that would replace the export ``name`` of ``out``, ``what`` it is."""
    p = Path(out) / name
    mine = "the export" if name.endswith(".xml") else "the file"
    kind = f"was {what}" if what.startswith("changed") else f"is {what}, not {mine} its run wrote"
    return (
        f"{p} {kind}; a run into {out} writes a file of that name: copy it out of the results "
        "directory (or move it away) and run again"
    )


def refuse_changed_export(out: Path, shown: str, rec: dict | None, study: object) -> None:
    """Refuse, before any work, a run of ``study`` into the results ``out`` (``shown`` as
    given, ``rec`` its record) whose export was changed by hand or has a FIFO, device, link or
    directory in its place, when the earlier run was of that study (which writes a file of its
    name; of another study, with ``--overwrite``, the publish carries it)."""
    config = rec.get("config") if isinstance(rec, dict) else None
    if not isinstance(config, dict) or config.get("study") != study:
        return
    found = changed_exports(out, rec, dirs=True)
    for name, what in sorted(found.items())[:1]:
        raise ConfigError("--out", changed_words(Path(shown), name, what))
