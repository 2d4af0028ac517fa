"""Monte-Carlo runner: trials in chunks, one spawned random stream per chunk.

Chunk ``k`` of stream ``part`` draws from
``numpy.random.SeedSequence(seed, spawn_key=(part, k))`` -- the same stream that
``SeedSequence(seed).spawn(part + 1)[part].spawn(k + 1)[k]`` gives -- so a result does not
depend on how many workers run the chunks, in which order, or on which machine; only
``seed``, ``part`` and the chunk size fix it.

A chunk function ``fn(rng, n)`` returns a dict of arrays:

* ``rows.<name>``: one value per trial (1-D, length ``n``): per-trial rows. They are
  written to the chunk's file and *not* kept in memory (unless ``keep_rows``), so the
  memory of a run does not grow with the number of trials.
* any other key: kept and concatenated along axis 0 over the chunks -- per-trial scalars
  (leading axis ``n``) or per-chunk statistics such as sums (leading axis 1).

With a :class:`ChunkStore` each finished chunk is written atomically (temporary file, then
rename) to ``<dir>/part-<p>/chunk-<k>.parquet``; a run that was killed and started again
loads the finished chunks and computes only the missing ones.

Executors (:func:`make_executor`): in-process (default), a local process pool
(``workers > 1``), or a ``dask.distributed`` client. The output is bit-for-bit the same.
"""

from __future__ import annotations

import json
import pickle
from contextlib import contextmanager
from dataclasses import dataclass, field
from pathlib import Path
from typing import Callable, Mapping

import numpy as np
import pyarrow as pa
import pyarrow.parquet as pq

from sim.lsq import distributions as D
from sim.mc.chunk_content import content_digest
from sim.mc.chunk_count import MIN_CHUNKS, require_chunks
from sim.mc.config import ConfigError, StudyError
from sim.mc.executors import InProcess, make_executor
from sim.mc.packed import pack, unpack
from sim.mc.progress import Progress
from sim.mc.storage import atomic_path, config_hash
from sim.mc.streams import chunk_rng
from sim.standard_error import say
from sim.stops import check_interrupt

__all__ = [
    "chunk_rng",
    "run_chunks",
    "ChunkStore",
    "make_executor",
    "jackknife",
    "require_finite",
    "require_chunks",
    "MIN_CHUNKS",
    "PROBE_TRIALS",
    "PROBE_SEED",
    "PROBE_MAX_ITER",
    "probe_limit",
]

#: a study's solver probe at load time (brown's check_solver, the network's probe_solver):
#: PROBE_TRIALS trials from a fixed stream of their own (PROBE_SEED, not the run's), run when
#: ``solver.max_iter`` is at most PROBE_MAX_ITER (their adjustments converge in 1 to 4)
PROBE_TRIALS, PROBE_SEED, PROBE_MAX_ITER = 16, 27, 8
ROWS = "rows."
_ARRAYS = b"sim.arrays"
_IDENTITY = b"sim.chunk"  # a chunk file's identity, checked when it is read back


def require_finite(name: str, array, part: str, key: str | None = None) -> np.ndarray:
    """``array`` as a float array, or :class:`sim.mc.config.StudyError` (one line naming the study
    ``part``, the quantity ``name`` and, when given, the config ``key`` to change) if any entry
    is NaN or infinite. Study code calls it where a number is required (NaN that stands for
    "missing" must not go through it)."""
    a = np.asarray(array, float)
    bad = ~np.isfinite(a)
    if bad.any():
        hint = f"; change {key}" if key else ""
        raise StudyError(
            f"{part}: {name} is not finite ({int(bad.sum())} of {a.size} values "
            f"NaN or infinite){hint}"
        )
    return a


def probe_limit(
    cfg: Mapping, statuses: Callable[[int], np.ndarray], default: int, model: str, why: str = ""
):
    """Refuse, at load time, a ``solver.max_iter`` no trial of the run can meet (the run
    computed every chunk, then refused): ``statuses(max_iter)`` gives the solver statuses of
    the study's :data:`PROBE_TRIALS` probe trials (a stream of :data:`PROBE_SEED`, not the
    run's) adjusted within ``max_iter`` iterations (1: the iteration limit, 0: converged).
    The limit is the cause only when none converges within it and the same trials converge
    at the key's ``default`` (a gross bias no limit helps is named elsewhere); probed only at
    a limit of at most :data:`PROBE_MAX_ITER`. One wording for every study (brown's
    ``check_solver``, the network's ``probe_solver``), naming the key and ``model`` (what
    the trials adjust with: "pivot model", "'grid plate' network"); ``why``: what the model
    knows of the iterations a trial needs, said after the common words (the network's: its
    first correction is the noise itself)."""
    limit, tol = cfg["solver.max_iter"], cfg["solver.tol_mm"]
    if limit > PROBE_MAX_ITER or not np.all(statuses(limit) == 1):
        return
    if np.any(statuses(default) == 0):
        raise ConfigError(
            "solver.max_iter",
            f"{limit} iteration{'s' * (limit > 1)} to solver.tol_mm = {tol:g}: none of "
            f"{PROBE_TRIALS} probe trials of the {model} converged, so no trial would (the run "
            "would compute every chunk, then refuse): raise solver.max_iter (or solver.tol_mm)"
            + (f"; {why}" if why else ""),
        )


@dataclass(frozen=True)
class ChunkStore:
    """A directory of finished chunks: ``<root>/part-<p>/chunk-<k>.parquet``.

    ``prov``: provenance written into every chunk file's metadata (``sim.provenance``).
    """

    root: Path
    prov: dict | None = None
    used: set = field(default_factory=set, compare=False, repr=False)

    def path(self, part: int, k: int) -> Path:
        return Path(self.root) / f"part-{part}" / f"chunk-{k:06d}.parquet"

    def save(
        self, part: int, k: int, n: int, data: Mapping[str, np.ndarray], seed: int | None = None
    ) -> None:
        rows = {key[len(ROWS) :]: v for key, v in data.items() if key.startswith(ROWS)}
        kept = {key: v for key, v in data.items() if not key.startswith(ROWS)}
        table = pa.table(
            {
                "chunk": np.full(n, k, np.int32),
                "trial_in_chunk": np.arange(n, dtype=np.int32),
                **rows,
            }
        )
        meta = {_ARRAYS: pack(kept), b"n": str(n).encode()}
        ident = {
            **self._identity(part, k, n, seed),
            "content": content_digest(table, meta[_ARRAYS]),
        }
        meta[_IDENTITY] = json.dumps(ident, sort_keys=True).encode()
        if self.prov is not None:
            meta[b"sim.provenance"] = json.dumps(
                {**self.prov, "chunk": k, "part": part, "spawn_key": [part, k]}, sort_keys=True
            ).encode()
        table = table.replace_schema_metadata(meta)
        with atomic_path(self.path(part, k)) as tmp:
            pq.write_table(table, tmp)
        self.used.add(self.path(part, k))

    def _identity(self, part: int, k: int, n: int, seed: int | None) -> dict:
        """What a chunk file must be to stand for chunk ``k`` of part ``part``: the study, the
        hash of its resolved config and code, the part, the index, the trials and the seed
        stream (``SeedSequence(seed, spawn_key=(part, k))``)."""
        prov = self.prov or {}
        return {
            "study": prov.get("study"),
            "config_hash": config_hash(prov.get("config"), prov.get("code_hash")),
            "part": part,
            "chunk": k,
            "trials": n,
            "seed": seed,
            "spawn_key": [part, k],
        }

    def load(
        self, part: int, k: int, keep_rows: bool = False, n: int | None = None, seed=None
    ) -> dict | None:
        """The stored chunk ``k`` of part ``part``, or None when it is missing, unreadable or
        not what its name says (another study, config, part, index, size or seed) or not what
        the run wrote (its content digest differs: edited by hand): the caller computes it
        again and the file is replaced."""
        p = self.path(part, k)
        if (table := self._checked(p, part, k, n, seed)) is None:
            return None
        try:
            out = unpack(table.schema.metadata[_ARRAYS])
        except (KeyError, ValueError, TypeError, AttributeError):
            return None  # unreadable or foreign: recompute it
        if keep_rows:
            for name in table.column_names:
                if name not in ("chunk", "trial_in_chunk"):
                    out[ROWS + name] = table.column(name).to_numpy()
        self.used.add(p)
        return out

    def _checked(self, p: Path, part: int, k: int, n, seed, config: bool = True):
        """The table of chunk file ``p`` when it is chunk ``k`` of part ``part`` as the run
        wrote it (``n``, ``seed`` None: as it records them; ``config=False``: of any study
        and config, a sweep cell's), else None."""
        if not p.is_file():
            return None
        try:
            table = pq.read_table(p)
            meta = table.schema.metadata or {}
            ident = json.loads(meta[_IDENTITY])
            want = self._identity(part, k, n if n is not None else ident.get("trials"), seed)
            if seed is None:
                want["seed"] = ident.get("seed")
            if not config:
                want.update(study=ident.get("study"), config_hash=ident.get("config_hash"))
            content = ident.pop("content", None)
            if ident != want or table.num_rows != want["trials"]:
                return None
            return table if content == content_digest(table, meta[_ARRAYS]) else None
        except (OSError, KeyError, ValueError, TypeError, AttributeError, pa.ArrowException):
            return None  # unreadable or foreign: recompute it

    def strays(self) -> list[Path]:
        """Chunk files under the store that this run neither wrote nor read (left over from
        another run, or copied in): they are not part of its trials."""
        root = Path(self.root)
        if not root.is_dir():
            return []
        return sorted(p for p in root.rglob("*") if p not in self.used and p.is_file())


def _picklable(fn) -> bool:
    try:
        pickle.dumps(fn)
        return True
    except Exception:  # noqa: BLE001 - any pickling failure means: run in-process
        return False


class _Shared:
    """The run's shared bar, used by one :func:`run_chunks` call (it is not closed here)."""

    def __init__(self, bar):
        self.bar = bar

    def __enter__(self):
        return self.bar

    def __exit__(self, *exc):
        return None


def _work(units: float | None, n: int) -> float | None:
    return None if units is None else units * n


def run_chunks(
    fn: Callable[[np.random.Generator, int], Mapping[str, np.ndarray]],
    trials: int,
    seed: int,
    chunk: int,
    part: int = 0,
    label: str = "",
    quiet: bool = False,
    ctx=None,
    keep_rows: bool = False,
    units: float | None = None,
) -> dict[str, np.ndarray]:
    """Run ``fn(rng, n)`` over chunks of at most ``chunk`` trials and concatenate.
    ``units``: the unit adjustments one trial costs (the run's estimate's model of this part,
    :mod:`sim.mc.estimate`), which the run's bar fills by; default: the estimate's mean.

    ``ctx`` (a :class:`sim.studies.RunContext`) supplies the executor and the chunk store;
    without it the chunks run in this process and nothing is stored. Returns the kept arrays
    concatenated over chunks in chunk order (``rows.*`` only with ``keep_rows``).
    """
    if trials < 1:
        raise ValueError("trials must be >= 1")
    sizes = [min(chunk, trials - s) for s in range(0, trials, chunk)]
    store = getattr(ctx, "store", None)
    executor = getattr(ctx, "executor", None)
    quiet = quiet or getattr(ctx, "quiet", False)
    results: dict[int, dict] = {}
    todo = []
    for k, n in enumerate(sizes):
        got = store.load(part, k, keep_rows, n, seed) if store is not None else None
        if got is not None:
            results[k] = got
        else:
            todo.append((k, n))
    if executor is None or (not isinstance(executor, InProcess) and not _picklable(fn)):
        if executor is not None and not isinstance(executor, InProcess):
            say(
                f"sim: note: {label or 'this study'} runs in-process (its chunk function "
                "cannot be sent to workers)",
            )
        executor = InProcess()
    shared = getattr(ctx, "bar", None)
    # a chunk counts once a run on the shared bar: an adaptive stage reads its earlier stages'
    # chunks again (brown_design's bar counted 696 of its 470 trials, and an interrupt with
    # chunks still to come said every chunk was done: RunContext.all_counted)
    seen = getattr(ctx, "seen", None) if shared is not None and store is not None else None
    where = str(getattr(store, "root", ""))
    again = {k for k in results if seen is not None and (where, part, k) in seen}
    done_trials = sum(sizes[k] for k in results if k not in again)
    with (
        _Shared(shared)
        if shared is not None
        else Progress(trials, label, quiet=quiet, chunks=len(sizes))
    ) as bar:
        per = None if units is None else float(units)
        bar.update(done_trials, len(results) - len(again), _work(per, done_trials))
        if seen is not None:
            seen.update((where, part, k) for k in range(len(sizes)))
        check_interrupt()  # an interrupt Python dropped (a C callback) stops the run here,
        for k, n, out in executor.run(fn, seed, part, todo):
            if store is not None:
                store.save(part, k, n, out, seed)
            if not keep_rows:
                out = {key: v for key, v in out.items() if not key.startswith(ROWS)}
            results[k] = out
            bar.update(n, 1, _work(per, n))
            check_interrupt()  # or once the chunk it came in is saved
    keys = results[0].keys() if results else []
    return {
        key: np.concatenate([results[k][key] for k in range(len(sizes))], axis=0) for key in keys
    }


def jackknife(
    stat: Callable[[np.ndarray], np.ndarray],
    sums: np.ndarray,
    level: float = 0.95,
    min_chunks: int = MIN_CHUNKS,
):
    """Delete-one-chunk jackknife for a smooth function of per-chunk sums.

    sums : (C, ...) per-chunk sufficient statistics; ``stat`` maps the total (shape
    ``sums.shape[1:]``) to an estimate (scalar or array). Returns ``(estimate, lo, hi)`` with a
    Student-t interval (C - 1 degrees of freedom) from the jackknife standard error
    ``se^2 = (C - 1) / C * sum_c (theta_(c) - mean theta_(.))^2`` (Quenouille 1956, Tukey 1958).
    The rule: an interval is computed only from ``C >= min_chunks`` chunks (``MIN_CHUNKS``,
    20); fewer raise :class:`StudyError` naming the chunk size to use. Not for proportions:
    those get :func:`sim.claims.intervals.binomial_ci` from their counts.
    Streaming-friendly: memory grows with the number of chunks, not of trials.
    """
    sums = np.asarray(sums, float)
    C = sums.shape[0]
    if C < max(min_chunks, 2):
        raise StudyError(
            f"the jackknife interval needs at least {max(min_chunks, 2)} chunks, the run has "
            f"{C}: make chunk at most trials/{max(min_chunks, 2)}"
        )
    total = sums.sum(axis=0)
    est = np.asarray(stat(total), float)
    loo = np.stack([np.asarray(stat(total - sums[c]), float) for c in range(C)])
    se = np.sqrt((C - 1) / C * ((loo - loo.mean(axis=0)) ** 2).sum(axis=0))
    z = D.t_ppf(0.5 + level / 2, C - 1)
    return est, est - z * se, est + z * se


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
    counted: list = field(default_factory=list, compare=False)  # its trials, total at close
    seen: set = field(default_factory=set, compare=False)  # (store, part, chunk) on the bar

    def all_counted(self) -> bool:
        """Whether the run's bar has counted every trial of its estimate: every chunk is
        done (an interrupt then leaves only the tables and figures to the same command)."""
        if self.bars:  # its total: the estimate's, less the trials an adaptive stage left
            done, total = self.bars[-1].done, self.bars[-1].total
        else:
            done, total = self.counted or (0, getattr(self.estimate, "trials", 0) or 0)
        return total > 0 and done >= total

    @property
    def bar(self):
        """The run's shared progress bar while :meth:`progress_bar` is open, else None."""
        return self.bars[-1] if self.bars else None

    @contextmanager
    def progress_bar(self, label: str):
        """One bar for the whole run; its total is the estimate's trial count, filled by the
        estimate's work units of those trials (``work``: one a trial where it gives none)."""
        total = getattr(self.estimate, "trials", 0) or 0
        work = getattr(self.estimate, "work", 0.0) or None
        with Progress(total, label, quiet=self.quiet, work=work) as p:
            self.bars.append(p)
            try:
                yield p
            finally:
                self.bars.remove(p)
                self.counted[:] = [p.done, p.total]

    @contextmanager
    def doing(self, text: str, work: float = 0.0):
        """Show ``text`` on the run's bar while the block runs (a part that counts no trial:
        brown_design's analytic design grid and regions, half a minute at a bar of 0 %); the
        block done, the bar counts its ``work`` (the unit adjustments the estimate gave it)."""
        bar = self.bar
        if bar is not None:
            bar.set_doing(text)
        try:
            yield
            if bar is not None and work > 0:
                bar.update(0, 0, work)
        finally:
            if bar is not None:
                bar.set_doing("")

    def unneeded(self, trials: int, units: float | None = None) -> None:
        """Take ``trials`` the estimate counted and the run will not do (an adaptive stage
        that stopped, or predicts it stops, short of its maximum; ``units`` each) off the
        run's bar; ``trials`` < 0 puts them back (a later stage predicts more)."""
        if self.bar is not None and trials != 0:
            self.bar.lower(trials, None if units is None else units * trials)
