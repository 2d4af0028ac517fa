"""What a path the user gave is when it cannot be reached through its symbolic links.

pathlib's ``is_file``, ``is_dir`` and ``exists`` read a loop of links (the system's "too many
levels of symbolic links") as no file at all: a study file that is such a loop read "no such
study file", of a name ``ls`` shows. Each door that finds a path missing asks
:func:`link_problem` first, and says what is in the way. So is a name in another Unicode form
than the file's (doors24c): ``café.xml`` typed precomposed (NFC) for a file saved decomposed
(NFD, as macOS writes names) is another name to Linux, and was "no such file" of a name
``ls`` shows alike.

Beside it, what the system makes of an output path: :func:`absolute` (``..`` after a link is
the link target's parent), :func:`mount_point` and :func:`mounts_under` (a directory a run
cannot rename, or would empty), :func:`is_chunk_store` (another run's ``trials/``).
"""

from __future__ import annotations

import errno
import os
import re
import unicodedata
from pathlib import Path

from sim.mc.lookalike import differs

__all__ = ["absolute", "is_chunk_store", "link_problem", "mount_point", "mounts_under"]


def link_problem(p: str | os.PathLike) -> str | None:
    """Why ``p`` cannot be reached through a symbolic link, in words that follow the path
    (None: no link is in the way): it is, or goes through, a loop of links, or it is a link
    to a file that does not exist."""
    if _errno(p) == errno.ELOOP:
        q = Path(p)
        first = next((a for a in (*reversed(q.parents), q) if _errno(a) == errno.ELOOP), q)
        if first == q:
            return "is a symbolic-link loop"
        return f"goes through a symbolic-link loop ({first})"
    if _errno(p) == errno.ENOENT and os.path.islink(p):
        to = os.readlink(p)
        return f"is a symbolic link to {to if to.isprintable() else repr(to)}, which does not exist"
    if _errno(p) == errno.ENOENT:
        return _other_form(Path(p))
    return None


def _other_form(q: Path) -> str | None:
    """`` is not there; '...' is, its name in another Unicode form (...)`` for the first missing
    part of ``q`` whose directory holds a name that differs from it in normalisation only."""
    a = next((a for a in (*reversed(q.parents), q) if not os.path.lexists(a)), None)
    if a is None or not a.name:
        return None
    want = unicodedata.normalize("NFC", a.name)
    try:
        names = os.listdir(a.parent)
    except (OSError, ValueError):
        return None
    hit = next((n for n in names if n != a.name and unicodedata.normalize("NFC", n) == want), None)
    if hit is None:
        return None
    return (
        f"is not there; {str(a.parent / hit)!r} is, its name in another Unicode form "
        f"({differs(hit, a.name)}): give the name as the file has it"
    )


def _errno(p: str | os.PathLike) -> int | None:
    """The errno of ``stat(p)`` (None: it can be read; a NUL in the name: said elsewhere)."""
    try:
        os.stat(p)
    except OSError as e:
        return e.errno
    except ValueError:
        return None
    return None


def mount_point(p: str | os.PathLike) -> bool:
    """Whether the directory ``p`` is a mount point (a file system of its own mounted there,
    or a bind mount of a directory of the same one, which ``os.path.ismount`` does not see):
    the system refuses to rename it (EBUSY), so it cannot be a run's output directory."""
    return os.path.ismount(p) or os.path.realpath(p) in _mount_points()


def mounts_under(p: str | os.PathLike) -> list[str]:
    """The mount points inside the directory ``p`` (a disk or a tmpfs mounted in a results
    directory): a run that replaced ``p`` moved them aside with the old results, and emptied
    them while removing those (a copy of their files went into the new results)."""
    real = os.path.realpath(p).rstrip("/") + "/"
    return sorted(m for m in _mount_points() if m.startswith(real))


def _mount_points() -> set[str]:
    """Every mount point this process sees (``/proc/self/mountinfo``, its fifth field, with
    the octal escapes of a space, tab, line break and backslash undone); empty where the
    system has no such file."""
    try:
        with open("/proc/self/mountinfo", "rb") as f:
            fields = [ln.split() for ln in f]
    except OSError:
        return set()
    unescape = re.compile(rb"\\([0-7]{3})")
    return {
        os.fsdecode(unescape.sub(lambda m: bytes([int(m.group(1), 8)]), x[4]))
        for x in fields
        if len(x) > 4
    }


def absolute(p: str | os.PathLike) -> Path:
    """``p`` made absolute against the working directory as the system resolves it: a ``..``
    after a symbolic link is the parent of the link's target (``os.path.abspath`` drops
    ``lnk/..`` by its letters: ``--out lnk/../y`` wrote ``./y`` while the run said "results
    in lnk/../y", a path where ``ls`` finds nothing, and ``--overwrite`` replaced a ``./y``
    the user had not named). The last name is kept as given (a link there is the caller's
    to refuse); OSError where the working directory is gone and ``p`` is relative (an absolute
    ``p`` is not joined to it: in a process whose directory was removed, ``sim.load`` of an
    absolute path was refused as "relative, but the working directory is gone")."""
    a = os.fspath(p)
    a = a if os.path.isabs(a) else os.path.join(os.getcwd(), a)
    if ".." not in Path(a).parts:
        return Path(os.path.normpath(a))  # ("." and doubled or trailing slashes only)
    head, tail = os.path.split(a.rstrip("/"))
    if tail in ("..", "."):
        return Path(os.path.realpath(a))
    return Path(os.path.realpath(head)) / tail


def is_chunk_store(d: Path) -> bool:
    """Whether ``d`` is a run's chunk store: ``trials/`` holding ``part-<p>/`` (a folder of the
    user's named ``trials``, ``~/trials/run1``, is not another run's)."""
    return d.name == "trials" and any(d.glob("part-*"))
