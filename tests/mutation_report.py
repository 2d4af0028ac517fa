"""Write docs/mutation.md from a finished ``mutmut run`` (``make mutation``).

Reads ``mutmut results --all true`` (one ``name: status`` line a mutant) and, for each mutant
that was not killed, its diff (``mutmut show``). The score is killed / (all mutants), where a
mutant that makes the tests run past mutmut's time limit ("timeout": e.g. a refinement step that
no longer shrinks) counts as killed (the tests did not pass) and is listed apart; a mutant that
no selected test reaches ("no tests") counts as surviving. Lines marked
``# pragma: no mutate`` in the mutated modules are listed with the reason written beside them
(equivalent mutants: a change no test can see because the behaviour is the same).
"""

from __future__ import annotations

import subprocess
import sys
import tomllib
from collections import Counter
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
MUTMUT = [sys.executable, "-m", "mutmut"]

#: survivors checked by hand, with the reason they survive
NOTES = {
    "sim.claims.intervals.x_bootstrap_ci__mutmut_1": (
        "a default argument: mutmut's trampoline calls the mutant with the original default, "
        "so no test can see it. Applied by hand (n_boot = 401) the mutant fails "
        "tests/test_intervals.py::test_bootstrap_ci_is_the_2_5_and_97_5_percentiles_of_the_"
        "resamples: killed."
    ),
    **{
        f"sim.claims.intervals.x_spread_rows__mutmut_{k}": (
            "equivalent: np.asarray(x) without the float dtype; np.nanpercentile computes in "
            "floating point for any numeric input (integers give the same quantiles), and the "
            "two differ only for an object array such as a list holding None, which no caller "
            "passes (the callers pass simulated float arrays)."
        )
        for k in (13, 15)
    },
    "sim.claims.intervals.x_binomial_ci__mutmut_50": (
        "equivalent: the lower bound's np.where(k == 0, 0.0, ...) dropped; at k = 0 the Wilson "
        "lower bound centre - half is computed as fl(z*z)/denom - fl(z*sqrt(fl(z*z)))/denom, "
        "and sqrt(fl(z*z)) == z in IEEE arithmetic, so it is exactly 0.0 for every n and "
        "level (checked for n = 1..2000 at seven levels). The where keeps the bound exact "
        "should the formula change; tests/test_claim_book_checks.py pins lo == 0 at k = 0."
    ),
    "sim.claims.intervals.x_binomial_ci__mutmut_78": (
        "equivalent: np.minimum(centre + half, 2.0) for 1.0; the clamp only acts where "
        "centre + half > 1, which is at k = n only (rounding: k = n = 16 gives 1 + 2e-16), "
        "where np.where(k == n, 1.0, ...) sets the bound to 1 anyway; for k < n the upper "
        "bound stays <= 1 (checked for every k < n <= 2000 at seven levels and at k = n - 1 "
        "for n = 10 .. 1e18)."
    ),
    "sim.claims.book.xǁClaimBookǁ__init____mutmut_159": (
        "equivalent: the default of an omitted decimals, 1 for 0, feeds only the range check "
        "-12 <= d <= 12, which both pass; the claim's spec keeps no decimals key (scoring "
        "reads an omitted decimals as an exact reference), as "
        "tests/test_claim_book_checks.py checks."
    ),
    "sim.claims.rules.x__shown__mutmut_9": (
        "equivalent: repr for str() on every value that is no float, list or string; a "
        "validated configuration value is then an int, a bool, None or a records table (a "
        "dict), whose repr and str are the same text (sim.mc.config.check_value); a string is "
        "shown quoted either way, which tests/test_rules_off_paper.py pins."
    ),
    "sim.claims.rules.x_printed_differs__mutmut_5": (
        "equivalent: getattr's default None for False; both are false, so a field without a "
        "printed attribute is not printed either way."
    ),
    **{
        f"sim.claims.rules.x_printed_differs__mutmut_{k}": (
            "equivalent: getattr's default (dropped, or True for False) is read only for a "
            "schema value without a printed attribute; every value of every study schema is a "
            "sim.mc.config.Field, whose printed defaults to False (checked over the 15 schema "
            "tables of sim/studies/*/schema.py; sim.cli reads f.printed directly)."
        )
        for k in (8, 11)
    },
    **{
        f"sim.claims.inference.x__evidence__mutmut_{k}": (
            "equivalent: the value array without the float dtype; it is used only as the "
            "default of low and high, which are converted to float on the next lines (a None "
            "in it becomes NaN there), so status() sees the same arrays."
        )
        for k in (5, 7)
    },
    **{
        f"sim.claims.inference.x_status__mutmut_{k}": (
            "equivalent: reshape(n, -2) for reshape(n, -1); NumPy takes any negative size as "
            "the one unknown dimension, so the arrays are the same."
        )
        for k in (16, 22)
    },
    "sim.claims.inference.x_status__mutmut_52": (
        "equivalent for every level written with at most 12 decimals (0.95, 0.9, 0.99, ...): "
        "round(1 - level, 13) and round(1 - level, 12) are then the same float (the rounding "
        "only removes the binary error of 1 - level, e.g. 0.05000000000000004)."
    ),
    **{
        f"sim.claims.inference.x__boundary__mutmut_{k}": (
            "equivalent: the early return when every point has the same label is a shortcut. "
            "Without it (or with label[1] for label[0], or a float array of zeros for the bool "
            "one) every neighbourhood has one label, so no point is on the boundary either; "
            "np.flatnonzero of float zeros is empty as of bool ones."
        )
        for k in (1, 2, 4, 6)
    },
    "sim.claims.inference.x_explore__mutmut_4": (
        "equivalent at the default per_point = 4: the cap is max_new // per_point points, "
        "4096 // 4 = 4097 // 4 = 1024, and edge.size * 4 > 4096 iff > 4097 (a multiple of 4). "
        "It differs only for per_point = 1 with exactly 4097 boundary points."
    ),
    "sim.claims.inference.x_explore__mutmut_45": (
        "equivalent: the unit-cube coordinate of a fixed input (low == high) is 0.5 or 1.5, "
        "scaled by high - low = 0 to low either way; refinement jitters free inputs only."
    ),
    "sim.claims.inference.x_explore__mutmut_124": (
        "equivalent: replace=None is falsy, rng.choice samples without replacement as with "
        "replace=False."
    ),
    **{
        f"sim.claims.inference.x_explore__mutmut_{k}": (
            "equivalent: the refinement label only has to tell apart the combinations "
            "(accepted, holds for prediction k); a float label, -= for +=, weights 3 << k "
            "(3 times distinct powers of two) or the complement != HOLDS within the accepted "
            "points give the same partition of the points, hence the same boundary points and "
            "the same draws."
        )
        for k in (87, 90, 93, 103)
    },
    "sim.claims.inference.x_explore__mutmut_142": (
        "equivalent in law: the jitter U(-h, h) is symmetric, so x - U and x + U have the same "
        "distribution; the region's guarantees (every point tested exactly, resolution h) are "
        "the same, only the particular seeded points differ, which no property pins."
    ),
    "sim.claims.region.x_region_verdict__mutmut_2": (
        "equivalent: n_points < 0 for n_points <= 0; with n_points = 0 the counts of holding "
        "and failing points (subsets of the region's points) are 0, so the second clause "
        "gives 'undecidable' as well."
    ),
    **{
        f"sim.claims.region.x_decide_over__mutmut_{k}": (
            "equivalent: Region.describe of an empty mask is 'nowhere' already, so the "
            "`if nh` / `if nf` shortcut does not change holds_where / fails_where."
        )
        for k in (55, 61)
    },
    **{
        f"sim.claims.region.x_region_row__mutmut_{k}": (
            "equivalent: book.score only builds the row's identity columns here; its value, "
            "ci, interval and outcome are all overwritten by the row.update below (value, "
            "ci_low/high, interval='region', outcome/verdict/holds of the region verdict), "
            "and an exact score with no ci (or interval 'ci' with ci = (lo, lo)) decides the "
            "same point interval without error. tests/test_region_rows.py pins every "
            "overwritten column."
        )
        for k in (17, 23, 30, 35, 36, 37, 38)
    },
    **{
        name: (
            "equivalent: the p values without the float dtype; every caller passes floats "
            "(one-plate p), and with integers or a list the arithmetic that follows (Holm's "
            "products, np.minimum with 1.0, the comparisons with 0.05) gives the same numbers."
        )
        for name in (
            "sim.claims.family.x_holm__mutmut_3",
            "sim.claims.family.x_holm__mutmut_5",
            "sim.claims.family.x_family_status__mutmut_4",
            "sim.claims.family.x_family_status__mutmut_6",
            "sim.claims.family.x_family_row__mutmut_4",
            "sim.claims.family.x_family_row__mutmut_6",
            "sim.claims.family.x_family_outcomes__mutmut_7",
            "sim.claims.family.x_family_outcomes__mutmut_9",
            "sim.claims.family.x_mc_p__mutmut_14",
            "sim.claims.family.x_mc_p__mutmut_16",
        )
    },
    "sim.claims.family.x_family_status__mutmut_19": (
        "equivalent: the Holm p of a row holding a NaN is NaN either way (holm keeps the NaN "
        "and .min() propagates it), and a NaN Holm p is then undecided."
    ),
    **{
        f"sim.claims.family.x_family_{f}__mutmut_1": (
            "a default argument (note = ''): mutmut's trampoline calls the mutant with the "
            "original default, so no test can see it; the note itself is pinned by "
            "tests/test_agnard_family.py (family_row_names_every_member_with_its_p, "
            "family_over_a_region)."
        )
        for f in ("row", "over")
    },
    **{
        f"sim.claims.family.x_family_over__mutmut_{k}": (
            "equivalent: `why` is the statement's `decide` text, which decide_over reads only "
            "for a non-empty region, and there it is always replaced by the Holm p range; for "
            "an empty region decide_over names the conflicting statements instead."
        )
        for k in (12, 13)
    },
}


#: the mutated line (the `+` line of `mutmut show`, stripped) each note of :data:`NOTES` was
#: checked against: a note goes to a survivor of the same function with the same mutated line,
#: whatever its number (numbers shift when the module changes: a note keyed by number alone
#: came to stand under another mutant's diff), and to no other
CHECKED = {
    "sim.claims.intervals.x_bootstrap_ci__mutmut_1": "n_boot: int = 401,",
    "sim.claims.book.xǁClaimBookǁ__init____mutmut_159": 'd = s.get("decimals", 1)',
    "sim.claims.intervals.x_binomial_ci__mutmut_50": "lo = np.where(None, 0.0, np.maximum(centre - half, 0.0))[()]  # [()]: a scalar stays one",
    "sim.claims.intervals.x_binomial_ci__mutmut_78": "return p, lo, np.where(k == n, 1.0, np.minimum(centre + half, 2.0))[()]",
    "sim.claims.intervals.x_spread_rows__mutmut_13": "lo, med, hi = np.nanpercentile(np.asarray(x, None), [a, 50, 100 - a], axis=1)",
    "sim.claims.intervals.x_spread_rows__mutmut_15": "lo, med, hi = np.nanpercentile(np.asarray(x, ), [a, 50, 100 - a], axis=1)",
    "sim.claims.family.x_mc_p__mutmut_14": "return np.minimum(1.0, (np.asarray(p, None) * n + 2.0) / (n + 1.0))",
    "sim.claims.family.x_mc_p__mutmut_16": "return np.minimum(1.0, (np.asarray(p, ) * n + 2.0) / (n + 1.0))",
    "sim.claims.family.x_holm__mutmut_3": "p = np.asarray(p, None)",
    "sim.claims.family.x_holm__mutmut_5": "p = np.asarray(p, )",
    "sim.claims.family.x_family_status__mutmut_4": "p, member = np.atleast_2d(np.asarray(p, None)), np.atleast_2d(member)",
    "sim.claims.family.x_family_status__mutmut_6": "p, member = np.atleast_2d(np.asarray(p, )), np.atleast_2d(member)",
    "sim.claims.family.x_family_status__mutmut_19": "hp = np.array([holm(row).min() if (np.isfinite(row).all()) or True else np.nan for row in p])",
    "sim.claims.family.x_family_row__mutmut_1": 'book, cid: str, members: Sequence[Mapping[str, Any]], note: str = "XXXX", *, n: int',
    "sim.claims.family.x_family_row__mutmut_4": 'p = np.array([r["p_plate"] for r in members], None)',
    "sim.claims.family.x_family_row__mutmut_6": 'p = np.array([r["p_plate"] for r in members], )',
    "sim.claims.family.x_family_outcomes__mutmut_7": 'p = np.stack([np.asarray(region.outputs[m]["p"], None) for m in members], axis=1)',
    "sim.claims.family.x_family_outcomes__mutmut_9": 'p = np.stack([np.asarray(region.outputs[m]["p"], ) for m in members], axis=1)',
    "sim.claims.family.x_family_over__mutmut_1": 'book, region: Region, cid: str, members: Sequence[str], note: str = "XXXX", *, n: int',
    "sim.claims.family.x_family_over__mutmut_12": "why = None",
    "sim.claims.family.x_family_over__mutmut_13": 'why = "XXXX"',
    "sim.claims.inference.x__evidence__mutmut_5": 'v = np.asarray(ev["value"], None) if "value" in ev else None',
    "sim.claims.inference.x__evidence__mutmut_7": 'v = np.asarray(ev["value"], ) if "value" in ev else None',
    "sim.claims.inference.x_status__mutmut_16": "lo2, hi2 = lo.reshape(n, -2), hi.reshape(n, -1)",
    "sim.claims.inference.x_status__mutmut_22": "lo2, hi2 = lo.reshape(n, -1), hi.reshape(n, -2)",
    "sim.claims.inference.x_status__mutmut_52": "miss = p < round(1 - level, 13)",
    "sim.claims.inference.x__boundary__mutmut_1": "if (label != label[0]).all():",
    "sim.claims.inference.x__boundary__mutmut_2": "if (label == label[1]).all():",
    "sim.claims.inference.x__boundary__mutmut_4": "return np.zeros(len(u), None)",
    "sim.claims.inference.x__boundary__mutmut_6": "return np.zeros(len(u), )",
    "sim.claims.inference.x_explore__mutmut_4": "max_new: int = 4097,",
    "sim.claims.inference.x_explore__mutmut_45": "u = np.full((2**m, len(inputs)), 1.5)",
    "sim.claims.inference.x_explore__mutmut_87": "label = acc.astype(None)",
    "sim.claims.inference.x_explore__mutmut_90": "label -= (2 << k) * (acc & (status(p, out[p.id], len(u), level) == HOLDS))",
    "sim.claims.inference.x_explore__mutmut_93": "label += (3 << k) * (acc & (status(p, out[p.id], len(u), level) == HOLDS))",
    "sim.claims.inference.x_explore__mutmut_103": "label += (2 << k) * (acc & (status(p, out[p.id], len(u), level) != HOLDS))",
    "sim.claims.inference.x_explore__mutmut_124": "edge = rng.choice(edge, max_new // per_point, replace=None)",
    "sim.claims.inference.x_explore__mutmut_142": "new[:, free] -= rng.uniform(-h, h, size=(len(new), len(free)))",
    "sim.claims.region.x_region_verdict__mutmut_2": "if n_points < 0 or n_holds + n_fails == 0:",
    "sim.claims.region.x_decide_over__mutmut_55": 'hw = region.describe(h) if (nh) or True else "nowhere"',
    "sim.claims.region.x_decide_over__mutmut_61": 'fw = region.describe(f) if (nf) or True else "nowhere"',
    "sim.claims.region.x_region_row__mutmut_17": 'row = book.score(cid, lo, None, "exact", value_high=hi)',
    "sim.claims.region.x_region_row__mutmut_23": "row = book.score(cid, lo, (lo, lo), value_high=hi)",
    "sim.claims.region.x_region_row__mutmut_30": 'row = book.score(cid, 0.0, None, "exact")',
    "sim.claims.region.x_region_row__mutmut_35": "row = book.score(cid, 0.0, (0.0, 0.0), )",
    "sim.claims.region.x_region_row__mutmut_36": 'row = book.score(cid, 1.0, (0.0, 0.0), "exact")',
    "sim.claims.region.x_region_row__mutmut_37": 'row = book.score(cid, 0.0, (1.0, 0.0), "exact")',
    "sim.claims.region.x_region_row__mutmut_38": 'row = book.score(cid, 0.0, (0.0, 1.0), "exact")',
    "sim.claims.rules.x__shown__mutmut_9": "return repr(v) if (isinstance(v, str)) or True else str(v)",
    "sim.claims.rules.x_printed_differs__mutmut_5": (
        'if getattr(f, "printed", None) and shown(cfg.get(k, f.default)) != shown(f.default):'
    ),
    "sim.claims.rules.x_printed_differs__mutmut_8": (
        'if getattr(f, "printed", ) and shown(cfg.get(k, f.default)) != shown(f.default):'
    ),
    "sim.claims.rules.x_printed_differs__mutmut_11": (
        'if getattr(f, "printed", True) and shown(cfg.get(k, f.default)) != shown(f.default):'
    ),
}


def note_for(name: str, mutated: list[str]) -> tuple[str | None, bool]:
    """The hand-checked note for the survivor ``name`` whose diff's ``+`` lines (stripped) are
    ``mutated``: that of a mutant of the same function checked against one of those lines;
    and whether a note keyed by ``name`` itself was written for another diff (to re-check)."""
    fn = name.rsplit("__mutmut_", 1)[0]
    for k, text in NOTES.items():
        if k.rsplit("__mutmut_", 1)[0] == fn and CHECKED.get(k) in mutated:
            return text, False
    return None, name in NOTES


def _mutmut(*args: str) -> str:
    return subprocess.run(
        [*MUTMUT, *args], cwd=ROOT, capture_output=True, text=True, check=True
    ).stdout


def main(out: Path = ROOT / "docs" / "mutation.md") -> int:
    status = {}
    for line in _mutmut("results", "--all", "true").splitlines():
        name, _, st = line.strip().rpartition(": ")
        if name:
            status[name] = st
    if not status:
        print("mutation_report: no mutmut results (run `make mutation`)", file=sys.stderr)
        return 2
    modules = tomllib.loads((ROOT / "pyproject.toml").read_text())["tool"]["mutmut"]
    by_module: dict[str, Counter] = {}
    for name, st in status.items():
        by_module.setdefault(name.split(".x")[0], Counter())[st] += 1
    killed = sum(c["killed"] + c["timeout"] for c in by_module.values())
    total = len(status)
    commit = subprocess.run(
        ["git", "rev-parse", "--short=8", "HEAD"], cwd=ROOT, capture_output=True, text=True
    ).stdout.strip()
    lines = [
        "# Mutation testing of the verdict rules and intervals",
        "",
        f"Written by `make mutation` at commit `{commit or 'unknown'}` (mutmut on "
        + ", ".join(f"`{m}`" for m in modules["only_mutate"])
        + "; tests: "
        + ", ".join(f"`{t}`" for t in modules["pytest_add_cli_args_test_selection"])
        + "). A mutant is a small change to the code (an operator, a constant, a comparison, "
        "a string); it is *killed* when a test fails. See [verdict rules](verdict-rules.md).",
        "",
        f"**Score: {killed} of {total} mutants killed ({100 * killed / total:.1f} %).**",
        "",
        "| module | mutants | killed | timeout | score | survived | no tests | other |",
        "| --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: |",
    ]
    for mod, c in sorted(by_module.items()):
        n = sum(c.values())
        k = c["killed"] + c["timeout"]
        other = n - k - c["survived"] - c["no tests"]
        lines.append(
            f"| `{mod}` | {n} | {c['killed']} | {c['timeout']} | {100 * k / n:.1f} % | "
            f"{c['survived']} | {c['no tests']} | {other} |"
        )
    left = [n for n, st in status.items() if st not in ("killed", "timeout")]
    lines += ["", f"## Mutants not killed ({len(left)})", ""]
    if not left:
        lines.append("None.")
    for n in left:
        diff = [
            ln
            for ln in _mutmut("show", n).splitlines()
            if ln[:1] in "+-" and not ln.startswith(("+++", "---"))
        ]
        note, stale = note_for(n, [d[1:].strip() for d in diff if d.startswith("+")])
        st = status[n] + ("; its note was written for another diff: re-check" if stale else "")
        lines += [f"- `{n}` ({st})", "", "  ```diff", *("  " + d for d in diff), "  ```"]
        if note:
            lines += ["", f"  {note}"]
    lines += ["", "## Lines not mutated, with the reason (equivalent mutants)", ""]
    marked = []
    for mod in modules["only_mutate"]:
        for i, ln in enumerate((ROOT / mod).read_text().splitlines(), 1):
            if "pragma: no mutate" in ln:
                marked.append(
                    f"- `{mod}:{i}`: `{ln.split('#')[0].strip()}` -- {ln.split('#', 1)[1]}"
                )
    lines += marked or ["None."]
    out.write_text("\n".join(lines) + "\n")
    print(f"mutation: {killed} of {total} killed ({100 * killed / total:.1f} %); see {out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
