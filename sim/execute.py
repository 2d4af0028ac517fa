"""Run a study: a validated configuration into an output directory, safely.

The one path every door takes (``sim run``, :meth:`sim.api.StudyHandle.run`, ``sim.batch``):
the work estimate and its limits, the output checks (nothing the suite did not write is ever
replaced), the executor, a locked staging directory ``.<out>.partial/`` that is resumed after a
kill and replaces ``<out>`` only when everything succeeded, a ``[sweep]`` over the study's keys
(:func:`run_sweep`), and one line for any failure (:class:`ConfigError`, :class:`StudyError`).
"""

from __future__ import annotations

import dataclasses
import functools
import logging
import multiprocessing
import os
import re
import sys
from concurrent.futures import BrokenExecutor
from contextlib import nullcontext
from pathlib import Path
from typing import Any, Callable, Collection, Mapping

import numpy as np

from sim.execute_sweep import check_sweep, not_the_cells, sweep_limits
from sim.held_stops import held_stops
from sim.input_places import check_inputs_outside
from sim.mc.argv import most_workers
from sim.mc.config import ConfigError, StudyError, check_chunks
from sim.mc.estimate import chunk_note
from sim.mc.executors import StartRefused, end_dask_clusters, script_words
from sim.mc.left_behind import clear_replaced
from sim.mc.outputs import _chunks, _differs, _same, check_out, drop_stage, prepare_stage, stage_dir
from sim.mc.publish import publish, seal
from sim.mc.resumed import resumed_words
from sim.mc.runner import ChunkStore, RunContext, make_executor
from sim.mc.storage import (
    code_hash,
    provenance,
    read_record,
    read_table,
    umask_problem,
    versions,
    write_table,
)
from sim.mc.study_source import source_fields
from sim.mc.sweep import cell_config, cell_label, cell_seed, expand, swept_order
from sim.mc.table_edits import edited_chunks, edited_tables
from sim.places import check_place
from sim.report.plotting import without_figures
from sim.report.sweep import fig_sweep
from sim.run_failure import numeric_failure
from sim.spared_workers import start_sparing_workers
from sim.standard_error import say
from sim.start_method import for_the_callers_process
from sim.stops import check_interrupt, keep_lost_interrupts
from sim.threads import interrupted, shadowed

__all__ = ["execute", "run_sweep", "check_sweep", "sweep_limits", "drop_half_imported"]


#: a Dask scheduler address: tcp://HOST:PORT (or another Dask protocol)
_SCHEDULER = re.compile(
    r"^(?:(?:tcp|tls|ucx|ws|wss)://)?(?:\[[0-9A-Fa-f:.]+\]|[A-Za-z0-9._-]+)"
    r":(\d{1,5})/?$"
)


def _check_options(executor: Any, workers: Any, scheduler: Any) -> None:
    """The run options every door passes (``sim run``, the Python API): one line naming it."""
    if not isinstance(executor, str) or executor not in ("local", "dask"):  # never its __eq__
        raise ConfigError("executor", f"must be 'local' or 'dask' (got {executor!r})")
    top = most_workers()
    if isinstance(workers, bool) or not isinstance(workers, (int, np.integer)):
        raise ConfigError("workers", f"must be an integer between 1 and {top} (got {workers!r})")
    if not 1 <= workers <= top:
        raise ConfigError("workers", f"must be between 1 and {top} (got {workers})")
    if scheduler is not None:
        m = _SCHEDULER.match(scheduler) if isinstance(scheduler, str) else None
        if not m or not 0 < int(m.group(1)) < 65536:
            raise ConfigError(
                "scheduler", f"not a scheduler address like tcp://HOST:8786 (got {scheduler!r})"
            )
        if executor != "dask":
            raise ConfigError("scheduler", "needs executor dask")


def _not_in_a_starting_worker() -> None:
    """A worker process that ``spawn`` or ``forkserver`` is starting imports the caller's
    script again (as ``__mp_main__``); a script without ``if __name__ == "__main__":`` starts
    its run again there. That process ends here, silently (its parent, whose executor then
    fails to start, says why in one line: :func:`sim.mc.executors.script_words`): each worker
    printed multiprocessing's "bootstrapping phase" traceback, and under Dask each started a
    cluster of its own, about 250 lines of tracebacks before the parent's one line."""
    if getattr(multiprocessing.current_process(), "_inheriting", False):
        os._exit(1)


def drop_half_imported(before: Collection[str]) -> list[str]:
    """Remove from ``sys.modules`` every module a failed or interrupted command imported
    (not in ``before``, the names held when it started) whose import did not finish (Ctrl-C
    while a run imports matplotlib or numba on first use, about a second): Python removes the
    package whose code was interrupted, but not its submodules already loaded, which keep the
    half-made package (``matplotlib.rcsetup`` bound to a ``matplotlib`` without
    ``get_data_path``). The next import of the package ran its code again over them, and in a
    long-lived process (a notebook) every later run failed ("module 'matplotlib' has no
    attribute '_docstring'", numba's "module 'numba' has no attribute 'core'") until the
    process was restarted. A module left behind is one whose parent package is no longer in
    ``sys.modules``; the next import loads them afresh. A module of the caller's that was
    there before the command (a stub put in ``sys.modules`` by hand, a test's mock) is left
    alone, whatever its name (here, not in :mod:`sim.stops`, part of every study's code hash)."""
    mods = sys.modules
    gone = [
        n
        for n in list(mods)
        if "." in n
        and n not in before
        and any(n.rsplit(".", k)[0] not in mods for k in range(1, n.count(".") + 1))
    ]
    for n in gone:
        mods.pop(n, None)
    return gone


def _no_half_imports(fn):
    """``fn`` leaving no half-imported library behind when it fails or is interrupted
    (:func:`drop_half_imported` of the modules it imported): the next run in the process
    imports it again."""

    @functools.wraps(fn)
    def wrapped(*args, **kwargs):
        before = set(sys.modules)
        try:
            return fn(*args, **kwargs)
        except BaseException:
            drop_half_imported(before)
            raise

    return wrapped


@_no_half_imports  # every door: Ctrl-C in matplotlib's or numba's first import poisons nothing
@keep_lost_interrupts()  # every door: Ctrl-C that Python drops in a C callback is kept
@for_the_callers_process  # every door: start method unset after, a <stdin> script not re-run
def execute(
    study,
    cfg: dict,
    sweep: dict,
    out: Path,
    shown: str | None = None,
    *,
    executor: str = "local",
    workers: int = 1,
    scheduler: str | None = None,
    overwrite: bool = False,
    quiet: bool = False,
    max_memory_gb: float | None = None,
    max_adjustments: float | None = None,
    figures: bool = True,
    readme: Callable[[Path, str], Any] | None = None,
    overrides: list[str] | None = None,
    source: str | os.PathLike | None = None,
):
    """Run a validated study config (and its sweep) into ``out`` (absolute): estimate and
    limits, output checks, executor, locked staging directory, the run, and the final
    replacement of ``out``. ``figures=False``: no figure is drawn (the tables are the same;
    ``run.json`` says ``"figures": false``, so ``make reproduce`` does not take the results
    as up to date). ``readme(stage, name)``: writes the run's README.md into the sealed
    staging directory before it replaces ``out`` (``sim run``; written after, a failure or a
    kill there left the new results without it, or with a ``run.json`` that did not list it,
    and exit 0). ``overrides``: the run's, as ``run.json`` records them (:mod:`sim.mc.overrides`);
    ``source``: its study file (:mod:`sim.mc.study_source`). Raises ConfigError/StudyError (one
    line) on any failure. Returns the run's :class:`sim.mc.estimate.Estimate`."""

    _not_in_a_starting_worker()
    shown = shown or str(out)
    _check_options(executor, workers, scheduler)
    check_chunks(cfg)
    est = sweep_limits(study, cfg, sweep, max_memory_gb, max_adjustments, workers)
    check_sweep(study, cfg, sweep, quiet)
    if not quiet and (note := chunk_note(est, cfg["chunk"])):
        say(f"sim: {note}")
    record = {
        "config": {**cfg, "sweep": sweep} if sweep else cfg,
        "code_hash": code_hash(cfg["study"]),
        **swept_order(sweep),  # the order of its keys makes its cells: sorted in the config
        "versions": versions(),
        **({} if figures else {"figures": False}),
        **({"overrides": overrides} if overrides else {}),
        **source_fields(source, out),
    }
    if (why := umask_problem()) is not None:
        raise ConfigError(None, why)
    check_place(out, shown)  # not in sim/ (a study's code hash), not below a broken link
    check_out(out, shown, record, overwrite)
    check_inputs_outside(out, shown, cfg, sweep)  # a run never replaces a file its study reads
    stage = stage_dir(out)
    clear_replaced(stage, out, shown)  # a kill between publishing's two steps left them there
    try:
        ex = start_sparing_workers(
            executor, lambda: make_executor(executor, workers, scheduler), _end
        )
    except (RuntimeError, OSError, TimeoutError, ValueError, TypeError) as e:
        key = "--scheduler" if scheduler else "--executor"
        msg = (str(e).strip().splitlines() or [type(e).__name__])[0]
        # a refusal before any worker started is not a script's missing main guard
        words = "" if isinstance(e, StartRefused) else script_words(executor, workers, scheduler)
        raise ConfigError(key, f"cannot start the {executor} executor: {msg}{words}") from None
    lock = ctx = None
    finished = False  # the study's run returned: every chunk done, its tables written
    try:
        dropped = _replaced(stage, record) if overwrite else None
        try:
            lock, resumed = prepare_stage(stage, out, shown, record, overwrite)
        except ConfigError as e:
            raise _this_process(e) from None
        # again, under the lock: another run may have published into out since the check
        # above (a Dask cluster or a pool starting in between): its results are not ours
        check_out(out, shown, record, overwrite)
        if not figures:  # figures of an earlier, killed attempt would pass for this run's
            for png in stage.rglob("*.png"):
                png.unlink()
        store = ChunkStore(stage / "trials", provenance(cfg))
        if resumed:
            say(f"sim: resuming {cfg['study']}: {resumed_words(store)}")
        if dropped:  # not resumed: another version's chunks are not mixed with this one's
            say(
                f"sim: starting {cfg['study']} over: {dropped} is replaced, not resumed",
            )
        ctx = RunContext(quiet=quiet, executor=ex, store=store, estimate=est)
        try:
            with ctx.progress_bar(cfg["study"]), nullcontext() if figures else without_figures():
                run_sweep(study, cfg, sweep, stage, ctx) if sweep else study.run(cfg, stage, ctx)
            finished = True
            check_interrupt()  # dropped by Python after the last chunk: the stage is kept
        except (ConfigError, StudyError, OSError, KeyboardInterrupt, SystemExit):
            raise
        except Exception as e:
            if interrupted(e):  # Ctrl-C inside an import (or a library that wraps it)
                raise KeyboardInterrupt from None
            if isinstance(e, (ArithmeticError, ValueError, MemoryError)):  # numbers the model
                raise numeric_failure(e, study, cfg, est.memory_keys) from None  # cannot take
            if (words := shadowed(e, forget=True)) is not None:  # a user's matplotlib.py
                raise StudyError(f"{cfg['study']}: {words}") from None
            if isinstance(e, BrokenExecutor):  # a worker killed (kill -9, the OOM killer): the
                raise StudyError(  # study part was blamed, exit 3 "internal error"
                    f"{cfg['study']}: a worker process of the run ended abruptly (killed, or out "
                    "of memory?); the finished chunks are kept: run the same command again to "
                    "resume"
                ) from None
            if os.environ.get("SIM_DEBUG"):  # a bug: one line, the traceback on request
                raise
            err = numeric_failure(e, study, cfg)
            err.internal = True
            raise err from None
    except BaseException as e:
        if isinstance(e, KeyboardInterrupt) and (finished or (ctx and ctx.all_counted())):
            e.chunks_done = True  # the same command only writes the results: none is missing
        if executor == "dask":
            _quiet_dask_logs()  # its closing chatter is not for users (one line is)
        ex.close(kill=True)
        if lock is not None:  # a failure of the run (not an interrupt) is marked replaceable
            failed = isinstance(e, (ConfigError, StudyError))
            drop_stage(stage, lock, reason=str(e) if failed else None)
        raise
    ex.close()
    published = False
    try:
        check_interrupt()  # not published: an interrupted run never looks finished
        check_out(out, shown, record, overwrite)  # again, under the lock: ours or absent
        seal(stage, ctx.store)
        if readme is not None:
            readme(stage, out.name)
        edited = _edits(out)
        with held_stops():  # an interrupt between its renames: handled once they are done
            publish(stage, out)
            published = True
            lock.release()
        _say_edits_replaced(edited, shown)
    except BaseException as e:
        if not published:
            drop_stage(stage, lock)
            if isinstance(e, KeyboardInterrupt):  # every chunk done: only the results are
                e.chunks_done = True  # left to write
        elif isinstance(e, KeyboardInterrupt):  # the results stand: say where, not "resume"
            e.published = shown
        raise
    return est


def _edits(out: Path) -> list[str]:
    """The tables of the earlier results ``out`` changed (or removed) after their run wrote
    them, and its chunks changed (their sha256 is not the one its ``run.json`` records), which
    a publish replaces."""
    try:
        return (
            edited_tables(out) + edited_chunks(out) if out.is_dir() and not out.is_symlink() else []
        )
    except OSError:
        return []


def _say_edits_replaced(edited: list[str], shown: str) -> None:
    """One note naming the ``edited`` tables (:func:`_edits`) the run has replaced: the same
    command again replaced a verdict or a number edited by hand with the run's, without a
    word (a file of the user's, which the run did not write, is carried over as it is)."""
    if edited:
        names = ", ".join(edited[:3]) + (f" and {len(edited) - 3} more" if len(edited) > 3 else "")
        say(
            f"sim: note: {names} in {shown} changed after the run that wrote "
            f"{'it' if len(edited) == 1 else 'them'} (edited by hand?): replaced by this run's",
        )


def _this_process(e: ConfigError) -> ConfigError:
    """``e``, or when it names this process as the running sim that writes ``out`` (two runs
    of the API in threads of one notebook), in words that say so: "(pid 9485)" named the
    caller's own kernel as the process to wait for (or to kill)."""
    me = f"(pid {os.getpid()})"
    if me not in str(e):
        return e
    msg = e.detail.replace(me, "(another run in this process: a thread)")
    return ConfigError(e.key, msg)


def _replaced(stage: Path, record: dict) -> str | None:
    """What ``--overwrite`` replaces in the staging directory ``stage`` instead of resuming
    it: an unfinished run of other code (killed, the code pulled since) or of another config
    with its chunks (``make reproduce`` after a pull started it over without a word; its chunks
    are never mixed with this run's). Read before the lock, for the message only, with the
    staging rules' own tests (:mod:`sim.mc.outputs`: the same run, its chunks, how it differs)."""
    try:
        old = read_record(stage) if stage.is_dir() and not stage.is_symlink() else None
        n = _chunks(stage) if old else 0
    except OSError:
        return None
    if not n or old.get("failed") or _same(old, record):
        return None
    return f"its unfinished run of {_differs(old, record)} ({n} chunks)"


def _end(ex) -> None:
    """An executor started, or (None) the Dask clusters starting, ended by an interrupt:
    quietly, as after a run's."""
    _quiet_dask_logs()
    if ex is None:
        end_dask_clusters()
    else:
        ex.close(kill=True)


def _quiet_dask_logs() -> None:
    """Before an interrupted Dask run is closed: the loggers of this process that would print
    the closing connections' errors (tornado's "Exception in callback", distributed's
    CommClosedError of a worker's heartbeat), each of them, whatever level dask's config
    gave it, are silenced."""
    names = [
        n
        for n in list(logging.root.manager.loggerDict)
        if n.split(".")[0] in ("asyncio", "distributed", "tornado")
    ]
    for n in ("asyncio", "distributed", "tornado", *names):
        logging.getLogger(n).setLevel(logging.CRITICAL + 1)


def run_sweep(study, cfg: dict, table: Mapping[str, Any], out: Path, ctx) -> dict:
    """Run every cell of ``table`` for ``study`` from the resolved base ``cfg``; write
    ``out/sweep.parquet`` and ``out/cells/<label>/``. Returns the table's columns."""

    keys, cells, reps, mode = expand(table, study.schema)
    rows: list[dict[str, Any]] = []
    kinds: dict[str, list[str]] = {}  # each claim's interval kinds over the cells (the figure's)
    for i, cell in enumerate(cells):
        for r in range(reps):
            seed = cell_seed(cfg["seed"], i, r, mode)
            row: dict[str, Any] = {
                "cell": i,
                "replicate": r,
                "label": cell_label(i, r),
                "seed": seed,
                "feasible": True,
                "reason": "",
            }
            row.update({k: cell[k] for k in keys})
            try:
                ccfg = cell_config(study, cfg, cell, seed)
            except ConfigError as e:
                if not_the_cells(e):  # an input file changed since the study was loaded
                    raise
                row.update(feasible=False, reason=str(e))
                rows.append(row)
                continue
            d = out / "cells" / row["label"]
            d.mkdir(parents=True, exist_ok=True)
            cctx = ctx
            if getattr(ctx, "store", None) is not None:  # each cell its own chunk store
                cctx = dataclasses.replace(
                    ctx,
                    store=type(ctx.store)(
                        d / "trials", provenance(ccfg, sweep_cell=row["label"], sweep=dict(table))
                    ),
                )
            try:
                study.run(ccfg, d, cctx)
            except (KeyboardInterrupt, SystemExit):
                raise
            except Exception as e:  # noqa: BLE001 - a failed cell is recorded, the sweep goes on
                if not_the_cells(e):  # a full disk, a killed worker: the run stops, resumable
                    raise
                row.update(feasible=False, reason=f"failed: {e}".splitlines()[0])
                rows.append(row)
                continue
            if (d / "claims.parquet").is_file():
                for c in read_table(d / "claims.parquet").to_pylist():
                    row[c["claim"]] = c["value"]
                    row[c["claim"] + ":lo"] = c["ci_low"]
                    row[c["claim"] + ":hi"] = c["ci_high"]
                    kinds.setdefault(c["claim"], [])
                    if c["interval"] not in kinds[c["claim"]]:
                        kinds[c["claim"]].append(c["interval"])
            rows.append(row)
    if rows and not any(r["feasible"] for r in rows):
        reasons = list(dict.fromkeys(r["reason"] for r in rows))
        raise StudyError(
            f"sweep: every cell failed ({len(rows)} of {len(rows)}): "
            + "; ".join(reasons[:3])[:500]
            + (" ..." if len(reasons) > 3 else "")
        )
    cols: dict[str, list] = {}
    names = list(dict.fromkeys(k for row in rows for k in row))
    for k in names:
        vals = [row.get(k) for row in rows]
        if all(
            isinstance(v, (int, float, np.floating, np.integer)) or v is None for v in vals
        ) and any(isinstance(v, (float, np.floating)) for v in vals):
            vals = [np.nan if v is None else float(v) for v in vals]
        elif any(isinstance(v, list) for v in vals):
            vals = [repr(v) for v in vals]
        cols[k] = vals
    write_table(
        out / "sweep.parquet",
        cols,
        provenance(cfg, sweep=dict(table), sweep_keys=keys, seed_mode=mode, claim_intervals=kinds),
    )
    fig_sweep(out / "sweep.parquet", out / "sweep.png")
    return cols
