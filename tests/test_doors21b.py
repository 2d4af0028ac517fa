"""The classes of the sweep doors21b (every number a reader sees of a claim, traced to its
table), one case each on a hand-made claims row; each failed on the code before its fix.

* a Monte-Carlo value and interval below 1e-9 (a self-check's residual, a tiny bias) printed as
  ``0.000000000 [0.000000000, 0.000000000]`` in README.md, ``sim show`` and REPORT.md's first
  screen, and a decision zone of such a size as ``≤ 0.000000000``: the decimals were capped at
  nine (:func:`sim.report.claimtext.decimals_for`, :func:`sim.report.tables.fmt`), so a nonzero
  value read as zero and its interval as of zero width. They print in significant digits now;
* REPORT.md's *Every headline claim* printed a variant run's rows (``agnard_block_104``, every
  verdict ``finding``) under the same claim names as the main run's, told apart only by the
  link target, and the study's title twice: a variant's rows now name their directory and say
  they are not counted;
* REPORT.md's first screen printed an exact value at 3 significant digits even where they
  cross an edge of the decision zone (1.4999 against ``≥ 1.5``, verdict fails, read "1.50"):
  it keeps the digits README.md prints there;
* the count line of REPORT.md's first screen, README.md and ``sim show`` counted a paper-check
  that holds (the paper's own arithmetic) as ``holds`` (Wolf & Pearsall: "47 holds", none of
  them a prediction) while *Counts per study* said ``paper consistent``; that table in turn
  counted an inconclusive paper-check as ``paper consistent``;
* the region line pooled a region of parts (brown_design: "2289 accepted input vectors")
  while the verdicts count the points of their part ("holds at all 2261 points"): it gives
  each part's count;
* a value of 0 read "0" on the first screen and "0.00" in README.md ("0–1.00" against
  "0.00–1.00"); a region's range of no width read "2.00–2.00".
"""

from __future__ import annotations

import math
import re

from sim.report.claimtext import interval_text, ref_text, sim_text
from sim.report.glance import _sig3
from sim.report.tables import fmt

NUM = re.compile(r"-?\d+(?:\.\d+)?(?:e[-+]?\d+)?")


def _row(**kw) -> dict:
    r = dict(
        claim="x.tiny",
        paper="a sentence of the paper",
        verdict="holds",
        interval="ci",
        form="upper",
        value=1.23e-11,
        value_high=math.nan,
        ci_low=1.20e-11,
        ci_high=1.26e-11,
        zone_low=math.nan,
        zone_high=3.0e-11,
        p_plate=None,
        headline=True,
    )
    r.update(kw)
    return r


def _numbers(text: str) -> list[float]:
    return [float(t) for t in NUM.findall(text)]


def test_a_tiny_monte_carlo_value_and_its_interval_print_as_what_they_are():
    r = _row()
    for text, want in (
        (sim_text(r), [r["value"]]),
        (interval_text(r), [r["ci_low"], r["ci_high"]]),
        (_sig3(r), [r["value"], r["ci_low"], r["ci_high"]]),
        (ref_text(r), [r["zone_high"]]),
    ):
        got = _numbers(text)
        assert len(got) == len(want), text
        for g, w in zip(got, want):
            assert g != 0 and abs(g - w) <= 0.01 * abs(w), (text, w)
    lo, hi = _numbers(interval_text(r))
    assert lo < hi  # the interval does not read as of zero width


def test_a_value_far_above_its_tiny_interval_keeps_its_decimals_in_fixed_notation():
    r = _row(value=5.0, ci_low=5 - 1e-11, ci_high=5 + 1e-11, zone_high=6.0)
    lo, hi = _numbers(interval_text(r))
    assert lo < 5 < hi and sim_text(r).startswith("5.0000000000")


def test_fmt_never_prints_a_nonzero_number_as_zero():
    for x in (1.234e-12, -4.5e-10, 7e-300):
        text = fmt(x)
        assert float(text) != 0 and abs(float(text) - x) <= 0.01 * abs(x), text
    assert fmt(3.13e-5) == "0.0000313"  # what the shipped results print is unchanged


def test_a_variant_runs_headline_rows_in_report_md_say_whose_they_are():
    """REPORT.md's *Every headline claim* printed ``agnard_block_104``'s rows (verdict
    ``finding``) under the same claim names as ``agnard_block``'s (``undecidable``...), told
    apart only by a link target, and the paper's study title twice."""
    from types import SimpleNamespace

    from sim.report.markdown import referee_summary

    study = SimpleNamespace(name="blk", title="The block", seed_file="agnard.toml")
    main = [_row(claim="blk.headline", verdict="undecidable")]
    variant = [_row(claim="blk.headline", verdict="finding")]
    md = referee_summary(
        [(None, "blk", study, main, None), (None, "blk_104", study, variant, None)]
    )
    rows = [line for line in md.splitlines() if line.startswith("| [`blk.headline`]")]
    assert len(rows) == 2
    main_row, variant_row = rows
    assert "(blk/README.md) |" in main_row and "undecidable" in main_row
    assert "(blk_104/README.md) (`blk_104`, not counted) |" in variant_row
    assert md.count("The block") == 1


def test_report_md_first_screen_keeps_an_exact_value_on_its_side_of_the_zone():
    """An exact 1.4999 against ``≥ 1.5`` (verdict fails) read "1.50" on REPORT.md's first
    screen, while README.md and ``sim show`` print 1.4999."""
    r = _row(interval="exact", verdict="fails", form="lower", value=1.4999, zone_low=1.5)
    r.update(ci_low=1.4999, ci_high=1.4999, zone_high=math.nan)
    assert float(_sig3(r)) < 1.5 and _sig3(r) == sim_text(r) == "1.4999"
    r.update(value=-59.2, zone_low=-59.25, zone_high=-59.15, form="value", verdict="holds")
    assert _sig3(r) == "-59.2"  # 3 significant digits where they stay on their side


def test_a_paper_check_is_counted_alike_on_the_first_screen_and_in_the_counts_per_study():
    """REPORT.md's first screen (and README.md's and ``sim show``'s count line) counted a
    paper-check that holds (the paper's own arithmetic) as ``holds``: Wolf & Pearsall read
    "47 holds" though none of its predictions holds, while *Counts per study* read holds 0,
    paper consistent 47; and that table counted a paper-check the simulation left
    inconclusive (gridplate_two_plates, 2) as ``paper consistent``."""
    from sim.report.markdown import verdict_counts
    from sim.report.run_summary import verdict_line

    claims = [
        {"kind": "prediction", "verdict": "fails"},
        {"kind": "paper-check", "verdict": "holds"},
        {"kind": "paper-check", "verdict": "holds"},
        {"kind": "paper-check", "verdict": "inconclusive"},
        {"kind": "paper-check", "verdict": "erratum"},
    ]
    assert verdict_line(claims) == (
        "5 claims: 1 fails, 1 inconclusive, 1 erratum, 2 paper consistent"
    )
    c = verdict_counts(claims)
    assert (c["holds"], c["fails"], c["inconclusive"], c["erratum"], c["paper ok"]) == (
        0,
        1,
        1,
        1,
        2,
    )


def test_the_region_line_counts_each_part_of_a_region_of_parts(tmp_path):
    """brown_design's region has two parts (tolerances 2261 vectors, plates 28): REPORT.md's
    first screen read "2289 accepted input vectors" and README.md's verdicts "holds at all
    2261 points of the region", with nothing to tie the two numbers together."""
    from sim.mc.storage import write_table
    from sim.report.run_summary import region_line

    write_table(
        tmp_path / "consistent_region.parquet",
        {
            "offset_mm": [1.0, 2.0, 4.0],
            "confirmed": [True, True, True],
            "part": ["tolerances", "tolerances", "plates"],
        },
        {"study": "brown_design"},
    )
    assert region_line(tmp_path) == (
        "consistent region: 3 accepted input vectors (tolerances 2, plates 1; offset_mm 1.00–4.00)"
    )


def test_the_same_interval_reads_the_same_on_the_first_screen_and_in_readme():
    """twoplate.weight_ratio.reweight_trials (0 to 1 over a region) read "0–1.00" on REPORT.md's
    first screen and "0.00–1.00" in README.md; a region over which the value does not move
    read "2.00–2.00"."""
    r = _row(interval="region", value=0.0, value_high=1.0, ci_low=0.0, ci_high=1.0)
    assert _sig3(r) == sim_text(r) == "0.00–1.00"
    r = _row(interval="region", value=2.0, value_high=2.0, ci_low=2.0, ci_high=2.0)
    assert sim_text(r) == "2.00"
