"""The listing of ``sim check STUDY.toml`` (:mod:`sim.cli_check` calls it once the study file
is read and its config resolved): each key with its meaning, bounds and unit, the sweep, and
the work the run would do (:func:`sim.execute_sweep.sweep_limits`: the estimate's engine), and what
the run would refuse of the sweep and its size."""

from __future__ import annotations

from sim.claims.rules import printed_differs
from sim.execute_sweep import check_sweep, sweep_limits
from sim.mc.read_when import read_in_a_cell
from sim.mc.sweep import expand, read_sweep
from sim.mc.toml_text import toml_key, toml_value
from sim.report.off_paper import off_setup
from sim.studies import unread_keys

__all__ = ["listing"]


def _n(x: float) -> str:
    """A bound as ``sim check`` lists it: an integer exactly (``seed``'s 2**63 - 1 was
    ``9.22337e+18``, below the value it let the key hold), a float's whole number with its
    digits grouped, another float as ``%g``."""
    if isinstance(x, int):
        return f"{x:_}"
    return f"{int(x):_}" if float(x).is_integer() and abs(x) < 1e16 else f"{x:g}"


def _bounds(f) -> str:
    if f.choices:
        return "one of " + ", ".join(map(str, f.choices))
    if f.lo is None and f.hi is None:
        return ""
    lo = "" if f.lo is None else (f"> {_n(f.lo)}" if f.lo_open else f">= {_n(f.lo)}")
    hi = "" if f.hi is None else f"<= {_n(f.hi)}"
    return ", ".join(x for x in (lo, hi) if x)


#: ``sim check``'s note on a printed key: another value, or the paper's setup in other keys
_PRINTED = ("another value is off its setup", "the paper's setup spelled another way")


def listing(args, study, cfg) -> int:
    """The listing of ``sim check`` of the study ``study`` at the resolved ``cfg`` (the
    options ``args``); a sweep or a size the run would refuse is refused here."""
    sweep = read_sweep(args.study, study.schema)
    est = sweep_limits(study, cfg, sweep, args.max_memory_gb, args.max_adjustments)  # at one worker
    check_sweep(study, cfg, sweep)  # a sweep of only refused cells is refused (sim run too)
    print(f"# {cfg['study']}: {study.title}")
    # listed commented out (set, they would be refused); one a sweep's cells read is kept
    cells = expand(sweep)[1] if sweep else []
    skip = {
        k: w
        for k, w in unread_keys(study, cfg).items()
        if not read_in_a_cell(study.schema[k], cfg, cells)
    }
    off = printed_differs(study.schema, cfg, study.as_printed)
    # a printed key spelling the paper's setup another way (Table 1's 25 points as a list)
    spelled = {s.split(" = ")[0] for s in printed_differs(study.schema, cfg)}
    spelled -= {s.split(" = ")[0] for s in off}
    for k, v in cfg.items():
        f = study.schema.get(k)
        if f is None:
            print(f"{k} = {toml_value(v)}")
            continue
        unit = f.unit or ""
        notes = "; ".join(
            x
            for x in (
                unit and f"unit {unit}",
                _bounds(f),
                f.compared
                and "settings compared: each once"
                + ("" if f.kind == "list[str]" else ", read in increasing order"),
                "paper input" if f.input else "",
                f.printed and f"printed by the paper: {_PRINTED[k in spelled]}",
                k in skip and f"not read: {skip[k]}",
            )
            if x
        )
        line = f"{k} = {toml_value(v)}  # {f.doc}" + (f" ({notes})" if notes else "")
        print(f"# {line}" if k in skip else line)
    if sweep:  # as the file gives it: the listing saved is the same study, sweep and all
        print("[sweep]")
        for k, v in sweep.items():
            print(f"{toml_key(k)} = {toml_value(v)}")
    if off:  # said before the run: its predictions will be findings (sim.claims.rules)
        print(f"# {off_setup(study, cfg, before=True)}")
    print(f"# work: {est.describe()}; {est.core_time()}")
    for note in study.notes(dict(cfg)) if study.notes else []:  # N45: said before the run
        print(f"# note: {note}")
    return 0
