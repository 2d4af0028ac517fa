"""Where the suite's commands write when not told, and where they never write.

* :func:`base`: the directory the command line's defaults are taken in (``sim run``'s
  ``results/<name>`` and ``scratch/<name>-<hash>``, ``sim report``'s ``results``): the
  working directory, or the project's root when the working directory lies inside the
  project below its root. Run from ``docs/``, ``studies/`` or ``sim/studies/network/``, a run
  made ``results/<name>`` there (a results directory in the project's sources, said as
  ``results in results/<name>/``, which the user took for the project's own; inside a study's
  package its ``run.json`` changed that study's code hash, so every committed result of the
  study read stale and ``make reproduce`` re-ran them).
* :func:`check_not_in_code`: an output directory inside the suite's package ``sim/`` is
  refused (the data files of a study's package, ``.json`` and ``.toml`` among them, are part of
  its code hash: a run's ``run.json`` there made the study's committed results stale).
"""

from __future__ import annotations

import os
from pathlib import Path

from sim.mc.config import ConfigError

__all__ = ["CODE", "PROJECT", "base", "check_not_in_code", "shown_path"]

#: the suite's package directory (``sim/``) and the checkout it lies in
CODE = Path(__file__).resolve().parent
PROJECT = CODE.parent


def _cwd() -> Path | None:
    try:
        return Path.cwd().resolve()
    except (OSError, RuntimeError):  # the working directory was removed
        return None


def base() -> Path:
    """``.``, or the project's root when the working directory lies inside the project's
    checkout (its ``studies/`` beside ``sim/``) but is not its root."""
    cwd = _cwd()
    if cwd is None or cwd == PROJECT or not (PROJECT / "studies").is_dir():
        return Path(".")
    return PROJECT if cwd.is_relative_to(PROJECT) else Path(".")


def shown_path(path: Path) -> str:
    """``path`` as the user reads it: relative to the working directory."""
    try:
        return os.path.relpath(path)
    except (OSError, ValueError):
        return str(path)


def check_not_in_code(out: Path, shown_as: str) -> None:
    """Refuse ``out`` (absolute) inside the suite's package directory, one line naming it."""
    try:
        real = Path(os.path.realpath(out))
    except (OSError, ValueError):
        real = out
    if out.is_relative_to(CODE) or real.is_relative_to(CODE):
        raise ConfigError(
            "--out",
            f"{shown_as} lies inside the suite's code {CODE} (the data files of a study's "
            "package are part of its code hash: a run's files there would make its committed "
            "results stale); choose a directory outside it",
        )
