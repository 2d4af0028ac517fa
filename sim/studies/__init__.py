"""The study registry: a study is a TOML file (data) plus a module here (code).

Each study module defines ``STUDIES = {name: Study(...)}``. ``run(cfg, out, ctx)`` writes the
study's Parquet files and figures into ``out``; ``report(out)`` returns the Markdown section
of ``results/REPORT.md`` built from those files alone.
"""
from __future__ import annotations

import importlib
from dataclasses import dataclass
from pathlib import Path
from typing import Callable, Mapping

from ..config import ConfigError, Field

__all__ = ["Study", "RunContext", "get_study", "MODULES"]

#: study name -> module that defines it (imported on demand)
MODULES = {
    "brown_dilution": "sim.studies.brown",
    "brown_table1": "sim.studies.brown",
    "gridplate_two_plates": "sim.studies.gridplate",
    "salsig_encoders": "sim.studies.salsig",
    "wolf_polynomial": "sim.studies.wolf",
    "agnard_block": "sim.studies.agnard",
    "brown_design": "sim.studies.design",
}


@dataclass(frozen=True)
class RunContext:
    """What a study's ``run`` gets besides its config: pass it to
    :func:`sim.runner.run_chunks` (``ctx=ctx``) so chunks use the chosen executor and are
    stored for resumption."""

    quiet: bool = False
    executor: object = None   # from sim.runner.make_executor; None = in-process
    store: object = None      # sim.runner.ChunkStore of the run's staging directory


@dataclass(frozen=True)
class Study:
    name: str
    title: str
    seed_file: str
    schema: Mapping[str, Field]
    run: Callable[[dict, Path, RunContext], None]
    report: Callable[[Path], str]
    check: Callable[[dict], None] | None = None
    order: int = 50  # position in REPORT.md


def get_study(name: str) -> Study:
    if not isinstance(name, str) or name not in MODULES:
        raise ConfigError("study", f"unknown study {name!r}; known: {', '.join(sorted(MODULES))}")
    try:
        mod = importlib.import_module(MODULES[name])
    except ModuleNotFoundError as e:
        if e.name == MODULES[name]:
            raise ConfigError("study", f"study {name!r} is not implemented yet") from None
        raise
    return mod.STUDIES[name]
