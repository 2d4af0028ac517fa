"""The first screen of ``results/REPORT.md`` (issue 25): per paper one row with its
studies, the verdict counts and three headline verdicts at the precision their interval
supports; the consistent regions, the variant runs of a study (counted apart) and the
network studies below it. Built from the Parquet files alone."""

from __future__ import annotations

import math
from pathlib import Path
from typing import Callable

import pyarrow as pa

from sim.mc.storage import read_provenance
from sim.report.claimtext import decimals_for, exact_text, fmt_at
from sim.report.config_diff import changed_keys, changes_text, design_of
from sim.report.off_paper import off_setup
from sim.report.papers import paper_name
from sim.report.run_summary import headline_rows, region_line, verdict_line
from sim.report.tables import Md, fmt, md_link, md_table

__all__ = ["opening", "by_paper", "main_and_variants", "number", "VERDICT_TEXT"]


VERDICT_TEXT = {
    "holds": "holds",
    "fails": "**fails**",
    "inconclusive": "inconclusive",
    "depends": "depends",
    "holds or undecided": "holds or undecided",
    "fails or undecided": "fails or undecided",
    "undecidable": "undecidable",
    "erratum": "**erratum**",
    "input": "input",
    "self-check": "self-check",
    "finding": "finding",
    "not comparable": "not comparable",
    "not applicable": "not applicable",
}


def number(x):
    """A table cell as a number, or None where it is missing or NaN."""
    return None if x is None or (isinstance(x, float) and math.isnan(x)) else x


def _headline_pick(studies: list[tuple], n: int = 3) -> list[tuple]:
    """Up to ``n`` headline claims of one paper: one per study in turn, each in its claim
    book's order. ``studies``: ``[(dir name, study, claims)]``."""
    queues = [[(name, r) for r in headline_rows(claims)] for name, _, claims in studies]
    out: list[tuple] = []
    while len(out) < n and any(queues):
        for q in queues:
            if q and len(out) < n:
                out.append(q.pop(0))
    return out


def _num(x, dec: int | None) -> str:
    """``x`` at the decimals its interval supports (``dec``; see
    :func:`sim.report.claimtext.decimals_for`) and at most 3 significant digits; a whole
    number as such."""
    if not isinstance(x, (int, float)) or not math.isfinite(x):
        return fmt(x)
    if float(x).is_integer() and abs(x) < 1e6 and not dec:
        return str(int(x))
    if x == 0:  # at the interval's decimals, as README.md prints it ("0.00–1.00", not "0–1.00")
        return fmt_at(0.0, dec) if dec else "0"
    three = 2 - math.floor(math.log10(abs(x)))  # decimals of 3 significant digits
    return fmt_at(x, three if dec is None else min(dec, three))


def _on_its_side(x, text: str, r: dict) -> str:
    """``text`` (``x`` at 3 significant digits), or the digits that keep it on its side of
    each edge of the claim's decision zone where 3 do not (an exact 1.4999 against ``≥ 1.5``
    read "1.50" and *fails*; README.md prints 1.4999)."""
    try:
        y = float(text)
    except ValueError:
        return text
    for b in (number(r.get("zone_low")), number(r.get("zone_high"))):
        if (
            isinstance(b, (int, float))
            and math.isfinite(b)
            and ((y < b) != (x < b) or (y > b) != (x > b))
        ):
            return exact_text(x, r)
    return text


def _sig3(r: dict) -> str:
    """A claim's simulated value at the precision its interval supports, at most 3
    significant digits (a range over a region as low–high); its 95 % interval after it
    unless it is that range, or of zero width."""
    if r["verdict"] == "not comparable":
        return ""
    lo, hi = number(r.get("ci_low")), number(r.get("ci_high"))
    dec = decimals_for(lo, hi) if r["interval"] != "exact" else None
    num = _num if r["interval"] != "exact" else lambda x, d: _on_its_side(x, _num(x, d), r)
    v = num(r["value"], dec)
    vh = number(r.get("value_high"))
    if vh is not None and vh != r["value"]:
        v += f"–{num(vh, dec)}"
    same = (lo, hi) == (r["value"], vh) or lo == hi
    if r["interval"] != "exact" and lo is not None and not same:
        v += f" [{_num(lo, dec)}, {_num(hi, dec)}]"
    return v


def by_paper(entries: list[tuple]) -> dict[str, list]:
    by_seed: dict[str, list] = {}
    for _, name, study, claims, _ in entries:
        by_seed.setdefault(study.seed_file or "", []).append((name, study, claims))
    return by_seed


def main_and_variants(studies: list[tuple]) -> tuple[list, list]:
    """The studies of one paper split into its main runs (one per registered study, the
    directory named as the study first) and the variants (another run of a study already
    shown, e.g. ``agnard_block_104``: the same study at a real block's size)."""
    main: dict[str, tuple] = {}
    for entry in sorted(studies, key=lambda e: (e[0] != e[1].name, e[0])):
        main.setdefault(entry[1].name, entry)
    chosen = {id(e) for e in main.values()}
    return [e for e in studies if id(e) in chosen], [e for e in studies if id(e) not in chosen]


def _config_of(out: Path) -> dict:
    try:
        return dict(read_provenance(out / "claims.parquet").get("config") or {})
    except (OSError, ValueError, pa.ArrowException):
        return {}


def _variant_note(results: Path, name: str, study, claims: list, of: str, main: str) -> str:
    """One line on a variant run of study ``of``: what its config changes (at most four
    keys) from the main run's, in ``main`` (named otherwise than ``of``, a directory of
    yours: the keys were compared with none and the line listed keys both runs share), its
    counts, a link."""
    mine, base = _config_of(results / name), _config_of(results / main)
    skip = {"seed", "trials", "chunk"}
    diff = [
        k for k in mine if k not in skip and not k.startswith("region.") and mine[k] != base.get(k)
    ]
    what = ", ".join(f"`{k}` = {fmt(mine[k])}" for k in diff[:4]) + (
        ", ..." if len(diff) > 4 else ""
    )
    return (
        f"- {md_link(name)} is the study `{of}` again at another configuration"
        + (f" ({what})" if what else "")
        + f": {verdict_line(claims).split(': ', 1)[1]}; not counted in the row above."
    )


def _paper_row(seed: str, studies: list[tuple]) -> list[str]:
    """One row: the paper and its studies (linked), the counts, three headline claims with
    their values and verdicts (one per line of the cell)."""
    links = Md(", ".join(md_link(name) for name, _, _ in studies))
    counts = verdict_line([r for _, _, c in studies for r in c]).split(": ", 1)[1]
    picks = [r for _, r in _headline_pick(studies)]
    if not picks:
        return [f"**{paper_name(seed)}** ({links})", counts, "_no headline claim_", "", ""]
    return [
        f"**{paper_name(seed)}** ({links})",
        counts,
        "<br>".join(f"`{r['claim']}`" for r in picks),
        "<br>".join(_sig3(r) or "—" for r in picks),
        "<br>".join(VERDICT_TEXT.get(r["verdict"], r["verdict"]) for r in picks),
    ]


def opening(entries: list[tuple], results: Path) -> str:
    """One screen: per paper one row (its studies linked to their README.md, the verdict
    counts, three headline verdicts at the precision their interval supports); below it
    each consistent region's line, the variant runs of a study (another configuration of
    the same paper's study, counted apart) and the network studies (no paper)."""
    rows, notes, variants = [], [], []
    by_seed = by_paper(entries)
    # a directory named as another study holds (results dirs swapped or renamed by hand): the
    # report went by the directory's name, brown_dilution's claims shown as brown_table1's
    names = {e[2].name for e in entries}
    for _, name, study, _, _ in entries:
        if name != study.name and name in names:
            variants.append(
                f"- {md_link(name)} holds the results of the study `{study.name}` "
                f"(its tables say so), not of `{name}`: a directory renamed or swapped by hand"
            )
    for seed in sorted(s for s in by_seed if s):
        main, other = main_and_variants(by_seed[seed])
        rows.append(_paper_row(seed, main))
        mains = {s.name: n for n, s, _ in main}
        for name, study, claims in other:
            variants.append(
                _variant_note(results, name, study, claims, study.name, mains[study.name])
            )
        for name, _, _ in main:
            if (reg := region_line(results / name)) is not None:
                notes.append(f"- `{name}`: {reg}")
    nets = by_seed.get("", [])
    if nets:
        notes.append(
            "- Network studies (a declared network, no paper): "
            + "; ".join(
                f"{md_link(name)} {verdict_line(c).split(': ', 1)[1]}" for name, _, c in nets
            )
        )
    table = md_table(
        ["paper (studies)", "verdicts", "headline claims", "simulated [95%]", "verdict"], rows
    )
    # network studies alone (two designs of one's own): the table was its header, no row
    table = [table, ""] if rows else []
    return "\n".join(["## The verdicts at a glance", "", *table, *variants, *notes, ""])


def design_notes(entries: list[tuple], results: Path, design: Callable | None) -> list[str]:
    """One line per results directory whose run changed the config of the study file it
    stands for (``studies/<name>.toml``, else ``studies/<study>.toml``: ``design(name)``, see
    :func:`sim.report.config_diff.design_of`): the keys changed (at most six), so that a
    ``--set`` run is not read as the paper's design."""
    out = []
    for _, name, study, *_ in entries:
        base = design(name) if design is not None else None
        if base and base.get("study") != study.name:  # a study file of another study named
            # like it: its keys were compared with the other study's ("(the file: )" for each)
            out.append(
                f"- {md_link(name)} holds a run of the study `{study.name}`, not of "
                f"`studies/{name}.toml` (the study `{base.get('study')}`): a study file of "
                f"`{study.name}` named `{name}.toml`. Its verdicts are `{study.name}`'s."
            )
            continue
        mine = _config_of(results / name)
        found = design_of(mine, name, design) if mine else None
        if found is None or not changed_keys(mine, found[1]):
            continue
        off = off_setup(study, mine)  # README.md's and sim show's line (doors36q)
        out.append(
            f"- {md_link(name)} did not run the configuration of "
            f"`{found[0]}`: {changes_text(mine, found[1])}. Its verdicts are about this run's "
            "configuration, not the study file's design."
            + (f" {off[:1].upper()}{off[1:]}." if off else "")
        )
    return out
