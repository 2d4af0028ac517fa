"""What a path the user gave is when it cannot be reached through its symbolic links.

pathlib's ``is_file``, ``is_dir`` and ``exists`` read a loop of links (the system's "too many
levels of symbolic links") as no file at all: a study file that is such a loop read "no such
study file", of a name ``ls`` shows. Each door that finds a path missing asks
:func:`link_problem` first, and says what is in the way.
"""

from __future__ import annotations

import errno
import os
from pathlib import Path

__all__ = ["link_problem"]


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
    return None


def _errno(p: str | os.PathLike) -> int | None:
    """The errno of ``stat(p)`` (None: it can be read; a NUL in the name: said elsewhere)."""
    try:
        os.stat(p)
    except OSError as e:
        return e.errno
    except ValueError:
        return None
    return None
