"""Which study file a results directory was written from, and under which name.

A run records in ``run.json`` the study file it ran (``study_file``: its path, relative to
the working directory when inside it, and the sha256 of its bytes) and the name of the
directory it wrote (``written_as``). A network study has no name of its own: its results are
named by their directory (a batch's ``<results>/<study file name>``), so a directory copied
by hand over another (``cp -r B/alpha B/beta``) was shown, reported, verified and taken as
current as ``beta`` with alpha's numbers. :func:`other_source` says so: the readers that name
a study (``sim show``, ``sim report``, :class:`sim.Results`, ``make verify``,
``python -m sim.batch --stale-only``) name the directory and the study file its record names.
A record of an older version (without the fields) is read as before.
"""

from __future__ import annotations

import hashlib
import os
import stat
from pathlib import Path

from sim.mc.message_text import printable
from sim.mc.storage import read_record
from sim.mc.study_file import MAX_STUDY_BYTES

__all__ = ["other_source", "recorded_source", "source_fields"]


def source_fields(study_file: str | os.PathLike | None, out: Path) -> dict:
    """The run record's ``study_file`` (none for a study given as a config, not a file) and
    ``written_as`` (the name of the results directory ``out``)."""
    try:
        fields: dict = {"written_as": Path(os.path.abspath(out)).name}
    except OSError:  # the working directory removed meanwhile (execute's out is absolute)
        fields = {"written_as": Path(out).name}
    if study_file is None:
        return fields
    p = Path(study_file)
    try:  # gone, or no study file since it was read (a FIFO would block): named, not read
        st = os.stat(p)
        sha = None
        if stat.S_ISREG(st.st_mode) and st.st_size <= MAX_STUDY_BYTES:
            with open(p, "rb") as f:
                sha = hashlib.sha256(f.read()).hexdigest()
    except OSError:  # gone since it was read: the record names it without its content
        sha = None
    try:  # the working directory removed meanwhile: the path as given
        p = Path(os.path.abspath(p))
        shown = str(p.relative_to(Path.cwd()))
    except (ValueError, OSError):
        shown = str(p)
    return {**fields, "study_file": {"path": shown, "sha256": sha}}


def recorded_source(record: dict | None) -> tuple[str | None, str | None]:
    """``(written_as, study file path)`` of a run record (None for a field it lacks: an
    older version's record, or one edited into another shape)."""
    rec = record if isinstance(record, dict) else {}
    written = rec.get("written_as")
    sf = rec.get("study_file")
    path = sf.get("path") if isinstance(sf, dict) else None
    return (
        written if isinstance(written, str) and written else None,
        path if isinstance(path, str) and path else None,
    )


def other_source(
    d: str | Path, name: str | None = None, record: dict | None = None, studies: Path | None = None
) -> str | None:
    """Why the results directory ``d`` holds another study's results than its name says, or
    None: its record was written into a directory of another name from a study file of
    another name (copied or renamed by hand). ``name``: the study the reader expects (a
    batch's study file name, a committed study's for ``make verify``), default the
    directory's name, which says a study only when its run was written under its study
    file's name (a batch's ``<results>/<study>``): results written under a name of the
    user's (``sim run x.toml --out r1``) were named by no study, and moved or renamed as a
    whole (``mv r1 r2``) they were noted by ``sim show`` and warned of by ``sim.Results`` as
    "not r2's (copied or renamed by hand?): run r2's own study file", a file that never
    was. A symbolic link to results (``latest -> B/alpha``) is named by what it leads to.
    ``record``: its run record if read already; ``studies``: the directory of the study files
    (``make verify``'s), where one of the expected name may be missing (it said "run mine's
    own study file" then)."""
    here = Path(os.path.abspath(d))
    rec = record if record is not None else read_record(here)
    written, path = recorded_source(rec)
    stem = Path(path).stem if path else None
    if name is None and stem is not None and written != stem:
        return None  # a directory the user named, not for its study: its name says none
    # a link's name is not the directory's (latest -> B/alpha: "not latest's", R50)
    want = name if name is not None else Path(os.path.realpath(here)).name
    if written is None or want in (written, stem):
        return None
    where = f" of {path}" if path else ""
    fix = f"run {want}'s own study file to replace them"
    if studies is not None and not (Path(studies) / f"{want}.toml").is_file():
        fix = f"there is no {Path(studies) / want}.toml to replace them: move {d} away"
    return printable(  # a record forged with escape sequences: shown, not obeyed
        f"{d} holds the results of a run{where} written as {written}/ (its run.json), not "
        f"{want}'s (copied or renamed by hand?): {fix}"
    )
