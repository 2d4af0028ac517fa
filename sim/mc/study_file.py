"""Whether a path can be read as a study file: the one check of ``sim check``/``sim run``
(:func:`sim.mc.config.read_toml`), ``python -m sim.batch`` before any run, and ``sim.load``.

The batch had its own near-copy of these checks in other words ("no study file x.toml"
beside read_toml's "x.toml: no such study file", a pattern hint the command line lacked,
no size limit until the file's config was read): one check, one wording, the path first.
"""

from __future__ import annotations

import difflib
import fnmatch
import itertools
import os
import re
from pathlib import Path

from sim.mc.lookalike import looks
from sim.mc.paths import link_problem

__all__ = ["MAX_STUDY_BYTES", "study_file_hint", "study_file_problem"]

#: largest study file read (bytes): a study file is a page of keys, not data
MAX_STUDY_BYTES = 16 * 1024**2


def study_file_hint(p: str | Path) -> str:
    """`` (did you mean studies/brown_table1.toml?)`` for a study file named the way a new
    user names it: without ``.toml``, without ``studies/``, or with Windows backslashes, from
    the project's root or a directory below it (``docs/``: ``../studies/brown_table1.toml``)."""
    text = str(p).replace("\\", "/")
    tries = [text, f"{text}.toml"]
    if _bare(Path(text)):
        name = Path(text).name
        tries += [str(d / n) for d in _studies_dirs() for n in (name, f"{name}.toml")]
    hit = next((t for t in tries if t != str(p) and Path(t).is_file()), None)
    return f" (did you mean {hit or _near(Path(text))}?)" if hit or _near(Path(text)) else ""


def _bare(p: Path) -> bool:
    """Whether ``p`` names a study the way a user names one of the project's: a bare name
    (``brown_table1``) or one under ``studies/``, from wherever in the project it is typed."""
    return p.parent == Path(".") or p.parent == Path("studies")


def _studies_dirs() -> list[Path]:
    """The ``studies/`` directories a bare name may mean, as typed from here: ``studies``,
    and the project's (:func:`sim.places.base`) from a directory below its root: ``.`` in
    ``studies/``, ``../studies`` from ``docs/`` (a bare name from ``docs/`` was "no such study
    file" with no guess: D38), and from a directory of yours outside the project (no
    ``studies/`` here) the project's own, by its absolute path (``sim run brown_table1`` from
    ``~`` was "no such study file" with no guess: D45)."""
    from sim.places import PROJECT, base, shown_path  # here: sim.places reads sim.mc.config

    dirs = [Path("studies"), Path(shown_path(base() / "studies"))]
    if not Path("studies").is_dir() and (PROJECT / "studies").is_dir():
        dirs.append(PROJECT / "studies")
    return list(dict.fromkeys(dirs))


def _near(p: Path) -> str | None:
    """The study file of a name near ``p``'s in its directory (and the project's ``studies/``
    for a bare name, :func:`_studies_dirs`): the one that looks the same (another case, a
    lookalike letter), else the closest spelling (difflib, as a mistyped key or option is
    answered): ``studies/brown_tabel1.toml`` was "no such study file" without the
    ``studies/brown_table1.toml`` beside it (L37)."""
    stem = _stem(p.name)
    seen: dict[str, Path] = {}
    for d in [_folded_dir(p.parent)] + (_studies_dirs() if _bare(p) else []):
        try:
            with os.scandir(d) as it:  # a few hundred names at most: not a whole disk
                for e in itertools.islice(it, 2000):
                    if e.name.endswith(".toml") and e.is_file():
                        seen.setdefault(e.name.removesuffix(".toml"), d / e.name)
        except OSError:
            continue
    same = [n for n in seen if looks(n) == looks(stem) and n != stem]
    close = same + difflib.get_close_matches(stem, list(seen), n=3, cutoff=0.75)
    return next((str(seen[n]) for n in close if _names_a_study(seen[n])), None)


def _folded_dir(d: Path) -> Path:
    """``d``, or when it is not a directory, the one whose names look the same as its, part by
    part (another case, a lookalike letter): ``Studies/Brown_Table1.toml`` was "no such study
    file" with no guess, the directory ``Studies`` being none (``studies`` is)."""
    if d.is_dir() or d == Path("."):
        return d
    parts = d.parts
    at = Path(parts[0]) if d.is_absolute() else Path(".")
    for part in parts[1:] if d.is_absolute() else parts:
        if (at / part).is_dir() or part in (".", ".."):
            at = at / part
            continue
        try:
            with os.scandir(at) as it:  # a few hundred names at most: not a whole disk
                names = [e.name for e in itertools.islice(it, 2000) if e.is_dir()]
        except OSError:
            return d
        same = [n for n in names if looks(n) == looks(part)]
        if len(same) != 1:
            return d
        at = at / same[0]
    return at


def _stem(name: str) -> str:
    """``name`` without ``.toml`` or a mistyped one (``my.tom``, ``x.tml``: "no such study
    file" without a guess where the name was short, the suffix too far off ``my``)."""
    base, dot, ext = name.rpartition(".")
    if dot and base and difflib.SequenceMatcher(None, ext.lower(), "toml").ratio() >= 0.75:
        return base
    return name


def _in_dir(p: Path) -> str:
    """What the directory ``p`` holds, for the line that refuses it as a study file: its
    study files, or none: "its study files are DIR/*.toml" was said of an empty directory and
    of a run's results (``sim.load("results/brown_table1")``), where the pattern matches none.
    """
    try:
        with os.scandir(p) as it:
            entries = itertools.islice(it, 10_000)  # a FIFO named x.toml: never opened
            tomls = [e.path for e in entries if e.name.endswith(".toml") and e.is_file()]
    except OSError:
        tomls = []
    if any(_names_a_study(Path(t)) for t in tomls[:100]):
        return f"its study files are {p}/*.toml"
    if os.path.isfile(p / "run.json"):
        return "it holds a run's results and no study file: name the study file the run read"
    return "it holds no study file: name one"


def _names_a_study(p: Path) -> bool:
    """Whether ``p`` holds a top-level ``study = ...`` line (not ``pyproject.toml``)."""
    try:
        with open(p, "rb") as fh:
            head = fh.read(65536)
    except OSError:
        return False
    return re.search(rb"(?m)^[ \t]*study[ \t]*=", head) is not None


#: the most files a pattern given as a study file is counted matching (more: "more than")
_LOOKED = 2000
#: the most entries of the pattern's directory read (a directory of a million files is not
#: read whole before a one-line refusal)
_SCANNED = 200_000


def _wild(d: Path) -> bool:
    """Whether the directory part ``d`` of a study file's path is a pattern: it holds ``*``,
    ``?`` or ``[`` and names no directory (``run[1]/``, a directory of that very name, is
    read as itself: a name mistyped in it was "a pattern, not a study file")."""
    return any(c in str(d) for c in "*?[") and not d.is_dir()


def _matches(p: Path) -> int | None:
    """How many files the pattern ``p`` matches (over :data:`_LOOKED`: ``_LOOKED + 1``),
    looking in one directory only, the pattern's own, as the shell would (a name that starts
    with ``.`` only for a pattern that does); None for a pattern in its folders
    (``'*/x.toml'``), which is not walked: ``glob`` of ``'/*/*/*/*/*/*/*/*/*.toml'`` walked
    the whole disk, /proc too, and ``sim check`` ran for minutes before its one line. The
    directory's entries are read up to :data:`_SCANNED`, not its first :data:`_LOOKED` only: a
    study file listed after them (``'runs/*.toml'`` in a directory of 3,000 outputs) was "a
    pattern that matched no file". A directory that cannot be read raises its ``OSError``
    (it was "matched no file" too, of a directory of study files that could not be listed)."""
    if _wild(p.parent):
        return None
    n, hidden = 0, p.name.startswith(".")
    with os.scandir(p.parent) as it:
        for e in itertools.islice(it, _SCANNED):
            if fnmatch.fnmatchcase(e.name, p.name) and (hidden or e.name[0] != "."):
                n += 1
                if n > _LOOKED:
                    break
    return n


def study_file_problem(p: str | Path) -> str | None:
    """Why ``p`` cannot be read as a study file, one line that starts with the path, or None:
    a directory, a pipe or a device (opening a FIFO nobody writes to blocks), a link that
    leads nowhere or loops, a shell pattern that matched no file (the shell passes it on as
    it is), nothing there (with the file meant, when a near name is one), or a file over
    :data:`MAX_STUDY_BYTES`. A file that cannot be read is said when it is read."""
    p = Path(p)
    if p.is_dir():  # both were "no such study file", of a file that is there
        return f"{p}: is a directory, not a study file ({_in_dir(p)})"
    if p.exists() and not p.is_file():  # a pipe (cat x.toml | sim check /dev/stdin), a device
        return f"{p}: not a regular file (a pipe or a device): name the study file"
    if not p.is_file():
        if why := link_problem(p):  # a link loop was "no such study file", of a name there
            return f"{p}: {why}"
        if any(c in p.name for c in "*?[") or _wild(p.parent):
            try:
                hits = _matches(p)  # quoted, the shell passed on a pattern of files
            except FileNotFoundError:
                return f"{p}: no such study file (a pattern in {p.parent}, no such directory)"
            except OSError as e:  # unreadable (chmod 000), not a directory, gone
                return (
                    f"{p}: a pattern whose directory {p.parent} could not be read "
                    f"({e.strerror or type(e).__name__}): name the study files"
                )
            if hits is None:  # a pattern of folders: not walked
                return (
                    f"{p}: a pattern, not a study file (which the shell did not expand: leave "
                    "it unquoted, or name the files)"
                )
            if hits:
                many = f"more than {_LOOKED}" if hits > _LOOKED else str(hits)
                return (
                    f"{p}: a pattern, not a study file (it matches {many} file"
                    f"{'s' * (hits > 1)}, "
                    "which the shell did not expand: leave it unquoted, or name the files)"
                )
            return (
                f"{p}: no such study file (a pattern that matched no file: the shell passed "
                "it on as it is)"
            )
        return f"{p}: no such study file{study_file_hint(p)}"
    try:
        size = os.stat(p).st_size
    except OSError:  # gone since, or a directory of the path not searchable: said on reading
        return None
    if size > MAX_STUDY_BYTES:
        return f"{p}: over {MAX_STUDY_BYTES // 1024**2} MiB, too large for a study file"
    return None
