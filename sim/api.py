"""The Python API: load a study, override keys, run it, read its tables.

>>> import sim
>>> st = sim.load("studies/brown_table1.toml", trials=400, chunk=20, **{"errors.settings": 3})
>>> res = st.run(workers=2)                     # a fresh temporary directory unless out=...
>>> res.claims().to_pylist()[0]["claim"]        # pyarrow tables
>>> res.table("points").column("sigma_x_um")

Overrides are config keys by their dotted names, with ``__`` standing for a dot in keyword
form (``plate__grid=7`` is ``plate.grid = 7``); they are validated exactly like a study file
(:class:`sim.mc.config.ConfigError`, one line naming the key). A run goes through the same
machinery as ``sim run``: the estimate and its limits, the locked staging directory, the
executors, and the rule that nothing the suite did not write is ever replaced.
"""

from __future__ import annotations

import sim.api_env  # noqa: F401 - the environment, before NumPy and Arrow load

# isort: split
import os
import re
import tempfile
from dataclasses import dataclass, field, fields
from pathlib import Path
from typing import Any

import pyarrow as pa
import pyarrow.parquet as pq

from sim.api_args import arguments as _arguments
from sim.api_args import count as _count
from sim.api_args import dotted as _key
from sim.api_args import flag, no_none
from sim.api_args import keyed as _keyed
from sim.api_loggers import loggers_kept
from sim.api_paths import absolute_path as _absolute
from sim.api_paths import (
    another_run,
    cell_chunks,
    cell_mixed,
    check_identity,
    chunks_recorded,
    root_hint,
    study_runs_in,
    why_not_a_dir,
    why_unread,
)
from sim.api_paths import arrow_name as _arrow_name
from sim.api_paths import check_path as _check_path
from sim.api_paths import run_identity as _run_identity
from sim.api_state import anonymous_dir, check_state, state_sha256, working_dir
from sim.api_state import check_files as _check_files
from sim.api_state import made_by_load as _by_load
from sim.api_state import study_sha256 as _sha256
from sim.api_state import unchanged as _unchanged
from sim.api_state import unchecked as _unchecked
from sim.api_tables import a_run, own_trials, run_tables, stale_warning
from sim.api_tables import check_owner as _check_owner
from sim.api_tables import owner as _owner
from sim.api_tmp import check_env, temp_dir
from sim.api_words import Method, missing
from sim.execute import execute
from sim.mc.config import ConfigError
from sim.mc.estimate import estimate
from sim.mc.overrides import as_read, recorded
from sim.mc.paths import link_problem
from sim.mc.publish import damaged_chunks
from sim.mc.pyvalue import as_config_value
from sim.mc.settle import settled
from sim.mc.study_file import study_file_problem
from sim.mc.sweep import read_sweep, refused_cells
from sim.mc.table_shape import (
    record_line,
    record_problem,
    recorded_shape,
    shape_problem,
    sum_problem,
)
from sim.report.mpl import kept
from sim.report.read import mixed_run
from sim.report.run_summary import write_run_readme
from sim.studies import design_config, get_study
from sim.studies.picking import load_picking_chunk

__all__ = ["load", "StudyHandle", "Results"]


class _Handles:
    """``run()``'s ``trials`` and ``seed`` left out: the handle's (``None`` is refused)."""

    def __repr__(self) -> str:
        return "<the handle's>"


HANDLES = globals().get("HANDLES", _Handles())  # one, as a reload(sim.api)'s old handles have


@dataclass(frozen=True)
class Results:
    """A finished run's directory (a relative ``path`` is taken from the current directory
    when the Results is made); tables are read from its Parquet files."""

    path: Path
    study: str
    #: the run that returned them (:func:`_run_identity`; "" any): two runs into one out differ
    run_sha256: str = field(default="")

    def __post_init__(self):  # Results("results/x", "x"): a str is taken as the path
        _check_path("path", self.path)
        check_identity(self.run_sha256)  # not a table's name given third
        if not isinstance(self.study, str) or not self.study.isidentifier():
            raise ConfigError(
                "study", f"must be a study name such as 'network' (got {self.study!r})"
            )
        try:  # taken where it was named: a later os.chdir read another directory's tables
            where = Path(self.path).absolute()
        except OSError:  # the current directory was removed: a relative path names nothing
            raise ConfigError(
                "path", f"{self.path} is relative and the current directory no longer exists"
            ) from None
        object.__setattr__(self, "path", where)
        _arrow_name("path", where)  # Arrow's file names other than Python's (a Latin-1 locale)

    __getattr__ = missing  # res.trials, res.tables: Python's bare words (sim.api_words)

    def _check_dir(self) -> None:  # not "no table": the directory itself is wrong
        if not self.path.is_dir():  # a run's, deleted since, was "not a results directory"
            why = link_problem(self.path) or why_not_a_dir(self.path, bool(self.run_sha256))
            raise ConfigError("path", f"{self.path} {why}")
        if self.run_sha256 and _run_identity(self.path) not in ("", self.run_sha256):
            # its tables read silently as this run's (another seed's)
            raise ConfigError("path", another_run(self.path, self.study))

    def _within(self) -> str:
        """``; <path>/<study> is its results directory: ...`` where ``path`` is a results root
        (``sim.Results("results", "network")``, for ``results/network``), else ""."""
        inner = self.path / self.study
        if not os.path.isdir(inner) or not any(inner.glob("*.parquet")):  # glob: ENAMETOOLONG
            runs = study_runs_in(self.path, self.study)  # a network's: by its study file's name
            if not runs:  # none of the study: the studies it holds, if a results root
                return root_hint(self.path, self.study)
            more = f" (and {len(runs) - 1} more)" if len(runs) > 1 else ""
            return f"; {runs[0]}{more} holds the study's results: give that path"
        return f"; {inner} holds the study's results: give that path"

    def _dataset(self, name: str) -> bool:
        """Whether ``name`` is the chunk dataset ``trials/``: ``chunks`` always, ``trials``
        unless the run wrote a ``trials.parquet`` (wolf, agnard, gridplate: :func:`own_trials`),
        which that name reads (it was unreachable, and listed twice)."""
        return name == "chunks" or (name == "trials" and not own_trials(self.path, self.study))

    @Method
    @_arguments
    def names(self) -> list[str]:
        """The tables of the run: each once; ``chunks`` is the per-trial chunk dataset (also
        ``trials`` when the study writes no ``trials.parquet``)."""
        self._check_dir()
        files, ran = list(self.path.glob("*.parquet")), run_tables(self.path, self.study)
        listed = any(n.endswith(".parquet") for n in ran)  # else an older run's: by provenance
        names = {p.stem for p in files if p.name in ran or not listed and _owner(p) == self.study}
        within = "" if names else self._within()
        if within:  # a results root (results/ and its verify record): [], or 'verify''s tables
            raise ConfigError("path", f"{self.path} is not a results directory{within}")
        if not files:  # as table() says it: [] told nothing (a batch's --results of networks)
            raise ConfigError("path", f"{self.path} is not a results directory (no tables)")
        if files and not names:  # another study's run: its tables, none of which table() reads
            whose = sorted({repr(o) for p in files if isinstance(o := _owner(p), str)})
            raise ConfigError(
                "study",
                f"{self.path} holds tables of {' and '.join(whose) or 'no study sim ran'}, "
                f"not of {self.study!r}{self._within()}",
            )
        if (self.path / "trials").is_dir() and chunks_recorded(self.path):  # else unread
            names |= {"chunks", "trials"} if self._dataset("trials") else {"chunks"}
        return sorted(names)

    @Method
    @_arguments
    def table(self, name: str) -> pa.Table:
        """The table ``name`` (``claims``, ``points``, ..., ``trials`` or ``chunks``) as a
        pyarrow Table (read again when a run published the directory while it was read: a
        table read of a run whose run.json was read before was called another run's)."""
        if not isinstance(name, str) or not name.isidentifier():
            raise ConfigError("table", f"must be a table name such as 'claims' (got {name!r})")
        return settled(self.path, lambda: self._table(name), "path")

    def _table(self, name: str) -> pa.Table:
        self._check_dir()
        dataset = self._dataset(name)
        p = self.path / ("trials" if dataset else f"{name}.parquet")
        there = os.path.exists(p)  # a name too long for a file is none (pathlib's raised)
        if not there and not self.names():  # not "no table 'claims'; it has " (none)
            raise ConfigError(
                "path", f"{self.path} is not a results directory (no tables){self._within()}"
            )
        if not there and p.name in run_tables(self.path, self.study):  # not "has no table"
            why = "the committed results/ hold no chunks; removed by hand?): run the study again"
            why = why if dataset else "removed by hand?)"
            raise ConfigError("table", f"{p} is missing: its run wrote it ({why}")
        ran = run_tables(
            self.path, self.study
        )  # a copy beside them (claims_old.parquet): unchecked
        if there and not dataset and p.name not in ran and any(n.endswith(".parquet") for n in ran):
            why = "a copy or a file added by hand? its run.json does not list it"
            raise ConfigError("table", f"{p} is not a table its run wrote ({why})")
        if not there:  # a sweep's claims() named only 'sweep', not where its cells' tables are
            cells = (self.path / "sweep.parquet").is_file() and (self.path / "cells").is_dir()
            cells = f" (a sweep: each cell's in {self.path / 'cells'}/<label>)" if cells else ""
            has = f"it has {', '.join(self.names())}{cells}"
            raise ConfigError("table", f"{self.study} has no table {name!r}; {has}")
        if dataset and (bad := damaged_chunks(self.path)):
            raise ConfigError("table", f"{name}: {cell_chunks(self.path) or bad}")
        if not dataset and not p.is_file():  # pyarrow reads a directory as a dataset
            raise ConfigError("table", f"{p} is not a file; run the study again")
        try:
            table = pq.read_table(p)
        except (OSError, pa.ArrowException) as e:
            raise ConfigError("table", f"{p} cannot be read ({why_unread(e)})") from None
        if not dataset:
            _check_owner(p, self.study)
            mixed = mixed_run(self.path, [p.name]) or cell_mixed(self.path, [p.name])
            if mixed is not None:  # copied from another run, or another cell's
                raise ConfigError("table", mixed)
            if (bad := record_problem(p, missing=a_run(self.path))) is not None:  # unchecked
                raise ConfigError("table", record_line(bad))
            shaped = recorded_shape(p)  # none recorded: its sha256, where recorded
            edit = shape_problem(table, shaped) if shaped is not None else sum_problem(p)
            if edit is not None:  # edited by hand
                raise ConfigError("table", f"{p} is not the table its run wrote: {edit}")
        self._check_dir()  # replaced while it was read
        stale_warning(self.path)  # sim show's note on results of another version's code
        return table

    @Method
    @_arguments
    def claims(self) -> pa.Table:
        """The claims table: each paper claim beside the simulated value and its verdict."""
        return self.table("claims")


@dataclass(frozen=True)
class StudyHandle:
    """A validated study configuration, ready to run: made by :func:`load` (by hand, refused)."""

    path: Path
    study: Any = field(repr=False)
    config: dict = field(repr=False)
    overrides: dict = field(default_factory=dict)  # shown: two handles of one file differ
    sweep: dict = field(default_factory=dict, repr=False)
    file_sha256: str = field(default="", repr=False)
    #: :func:`sim.api_state.state_sha256` of config, overrides and sweep as loaded ("": none)
    state_sha256: str = field(default="", repr=False)
    #: the working directory of sim.load(), which a relative ``network.gama_xml`` is read from
    cwd: str = field(default="", repr=False, compare=False)

    def __hash__(self) -> int:  # the dataclass's would hash the config dict: TypeError
        return hash((self.path, self.file_sha256, repr(sorted(self.overrides.items()))))

    def __reduce__(self):  # pickled (a Pool's task): the study by its name, not its closures
        state = {f.name: getattr(self, f.name) for f in fields(self) if f.name != "study"}
        try:
            known = get_study(self.study.name) is self.study
        except ConfigError:  # a study of the caller's own making: pickled as it is
            known = False
        return (_unpickled, (self.study.name if known else self.study, state))

    @property
    def name(self) -> str:
        return self.config["study"]

    @_arguments
    def estimate(self):
        """Work and memory of a run (:class:`sim.mc.estimate.Estimate`), without the sweep
        cells the study refuses, as ``sim check`` counts them (:func:`refused_cells`): it
        counted them, 404 trials in 2 cells of ``trials = [400, 4]``, a sweep that runs one)."""
        check_state(self)
        skip = refused_cells(self.study, self.config, self.sweep)[0] if self.sweep else ()
        return estimate(self.config, self.sweep, skip=skip)

    @_arguments
    def replace(self, **overrides) -> "StudyHandle":
        """A new handle with more overrides."""
        _unchanged(self)
        no_none(_keyed(overrides), "replace")
        new = load(self.path, **{**self.overrides, **_keyed(overrides)})
        _check_files(self, new)  # a network.gama_xml edited since: refused, as run() does
        return new

    @_arguments
    def run(
        self,
        out: str | os.PathLike | None = None,
        executor: str = "local",
        workers: int = 1,
        trials: int = HANDLES,
        seed: int = HANDLES,
        *,
        scheduler: str | None = None,
        overwrite: bool = False,
        quiet: bool = True,
        figures: bool = True,
    ) -> Results:
        """Run the study into ``out`` (default: a new temporary directory) and return its
        :class:`Results`: the directory ``sim run`` writes (its README.md too). ``executor``:
        ``local`` (a process pool when ``workers > 1``) or ``dask``. Output is identical for
        every executor and worker count. ``figures=False``: no PNG is drawn (``sim run
        --no-figures``), the tables are the same."""
        _check_path("out", out, none_ok=True)  # trials, seed: validated as the config keys
        workers = _count("workers", workers)  # np.array(2), Decimal("2"): 2, as trials reads
        overwrite, quiet, figures = (
            flag(*a) for a in (("overwrite", overwrite), ("quiet", quiet), ("figures", figures))
        )
        _unchanged(self)
        given = {k: v for k, v in (("trials", trials), ("seed", seed)) if v is not HANDLES}
        no_none(given, "run")  # as sim.load refuses it
        h = load(self.path, **{**self.overrides, **given}) if given else self
        _check_files(self, h)  # a network.gama_xml edited since: refused, as run() does
        base = None  # the temporary directory made for this run (out=None)
        if out is None:
            try:  # the caller's tempfile.tempdir (or TMPDIR) may be gone, a file, or full
                base = temp_dir(h.name)  # a killed run's removed first
            except OSError as e:
                raise ConfigError(
                    "out",
                    f"is None, and no temporary directory can be made in "
                    f"{tempfile.gettempdir()} ({e.strerror}): name an output directory",
                ) from None
            out = base / h.name
        elif not str(out).strip():
            raise ConfigError("out", "is empty: name an output directory")
        out = _absolute("out", out)
        _arrow_name("out", out)
        # the caller's matplotlib and log levels kept; a failed run's temp dir removed or named
        with kept(), loggers_kept(), anonymous_dir(base, out):
            try:
                execute(
                    h.study,
                    h.config,
                    h.sweep,
                    out,
                    str(out),
                    executor=executor,
                    workers=workers,
                    scheduler=scheduler,
                    overwrite=overwrite,
                    quiet=quiet,
                    figures=figures,
                    # the README.md sim run writes: the same directory by either door
                    readme=lambda stage, name: write_run_readme(
                        stage, get_study, name, out, design_config
                    ),
                    overrides=recorded(as_read(h.overrides, h.config)),  # as sim run's
                    source=h.path,
                )
            except ConfigError as e:
                if e.key in _ARGUMENTS:  # the command line's option: the argument of run()
                    raise ConfigError(_ARGUMENTS[e.key], e.detail) from None
                if e.key != "--out" and not any(cli in str(e) for cli, _ in _LIMITS):
                    raise
                raise _api_words(e) from None
        return Results(out, h.name, _run_identity(out))


#: the loggers a failed or interrupted Dask run silences (:func:`sim.execute._quiet_dask_logs`)
Results.__init__ = _arguments(Results.__init__)  # type: ignore[method-assign]
StudyHandle.__init__ = _by_load(StudyHandle.__init__)  # type: ignore[method-assign]


def _api_words(e: ConfigError) -> ConfigError:
    """An output-directory refusal in the API's words: the argument is ``out`` and the way to
    replace is ``overwrite=True`` (the command line's ``--out``/``--overwrite`` name nothing
    a caller of ``run()`` can pass); a work limit's, the environment variable (:data:`_LIMITS`)."""
    if e.key != "--out":  # a work limit: run() takes no option for it, the environment does
        msg = re.sub(r"use --workers (\d+)", r"use workers=\1", e.detail)  # run()'s argument
        for cli, api in _LIMITS:
            msg = msg.replace(cli, api)
        return ConfigError(e.key, msg)
    msg = str(e).removeprefix("--out: ")
    for cli, api in (("--overwrite", "overwrite=True"), ("--out", "out")):
        msg = msg.replace(cli, api)
    return ConfigError("out", msg)


#: the command line's options a refusal names, and the argument of ``run()`` each is
_ARGUMENTS = {"--executor": "executor", "--workers": "workers", "--scheduler": "scheduler"}

#: the command line's limit options in a refusal, and what a caller of ``run()`` sets instead
#: (it said "--max-adjustments or SIM_MAX_ADJUSTMENTS": an option ``run()`` does not take)
_LIMITS = (
    ("--max-adjustments or SIM_MAX_ADJUSTMENTS", "the environment variable SIM_MAX_ADJUSTMENTS"),
    ("--max-memory-gb or SIM_MAX_MEMORY_GB", "the environment variable SIM_MAX_MEMORY_GB"),
)


def _unpickled(study: Any, state: dict) -> StudyHandle:
    """A pickled handle made as it was (changed in place: refused by run(), not in a worker)."""
    study = get_study(study) if isinstance(study, str) else study
    return _unchecked(StudyHandle, study=study, **state)


@_arguments
def load(study_file: str | os.PathLike, **overrides) -> StudyHandle:
    """Load and validate a study file with ``overrides`` (dotted keys, or ``__`` for the dot)."""
    _check_path("study_file", study_file)
    check_env()  # TQDM_NCOLS=abc, NUMBA_OPT=x: refused here, not in the middle of a run
    _absolute("study_file", study_file)  # the working directory gone: not "no such study file"
    if why := study_file_problem(study_file):  # sim check's own check of a file
        raise ConfigError("study_file", why)
    # absolute: a handle re-loads its file later, perhaps from another working directory
    study_file = _absolute("study_file", study_file)
    for k in overrides:
        if not _key(k).strip(".").strip() or not k.isprintable():
            raise ConfigError(repr(k), "is not a config key (a dotted name such as 'trials')")
    # each value as a study file would hold it (sim.mc.pyvalue): np.int64(40) is 40, a tuple
    # a list, Decimal("0.1") 0.1, an IntEnum member its int: validated and hashed like one
    vals = {k: as_config_value(str(k), v) for k, v in _keyed(overrides).items()}
    if none := [k for k, v in vals.items() if v is None]:  # not "is required" of a file's key
        raise ConfigError(none[0], "is None, which no study file holds: leave it out for its value")
    sha = _sha256(study_file)
    picks = "trials" in vals and "chunk" not in vals  # sim run --trials's chunk
    try:
        study, cfg = load_picking_chunk(study_file, picks, values=vals)
    except ConfigError as e:  # a network over the memory limit at load: the environment's
        raise (_api_words(e) if any(c in str(e) for c, _ in _LIMITS) else e) from None
    sweep = read_sweep(study_file, study.schema)
    if _sha256(study_file) != sha:  # written to while it was read: which version is this?
        raise ConfigError("study_file", f"{study_file} changed while it was loaded: load it again")
    vals = as_read(vals, cfg)  # trials=1e3 is shown as the 1000 its record says, not 1000.0
    state = state_sha256(cfg, vals, sweep)
    return StudyHandle(study_file, study, cfg, vals, sweep, sha, state, working_dir())
