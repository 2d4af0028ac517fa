"""The study registry: a study is a TOML file (data) plus a module here (code).

Each study module defines ``STUDIES = {name: Study(...)}``. ``run(cfg, out, ctx)`` writes the
study's Parquet files and figures into ``out``; ``report(out)`` returns the Markdown section
of ``results/REPORT.md`` built from those files alone.
"""

from __future__ import annotations

import importlib
import os
import sys
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any, Callable, Mapping

from sim.mc.config import ConfigError, Field, flatten, parse_override, read_toml, validate
from sim.mc.lookalike import looks
from sim.mc.read_when import refuse_unread, unread
from sim.mc.registry import MODULES
from sim.mc.sweep import RESERVED, expand, read_sweep
from sim.studies.scored_ids import check_literal_ids, check_scored, named_ids

if TYPE_CHECKING:
    from sim.mc.runner import RunContext

__all__ = [
    "Part",
    "names_from",
    "Study",
    "data_check",
    "RunContext",
    "design_config",
    "get_study",
    "load_study",
    "claim_ids",
    "unread_keys",
    "MODULES",
]


def __getattr__(name: str) -> Any:
    """``RunContext`` (the studies' run modules import it from here), loaded with the
    Monte-Carlo runner only when a run module asks for it: validating a study file does not
    load the runner (SciPy, Arrow)."""
    if name == "RunContext":
        from sim.mc.runner import RunContext

        return RunContext
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


@dataclass(frozen=True)
class Part:
    """A study's function named by its module and name, imported when it is first called: a
    study package names its run and report code and its :attr:`Study.data` check so
    (``Part("sim.studies.wolf.run", "run")``) and validating a study file (``sim check``, the
    batch's checks, :func:`sim.load`) loads its keys and checks only, not the code that runs
    the trials, draws and reports (SciPy, Arrow, Matplotlib). The code hash counts every module of a study's
    package (:func:`sim.mc.codehash.study_files`), these included."""

    module: str
    name: str

    @property
    def function(self) -> Callable:
        """The function itself (imported now)."""
        return getattr(importlib.import_module(self.module), self.name)

    def __call__(self, *args: Any, **kwargs: Any) -> Any:
        return self.function(*args, **kwargs)

    def __getattr__(self, name: str) -> Any:
        """The function's own attributes (a :func:`data_check`'s ``scored``)."""
        if name.startswith("__"):  # pickle's and copy's look-ups: not the function's
            raise AttributeError(name)
        return getattr(self.function, name)


def names_from(table: Mapping[str, str]) -> Callable[[str], Any]:
    """A study package's module ``__getattr__``: each name of ``table`` (name -> the module of
    the package that defines it) imported from there when first asked for, so that the
    package keeps offering its functions (``sim.studies.wolf.main_chunk``) without loading
    them with its keys."""

    def __getattr__(name: str) -> Any:
        if name not in table:
            raise AttributeError(f"no attribute {name!r}")
        return getattr(importlib.import_module(table[name]), name)

    return __getattr__


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
    #: reads the study's claim book and region declarations over the validated config
    #: (ConfigError naming the file and the key or claim id), so that ``sim check`` and the
    #: start of a run refuse an edited data file instead of the end of the run
    data: Callable[[dict, Mapping[str, Field]], None] | None = None
    #: the keys the resolved config does not read by a condition no ``read_when`` of the schema
    #: can say (the network's keys of the distances, in a network without one), each with why
    unread: Callable[[dict], Mapping[str, str]] | None = None
    #: the predictions the study decides on the paper's own setup whatever the run's design
    #: (brown's region rows): on a run off the paper's setup they stay the paper's verdicts
    #: (its run passes them to write_claims; ``sim check`` says so)
    paper_design: frozenset[str] = frozenset()
    #: the config spelled in the paper's printed keys where another spelling resolves to the
    #: paper's setup (brown_table1's list of Table 1's 25 points); None: as it is
    as_printed: Callable[[dict], dict] | None = None
    #: what ``sim check`` says of the run of the validated config before it (a note a line:
    #: the network's self-checks a bias will leave not applicable); None: nothing
    notes: Callable[[dict], list[str]] | None = None


def unread_keys(study: Study, cfg: Mapping[str, Any]) -> dict[str, str]:
    """The keys of ``study`` that the resolved ``cfg`` does not read, each with why: by the
    schema's ``read_when`` (:func:`sim.mc.read_when.unread`) and the study's own
    :attr:`Study.unread`."""
    out = unread(study.schema, cfg)
    if study.unread is not None:
        out.update(study.unread(dict(cfg)))
    return out


def data_check(
    load_book: Callable[[], Any],
    *declarations: Any,
    scores: Callable[[str], bool] | None = None,
    scored: Callable[[dict, Any], Any] | None = None,
) -> Callable[..., None]:
    """A :attr:`Study.data` that loads the claim book and each region declaration over it.
    A declaration is a path, or ``(path, names, keys)``: ``names(cfg)`` the inputs the study's
    code reads, which it must declare exactly (one renamed was a KeyError deep in the run,
    one added was explored and read by no code), and ``keys`` where each input goes, whose
    bounds its range must keep (a negative sigma was explored): a config key it sets as it is,
    ``(key, factor)`` for a key it sets scaled (``factor`` a number or ``factor(cfg)``; 10 ppm
    for 1 um over 100 mm: the range was checked against no bound), a :class:`Field` for an
    input that reaches no key (the bounds its code takes), or a list of these (one input
    setting two keys). The claim ids the study's code names as literals must be declared in
    the book (:mod:`sim.studies.scored_ids`; ``scores``: which of them this study scores), and
    ``scored(cfg, book)``, the ids the run of ``cfg`` builds (with the declared ones the code
    names: every id it scores), exactly the ones the book declares
    (:func:`sim.studies.scored_ids.check_scored`)."""

    package = Path(sys.modules[load_book.__module__].__file__).parent  # the study's code

    def check(cfg: dict, schema: Mapping[str, Field] | None = None) -> None:
        from sim.claims.book_region import load_declaration

        book = load_book()
        check_literal_ids(book, package, schema or {}, scores)  # a claim its code names
        if scored is not None:  # and every claim its run scores, as the run will build it
            check_scored(book, listed(book, cfg))
        for d in declarations:
            path, names, keys = d if isinstance(d, tuple) else (d, None, {})
            dec = load_declaration(path, book)
            for i in dec.inputs:
                for end, v in (("low", i.low), ("high", i.high)):
                    why = _out_of_bounds(v, keys.get(i.name, []), cfg, schema or {})
                    if why:
                        raise ConfigError(f"inputs.{i.name}.{end}", f"{path}: {why}")
            if names is None:
                continue
            want, got = set(names(cfg)), {i.name for i in dec.inputs}
            for name in sorted(want - got):
                raise ConfigError(
                    f"inputs.{name}", f"{path}: the study's code reads this input: declare it"
                )
            for name in sorted(got - want):
                raise ConfigError(
                    f"inputs.{name}",
                    f"{path}: no code of the study reads this input (it reads "
                    f"{', '.join(sorted(want))})",
                )

    def listed(book: Any, cfg: dict) -> list[str]:
        """The ids the code builds (``scored``) and the declared ones it names as literals."""
        built = list(scored(cfg, book))  # type: ignore[misc]  (only called when given)
        kept = set(built)
        return built + [c for c in named_ids(book, package, scores) if c not in kept]

    check.scored = None if scored is None else lambda cfg: listed(load_book(), cfg)
    return check


def claim_ids(study: Study, cfg: Mapping[str, Any]) -> list[str] | None:
    """Every claim id the run of ``study`` at the resolved ``cfg`` scores, listed without
    running a trial (the ``scored`` of its :func:`data_check`), or None for a study that does
    not list them (the network kind: its book is built by its code, nothing to edit)."""
    listing = getattr(study.data, "scored", None)
    return None if listing is None else listing(dict(cfg))


def _out_of_bounds(v: float, goes: Any, cfg: dict, schema: Mapping[str, Field]) -> str | None:
    """Why the region input value ``v`` is outside the bounds of where it goes (``goes``: a
    value of :func:`data_check`'s ``keys``), or None."""
    for g in goes if isinstance(goes, list) else [goes]:
        key, factor = g if isinstance(g, tuple) else (g, 1.0)
        f = key if isinstance(key, Field) else schema.get(key) if isinstance(key, str) else None
        if f is None:
            continue
        w = v * (factor(cfg) if callable(factor) else factor)
        if (f.lo is not None and (w < f.lo or (f.lo_open and w == f.lo))) or (
            f.hi is not None and w > f.hi
        ):
            bounds = f"({'>' if f.lo_open else '>='} {f.lo}, <= {f.hi})"
            if isinstance(key, Field):
                return f"{v:g} is outside the bounds its code takes {bounds}: {key.doc}"
            scaled = "" if w == v else f" ({w:g} in {key})"
            return f"{v:g}{scaled} is outside {key}'s bounds {bounds}"
    return None


def get_study(name: str) -> Study:
    if isinstance(name, (dict, list)):  # study = { name = "..." } was "study: missing" (its
        what = "a table" if isinstance(name, dict) else "an array"  # key study.name), and
        raise ConfigError(  # [[study]] "unknown study [{'name': 'x'}]", Python's words
            "study", f'must name the study as a string, study = "..." (got {what})'
        )
    if not isinstance(name, str) or name not in MODULES:
        near = [m for m in MODULES if isinstance(name, str) and looks(m) == looks(name)]
        meant = f" (did you mean {near[0]}?)" if near else ""  # "Brown_Table1": no guess
        raise ConfigError(
            "study", f"unknown study {name!r}{meant}; known: {', '.join(sorted(MODULES))}"
        )
    try:
        mod = importlib.import_module(MODULES[name])
    except ModuleNotFoundError as e:
        if e.name == MODULES[name]:
            raise ConfigError("study", f"study {name!r} is not implemented yet") from None
        raise
    return mod.STUDIES[name]


def _overridable(key: str, swept: set) -> None:
    """``study`` is never overridden; a key the file's ``[sweep]`` table sweeps neither (every
    cell would set it again: the override would do nothing)."""
    if key == "study":
        raise ConfigError("study", "cannot be overridden")
    if key in swept:
        raise ConfigError(
            key, "is swept by the file's [sweep] table: an override would have no effect"
        )


#: the two top-level words of every study file, and what each is (a key of the file that looks
#: like one, in another case or with white space, is refused saying so)
_SPELT = {
    "study": 'a study file names its study by study = "..."',
    "sweep": "the table of swept keys is [sweep]",
}


def load_study(
    path: str | Path,
    overrides: list[str] | tuple = (),
    trials: int | None = None,
    seed: int | None = None,
    values: Mapping[str, Any] | None = None,
):
    """Load, override and validate a study file.

    ``overrides``: ``"key=value"`` strings (values read as TOML, as ``--set``); ``values``:
    ``{dotted.key: value}`` with Python values (the Python API).

    Returns ``(study, cfg)`` where ``study`` is the registered :class:`sim.studies.Study`
    and ``cfg`` the resolved flat configuration (including ``study``).
    """
    doc = read_toml(path)
    for k in doc:  # Study = "..." was "study: missing", [Sweep] trials = [...] "Sweep.trials:
        if k not in _SPELT and looks(k) in _SPELT:  # unknown key (did you mean trials?)"
            raise ConfigError(k, f"is not {looks(k)} ({_SPELT[looks(k)]}, spelt so)")
    if isinstance(doc.get("study"), (dict, list)):
        get_study(doc["study"])  # refused there, not flattened to study.name
    flat = flatten({k: v for k, v in doc.items() if k != "sweep"})  # [sweep]: sim.mc.sweep
    name = flat.pop("study", None)
    if name is None:
        raise ConfigError("study", 'missing: the file must say which study it is (study = "...")')
    study = get_study(name)
    table = read_sweep(path, study.schema) if "sweep" in doc else {}  # unknown keys first
    swept = set(table) - set(RESERVED)
    for text in overrides:
        key, value = parse_override(text)
        _overridable(key, swept)
        flat[key] = value
    for key, value in (values or {}).items():
        _overridable(key, swept)
        flat[key] = list(value) if isinstance(value, tuple) else value
    if trials is not None:  # --trials 60 of a sweep over trials: recorded, no cell ran 60
        _overridable("trials", swept)
        flat["trials"] = trials
    if seed is not None:
        flat["seed"] = seed
    try:
        cfg = validate(flat, study.schema, study.check)
    except ConfigError as e:  # a key the study has not (``include = "x.toml"``) is not a path,
        # and one read from the repository root (Wolf's tables) says so itself
        field = study.schema.get(e.key) if isinstance(e.key, str) else None
        cwd = field is not None and "repository root" not in field.doc
        e = _beside_the_study(e, Path(path), flat) if cwd else e
        raise _unswept(_set_key(e, overrides, values), swept, flat, study, table) from None
    refuse_unread(
        study.schema,
        cfg,
        _asked(study.schema, flat, overrides, values),
        _cells(table, study.schema),
    )
    if study.data is not None:
        study.data(cfg, study.schema)
    return study, {"study": name, **cfg}


def _asked(
    schema: Mapping[str, Field], flat: Mapping[str, Any], overrides: Any, values: Any
) -> set[str]:
    """The keys of ``flat`` whose being unread is refused: every key an override (``--set``,
    the Python API) sets, and every key of the file but those whose switch an override sets.
    Switching the file's pattern (``--set plate.pattern=random`` on a file with ``grid = 5``)
    leaves the file's keys of the other pattern unread by the user's choice: refusing them
    ("leave it out") asked for an edit of the file no option can make."""
    over = {parse_override(t)[0] for t in overrides} | set(values or {})
    return {
        k
        for k in flat
        if k in over
        or (w := getattr(schema.get(k), "read_when", None)) is None
        or w.switch not in over
    }


def _set_key(e: ConfigError, overrides: Any, values: Any) -> ConfigError:
    """``e`` named by the key an override set when the refusal stands for several keys
    (``e.also``): ``--set network.grids=[]`` on a grid plate was refused as
    "network.points: a network needs at least two points", a key the user never named."""
    over = {parse_override(t)[0] for t in overrides} | set(values or {})
    keys = [k for k in (e.key, *getattr(e, "also", ())) if k in over]
    return e if not keys or keys[0] == e.key else ConfigError(keys[0], e.detail)


#: the cells :func:`_unswept` validates to tell whether the sweep bears on a refusal
CELLS_TRIED = 8


def _unswept(e: ConfigError, swept: set[str], flat: Mapping[str, Any], study, table) -> ConfigError:
    """``e``, saying so when a swept key is not given outside ``[sweep]``: the file's own
    values are validated first, as a study of their own, so a network whose points are given
    only as the sweep's layouts was refused "a network needs at least two points"; a key
    refused by those values alone, that a cell would read (``network.constant_mm`` where the
    file's own observations have no distance), says so too. Only when a cell's swept values
    change the refusal: ``trials = 1e30`` beside a sweep was told to give the swept keys one of
    their values, which refuses it all the same."""
    missing = sorted(k for k in swept if k not in flat)
    if not swept or (not missing and e.key in swept) or not _cell_bears(e, flat, study, table):
        return e
    if not missing:
        return ConfigError(  # a key that one cell reads, refused by the file's own values
            e.key,
            f"{e.detail} (the values outside [sweep] are checked "
            f"first, as a study of their own, with {', '.join(sorted(swept))} as given there: "
            "give there values under which it holds)",
        )
    return ConfigError(
        e.key,
        f"{e.detail} (the values outside [sweep] are checked first, "
        f"as a study of their own: {', '.join(missing)} is swept but not given there, so it "
        "takes its default; give it one of the swept values too)",
    )


def _cell_bears(e: ConfigError, flat: Mapping[str, Any], study, table) -> bool:
    """Whether the file's values with a cell's swept values (one of the first
    :data:`CELLS_TRIED`) are refused otherwise than ``e``, or not at all."""
    for cell in (_cells(table, study.schema) or [])[:CELLS_TRIED]:
        try:
            validate({**flat, **cell}, study.schema, study.check)
        except ConfigError as again:
            if (again.key, again.detail) == (e.key, e.detail):
                continue
        return True
    return False


def _cells(table: Mapping[str, Any], schema: Mapping[str, Field]) -> list[dict] | None:
    """The cells of a study file's sweep ``table`` (None without one, or when the table is
    refused: the sweep's own check names why, after the load)."""
    if not table:
        return None
    try:
        return expand(table, schema)[1]
    except ConfigError:
        return None


def _beside_the_study(e: ConfigError, path: Path, flat: Mapping[str, Any]) -> ConfigError:
    """``e``, or, when it names a key whose value is a relative path that does not exist in
    the working directory (against which such paths resolve, as documented) but does beside
    the study file, one line saying so: run from there or give an absolute path."""
    v = flat.get(e.key) if isinstance(e.key, str) else None
    if not isinstance(v, str) or not v.strip() or os.path.isabs(v) or os.path.lexists(v):
        return e
    try:
        beside = path.parent / v
        if not beside.is_file():
            return e
        where = os.path.relpath(path.parent) if path.parent != Path(".") else "."
        shown = os.path.relpath(beside)
    except (OSError, ValueError):
        return e
    return ConfigError(
        e.key,
        f"{v} not found in {os.getcwd()} (a relative path is read from the working directory); "
        f"{shown} exists: run from {where} or give an absolute path",
    )


#: the project's study files: a results directory named as one of them is that study's design
STUDY_FILES = Path(__file__).resolve().parents[2] / "studies"


def design_config(name: str) -> dict | None:
    """The resolved config of the project's study file ``studies/<name>.toml`` (the design a
    results directory of that name stands for), or None when there is none or it does not
    load: ``sim report`` names what a run changed from it."""
    f = STUDY_FILES / f"{name}.toml"
    try:
        return load_study(f)[1] if f.is_file() else None
    except (ConfigError, OSError, ValueError):
        return None
