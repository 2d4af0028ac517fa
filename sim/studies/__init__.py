"""The study registry: a study is a TOML file (data) plus a module here (code).

Each study module defines ``STUDIES = {name: Study(...)}``. ``run(cfg, out, ctx)`` writes the
study's Parquet files and figures into ``out``; ``report(out)`` returns the Markdown section
of ``results/REPORT.md`` built from those files alone.
"""

from __future__ import annotations

import importlib
from contextlib import contextmanager
from dataclasses import dataclass, field
from pathlib import Path
from typing import Callable, Mapping

from sim.mc.config import ConfigError, Field

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
    "network": "sim.studies.network",
}


@dataclass(frozen=True)
class RunContext:
    """What a study's ``run`` gets besides its config: pass it to
    :func:`sim.mc.runner.run_chunks` (``ctx=ctx``) so chunks use the chosen executor and are
    stored for resumption, and share the run's one progress bar."""

    quiet: bool = False
    executor: object = None  # from sim.mc.runner.make_executor; None = in-process
    store: object = None  # sim.mc.runner.ChunkStore of the run's staging directory
    estimate: object = None  # sim.mc.estimate.Estimate of the run (the progress bar's total)
    bars: list = field(default_factory=list, compare=False)  # the open shared bar, if any

    @property
    def bar(self):
        """The run's shared progress bar while :meth:`progress_bar` is open, else None."""
        return self.bars[-1] if self.bars else None

    @contextmanager
    def progress_bar(self, label: str):
        """One bar for the whole run; its total is the estimate's trial count."""
        from sim.mc.progress import Progress

        total = getattr(self.estimate, "trials", 0) or 0
        with Progress(total, label, quiet=self.quiet) as p:
            self.bars.append(p)
            try:
                yield p
            finally:
                self.bars.remove(p)


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
