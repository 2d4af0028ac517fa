"""Sweeps of the inputs the paper does not print, and the *consistent set* of each.

Wolf & Pearsall 1976 (seed ``000_668e60e68f004f98.txt``) print neither the pointing error of
one reading, nor the sizes of the systematic error sources, nor the monocomparator's error.
Each is swept (common random numbers: the same instruments for every value, see
:mod:`.chunks`): ``reading.pointing_sigma_um``, a common factor ``field_scale`` on the seven
``field.*_um`` amplitudes (their mix fixed), ``field.restitution_um``,
``field.drift_fraction`` and ``mono.sigma_um``. For every value the claims
that depend on the swept inputs are scored by the claim book's own rule. A claim is
*consistent* with a value when it holds there or, for a one-plate statistic (the paper's number
is one instrument's or plate's; it never "holds" sharply with ten points), when a plate at
least as extreme is not rarer than 5 % (the outcome is not ``fails``). The *consistent set*
(claim ``ALL``) is the set of values where every claim that depends on the input is
consistent together; ``ALL-feasible`` the same without the claims that are consistent at no
value tried (named in the ``ALL`` row's note), which would otherwise empty it.
"""

from __future__ import annotations

import numpy as np

from sim.claims.book import ClaimBook
from sim.studies.wolf.claims import HEADLINE, score_simulated, swept_claims

#: swept input -> (config key of its values, the cell key it overrides)
INPUTS = {
    "reading.pointing_sigma_um": ("unprinted.pointing_sigmas_um", "reading.pointing_sigma_um"),
    "field_scale": ("unprinted.field_scales", "field_scale"),
    "field.restitution_um": ("unprinted.restitutions_um", "field.restitution_um"),
    "field.drift_fraction": ("unprinted.drift_fractions", "field.drift_fraction"),
    "mono.sigma_um": ("unprinted.mono_sigmas_um", "mono.sigma_um"),
}


#: the consistent set of the claims that are consistent somewhere in the sweep
ALL_FEASIBLE = "ALL-feasible"


def sweep_cells(cfg: dict) -> list[tuple[str, str, float, dict]]:
    """``(tag, input, value, override)`` of every sweep cell."""
    out = []
    for name, (key, cell_key) in INPUTS.items():
        for i, v in enumerate(cfg[key]):
            out.append((f"s.{name}.{i}.", name, float(v), {cell_key: float(v)}))
    return out


def _criterion(spec: dict) -> str:
    return "not fails (p >= 0.05)" if spec.get("form") == "one-plate" else "holds"


def _consistent(row: dict, spec: dict) -> bool:
    if spec.get("form") == "one-plate":
        return row["outcome"] != "fails"
    return row["outcome"] == "holds"


def evaluate(cfg: dict, res: dict, book: ClaimBook) -> tuple[dict, dict]:
    """Score the swept claims at every sweep value.

    ``res``: the cells run (per-trial statistics, keys prefixed by each cell's tag).
    Returns ``(values, consistent)``: the long table (one row per input, value and claim) and
    the consistent-set table (one row per input and claim, plus ``ALL``).
    """
    cids = swept_claims(book)
    specs = list(book.specs.values())
    vals = {
        k: []
        for k in (
            "input",
            "value",
            "claim",
            "median",
            "lo",
            "hi",
            "p_plate",
            "outcome",
            "consistent",
        )
    }
    for tag, name, v, _ in sweep_cells(cfg):
        stats = {k[len(tag) :]: a for k, a in res.items() if k.startswith(tag)}
        fresh = ClaimBook(specs, [], book.path)
        for cid in cids:
            r = score_simulated(fresh, cid, stats, cfg["unprinted.trials"])
            for k, x in (
                ("input", name),
                ("value", v),
                ("claim", cid),
                ("median", r["value"]),
                ("lo", r["ci_low"]),
                ("hi", r["ci_high"]),
                ("p_plate", r["p_plate"]),
                ("outcome", r["outcome"]),
                ("consistent", _consistent(r, book.specs[cid])),
            ):
                vals[k].append(x)
    cons = {
        k: []
        for k in (
            "input",
            "claim",
            "criterion",
            "depends",
            "holds_low",
            "holds_high",
            "n_values",
            "n_consistent",
            "note",
        )
    }
    V = {k: np.asarray(a) for k, a in vals.items()}
    for name in INPUTS:
        m = V["input"] == name
        xs = np.unique(V["value"][m])
        oks = {}
        for cid in cids:
            mc = m & (V["claim"] == cid)
            order = np.argsort(V["value"][mc])
            x, ok = V["value"][mc][order], V["consistent"][mc][order]
            depends = _depends(name, cid)
            if depends:
                oks[cid] = ok
            lo, hi = (float(x[ok].min()), float(x[ok].max())) if ok.any() else (np.nan, np.nan)
            _add(
                cons,
                name,
                cid,
                _criterion(book.specs[cid]),
                depends,
                lo,
                hi,
                xs.size,
                int(ok.sum()),
                ""
                if ok.all() or not ok.any() or np.all(np.diff(np.flatnonzero(ok)) == 1)
                else "not contiguous",
            )
        empty = [c for c, ok in oks.items() if not ok.any()]
        for label, use in (("ALL", list(oks)), (ALL_FEASIBLE, [c for c in oks if c not in empty])):
            together = np.ones(xs.size, bool)
            for c in use:
                together &= oks[c]
            note = ""
            if label == "ALL" and empty:
                note = "consistent nowhere: " + ", ".join(empty)
            elif not together.any() and use:
                rng = {c: (xs[oks[c]].min(), xs[oks[c]].max()) for c in use}
                a = max(rng, key=lambda c: rng[c][0])
                b = min(rng, key=lambda c: rng[c][1])
                note = f"conflict: {a} needs >= {rng[a][0]:g}, {b} needs <= {rng[b][1]:g}"
            if label != "ALL" and empty:
                note = (
                    note + "; " if note else ""
                ) + f"without the {len(empty)} consistent nowhere"
            lo, hi = (
                (float(xs[together].min()), float(xs[together].max()))
                if together.any()
                else (np.nan, np.nan)
            )
            _add(
                cons,
                name,
                label,
                "every dependent claim consistent",
                True,
                lo,
                hi,
                xs.size,
                int(together.sum()),
                note,
            )
    return vals, cons


def _depends(name: str, cid: str) -> bool:
    """Whether claim ``cid`` depends on the swept input ``name`` (by the model: the
    monocomparator enters only the comparisons with it)."""
    if name == "mono.sigma_um":
        return cid.startswith("wolf.table2.") or cid == HEADLINE
    return True


def _add(t, *row):
    for k, v in zip(t, row):
        t[k].append(v)
