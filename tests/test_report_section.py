"""The shared study-report skeleton (sim.report.section) and claim-table helper
(sim.claims.table), on constructed claim books and Parquet files."""

from __future__ import annotations

import math

import numpy as np
import pytest

from sim.claims.book import ClaimBook, write_claims
from sim.claims.table import Sim, claim_rows, exact, mc, plates
from sim.mc.config import ConfigError
from sim.mc.storage import write_table
from sim.report.section import errata, printed, recomputed, region_lead, section, span

SPECS = [
    {
        "id": "t.a",
        "source": "s",
        "paper": "a",
        "kind": "prediction",
        "form": "value",
        "ref": 1.0,
        "tol": 0.1,
    },
    {"id": "t.b", "source": "s", "paper": "b", "kind": "finding"},
    {
        "id": "t.c",
        "source": "s",
        "paper": "c",
        "kind": "prediction",
        "form": "one-plate",
        "ref": 2.0,
        "tol": 0.1,
    },
    {"id": "t.d", "source": "s", "paper": "d", "kind": "finding"},
]


def book():
    return ClaimBook([dict(s) for s in SPECS], [], "<test>")


def test_claim_rows_equal_the_book_scored_one_by_one_in_table_order():
    x = np.random.default_rng(7).normal(2.0, 0.01, 400)
    table = {
        "t.c": plates(x, "plates"),
        "t.a": mc(1.02, 0.01, "mc"),
        "t.b": exact(3, "count"),
        "t.d": Sim(0.5, (0.4, 0.6), "spread", note="sp"),
    }
    got = claim_rows(book(), table)
    b = book()
    want = [
        b.score("t.c", samples=x, note="plates"),
        b.score("t.a", 1.02, (1.02 - 1.96 * 0.01, 1.02 + 1.96 * 0.01), note="mc"),
        b.score("t.b", 3.0, interval="exact", note="count"),
        b.score("t.d", 0.5, (0.4, 0.6), "spread", note="sp"),
    ]
    assert [r["claim"] for r in got] == ["t.c", "t.a", "t.b", "t.d"]
    for g, w in zip(got, want):
        assert g.keys() == w.keys()
        for k in g:  # bit for bit: NaN where the book has no reference
            assert g[k] == w[k] or (
                isinstance(w[k], float) and math.isnan(g[k]) and math.isnan(w[k])
            )
    # decided by the book's rule: 1.02 +- 0.0196 lies inside 1 +- 0.1
    assert got[1]["verdict"] == "holds"


def test_a_none_entry_completes_the_book_without_a_row():
    b = book()
    rows = claim_rows(b, {"t.a": exact(1.0), "t.b": None, "t.c": exact(2.0), "t.d": None})
    assert [r["claim"] for r in rows] == ["t.a", "t.c"]
    b.check_complete()  # no error: every declared claim accounted for
    with pytest.raises(ValueError, match="t.d"):
        b2 = book()
        claim_rows(b2, {"t.a": exact(1.0), "t.b": None, "t.c": exact(2.0)})
        b2.check_complete()


def test_an_undeclared_claim_is_named():
    # a ConfigError (one line, exit 2: a claim book edited by hand, doors19b), not a KeyError
    for sim_value in (None, exact(1.0)):
        with pytest.raises(ConfigError, match=r"claim 't\.zz', which the study scores, is not"):
            claim_rows(book(), {"t.zz": sim_value})


def test_span():
    assert span(None, None) == "nowhere" and span(float("nan"), 1.0) == "nowhere"
    assert span(1.0, 1.0, " mm") == "1.00 mm"
    assert span(1.0, 2.5) == "1.00–2.50"


def test_printed_and_recomputed_numbers_carry_the_papers_decimals():
    row = {"ref_low": 6.95, "ref_high": 7.05, "value": 7.280109889, "note": "sum 530 / 10."}
    assert printed(row) == "7.0" and recomputed(row) == "7.28"
    fine = {"ref_low": 0.9999786685, "ref_high": 0.9999786695, "value": 0.99997866291}
    assert printed(fine) == "0.999978669" and recomputed(fine) == "0.9999786629"
    # a zone without width (an exact printed number): the interval-free format
    assert printed({"ref_low": 43.0, "ref_high": 43.0, "value": 41.0}) == "43.0"
    claims = [
        row | {"claim": "t.x", "verdict": "erratum"},
        row | {"claim": "t.y", "verdict": "holds"},
    ]
    assert errata(claims) == (
        "**Errata** (the paper against its own printed data): `t.x`: printed 7.0, "
        "recomputed 7.28 (sum 530 / 10)."
    )
    assert errata(claims[1:]).endswith("printed data): none.")


def _study(tmp_path, region=True):
    out = tmp_path / "st"
    out.mkdir()
    b = book()
    rows = claim_rows(b, {"t.a": exact(1.0), "t.b": exact(5.0), "t.c": exact(2.5), "t.d": None})
    write_claims(out / "claims.parquet", rows, {"study": "st", "config": {"k": 4.0}}, b)
    if region:
        r = {
            "input": ["offset_mm", "beta_mm"],
            "declared_low": [0.0, 1.0],
            "declared_high": [50.0, 1.0],
            "why": ["hardware", "printed"],
            "region_low": [2.0, 1.0],
            "region_high": [40.0, 1.0],
            "together_low": [5.0, 1.0],
            "together_high": [20.0, 1.0],
            "resolution_interior": [0.5, 0.0],
            "resolution_boundary": [0.1, 0.0],
            "n_together": [12, 12],
            "n_region": [30, 30],
            "n_points": [64, 64],
        }
        write_table(out / "region_inputs.parquet", r, {"study": "st"})
    return out


class _Field:
    def __init__(self, doc, inp, default=4.0):
        self.doc, self.input, self.default = doc, inp, default


def test_section_keeps_the_order_and_leaves_out_empty_blocks(tmp_path):
    out = _study(tmp_path)
    (out / "f.png").write_bytes(b"png")  # g.png was not drawn (a run with --no-figures)
    schema = {"k": _Field("the k of the paper", True), "j": _Field("not an input", False)}
    txt = section(
        out,
        lead=[region_lead(out, "The predictions", values="every value analytic")],
        intro=["INTRO"],
        schema=schema,
        body=["BODY", ""],
        figures=[("a figure", "f.png"), ("b", "g.png")],
    )
    blocks = txt.split("\n\n")
    order = [
        txt.index("**Consistent region.** The predictions hold together for offset_mm 5.00–20.0"),
        txt.index("INTRO"),
        txt.index("| `t.a` |"),
        txt.index("| `k` | 4.0 | the k of the paper |"),
        txt.index("BODY"),
        txt.index("![a figure](st/f.png)\n*b: not drawn (`g.png` is missing"),
    ]
    assert order == sorted(order)
    assert "" not in blocks and "`j`" not in txt
    # the fixed input beta (declared as one value) is not named as implied
    assert "beta_mm 1" not in blocks[0]
    assert "(12 of the 30 input vectors of the region; 64 explored)" in txt
    assert "at the boundaries; every value analytic)" in txt


def test_region_lead_says_how_the_vectors_and_their_values_were_obtained(tmp_path):
    out = _study(tmp_path)
    txt = region_lead(out, "P", values="200 simulated models per vector", design="a Sobol design")
    assert "(`sim.claims.inference`: a Sobol design; 200 simulated models per vector)" in txt
    assert "analytic" not in txt and "refinement" not in txt


def test_section_without_lead_schema_or_figures(tmp_path):
    out = _study(tmp_path, region=False)
    txt = section(out, intro=["INTRO"])
    assert txt.startswith("INTRO\n\n| claim |") and "Inputs set" not in txt and "![" not in txt


def test_region_lead_when_nothing_holds_together(tmp_path):
    out = _study(tmp_path)
    from sim.mc.storage import read_table

    t = read_table(out / "region_inputs.parquet").to_pydict()
    t["n_together"] = [0, 0]
    write_table(out / "region_inputs.parquet", t, {"study": "st"})
    assert "hold together for no input of the region (30 input vectors of 64 explored)" in (
        region_lead(out, "They", values="every value analytic")
    )


def test_a_region_explored_per_part_is_led_part_by_part(tmp_path):
    out = _study(tmp_path)
    from sim.mc.storage import read_table

    t = read_table(out / "region_inputs.parquet").to_pydict()
    t["part"] = ["tol", "plates"]
    t["n_together"], t["n_region"], t["n_points"] = [12, 0], [30, 8], [64, 16]
    write_table(out / "region_inputs.parquet", t, {"study": "st"})
    txt = region_lead(out, "They", values="v")
    assert (
        "They, explored per part: in part `tol` they hold together for offset_mm 5.00–20.0 "
        "(12 of the 30 input vectors of the region; 64 explored); in part `plates` they hold "
        "together for no input of the region (8 input vectors of 16 explored)." in txt
    )
    assert "| part | input |" in txt and "| `plates` | `beta_mm` |" in txt


def test_a_missing_table_is_a_config_error_not_a_traceback(tmp_path):
    out = _study(tmp_path, region=False)
    with pytest.raises((ConfigError, OSError, FileNotFoundError)):
        region_lead(out, "x", values="every value analytic")
