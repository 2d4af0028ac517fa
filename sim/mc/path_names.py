"""The names of the suite's paths, before any file is touched: why a path given on the
command line cannot name a file of the suite (:func:`name_problem`), and the name of a run's
staging directory beside its output (:func:`stage_dir`). Plain text, no file system and no
NumPy: the command line checks its arguments with them before it loads a study
(:mod:`sim.mc.outputs` holds the output checks themselves)."""

from __future__ import annotations

import unicodedata
from pathlib import Path

__all__ = ["STAGE_SUFFIX", "name_problem", "stage_dir"]


def name_problem(text: str) -> str | None:
    """Why a path given on the command line cannot name a file of the suite, in a few words
    (None: it can): empty or blank, a control character or a line break, a leading ``~``
    the shell left unexpanded, or bytes that are not UTF-8 text (a Latin-1 name, or any
    non-ASCII name in a C locale without UTF-8 mode, which Python keeps as surrogate escapes;
    the suite writes every path it records as UTF-8, so such a run would fail at its end)."""
    if not text.strip():
        return "is empty"
    if any(unicodedata.category(c) in ("Cc", "Zl", "Zp") for c in text):
        return "contains a control character or a line break"
    if any(unicodedata.category(c) == "Cs" for c in text):
        return "contains bytes that are not UTF-8 text (a non-UTF-8 name or locale)"
    if text.startswith("~"):  # --out=~/x: the shell expands no ~ after "=", and a directory
        return (  # named "~" was made here, which "rm -rf ~" would then mistake for home
            "starts with '~', which the shell did not expand (it does not after '='): use "
            "$HOME, or a space for the '=' (./~ names a file that starts with ~)"
        )
    return None


#: the suffix of a run's staging directory ``.<out>.partial``
STAGE_SUFFIX = ".partial"


def stage_dir(out: Path) -> Path:
    """The run's staging directory next to ``out``: ``.<name>.partial`` (resumed after a kill)."""
    return out.parent / f".{out.name}{STAGE_SUFFIX}"
