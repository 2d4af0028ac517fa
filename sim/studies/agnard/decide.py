"""The regions of ``agnard_block`` (seed ``003_5ce730a990a7ebc5.txt``) explored through the
runner, their tables and figures, and the claims rows decided over them (issue 21):

* the lost five-point layout with the projection-centres option (``region.toml``, at the
  configured scanner: ``consistent_region.parquet``, the example the 5-control rows keep);
* the scanner's inputs under Table 1 (``scanner.toml``): the 21-control and first-pass rows
  over its vectors by the paired log shift (:mod:`.paired`), ``pass_rejections.digital`` by
  the paired shift of its distribution function (:mod:`.paired_count`,
  ``scanner_rejections.parquet``);
* the 5-control rows over both together, on the joint design of :mod:`.joint`
  (``joint_region.parquet``).
"""

from __future__ import annotations

from functools import partial

import numpy as np

from sim.claims.book import ClaimBook
from sim.claims.book_region import statements, write_explored
from sim.claims.family import family_evidence, family_outcomes, family_over
from sim.claims.inference import Region
from sim.claims.region import OUTCOME_NAMES, inputs_table, outcomes, region_table, statement_of
from sim.mc.storage import write_table
from sim.report.region import fig_region
from sim.studies.agnard.claims import JOINT, MEMBERS, PASS_82, WITHOUT_CENTRES
from sim.studies.agnard.joint import joint_region, layout_points, pairs_of, with_option
from sim.studies.agnard.leads import HOW
from sim.studies.agnard.paired import z_box
from sim.studies.agnard.paired_count import cdf_shift, mean_shift
from sim.studies.agnard.region import (
    CENTRES,
    CONFIGURED,
    COUNTS,
    REJECTED,
    SCANNER_KEYS,
    explore_region,
    explore_scanner,
    first_samples,
    many_samples,
    shift_table,
)
from sim.studies.run_steps import over_region

__all__ = ["five_region", "scanner_region", "over_scanner", "over_joint"]

#: how a region row undecided everywhere begins (sim.claims.region.region_row)
UNDECIDABLE = "undecidable: no input of the region decides it"

#: the share of pass points that mechanical pugging's snooping removes (:func:`without_snooping`)
MECHANICAL = "agnard.pass_rejections.mechanical_pct"


def five_region(cfg, block, book, runner, part, prov, out):
    """Explore the five-point layout (``region.toml``) at the configured scanner and write
    its tables and figure. Returns the region, its predictions, the per-point statistics and
    the explored insets (``runner(fn, trials, part, label)`` runs one part)."""
    region, preds, stats = explore_region(cfg, block, book, runner, part)
    _write_region(region, book, preds, cfg["region.trials"], prov, out)
    insets = [float(u) for u in region.x["five_inset_1"]]
    T = cfg["region.trials"]
    tab = {
        "inset": np.repeat(insets, T),
        "centres": np.repeat(region.x[CENTRES] > 0.5, T),
        "trial": np.tile(np.arange(T), len(insets)),
    }
    for c in preds:
        tab[c.split(".", 1)[1]] = np.concatenate([s[c] for s in stats])
    write_table(out / "region_five.parquet", tab, prov)
    fig_region(
        region,
        out / "consistent_region.png",
        title="seed 003: the lost five-point layout and the projection centres (no printed "
        "statement constrains them)",
        nominal={"five_inset_1": 0.0, CENTRES: 0.0},
        labels={CENTRES: "projection centres as model points (0 without, 1 with)"},
    )
    return region, preds, stats, list(dict.fromkeys(insets))


def _write_region(region, book, preds, n: int, prov, out) -> None:
    """``consistent_region.parquet`` and ``region_inputs.parquet``
    (:func:`sim.claims.book_region.write_region`), with the joint X, Y row's per-point
    outcome as a column (decided from its members' p over ``n`` blocks per point, not from
    evidence of its own)."""
    st = statements(book, preds)
    cols = region_table(region, st, preds)
    j5 = JOINT["control_5"]
    fam = family_outcomes(book, region, MEMBERS[j5], n=n)[1][region.accepted]
    cols[j5] = [OUTCOME_NAMES[int(o)] for o in fam]
    write_table(out / "consistent_region.parquet", cols, prov)
    write_table(out / "region_inputs.parquet", inputs_table(region, st), prov)


def _example(what: str, row: dict) -> str:
    """The configured ``what``'s (layout, scanner) result of a row, kept as an example."""
    return (
        f"at the configured {what} (an example): median {row['value']:.3g} cm, 95 % of "
        f"blocks {row['ci_low']:.3g}-{row['ci_high']:.3g}, outcome {row['outcome']}"
    )


def scanner_region(cfg, block, book, per_trial, runner, layout, prov, out):
    """Explore the scanner's unprinted inputs under Table 1 (``scanner.toml``), the
    21-control predictions paired with the configured scanner's main blocks
    (:mod:`.paired`), the digital rejections (:mod:`.paired_count`) and, at the joint
    design's layout points of the ``layout`` region (:mod:`.joint`), the 5-control pass;
    write ``scanner_region.parquet`` (every explored vector), ``scanner_shift.parquet``,
    ``scanner_rejections.parquet`` and the figure. Returns the region, its predictions,
    the per-vector statistics and the layout points."""
    base = {**many_samples(per_trial, f"layout_{cfg['control.many']}"), **first_samples(per_trial)}
    base[REJECTED] = np.asarray(per_trial["snoop_digital.rejected"], float)
    five = layout_points(layout)
    region, preds, stats = explore_scanner(
        cfg, block, book, runner, base, five, partial(pairs_of, n_points=len(five))
    )
    j21 = JOINT["control_21"]  # its per-vector outcome beside its members' (family_status)
    p = np.stack([region.outputs[m]["p"] for m in MEMBERS[j21]], axis=1)
    member = np.stack([outcomes(region, statement_of(book, m)) for m in MEMBERS[j21]], axis=1)
    region.outputs[j21] = family_evidence(p, member, n=cfg["trials"])  # p over the main blocks
    write_explored(out / "scanner_region.parquet", region, prov, statements(book, [*preds, j21]))
    logs = [c for c in preds if c not in COUNTS]
    write_table(out / "scanner_shift.parquet", shift_table(region, logs, stats), prov)
    write_table(out / "scanner_rejections.parquet", _rejections(book, region, base, stats), prov)
    fig_region(
        region,
        out / "scanner_region.png",
        title="seed 003: the scanner's unprinted inputs under Table 1"
        + (" (no vector consistent)" if region.empty else ""),
        nominal={name: cfg[key] for name, key in SCANNER_KEYS.items()},
    )
    return region, preds, stats, five


def _rejections(book, region, base: dict, stats: list[dict]) -> dict[str, list]:
    """``scanner_rejections.parquet``: per explored vector, the share of blocks losing no
    pass point (estimate, its interval, paired and unpaired standard errors) and the mean
    count shift from the configured scanner (paired difference of counts per block)."""
    cols: dict[str, list] = {k: np.asarray(v, float).tolist() for k, v in region.x.items()}
    ev = region.outputs[REJECTED]
    for q in ("share_zero", "share_zero_low", "share_zero_high", "p", "value", "high"):
        cols[q if q.startswith("share") or q == "p" else f"{q}_count"] = ev[q].tolist()
    names = ("share_zero_se", "share_zero_difference_se", "share_zero_unpaired_se", "beta")
    names += ("mean_rejected", "mean_rejected_se", "mean_rejected_unpaired_se")
    cols.update({q: [] for q in names})
    from_base = float(np.mean(base[REJECTED]))
    for p in stats:
        s = _zero_se(base[REJECTED], p[CONFIGURED + REJECTED], p[REJECTED])
        d, se, un = mean_shift(p[CONFIGURED + REJECTED], p[REJECTED])
        for q, x in zip(names, (*s, from_base + float(d[0]), float(se[0]), float(un[0]))):
            cols[q].append(x)
    cols["outcome"] = [
        OUTCOME_NAMES[int(o)] for o in outcomes(region, statement_of(book, REJECTED))
    ]
    return cols


def _zero_se(base, c, v) -> tuple[float, ...]:
    """The share of blocks losing none at one vector: its standard error, those of the
    paired difference and of independent blocks, and the control variate's coefficient."""
    s = cdf_shift(base, c, v)
    return tuple(
        float(s[q][0, 0]) if np.ndim(s[q]) == 2 else float(s[q][0])
        for q in ("se", "se_paired_difference", "se_unpaired", "beta")
    )


def over_scanner(book, scanner, preds, rows, k: int, n: int) -> list[dict]:
    """The 21-control, first-pass and rejection rows decided over the scanner's inputs (the
    not-comparable Table 1 set aside: every explored vector stays), each vector's evidence
    the configured scanner's main blocks moved by its paired shift (:mod:`.paired`; a count
    by :mod:`.paired_count`); the configured result kept in the note as an example, and the
    joint X, Y row decided from its members per vector (their p over the ``n`` main blocks)."""
    region = _aside(book, scanner)
    how = HOW[2:] + (
        f" {region.n} explored input vectors (scanner.toml), each "
        f"paired with the configured scanner on the same {k} blocks (common random "
        "numbers): the configured scanner's main blocks moved in logarithms by the paired "
        "shift (and stretched where the pairs show the spread changed), over its 97.5 % "
        "interval (sim.studies.agnard.paired)"
    )
    logs = [c for c in preds if c not in COUNTS]
    rows = over_region(book, region, logs, rows, lambda r: f"{how}; {_example('scanner', r)}")
    counted = HOW[2:] + (
        f" {region.n} explored input vectors (scanner.toml), each paired with the configured "
        f"scanner on the same {k} blocks: the count's distribution function (the share of "
        "blocks losing no pass point, ...) estimated from the vector's paired blocks with the "
        "configured scanner's as a control variate (its main blocks' share known), "
        "Agresti-Min smoothed standard error, over its 97.5 % interval "
        "(sim.studies.agnard.paired_count; scanner_rejections.parquet)"
    )
    counts = [c for c in preds if c in COUNTS]
    rows = over_region(
        book,
        region,
        counts,
        rows,
        lambda r: (
            f"{counted}; {_zeros(region, r['claim'], k)}; at the configured scanner (an "
            f"example): median {r['value']:.3g}, 95 % of blocks {r['ci_low']:.3g}-"
            f"{r['ci_high']:.3g}, outcome {r['outcome']}{_pass_count(r['note'])}"
        ),
    )
    why = f"no vector decides it with {k} pairs (the share of blocks that lose none, below)"
    rows = [
        {**r, "note": r["note"].replace(UNDECIDABLE, f"undecidable: {why}", 1)}
        if r["claim"] in counts
        else r
        for r in rows
    ]
    j21 = JOINT["control_21"]
    by = {r["claim"]: r for r in rows}
    ex = (
        f"at the configured scanner (an example): Holm p {by[j21]['value']:.3g}, outcome "
        f"{by[j21]['outcome']}"
    )
    joint = family_over(_fresh(book), region, j21, MEMBERS[j21], f"{how}; {ex}", n=n)
    return [joint if r["claim"] == j21 else r for r in rows]


def _pass_count(note: str) -> str:
    """The configured row's word on the pass-point count (the paper's 82, the block's own),
    kept in the row decided over the scanner."""
    i = note.find(PASS_82)
    return "" if i < 0 else ". " + note[i:]


def _zeros(region, cid: str, k: int) -> str:
    """What decides a count printed as none over the vectors: the share of blocks that lose
    none, its range and the lowest upper end of its interval (the fail needs it < 2.5 %)."""
    ev = region.outputs[cid]
    z, hi = np.asarray(ev["share_zero"]), np.asarray(ev["share_zero_high"])
    low = z < 0.1
    f0 = 1 / (k + 2)  # the smoothed share of a table with no zero (paired_count)
    return (
        f"the share of blocks that lose none is {_pct(z.min())}-{_pct(z.max())} % "
        f"over the vectors (under 10 % at {int(low.sum())} of {z.size}), the upper end of "
        f"its interval at least {_pct(hi.min())} %: the row fails at a vector only where "
        f"that end is under 2.5 % (a block losing none rarer than one in forty), which "
        f"{k} pairs cannot show: with none of them losing none it still reaches about "
        f"{_pct(min(1.0, z_box(k) * np.sqrt(f0 * (1 - f0) / k)))} %"  # a share: <= 100 %
    )


def _pct(share: float) -> str:
    """A share as a percentage of two significant digits, 100 as 100 (``:.2g`` wrote 1e+02)."""
    p = 100 * float(share)
    return f"{p:.0f}" if abs(p) >= 99.5 else f"{p:.2g}"


def _fresh(book) -> ClaimBook:
    """A copy of ``book`` with no row scored yet (a row is re-scored over a region)."""
    return ClaimBook(list(book.specs.values()), [], book.path)


def _aside(book, region):
    """``region`` with its not-comparable statements (Table 1) set aside."""
    aside = [s.id for s in region.statements if book.spec(s.id)["kind"] == "not comparable"]
    return region.without(aside)


def over_joint(cfg, book, rows, regions, five, prov, out):
    """The 5-control rows decided over the joint (layout, scanner) points (:mod:`.joint`)
    with the projection centres: the paper's program, SPACE-M, carries them (the paper names
    it; Blais's description), so its predictions are decided over those points only; each
    row of :data:`~.claims.WITHOUT_CENTRES` keeps the result over the points without them as
    a finding. ``regions``: the layout region, its predictions and statistics, the scanner
    region and its statistics. Their verdicts over the layout region at the configured
    scanner (with, for a finding without, the centres) are kept in the notes as an example.
    Writes ``joint_region.parquet`` (per joint point, with and without centres, its inputs,
    every row's outcome and value: a prediction's row decided over the points with centres,
    a finding's over those without)."""
    layout, preds, layout_stats, scanner, scanner_stats = regions
    T = cfg["region.trials"]
    j5 = JOINT["control_5"]
    lay_with, lay_without = with_option(layout, True), _findings(with_option(layout, False))
    at_cfg = {r["claim"]: r for r in over_region(book, lay_with, preds, rows, lambda r: "")}
    found = over_region(book, lay_without, [*WITHOUT_CENTRES.values()], rows, lambda r: "")
    at_cfg.update({r["claim"]: r for r in found if r["claim"] in WITHOUT_CENTRES.values()})
    at_cfg[j5] = family_over(_fresh(book), lay_with, j5, MEMBERS[j5], n=T)
    both = _findings(
        _aside(book, joint_region(book, layout, layout_stats, scanner, scanner_stats, five, preds))
    )
    joint, without = with_option(both, True), with_option(both, False)

    def how(r: Region, centres: str) -> str:
        return (
            f"decided over the {r.n} joint points of the lost layout and the scanner's "
            f"inputs {centres} ({len(five)} layout points, half with and half without the "
            f"projection centres, each with 2 of the {scanner.n} scanner vectors, each vector "
            "at 2 layout points, one with and one without: sim.studies.agnard.joint): at "
            f"each, the layout's {T} blocks at the configured scanner moved by the vector's "
            f"paired shift on {cfg['table1.trials']} blocks adjusted with the same control "
            "(common random numbers)"
        )

    def ex(cid: str) -> str:
        r = at_cfg[cid]
        option = "without" if cid in WITHOUT_CENTRES.values() else "with"
        return (
            f"over the layout region {option} the centres alone at the configured scanner "
            f"(an example): {r['value']:.3g}-{r['value_high']:.3g}, {r['outcome']}"
        )

    paper = (
        "with the projection centres (the paper's program SPACE-M carries them: the paper "
        "names it, Blais describes it; the points without them decide a finding)"
    )
    rows = over_region(book, joint, preds, rows, lambda r: f"{how(joint, paper)}; {ex(r['claim'])}")
    rows = over_region(
        book,
        without,
        [*WITHOUT_CENTRES.values()],
        rows,
        lambda r: f"{how(without, 'without the projection centres')}; {ex(r['claim'])}",
    )
    five_row = family_over(
        _fresh(book), joint, j5, MEMBERS[j5], f"{how(joint, paper)}; {ex(j5)}", n=T
    )
    found = [*preds, *WITHOUT_CENTRES.values()]  # every point's outcome of each
    cols = region_table(both, statements(book, found), values=found)
    fam = family_outcomes(book, both, MEMBERS[j5], n=T)[1][both.accepted]
    cols[j5] = [OUTCOME_NAMES[int(o)] for o in fam]
    write_table(out / "joint_region.parquet", cols, prov)
    return [five_row if r["claim"] == j5 else r for r in rows]


def _findings(region: Region) -> Region:
    """``region`` (the points without the projection centres) with the evidence of each
    finding row of :data:`~.claims.WITHOUT_CENTRES` that of its prediction there."""
    region.outputs.update({f: region.outputs[c] for c, f in WITHOUT_CENTRES.items()})
    return region


def without_snooping(cfg: dict, rows: list[dict]) -> list[dict]:
    """With ``snoop.max_reject = 0`` no pass point can be removed, so the rejection rows
    would be decided by construction, not by the simulation: the digital row (the paper:
    digital pugging removes none) would hold, the mechanical share (the paper: 6.5 %) is 0 %
    whatever the re-centring error and would fail ("input (fails)" at 40 plates, every block
    "below the paper's value"). Both are undecidable, saying why (the region verdict the count
    would have had, "holds at all ... points", is dropped from the note: :func:`_how_of`)."""
    if cfg["snoop.max_reject"]:
        return rows
    why = (
        "undecidable: snoop.max_reject = 0 (no data snooping), so no block can lose a pass "
        "point and the count is 0 by construction, not by the simulated measurement"
    )
    return [
        {
            **r,
            "outcome": "undecidable",
            "verdict": "undecidable",
            "holds": None,
            "note": f"{why}; {_how_of(r['note'])}",
        }
        if r["claim"] == REJECTED and r["kind"] == "prediction"
        else {
            **r,
            "outcome": "undecidable",
            "holds": None,
            "note": f"{why.replace('the count', 'the share')}; {r['note']}",
        }
        if r["claim"] == MECHANICAL
        else r
        for r in rows
    ]


def _how_of(note: str) -> str:
    """A row's note over the scanner's vectors without its leading region verdict (how it was
    decided onwards, :data:`~.leads.HOW`)."""
    i = note.find(HOW[2:])
    return note[i:] if i >= 0 else note
