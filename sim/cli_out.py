"""Where ``sim run`` without ``--out`` writes: the committed ``results/<name>/`` for the study
file as written, else ``scratch/<name>-<config hash>/`` (said on standard error).

``results/<name>/`` holds what ``make reproduce`` makes of ``studies/<name>.toml``. A run
without ``--out`` writes there only when it is a run of that file as written (no ``--set``,
``--trials``, ``--seed``, ``--chunk``; figures drawn) whose config and code are those of the
results there, or when there are none yet. A run with overrides wrote the committed results
when its config happened to be theirs (``--seed`` of the file's value, with the override
recorded in ``run.json``) and whenever ``results/<name>/`` did not exist (the user's
experiment became the study's results, for ``sim report``, ``REPORT.md`` and ``make
verify``); ``--no-figures`` replaced them by results without their figures (the PNG files
deleted). Such runs now go to ``scratch/``, as every other run off the committed results does;
``--out results/<name>`` (or ``make rerun RUN_FLAGS=...``) writes there when asked.
"""

from __future__ import annotations

import hashlib
import json
import os
import sys
from pathlib import Path

from sim.mc.config import config_changes
from sim.mc.storage import code_hash, read_record

__all__ = ["default_out"]


def _config_tag(record: dict) -> str:
    text = json.dumps(record["config"], sort_keys=True, default=repr)
    return hashlib.sha256(text.encode()).hexdigest()[:8]


def _differs(old: dict, record: dict) -> str:
    """What differs between a committed run record and this run's, in a few words."""
    a, b = old.get("config"), record["config"]
    if not isinstance(a, dict):  # a record edited by hand
        return "its config differs"
    if a != b:  # the keys, as --out's refusal names them (sim.mc.outputs)
        return f"its config differs ({config_changes(a, b)})"
    return "the code changed since they were made"


def default_out(
    cfg: dict, sweep: dict, path: Path, off: str | None = None
) -> tuple[Path, str, bool]:
    """Without --out: ``results/<name>`` (``name`` the study file ``path``'s, where ``make
    reproduce`` writes it, or the study kind's when only that exists) when it holds this very
    run (config and code) or does not exist, and the run is of the file as written (``off``:
    None; else the words of what makes it another run, as "the overrides trials=40"), else
    ``scratch/<name>-<config hash>`` (said on standard error). Returns ``(absolute path, shown
    path, overwrite)``; a scratch directory is replaced freely. (By the study kind,
    ``studies/network_brown.toml`` wrote into a new ``results/network/``; a new study file of
    the project's, ``studies/brown_large.toml``, was sent to ``scratch/`` as "of another
    config" than ``results/brown_table1``, where ``make reproduce`` writes
    ``results/brown_large``.) In the project's root a new ``results/<name>`` is made for its
    ``studies/<name>.toml`` only: an author's ``my_net.toml`` went into the committed results,
    REPORT.md and ``make verify``."""
    name = path.stem
    if (
        not (Path("results") / name).exists()
        and (Path("results") / cfg["study"]).exists()
        and not (Path("studies").is_dir() and _project_file(path, name))
    ):  # a copy of a study file under another name (not a new study file of the project's,
        name = cfg["study"]  # whose results make reproduce writes into results/<its name>)
    committed = Path("results") / name
    record = {
        "config": {**cfg, "sweep": sweep} if sweep else cfg,
        "code_hash": code_hash(cfg["study"]),
    }
    scratch = Path("scratch") / f"{name}-{_config_tag(record)}"
    old = read_record(committed)
    if not committed.exists() and not _project_file(path, name):
        print(
            f"sim: {path} is not the project's studies/{name}.toml: writing to {scratch}/ "
            "(--out DIR to choose; results/ holds the project's studies)",
            file=sys.stderr,
        )
        return Path(os.path.abspath(scratch)), str(scratch), True
    if not committed.exists() or (
        old is not None
        and old.get("config") == record["config"]
        and old.get("code_hash") == record["code_hash"]
    ):
        if off is None:
            return Path(os.path.abspath(committed)), str(committed), False
        print(
            f"sim: a run with {off} is not {path} as written, whose results go to "
            f"{committed}/: writing to {scratch}/ (--out DIR to choose)",
            file=sys.stderr,
        )
        return Path(os.path.abspath(scratch)), str(scratch), True
    why = _differs(old, record) if old is not None else "it is not a results directory of sim"
    print(
        f"sim: {committed}/ holds the committed results and {why}: writing to {scratch}/ "
        "(--out DIR to choose; make reproduce rewrites results/)",
        file=sys.stderr,
    )
    return Path(os.path.abspath(scratch)), str(scratch), True


def _project_file(path: Path, name: str) -> bool:
    """Whether ``path`` may make ``results/<name>``: it is ``studies/<name>.toml``, or the
    working directory is no project's root (no ``studies/``: its ``results/`` is the user's)."""
    own = Path("studies") / f"{name}.toml"
    try:
        return not Path("studies").is_dir() or path.resolve() == own.resolve()
    except (OSError, RuntimeError):
        return False
