"""The benchmark's page (``README.md`` beside its tables, ``make bench``): each compiled module
of the suite and the row of this run that justifies it, from the rows alone (no number is
typed in). A compiled path stays where its engine row shows at least
:data:`benchmarks.engines.KEEP_RATIO` over its NumPy path, or where a study row shows it saves
at least :data:`benchmarks.studies.KEEP_SHARE` of the study's time (issue 22)."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from benchmarks.engines import KEEP_RATIO
from benchmarks.studies import KEEP_SHARE
from sim.mc.storage import atomic_path

__all__ = ["HEADING", "STUDY_OF", "write_page"]

HEADING = "# Benchmark: compiled code and the rows that keep it"

#: compiled modules whose engine row falls below KEEP_RATIO and the study that decides them
STUDY_OF = {"sim.lsq.group_kernel, sim.lsq.group_kernel_solve": "agnard_block"}


def _share(studies, study: str, fast: str, slow: str) -> float:
    """1 - time(fast) / time(slow) of ``study`` in the study rows, NaN if not measured."""
    if not studies:
        return np.nan
    t = {
        (s, v): x
        for s, v, x in zip(studies["study"], studies["variant"], studies["seconds"])
        if s == study
    }
    if (study, fast) not in t or (study, slow) not in t:
        return np.nan
    return 1.0 - t[(study, fast)] / t[(study, slow)]


def _verdict(ratio: float, share: float, study: str | None) -> str:
    if ratio >= KEEP_RATIO:
        return f"kept: {ratio:.1f}x its NumPy path (at least {KEEP_RATIO:g}x)"
    if study and share >= KEEP_SHARE:
        return f"kept: saves {share:.0%} of {study} (at least {KEEP_SHARE:.0%})"
    if study and np.isnan(share):
        return f"{ratio:.1f}x on its row; the study row of {study} was not measured in this run"
    return "**not justified by this run**"


def _engines_table(eng) -> list[str]:
    lines = [
        "| engine row | compiled module | trials | compiled (us/trial) | NumPy (us/trial) "
        "| per-trial loop (us/trial) | compiled vs NumPy | vs loop |",
        "|---|---|---:|---:|---:|---:|---:|---:|",
    ]
    for i, name in enumerate(eng["engine"]):
        T = eng["trials"][i]
        us = [eng[c][i] / T * 1e6 for c in ("compiled_s", "numpy_s", "scipy_s")]
        lines.append(
            f"| {name} | {eng['compiled_module'][i] or '(none)'} | {T} | {us[0]:.3g} | "
            f"{us[1]:.3g} | {us[2]:.3g} | {eng['compiled_vs_numpy'][i]:.1f}x | "
            f"{eng['speedup'][i]:.0f}x |"
        )
    return lines


def write_page(path: Path, eng, studies, quick: bool) -> None:
    """Write the page from the columns of ``engines.parquet`` and ``studies.parquet`` (either
    None when not measured in this run)."""
    out = [HEADING, ""]
    out += [
        "Written by `make bench` (`python -m benchmarks`, "
        + ("`--quick`: smoke sizes, the numbers say nothing" if quick else "full size")
        + "). CPU time of this process (`time.process_time`, the best of repeated rounds, "
        "compiled and NumPy alternating: the machine may be shared); NumPy = the same trials "
        "with `SIM_NO_JIT=1` unless the row says otherwise. The rule (issue 22): a compiled "
        f"path stays where its engine row shows at least {KEEP_RATIO:g}x over its NumPy path, "
        f"or where it saves at least {KEEP_SHARE:.0%} of a study's time (`studies.parquet`).",
        "",
        "## Compiled modules",
        "",
        "| compiled module | row | measured | verdict |",
        "|---|---|---|---|",
    ]
    if eng:
        for i, mod in enumerate(eng["compiled_module"]):
            if not mod:
                continue
            ratio = float(eng["compiled_vs_numpy"][i])
            study = STUDY_OF.get(mod)
            share = _share(studies, study, "compiled", "numpy") if study else np.nan
            measured = f"engines `{eng['engine'][i]}`: {ratio:.1f}x against {eng['numpy_side'][i]}"
            if study and not np.isnan(share):
                measured += f"; studies `{study}`: saves {share:.0%} of its CPU time"
            out.append(f"| `{mod}` | {eng['engine'][i]} | {measured} | "
                       f"{_verdict(ratio, share, study)} |")  # fmt: skip
    out += ["", "## Engine rows (`engines.parquet`)", ""]
    out += _engines_table(eng) if eng else ["Not measured in this run."]
    out += ["", "## Study rows (`studies.parquet`)", ""]
    if studies:
        out += ["| study | variant | workers | CPU (s) | wall (s) |", "|---|---|---:|---:|---:|"]
        for i, s in enumerate(studies["study"]):
            out.append(
                f"| {s} | {studies['variant'][i]} | {studies['workers'][i]} | "
                f"{studies['cpu_s'][i]:.2f} | {studies['wall_s'][i]:.2f} |"
            )
    else:
        out.append("Not measured in this run.")
    with atomic_path(path) as tmp:  # a write cut short (a full disk) left a torn page in place
        tmp.write_text("\n".join(out) + "\n", encoding="utf-8")  # of the finished one
