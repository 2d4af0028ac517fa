"""Sweeps as data: parameter grids over any study's configuration, and adaptive trial counts.

A study file may declare a ``[sweep]`` table whose entries are config keys (dotted, or as
nested tables) with a list of values, or a range given as an inline table
``{start = a, stop = b, num = k}`` (``k`` values, ``linspace``) or ``{start, stop, step}``
(``stop`` included when it falls on the step). The cells are the Cartesian product in the
order the keys are written. Two reserved entries:

``replicates`` (int, default 1)
    independent repetitions of every cell;
``seed_mode`` (``"spawn"`` default, or ``"common"``)
    ``spawn``: cell ``i``, replicate ``r`` runs with its own root seed, drawn from
    ``SeedSequence(seed, spawn_key=(SWEEP_KEY, i, r))``; ``common``: every cell uses the
    study's seed (replicate ``r > 0``: the spawned seed of cell 0), i.e. common random
    numbers, so differences between cells carry no Monte-Carlo noise from the streams.

Each cell's configuration is validated with the study's schema and ``check``
(:func:`refused_cells`, before anything runs); a cell that fails (a constraint of the design,
e.g. a point outside the format) is recorded as infeasible with the reason and not run, and
``sim check`` and ``sim run`` say which cells once (:func:`refused_note`). A sweep in which
every cell is refused is itself refused, naming the swept keys and their values. A feasible cell runs the study into
``cells/<label>/`` and contributes one row per cell and replicate to ``sweep.parquet``:
``cell, replicate, label, seed, feasible, reason``, the swept keys, and for each claim of
the cell ``<claim>`` (value), ``<claim>:lo``, ``<claim>:hi`` (its 95 % interval). A cell
with its recorded seed reproduces ``sim run`` of the study with that seed exactly.

:func:`run_adaptive` adds chunks until the Monte-Carlo standard error of every reported
statistic is below its target (GUM Supplement 1, JCGM 101:2008, 7.9: the adaptive Monte
Carlo procedure), drawing the same chunk streams as :func:`sim.mc.runner.run_chunks`.
"""

from __future__ import annotations

import itertools
import math
import time
from pathlib import Path
from typing import Any, Callable, Mapping

import numpy as np

from sim.mc.chunk_count import MIN_CHUNKS
from sim.mc.config import (
    ConfigError,
    Field,
    check_chunks,
    check_value,
    did_you_mean,
    read_toml,
    validate,
)
from sim.mc.limit_error import LimitError
from sim.mc.message_text import near_keys
from sim.mc.numtext import UnheldError, unsigned_zeros
from sim.mc.progress import Progress
from sim.mc.streams import chunk_rng
from sim.mc.sweep_values import MAX_CELLS, _is_range, _values
from sim.mc.toml_text import toml_value
from sim.mc.unknown_key import item_hint

__all__ = [
    "SWEEP_KEY",
    "read_sweep",
    "expand",
    "cell_seed",
    "cell_label",
    "cell_config",
    "cell_values",
    "refused_cells",
    "refused_note",
    "reordered",
    "swept_order",
    "CHECK_SECONDS",
    "run_adaptive",
]

SWEEP_KEY = 0x5EE9  # spawn-key tag of the sweep's seed streams
RESERVED = ("replicates", "seed_mode")


def _flatten_sweep(d: Mapping, prefix: str = "") -> dict[str, Any]:
    """Flatten nested tables to dotted keys, keeping range tables ``{start, stop, ...}`` whole
    (``errors.settings = {start = 1, stop = 2, num = 2}`` is the range of one key)."""
    out: dict[str, Any] = {}
    for k, v in d.items():
        key = f"{prefix}{k}"
        if isinstance(v, dict) and not v:  # "datum.kind" = {} beside a swept key was dropped
            raise ConfigError(f"sweep.{key}", "is an empty table: give a list or a range")
        inner = (
            _flatten_sweep(v, key + ".") if isinstance(v, dict) and not _is_range(v) else {key: v}
        )
        for k2, v2 in inner.items():
            if k2 in out:  # "a.b" = [..] and [sweep.a] b = [..]: the same key twice
                raise ConfigError(
                    f"sweep.{k2}", "is given twice (as a quoted dotted key and in a table)"
                )
            out[k2] = v2
    return out


def read_sweep(path: str | Path, schema: Mapping | None = None) -> dict[str, Any]:
    """The ``[sweep]`` table of a study file, flattened (``{}`` if there is none); checked
    against ``schema`` when given (unknown keys and bad ranges raise ConfigError)."""
    doc = read_toml(path)
    sw = doc.get("sweep", {})
    if not isinstance(sw, dict):
        raise ConfigError("sweep", "must be a table")
    flat = _flatten_sweep(sw)
    for k, v in flat.items():  # -0.0 is 0.0; 1e-400 refused, not a cell of 0 (sim.mc.numtext)
        try:
            flat[k] = unsigned_zeros(v)
        except UnheldError as e:
            raise ConfigError(f"sweep.{k}", str(e)) from None
        except RecursionError:
            raise ConfigError(f"sweep.{k}", "is nested too deeply") from None
    if "sweep" in doc and not flat:
        raise ConfigError("sweep", "is empty: give at least one key to sweep")
    if flat and schema is not None:
        expand(flat, schema)
        flat = _canonical(flat, schema)
    return flat


def _canonical(flat: dict[str, Any], schema: Mapping) -> dict[str, Any]:
    """A validated sweep table in one spelling, so that one sweep is one config hash: a
    listed value as its key reads it (``35`` of a float key is ``35.0``), and the reserved
    entries at their defaults (``replicates = 1``, ``seed_mode = "spawn"``) left out when a
    key is swept (written, they made another hash of the same cells). A range stays as
    written."""
    keys = [k for k in flat if k not in RESERVED]
    out: dict[str, Any] = {}
    for k, v in flat.items():
        if keys and (k, v) in (("replicates", 1), ("seed_mode", "spawn")):
            continue
        if k in keys and isinstance(v, list) and isinstance(schema.get(k), Field):
            v = [check_value(f"sweep.{k}", schema[k], e) for e in v]
        out[k] = v
    return out


def expand(table: Mapping[str, Any], schema: Mapping | None = None):
    """Cells of a sweep table: ``(keys, cells, replicates, seed_mode)``, ``cells`` a list of
    ``{key: value}`` dicts in Cartesian-product order. At most :data:`MAX_CELLS` cells times
    replicates."""
    reps = table.get("replicates", 1)
    if not isinstance(reps, int) or isinstance(reps, bool) or not 1 <= reps <= MAX_CELLS:
        raise ConfigError(
            "sweep.replicates", f"must be an integer from 1 to {MAX_CELLS} (got {reps!r})"
        )
    mode = table.get("seed_mode", "spawn")
    if mode not in ("spawn", "common"):
        raise ConfigError("sweep.seed_mode", f"must be spawn or common (got {mode!r})")
    keys = [k for k in table if k not in RESERVED]
    for k in keys:
        if k in ("seed", "study"):
            raise ConfigError(f"sweep.{k}", "cannot be swept (use replicates for seeds)")
        if schema is not None and k not in schema:
            near = did_you_mean(k, {**dict.fromkeys(RESERVED), **schema})  # Replicates too
            # its unit said, as --set says it (sweep.plate.spacing_um's values in mm)
            hint = near_keys(f"sweep.{k}", [f"sweep.{n}" for n in near])
            # "network.grids[0].spacing_mm": the whole list is swept, one list a cell
            hint = item_hint(k, schema, swept=True) or hint
            raise ConfigError(f"sweep.{k}", f"unknown key{hint}")
        if schema is not None and getattr(schema[k], "sweep", None):
            raise ConfigError(f"sweep.{k}", f"cannot be swept: {schema[k].sweep}")
    vals = [_values(k, table[k]) for k in keys]
    total = math.prod(len(v) for v in vals) * reps
    if total > MAX_CELLS:
        raise ConfigError("sweep", f"{total:,} cells x replicates (at most {MAX_CELLS:,})")
    for j, (k, raw) in enumerate(zip(keys, vals)):  # a value its key refuses fails in every
        if schema is not None and isinstance(schema[k], Field):  # cell: refused here
            vals[j] = [
                check_value(f"sweep.{k}", schema[k], v.item() if isinstance(v, np.generic) else v)
                for v in raw
            ]  # as each cell reads it: 4.0 of an integer key is 4 (the table's column too)
        _no_repeats(k, raw, vals[j])
    cells = [dict(zip(keys, combo)) for combo in itertools.product(*vals)]
    return keys, cells, reps, mode


def _same(v: Any) -> Any:
    """What makes two values of a key one value (``1e-3`` and ``0.001``; ``4`` and ``4.0``;
    not ``2**53`` and ``2**53 + 1``: Python compares an int and a float exactly)."""
    if isinstance(v, (int, float, np.number)) and not isinstance(v, (bool, np.bool_)):
        return ("number", v.item() if isinstance(v, np.number) else v)
    return ("other", repr(v))


def _no_repeats(key: str, raw: list, vs: list) -> None:
    """A value given twice made two cells of one configuration, each with its own seed: the
    table and the figure showed one setting with two results, as if two designs. ``raw``: the
    values as written, ``vs``: as the key reads them."""
    seen: dict = {}
    for i, v in enumerate(vs):
        j = seen.setdefault(_same(v), i)
        if j != i:
            a, b = repr(raw[j]), repr(raw[i])
            twice = f"{a} and {b}" if a != b else a
            raise ConfigError(
                f"sweep.{key}",
                f"gives one value twice ({twice[:120]}): each would be a cell of the same "
                "configuration; for repetitions use replicates = 2",
            )


def cell_values(cfg: Mapping[str, Any], cell: Mapping[str, Any]) -> dict:
    """The values a cell sets over the base ``cfg``: its swept keys, and the chunk a swept
    ``trials`` picks when ``chunk`` is not swept (the base's, or the largest that gives
    :data:`MIN_CHUNKS` chunks, as ``--trials`` picks it). :func:`cell_config` runs them and
    :func:`sim.mc.estimate.estimate` counts them: it counted the base's chunk, ten times the
    memory of a cell of ``trials = [200]`` of network_plate (chunk 100; its cell runs 10)."""
    n = cell.get("trials")
    if isinstance(n, (int, float)) and not isinstance(n, bool) and "chunk" not in cell:
        if isinstance(cfg.get("chunk"), int) and math.isfinite(n):
            return {**cell, "chunk": min(cfg["chunk"], max(1, int(n) // MIN_CHUNKS))}
    return dict(cell)


def cell_config(study, cfg: Mapping[str, Any], cell: Mapping[str, Any], seed: int) -> dict:
    """The validated configuration of one cell: the resolved base ``cfg`` with the cell's
    values and ``seed``, through the study's schema and ``check`` and the chunk rule (a
    :class:`ConfigError` naming the key when the study refuses it)."""
    base = {k: v for k, v in cfg.items() if k != "study"}
    cell = cell_values(base, cell)
    # the cell's keys are the ones it sets: the base is resolved (its defaults already are)
    ccfg = validate({**base, **cell, "seed": seed}, study.schema, study.check, frozenset(cell))
    ccfg = {"study": cfg["study"], **ccfg}
    check_chunks(ccfg)
    return ccfg


def _distinct(vs: list) -> list:
    """The distinct values in order (a list-valued key's values are lists: not hashable)."""
    seen: dict[str, Any] = {}
    for v in vs:
        seen.setdefault(repr(v), v)
    return list(seen.values())


def _shown(keys: list[str], cell: Mapping[str, Any]) -> str:
    return ", ".join(f"{k} = {toml_value(cell[k])}" for k in keys)


#: seconds ``sim check`` / ``sim run`` spend validating a sweep's cells before it runs (a
#: 2,500-point network takes 0.7 s a cell): the cells not reached are validated when they run
CHECK_SECONDS = 15.0


def refused_cells(
    study, cfg: Mapping[str, Any], table: Mapping[str, Any], budget_s: float = CHECK_SECONDS
) -> tuple[dict[int, str], int]:
    """The cells of the sweep ``table`` the study refuses on load, ``({cell index: reason},
    cells checked)``, validated as the run validates them (with the base seed: a cell's seed
    does not decide whether it is feasible), in order, for at most ``budget_s`` seconds. When
    *every* cell is checked and refused, the sweep is: a :class:`ConfigError` naming the swept
    key (``sweep.<key>``, the key the reasons name when several are swept) and its values,
    and the first reason."""
    keys, cells, _, _ = expand(table, study.schema)
    bad: dict[int, str] = {}
    named: set = set()
    start, checked = time.monotonic(), 0
    for i, cell in enumerate(cells):
        if i and time.monotonic() - start > budget_s:
            break
        checked += 1
        try:
            cell_config(study, cfg, cell, cfg["seed"])
        except LimitError as e:  # this machine's limit, not the design's: the sweep is refused
            key = e.key if e.key in keys else keys[0] if len(keys) == 1 else None
            raise LimitError(
                f"sweep.{key}" if key else "sweep", f"in the cell of {_shown(keys, cell)}: {e}"
            ) from None
        except ConfigError as e:
            bad[i] = str(e)
            named.add(e.key)
    if cells and len(bad) == len(cells):
        values = {k: _distinct([c[k] for c in cells]) for k in keys}
        culprit = keys if len(keys) == 1 else [k for k in keys if k in named]
        key = f"sweep.{culprit[0]}" if len(culprit) == 1 else "sweep"
        shown = "; ".join(f"{k} = {v!r}" for k, v in values.items())[:300]
        reasons = list(dict.fromkeys(bad.values()))
        n = len(reasons) - 1
        more = f" (and {n} more reason{'s' * (n > 1)})" if n else ""
        raise ConfigError(
            key,
            f"every cell failed ({len(cells)} of {len(cells)}) on load, so the sweep has "
            f"nothing to run ({shown}): {reasons[0][:300]}{more}",
        )
    return bad, checked


def refused_note(table: Mapping[str, Any], bad: Mapping[int, str], checked: int) -> str:
    """One line naming the refused cells of a sweep (``""`` when none is and every cell was
    checked): they are recorded in ``sweep.parquet`` as infeasible, with the reason, and not
    run; the cells beyond ``checked`` are validated when they run."""
    keys, cells, _, _ = expand(table)
    rest = (
        f" (the first {checked} of {len(cells)} cells checked; the others are checked as they run)"
        if checked < len(cells)
        else ""
    )
    if not bad:
        return f"sweep: no cell refused{rest}" if rest else ""
    first = next(iter(bad))
    which = ", ".join(cell_label(i, 0).split("_")[0] for i in list(bad)[:8])
    which += " ..." if len(bad) > 8 else ""
    return (
        f"sweep: {len(bad)} of {len(cells)} cells are infeasible and are recorded as such, "
        f"not run: {which}{rest} (first: {cell_label(first, 0)}, "
        f"{_shown(keys, cells[first])}: {bad[first]})"
    )[:600]


def swept_order(table: Mapping[str, Any]) -> dict:
    """A run record's entry of a sweep's keys in their order, ``{"sweep_keys": [...]}``
    (``{}`` without a sweep): the order makes the cells (their labels, each setting's seed,
    the figure's first key), and the record's config, written with sorted keys, loses it."""
    keys = [k for k in table if k not in RESERVED]
    return {"sweep_keys": keys} if keys else {}


def reordered(old: Any, new: Any) -> str | None:
    """How two run records' sweeps differ in the order of their keys alone (their
    ``sweep_keys``, :func:`swept_order`), or None (the same order, or a record without it).
    A sweep with its keys reordered was "the same config": ``--stale-only`` called the other
    order's results current and ``sim run`` replaced them without ``--overwrite``."""
    a = old.get("sweep_keys") if isinstance(old, dict) else None
    b = new.get("sweep_keys") if isinstance(new, dict) else None
    if not isinstance(a, list) or not isinstance(b, list) or a == b:
        return None
    if sorted(map(str, a)) != sorted(map(str, b)):
        return None  # other keys: the configs differ, and say so
    return f"sweep (its keys in another order: {', '.join(map(str, a))}; this run {', '.join(b)})"


def cell_seed(seed: int, cell: int, replicate: int, mode: str = "spawn") -> int:
    """Root seed of one cell and replicate (see the module docstring)."""
    if mode == "common":
        if replicate == 0:
            return int(seed)
        cell = 0
    ss = np.random.SeedSequence(seed, spawn_key=(SWEEP_KEY, cell, replicate))
    return int(ss.generate_state(1, np.uint32)[0])


def cell_label(i: int, r: int) -> str:
    return f"cell{i:04d}_r{r}"


def run_adaptive(
    fn: Callable[[np.random.Generator, int], Mapping[str, np.ndarray]],
    stats: Callable[[dict], Mapping[str, tuple[float, float]]],
    target: float | Mapping[str, float],
    seed: int,
    chunk: int,
    part: int = 0,
    min_trials: int = 0,
    max_trials: int = 1_000_000,
    label: str = "",
    quiet: bool = False,
) -> tuple[dict[str, np.ndarray], dict[str, tuple[float, float]]]:
    """Add chunks of ``chunk`` trials until every statistic's standard error is below target.

    ``stats(results)`` returns ``{name: (value, standard_error)}`` from the concatenated
    results so far; ``target`` is one number or ``{name: target}``. Stops at ``max_trials``
    (the returned standard errors then show the shortfall). Chunk ``k`` uses the stream of
    :func:`sim.mc.runner.run_chunks`, so the first ``N`` trials equal a fixed run of ``N``.
    Returns ``(results, stats)``; ``len`` of any result is the number of trials it took.
    """
    parts: dict[str, list[np.ndarray]] = {}
    k = done = 0
    st: Mapping[str, tuple[float, float]] = {}
    with Progress(max_trials, label, quiet=quiet) as bar:
        while done < max_trials:
            n = min(chunk, max_trials - done)
            for key, v in fn(chunk_rng(seed, part, k), n).items():
                parts.setdefault(key, []).append(np.asarray(v))
            done += n
            k += 1
            bar.update(n)
            if done < min_trials:
                continue
            res = {kk: np.concatenate(v, axis=0) for kk, v in parts.items()}
            st = stats(res)
            tg = target if isinstance(target, Mapping) else {s: target for s in st}
            if all(se < tg.get(s, np.inf) for s, (_, se) in st.items()):
                break
    res = {kk: np.concatenate(v, axis=0) for kk, v in parts.items()}
    return res, dict(stats(res))
