"""Where the suite's commands write when not told, and where they never write.

* :func:`default_out`: where ``sim run`` writes without ``--out`` (the committed
  ``results/<name>`` only for a run of the committed config, code and figures; else
  ``scratch/<name>-<hash>``).
* :func:`base`: the directory the command line's defaults are taken in (``sim run``'s
  ``results/`` and ``scratch/``, ``sim report``'s and ``python -m sim.batch``'s ``--results``,
  the study names ``sim show`` reads): the working directory, or the project's root when the
  working directory lies inside the project below its root. Run from ``docs/``, ``studies/``
  or ``sim/studies/network/``, a run made ``results/<name>`` there (a results directory among
  the sources, said as ``results in results/<name>/``, which the user took for the project's
  own; inside a study's package its ``run.json`` changed that study's code hash, so every
  committed result of the study read stale and ``make reproduce`` re-ran them).
* :func:`check_place`: an output directory inside the suite's package ``sim/`` is
  refused, as is one below a symbolic link to nothing (the data files of a study's package, ``.json`` and ``.toml`` among them, are part of
  its code hash: a run's ``run.json`` there made the study's committed results stale).

Their notes ("writing to scratch/...") go through :func:`sim.standard_error.say`: printed
here, a study file's path with ``é`` ended a run under a strict-ASCII standard error in
``UnicodeEncodeError``, one with terminal control codes reached the terminal raw, and a closed
standard error (the Python API's caller's) ended it in ``ValueError``.
"""

from __future__ import annotations

import hashlib
import json
import os
from pathlib import Path

from sim.mc.config import ConfigError, config_changes
from sim.mc.storage import code_hash, read_record
from sim.mc.sweep import reordered, swept_order
from sim.standard_error import say

__all__ = [
    "CODE",
    "PROJECT",
    "base",
    "check_place",
    "default_out",
    "held_results",
    "shown_path",
    "show_target",
]

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


def held_results(d: Path) -> str:
    """``; it holds N: sim show D/<first>, ...`` of a directory of results directories (the
    project's ``results/``, a sweep's ``cells/``), which ``sim show`` refused naming none."""
    held = sorted({p.parent.name for k in ("claims", "sweep") for p in d.glob(f"*/{k}.parquet")})
    more = ", ..." if len(held) > 1 else ""
    return f"; it holds {len(held)}: sim show {d / held[0]}{more}" if held else ""


def show_target(where: Path) -> str:
    """What ``sim show`` is given to print the results directory ``where`` again (its
    README.md says it): its name where ``sim show`` finds it by name (in ``results/`` or
    ``scratch/`` of :func:`base`), else its absolute path. ``sim show NAME`` of a run written
    to ``/tmp/NAME`` said "does not exist", or printed the committed ``results/NAME``."""
    try:
        at = Path(os.path.abspath(where))
        if any(at.parent == Path(os.path.abspath(base() / d)) for d in ("results", "scratch")):
            return at.name
    except OSError:  # the working directory removed: ``.`` names no place (doors31b)
        return str(where)
    return str(at)


def check_place(out: Path, shown_as: str) -> None:
    """Refuse ``out`` (absolute) inside the suite's package directory, or below a symbolic
    link to nothing (a folder moved since: "cannot write to DIR: File exists"), one line."""
    for up in reversed(out.parents):
        if os.path.islink(up) and not os.path.exists(up):
            to = os.readlink(up)
            raise ConfigError(
                "--out",
                f"{shown_as}: {up} is a symbolic link to {to if to.isprintable() else repr(to)}, "
                "which does not exist",
            )
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


def _config_tag(record: dict) -> str:  # a sweep's keys in their order: they make its cells
    order = record.get("sweep_keys", [])
    text = json.dumps(
        {**record["config"], **({"sweep keys": order} if len(order) > 1 else {})},
        sort_keys=True,
        default=repr,
    )
    return hashlib.sha256(text.encode()).hexdigest()[:8]


def _differs(old: dict, record: dict) -> str:
    """What differs between a committed run record and this run's, in a few words."""
    a, b = old.get("config"), record["config"]
    if not isinstance(a, dict):  # a record edited by hand
        return "its config differs"
    if a != b or reordered(old, record):  # the keys, as --out's refusal names them
        return f"its config differs ({reordered(old, record) or config_changes(a, b)})"
    return "the code changed since they were made"


def default_out(
    cfg: dict, sweep: dict, path: Path, off: str | None = None
) -> tuple[Path, str, bool]:
    """Where ``sim run`` writes without --out: ``results/<name>`` (``name`` the study file
    ``path``'s, where ``make reproduce`` writes it, or the study kind's when only that exists)
    when it holds this very run (config and code) or does not exist, and the run is of the
    file as written (``off``: None; else the words of what makes it another run, as "the
    overrides trials=40" or "--no-figures"), else ``scratch/<name>-<config hash>`` (said on
    standard error). Returns ``(absolute path, shown path, overwrite)``; a scratch directory
    is replaced freely. Both are the project's from a directory inside it (:func:`base`).

    A run with overrides wrote the committed results when its config happened to be theirs
    (``--seed`` of the file's value, the override then recorded in ``run.json``) and whenever
    ``results/<name>/`` did not exist (the user's experiment became the study's results, for
    ``sim report``, ``REPORT.md`` and ``make verify``); ``--no-figures`` replaced them by
    results without their figures (the committed PNG files deleted, the results stale for
    ``make reproduce``). ``--out results/<name>`` (or ``make rerun RUN_FLAGS=...``) writes
    there when asked. By the study kind, ``studies/network_brown.toml`` wrote into a new
    ``results/network/``, and a new study file of the project's, ``studies/brown_large.toml``,
    was sent to ``scratch/`` as "of another config" than ``results/brown_table1``, where
    ``make reproduce`` writes ``results/brown_large``. In the project's root a new
    ``results/<name>`` is made for its ``studies/<name>.toml`` only: an author's
    ``my_net.toml`` went into the committed results, REPORT.md and ``make verify``."""
    name, at = path.stem, base()
    if (
        not os.path.lexists(at / "results" / name)
        and (at / "results" / cfg["study"]).exists()
        and not ((at / "studies").is_dir() and _project_file(path, name, at))
    ):  # a copy of a study file under another name (not a new study file of the project's,
        name = cfg["study"]  # whose results make reproduce writes into results/<its name>)
    committed = at / "results" / name
    record = {
        "config": {**cfg, "sweep": sweep} if sweep else cfg,
        "code_hash": code_hash(cfg["study"]),
        **swept_order(sweep),
    }
    old = read_record(committed)
    scratch = at / "scratch" / f"{name}-{_config_tag(record)}"
    if os.path.islink(committed):  # never replaced (sim.mc.outputs.check_out): it was
        say(  # "--out: results/<name> is a symbolic link" of a command without --out
            f"sim: {shown_path(committed)} is a symbolic link, which sim never replaces: "
            f"writing to {shown_path(scratch)}/ (--out DIR to choose)",
        )
        return Path(os.path.abspath(scratch)), shown_path(scratch), True
    if not committed.exists() and not _project_file(path, name, at):
        say(
            f"sim: {path} is not the project's studies/{name}.toml: writing to "
            f"{shown_path(scratch)}/ (--out DIR to choose; results/ holds the project's studies)",
        )
        return Path(os.path.abspath(scratch)), shown_path(scratch), True
    same = (
        old is not None
        and old.get("config") == record["config"]
        and not reordered(old, record)  # a sweep's keys in another order: other cells
        and old.get("code_hash") == record["code_hash"]
    )
    if not committed.exists() or same:
        if off is None:
            return Path(os.path.abspath(committed)), shown_path(committed), False
        say(
            f"sim: a run with {off} is not {path} as written, whose results go to "
            f"{shown_path(committed)}/: writing to {shown_path(scratch)}/ (--out DIR to choose)",
        )
        return Path(os.path.abspath(scratch)), shown_path(scratch), True
    why = _differs(old, record) if old is not None else "it is not a results directory of sim"
    say(
        f"sim: {shown_path(committed)}/ holds the committed results and {why}: writing to "
        f"{shown_path(scratch)}/ (--out DIR to choose; make reproduce rewrites results/)"
    )
    return Path(os.path.abspath(scratch)), shown_path(scratch), True


def _project_file(path: Path, name: str, at: Path) -> bool:
    """Whether ``path`` may make ``results/<name>`` in ``at``: it is ``studies/<name>.toml``, or
    ``at`` is no project's root (no ``studies/``: its ``results/`` is the user's)."""
    own = at / "studies" / f"{name}.toml"
    try:
        return not (at / "studies").is_dir() or path.resolve() == own.resolve()
    except (OSError, RuntimeError):
        return False
