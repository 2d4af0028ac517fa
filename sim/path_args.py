"""The paths a Python caller gives the API (``sim.load(study_file)``, ``run(out=...)``,
``sim.Results(path, ...)``), checked as the command line checks its own, with
no file read and no library loaded (:mod:`sim.cli` checks its paths with them before it
loads a study).

A path is a ``str`` or an ``os.PathLike`` of one (``pathlib.Path``, a str subclass), not blank,
without a control character, a line break or bytes that are not UTF-8 (as ``sim run``'s).
Python expands neither ``~`` nor ``$HOME`` in a path (a shell does, on the command line):
``run(out="~/runs/x")`` made a directory named ``~`` in the working directory,
which ``rm -rf ~`` would then mistake for home, and ``"$HOME/runs/x"`` one named ``$HOME``.
A path that starts with ``~`` or names a variable of the environment (``$HOME``, ``${HOME}``)
is refused, naming the argument and the function that expands it, unless a file of that
very name exists (an earlier ``./~`` is the caller's to read).
"""

from __future__ import annotations

import errno
import os
import sys
import unicodedata
from pathlib import Path
from typing import Any

from sim.mc.config import ConfigError
from sim.mc.paths import absolute

__all__ = ["absolute_path", "arrow_name", "check_path", "gone_cwd", "too_long"]


def _unwritable(text: str) -> str | None:
    """``sim run``'s words for a str no path of the suite may hold (:func:`sim.mc.path_names.
    name_problem`), or None. Every other str is a path, as on the command line: a name
    ``os.listdir`` gave of a non-UTF-8 directory (surrogate escapes) or one holding a line
    break was refused as "must be a path (a str or os.PathLike of a str)", of a str, and so
    was any name ``str.isprintable`` refuses that the command line takes (a no-break space,
    a zero-width space: ``sim.Results`` of the results ``sim run --out`` wrote there)."""
    if any(unicodedata.category(c) == "Cs" for c in text):
        return "contains bytes that are not UTF-8 text (a non-UTF-8 name or locale)"
    if any(unicodedata.category(c) in ("Cc", "Zl", "Zp") for c in text):
        return "contains a control character or a line break"
    return None


def check_path(name: str, v: Any, none_ok: bool = False) -> None:
    """``v`` is a path the API can take as argument ``name`` (module docstring)."""
    if v is None and none_ok:
        return
    try:  # an os.PathLike may give bytes, or (a broken one) neither str nor bytes
        text = os.fspath(v) if isinstance(v, os.PathLike) else v
    except TypeError:
        text = None
    except Exception as e:  # a broken os.PathLike of the caller's: its ValueError passed
        raise ConfigError(  # through the API as a traceback of the caller's own object
            name, f"is not a path: os.fspath() of its {type(v).__name__} raised {_said(e)}"
        ) from None
    if isinstance(text, str) and (why := _unwritable(text)) is not None:
        raise ConfigError(name, f"{why} (got {v!r})")
    if not isinstance(text, str) or not text.strip():
        raise ConfigError(name, f"must be a path (a str or os.PathLike of a str), got {v!r}")
    if (why := too_long(text)) is not None:
        raise ConfigError(name, why)
    if os.path.lexists(text):
        return
    if text.startswith("~"):
        raise ConfigError(
            name,
            f"{text} starts with '~', which Python does not expand: give "
            f"os.path.expanduser({text!r}) (./~ names a file that starts with ~)",
        )
    if os.path.expandvars(text) != text:
        raise ConfigError(
            name,
            f"{text} names an environment variable, which Python does not expand: give "
            f"os.path.expandvars({text!r})",
        )


def _said(e: Exception) -> str:
    """``ValueError: boom``: an exception of the caller's code in one line (its type alone
    when its own ``__str__`` raises: that second exception was a traceback)."""
    try:
        text = " ".join(str(e).split())
    except Exception:  # noqa: BLE001 - the caller's broken exception, named by its type
        text = ""
    return f"{type(e).__name__}: {text[:120]}" if text else type(e).__name__


def too_long(text: str) -> str | None:
    """Why the system cannot take the path ``text`` (a name in it over the file system's
    limit, or the whole over the system's: ENAMETOOLONG), in one line that shows the path cut
    short, or None. pathlib's ``exists``, ``is_dir`` and ``glob`` raise it where they read
    "absent" for a name that is not there: ``sim.load("a" * 5000)``, ``run(out=...)`` and
    ``sim.Results(path, ...)`` ended in pathlib's OSError with a traceback."""
    try:
        os.lstat(text)
    except OSError as e:
        if e.errno == errno.ENAMETOOLONG:
            longest = max(len(part.encode("utf-8", "surrogateescape")) for part in text.split("/"))
            shown = text if len(text) <= 80 else f"{text[:40]}...{text[-20:]}"
            return (
                f"{shown} is too long a path for the system ({e.strerror}: {len(text)} "
                f"characters, its longest name {longest} bytes): give a shorter one"
            )
    except ValueError:  # an embedded NUL: refused as no path by the callers
        pass
    return None


def absolute_path(name: str, v: str | os.PathLike) -> Path:
    """``v`` made absolute against the working directory, which may have been deleted (then
    one line naming the argument, not pathlib's FileNotFoundError)."""
    try:
        return absolute(v)
    except OSError as e:
        raise ConfigError(
            name, f"{os.fspath(v)} is relative, but the working directory is gone ({e.strerror})"
        ) from None


def arrow_name(name: str, v: str | os.PathLike) -> None:
    """Refuse ``v``, a directory whose tables Arrow reads or writes, when Arrow would name
    other files than Python: under a locale whose file names are not UTF-8 (``LC_ALL=
    de_DE.ISO-8859-1`` without UTF-8 mode) Python gives a name that is not ASCII to the system
    in the locale's encoding and Arrow in UTF-8. ``sim run --out dé`` failed at its first chunk
    on "No such file or directory: .../.dé.partial/trials/...", ``sim show`` and ``sim report``
    said a ``claims.parquet`` that is there could not be found, the API raised Arrow's
    FileNotFoundError. One line naming the argument and the locale's encoding instead."""
    enc = sys.getfilesystemencoding()
    try:
        text = os.fspath(absolute(v))
    except (OSError, TypeError, ValueError):  # said by the argument's own checks
        return
    if text.isascii() or enc.lower().replace("-", "").replace("_", "") in ("utf8", "utf8mb4"):
        return
    raise ConfigError(
        name,
        f"{text!r} is not ASCII and this locale's file names are {enc}, not UTF-8: Arrow, which "
        "reads and writes the tables, would name other files; set LC_ALL=C.UTF-8 (or "
        "PYTHONUTF8=1), or choose an ASCII path",
    )


def gone_cwd(name: str, v: str | os.PathLike) -> str | None:
    """The one line of :func:`absolute_path`'s refusal (``v`` relative, the working directory
    deleted), for a program that prints its own; None when ``v`` is a path here."""
    try:
        absolute_path(name, v)
    except ConfigError as e:
        return str(e)
    return None
