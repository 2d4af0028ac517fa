"""What a run's config changed from a study file's: named in the run's README.md, by
``sim show`` and in REPORT.md, so that a run with ``--set``, ``--trials`` or ``--seed`` (or of
an edited copy of a study file) is not read as the study file's design.

The reference is the project's study file the results stand for: ``studies/<dir>.toml`` when
one of the run's study is named like the results directory, else ``studies/<study>.toml`` (the
paper's design of the study); a study without such a file (the network kind) has none. The
``design`` callable (``sim.studies.design_config``) resolves a file's config: the report layer
reads no study file itself."""

from __future__ import annotations

from typing import Any, Callable, Mapping

from sim.mc.config import ConfigError
from sim.mc.numtext import shows_differently
from sim.mc.sweep import expand
from sim.mc.toml_text import toml_value
from sim.report.inputs import as_set
from sim.report.labels import apart, middle

__all__ = ["changed_keys", "changes_text", "design_of", "config_line", "sweep_config_line"]

#: keys of a run's config that are not a setting of the study ([sweep]: the sweep's own table)
_NOT_SETTINGS = {"sweep"}


#: keys a run record made before they existed lacks, and the key whose value the run used
#: instead: a run before ``region.seed`` drew its region from its ``seed``
_BEFORE = {"region.seed": "seed"}


def _as_run(mine: Mapping[str, Any], base: Mapping[str, Any]) -> Mapping[str, Any]:
    """``mine`` with the keys of :data:`_BEFORE` it lacks (and ``base`` has) at what its run
    used for them."""
    old = {
        k: mine[was] for k, was in _BEFORE.items() if k not in mine and k in base and was in mine
    }
    return {**mine, **old} if old else mine


def changed_keys(mine: Mapping[str, Any], base: Mapping[str, Any]) -> list[str]:
    """The keys whose value in ``mine`` is another than the one in ``base`` (either may lack
    it) as 12 significant digits show them (:func:`sim.mc.numtext.shown`, the rule of the
    README's inputs table and of ``printed_differs``): a swept 1.1 + 0.6 is a file's 1.7. A
    record made before a key of :data:`_BEFORE` existed is read with what its run used."""
    mine = _as_run(mine, base)
    keys = sorted((set(mine) | set(base)) - _NOT_SETTINGS)
    return [k for k in keys if shows_differently(mine.get(k), base.get(k))]


def _change(k: str, mine: Mapping[str, Any], base: Mapping[str, Any]) -> str:
    """One changed key: a key one side lacks is said to be missing there (a run of an older
    version, before the key existed, read "`plate.layout_seed` =  (the file: 1)": a blank)."""
    if k not in mine:
        return f"`{k}` not in its record (the file: {as_set(base.get(k))})"
    if k not in base:
        return f"`{k}` = {as_set(mine.get(k))} (not in the file)"
    return f"`{k}` = {as_set(mine.get(k))} (the file: {as_set(base.get(k))})"


def changes_text(mine: Mapping[str, Any], base: Mapping[str, Any], limit: int = 6) -> str:
    """``"`k` = v (the file: w), ..., and N more"``: the first ``limit`` changed keys."""
    diff, mine = changed_keys(mine, base), _as_run(mine, base)
    what = ", ".join(_change(k, mine, base) for k in diff[:limit])
    return what + (f", and {len(diff) - limit} more" if len(diff) > limit else "")


def design_of(
    cfg: Mapping[str, Any], name: str, design: Callable[[str], dict | None] | None
) -> tuple[str, dict] | None:
    """``(file name, its config)`` of the study file the results ``name`` of a run with ``cfg``
    stand for (see the module docstring), or None."""
    if design is None:
        return None
    for stem in (name, cfg.get("study")):
        base = design(stem) if isinstance(stem, str) and stem else None
        if base and base.get("study") == cfg.get("study"):
            return f"studies/{stem}.toml", base
    return None


def config_line(
    cfg: Mapping[str, Any], name: str, design: Callable[[str], dict | None] | None
) -> str | None:
    """One sentence naming what the run changed from its study file's config (at most six
    keys), or None when it ran that config (or there is no such file)."""
    found = design_of(cfg, name, design)
    if found is None or not changed_keys(cfg, found[1]):
        return None
    return (
        f"Not the configuration of `{found[0]}`: {changes_text(cfg, found[1])}. Its verdicts "
        "and numbers are of this run's configuration, not of the study file's design."
    )


#: the values of a swept key named in the sweep's configuration line: the first ones and the last
_SHOWN_VALUES = 6


def _values_text(vals: list) -> str:
    """A swept key's distinct values in order, as TOML writes them (``[35.0, 45.0]``; of
    many, the first five, ``...`` and the last, with their count), each at most 40
    characters that tell it from the others (:func:`sim.report.labels.apart`; ASCII: ``sim
    show`` writes to a terminal of any encoding)."""
    seen: dict[str, Any] = {}
    for v in vals:
        seen.setdefault(repr(v), v)
    shown = apart([toml_value(v) for v in seen.values()], 40, "...")
    if len(shown) > _SHOWN_VALUES:
        shown = [*shown[: _SHOWN_VALUES - 1], "...", shown[-1]]
        return f"[{', '.join(shown)}] ({len(seen)} values)"
    return f"[{', '.join(shown)}]"


def sweep_config_line(
    prov: Mapping[str, Any], name: str, design: Callable[[str], dict | None] | None
) -> str | None:
    """The configuration sentence of a sweep (its README.md, ``sim show``), from the
    provenance of its ``sweep.parquet``: the swept keys with their values (and the study
    file's value of each), the cells, replicates and seeds, then what the other keys changed
    from the study file. It named only the base config's changes (``chunk``, ``seed``,
    ``trials``), never the swept keys, whose cells leave the study file's design, and gave a
    swept key's base value, which no cell runs, as a change of the run. Of a study's
    provenance (no ``sweep``): :func:`config_line`."""
    cfg = prov.get("config") if isinstance(prov.get("config"), dict) else {}
    table, keys = prov.get("sweep"), prov.get("sweep_keys")
    try:
        _, cells, reps, mode = expand(table) if isinstance(table, dict) else (0, [], 0, "")
    except ConfigError:
        cells = []
    if not cells or not isinstance(keys, list) or not all(k in cells[0] for k in keys):
        return config_line(cfg, name, design)  # a record this version did not write
    found = design_of(cfg, name, design)
    base = found[1] if found else {}
    swept = "; ".join(
        f"`{k}` = {_values_text([c[k] for c in cells])}"
        + (f" (the file: {middle(as_set(base[k]), 40, '...')})" if k in base else "")
        for k in keys
    )
    n = len(cells) * reps
    seed = as_set(cfg.get("seed"))
    seeds = (
        f"every setting with seed {seed}"
        + (", each later replicate with one seed spawned from it" if reps > 1 else "")
        + " (seed_mode common)"
        if mode == "common"
        else f"each its own seed, spawned from seed {seed}"
    )
    reps_text = f" ({len(cells)} settings x {reps} replicates)" if reps > 1 else ""
    text = f"A sweep of {n} cell{'s' * (n > 1)}{reps_text} over {swept}: {seeds}."
    if not found:
        return text
    mine = {k: v for k, v in cfg.items() if k not in keys}
    theirs = {k: v for k, v in base.items() if k not in keys}
    if not changed_keys(mine, theirs):
        return f"{text} Its other keys are those of `{found[0]}`."
    return (
        f"{text} Its other keys are not the configuration of `{found[0]}`: "
        f"{changes_text(mine, theirs)}. Its verdicts and numbers are of these cells' "
        "configurations, not of the study file's design."
    )
