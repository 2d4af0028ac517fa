"""A run off the paper's printed setup (sim.claims.rules.off_paper): when an exact input row
(a configuration value the paper prints) fails its rule, every prediction of the run is a
finding about that setup, its outcome kept; on the paper's setup nothing changes."""

import math

import pyarrow.parquet as pq
import pytest

from sim.claims.book import ClaimBook, write_claims
from sim.claims.rules import NOT_APPLICABLE, off_paper, printed_differs
from sim.mc.config import Field
from sim.mc.schema_helpers import count, positive, printed, reals
from sim.report.markdown import verdict_counts


def _book():
    base = {"source": "s", "paper": "p", "form": "value", "decimals": 0, "tol": 0.0}
    return ClaimBook(
        [
            {**base, "id": "t.input.strips", "kind": "input", "ref": 2},
            {**base, "id": "t.input.share", "kind": "input", "form": "one-plate", "ref": 6},
            {**base, "id": "t.pred", "kind": "prediction", "ref": 29},
            {**base, "id": "t.check", "kind": "paper-check", "ref": 13},
        ],
        [],
        "<test>",
    )


def _rows(strips: float, share_samples):
    b = _book()
    return b, [
        b.score("t.input.strips", strips, interval="exact"),
        b.score("t.input.share", samples=share_samples),
        b.score("t.pred", 40.0, (38.0, 42.0)),  # fails its rule
        b.score("t.check", 14.0, interval="exact"),  # an erratum
    ]


def test_on_the_papers_setup_nothing_changes():
    # the Monte-Carlo input far from the paper (fails its rule) does not make the run off-paper
    _, rows = _rows(2.0, [20.0] * 50)
    assert rows[1]["outcome"] == "fails"
    assert off_paper(rows) == rows
    assert [r["verdict"] for r in rows] == ["input", "input", "fails", "erratum"]


def test_a_differing_printed_input_makes_predictions_findings(tmp_path):
    b, rows = _rows(4.0, [6.0] * 50)
    out = off_paper(rows)
    p = out[2]
    assert (p["outcome"], p["verdict"], p["holds"]) == ("fails", "finding", None)
    assert "t.input.strips" in p["note"] and "not a test of the paper" in p["note"]
    assert out[3]["verdict"] == "erratum"  # the paper's own arithmetic does not depend on the run
    assert rows[2]["verdict"] == "fails"  # the input rows are not modified in place
    write_claims(tmp_path / "claims.parquet", rows, {"study": "t"}, b)
    t = pq.read_table(tmp_path / "claims.parquet").to_pydict()
    assert t["verdict"] == ["input", "input", "finding", "erratum"]
    assert t["outcome"][2] == "fails"


# ------------------------------------------------------------ a self-check of the paper's setup
# docs/verdict-rules.md, "A self-check of the paper's setup": a self-check whose reference is
# a number of the paper's setup (paper_setup = true) is not applicable on a run off it, its
# value and outcome kept and the note saying why; an exact one that fails its rule is itself a
# differing printed input; a self-check without the flag is decided as ever.
BASE = {"source": "s", "paper": "p", "tol": 0.0}
SETUP_SPECS = [
    {**BASE, "id": "u.grid", "kind": "input", "form": "count", "ref": 5},
    {**BASE, "id": "u.dof", "kind": "self-check", "form": "count", "ref": 43, "paper_setup": True},
    {
        **BASE,
        "id": "u.mc",
        "kind": "self-check",
        "form": "value",
        "ref": 1.0,
        "tol": 0.1,
        "paper_setup": True,
    },
    {**BASE, "id": "u.identity", "kind": "self-check", "form": "upper", "ref": 1e-6},
    {**BASE, "id": "u.pred", "kind": "prediction", "form": "value", "ref": 2.0, "tol": 0.5},
    {"source": "s", "paper": "p", "id": "u.found", "kind": "finding"},
    {**BASE, "id": "u.check", "kind": "paper-check", "form": "value", "ref": 13},
]


def _setup_rows(grid, dof, mc, identity=0.0, mc_note=""):
    b = ClaimBook([dict(s) for s in SETUP_SPECS], [], "<t>")
    return b, [
        b.score("u.grid", grid, interval="exact"),
        b.score("u.dof", dof, interval="exact"),
        b.score("u.mc", mc, (mc - 0.01, mc + 0.01), note=mc_note),  # a Monte-Carlo interval
        b.score("u.identity", identity, interval="exact"),
        b.score("u.pred", 2.1, (2.0, 2.2)),
        b.score("u.found", 7.0, interval="exact"),
        b.score("u.check", 14.0, interval="exact"),  # an erratum
    ]


def _not_applicable(inputs: str, outcome: str) -> str:
    """The note docs/verdict-rules.md promises: why, the differing inputs, the kept outcome."""
    return (
        "not applicable: its reference is a number of the paper's setup, and this run's printed "
        f"inputs differ from the paper's ({inputs}); against that number the rule gives: {outcome}"
    )


def _same_columns(out, rows):  # every row keeps exactly the columns of claims.parquet
    assert [sorted(o) for o in out] == [sorted(r) for r in rows]


def test_off_the_setup_a_paper_setup_self_check_is_not_applicable_its_outcome_kept():
    b, rows = _setup_rows(4, 43, 1.5, mc_note="1000 trials")  # the grid differs from the paper's
    out = off_paper(rows, b.paper_setup)
    _same_columns(out, rows)
    grid, dof, mc, ident, pred, found, check = out
    assert (dof["verdict"], dof["outcome"], dof["holds"], dof["value"]) == (
        NOT_APPLICABLE,
        "holds",
        None,
        43.0,
    )
    assert (mc["verdict"], mc["outcome"], mc["holds"], mc["value"]) == (
        NOT_APPLICABLE,
        "fails",
        None,
        1.5,
    )
    # the note says why, names the differing input and the rule's outcome, then the row's own
    assert dof["note"] == _not_applicable("u.grid", "holds")
    assert mc["note"] == _not_applicable("u.grid", "fails") + "; 1000 trials"
    # a self-check without the flag, an input, a finding and an erratum are the same objects
    for k in (0, 3, 5, 6):
        assert out[k] is rows[k]
    assert (ident["verdict"], check["verdict"], found["verdict"]) == (
        "self-check",
        "erratum",
        "finding",
    )
    assert (pred["verdict"], pred["outcome"]) == ("finding", "holds")
    assert "(u.grid)" in pred["note"]  # the not-applicable self-checks are not inputs of their own
    # counted apart: two self-checks not applicable, none failed, though u.mc's outcome fails
    c = verdict_counts(out)
    assert (c["self-check"], c["self-check not applicable"], c["self-check failed"]) == (3, 2, 0)
    assert [r["verdict"] for r in rows[1:3]] == ["self-check"] * 2  # the input is not modified


def test_an_exact_paper_setup_self_check_that_fails_makes_the_run_off_the_setup():
    # every configured input is the paper's, but the design's count is not: 25, not 43
    b, rows = _setup_rows(5, 25, 1.0)
    out = off_paper(rows, b.paper_setup)
    dof, mc, pred = out[1], out[2], out[4]
    assert (dof["verdict"], dof["outcome"], dof["value"]) == (NOT_APPLICABLE, "fails", 25.0)
    assert dof["note"] == _not_applicable("u.dof", "fails")
    assert (mc["verdict"], mc["outcome"]) == (NOT_APPLICABLE, "holds")
    assert (pred["verdict"], pred["outcome"], pred["holds"]) == ("finding", "holds", None)
    assert pred["note"].startswith("not a test of the paper") and "(u.dof)" in pred["note"]
    assert sum(r["verdict"] == "holds" for r in out) == 0
    # the same row without the flag is a failed self-check, and the run stays on the paper
    plain = off_paper(rows)
    assert plain == rows and plain[1]["verdict"] == "self-check"
    assert verdict_counts(plain)["self-check failed"] == 1


@pytest.mark.parametrize(
    "mc, identity",
    [
        (1.5, 0.0),  # a paper_setup self-check with a Monte-Carlo interval fails its rule
        (1.0, 1e-3),  # a self-check without the flag (an identity) fails, exact
    ],
)
def test_a_failing_self_check_that_is_no_printed_input_leaves_the_run_on_the_paper(mc, identity):
    b, rows = _setup_rows(5, 43, mc, identity)
    out = off_paper(rows, b.paper_setup)
    assert all(o is r for o, r in zip(out, rows, strict=True)) and len(out) == len(rows)
    assert out[4]["verdict"] == "holds"  # the prediction is a test of the paper
    assert verdict_counts(out)["self-check failed"] == 1  # counted failed, not set aside


def test_a_differing_printed_key_alone_makes_the_run_off_the_setup():
    b, rows = _setup_rows(5, 43, 1.0)  # no row of its own fails
    assert off_paper(rows, b.paper_setup) == rows
    key = "plate.spacing_mm = 30 (paper: 45)"
    out = off_paper(rows, b.paper_setup, [key, "plate.n = 4 (paper: 5)"])
    _same_columns(out, rows)
    names = f"{key}, plate.n = 4 (paper: 5)"
    pred = out[4]
    assert (pred["verdict"], pred["outcome"], pred["holds"]) == ("finding", "holds", None)
    assert f"({names})" in pred["note"]
    assert [(r["verdict"], r["outcome"]) for r in out[1:3]] == [
        (NOT_APPLICABLE, "holds"),
        (NOT_APPLICABLE, "holds"),
    ]
    assert out[1]["note"] == _not_applicable(names, "holds")
    assert out[6]["verdict"] == "erratum" and out[6] is rows[6]


def test_a_prediction_already_a_finding_is_untouched():
    b, rows = _setup_rows(4, 43, 1.0)
    done = {**rows[4], "verdict": "finding", "holds": None, "note": "decided elsewhere"}
    out = off_paper([rows[0], done], b.paper_setup)
    assert out[1] is done and out[1]["note"] == "decided elsewhere"


# ------------------------------------------------------------------- printed configuration keys
# docs/verdict-rules.md: a configuration key whose default is the paper's own number is marked
# printed; a run whose value differs is off the paper's setup, the note naming the key, its
# value and the paper's ("plate.spacing_mm = 30 (paper: 45)").
SCHEMA = {
    "plate.n": printed(count(5, "points per side", 2)),
    "noise_um": positive(2.0, "an amplitude set to match the paper, not printed"),
    "plate.spacing_mm": printed(positive(45.0, "grid spacing", unit="mm")),
    "plate.design": printed(Field("grid", "str", "design", choices=("grid", "random"))),
    "plate.xs": printed(reals([1.0, 2.5], "abscissae", unit="mm")),
    "region.points": printed(count(3, "read only under a switch", 1)),
}
PAPER = {"plate.n": 5, "noise_um": 2.0, "plate.spacing_mm": 45.0, "plate.design": "grid"}


def test_on_the_papers_printed_values_nothing_differs():
    # an unprinted key may differ; a key the configuration leaves out has its default
    cfg = {**PAPER, "noise_um": 3.0, "plate.xs": [1.0, 2.5]}
    assert printed_differs(SCHEMA, cfg) == []
    assert printed_differs(SCHEMA, {}) == []


def test_each_differing_printed_key_is_named_with_its_value_and_the_papers_in_schema_order():
    cfg = {
        "plate.xs": [1.0, 12.700082809],
        "plate.design": "random",
        "plate.spacing_mm": 30.0,
        "noise_um": 3.0,
        "plate.n": 4,
    }
    assert printed_differs(SCHEMA, cfg) == [
        "plate.n = 4 (paper: 5)",
        "plate.spacing_mm = 30 (paper: 45)",
        "plate.design = 'random' (paper: 'grid')",
        "plate.xs = [1, 12.700082809] (paper: [1, 2.5])",
    ]


def test_a_change_in_the_seventh_digit_shows():
    (line,) = printed_differs(SCHEMA, {"plate.spacing_mm": 45.0000001})
    assert line == "plate.spacing_mm = 45.0000001 (paper: 45)"


def test_a_value_one_ulp_from_the_papers_is_the_papers():
    # a swept 1.1 + 0.6 = 1.7000000000000002: 12 significant digits decide, not the float
    assert printed_differs(SCHEMA, {"plate.spacing_mm": math.nextafter(45.0, 46.0)}) == []
    assert printed_differs(SCHEMA, {"plate.xs": [1.0, 2.5 + 1e-15]}) == []


def test_the_studys_spelling_of_the_papers_setup_is_the_papers():
    # as_printed (brown's list of Table 1's points, spelled as its grid) is applied to a copy
    def spelled(cfg):
        cfg["plate.design"] = "grid" if cfg["plate.design"] == "list" else cfg["plate.design"]
        return cfg

    cfg = {"plate.design": "list"}
    assert printed_differs(SCHEMA, cfg, spelled) == []
    assert cfg == {"plate.design": "list"}
    assert printed_differs(SCHEMA, cfg) == ["plate.design = 'list' (paper: 'grid')"]
    assert printed_differs(SCHEMA, {"plate.design": "random"}, spelled) == [
        "plate.design = 'random' (paper: 'grid')"
    ]


# ------------------------------------------------------------ predictions on the paper's design
# docs/verdict-rules.md: a prediction the study decides on the paper's own setup whatever the
# run's design (paper_design: Brown's region rows) keeps its verdict on a run off the setup,
# its note saying so before its own; every other row is treated as without it.
KEPT = (
    "the paper's verdict: decided on the paper's own setup, independent of this run's design, "
    "whose printed inputs differ (u.grid)"
)


def test_off_the_setup_a_paper_design_prediction_keeps_its_verdict():
    b, rows = _setup_rows(4, 43, 1.0)  # the grid differs from the paper's
    own = [{**r, "note": "over 300 points"} if r["claim"] == "u.pred" else r for r in rows]
    for given, note in ((rows, KEPT), (own, KEPT + "; over 300 points")):
        out = off_paper(given, b.paper_setup, (), ["u.pred", "u.dof"])
        _same_columns(out, given)
        pred = out[4]
        assert (pred["verdict"], pred["outcome"], pred["holds"]) == ("holds", "holds", True)
        assert pred["note"] == note
        # a self-check among the ids is no prediction: still not applicable
        assert out[1]["verdict"] == NOT_APPLICABLE
    assert rows[4]["verdict"] == "holds" and rows[4]["note"] == ""  # the input is not modified
    assert off_paper(rows, b.paper_setup)[4]["verdict"] == "finding"  # without the id


def test_a_paper_design_note_names_every_differing_input():
    """Two differing inputs (a failed exact input row and a printed key): the note lists both,
    comma-separated, as the findings' notes do."""
    b, rows = _setup_rows(4, 43, 1.0)
    out = off_paper(rows, b.paper_setup, ["plate.spacing_mm = 30 (paper: 45)"], ["u.pred"])
    assert out[4]["note"] == KEPT.replace("(u.grid)", "(u.grid, plate.spacing_mm = 30 (paper: 45))")


def test_on_the_setup_a_paper_design_prediction_is_unchanged():
    b, rows = _setup_rows(5, 43, 1.0)
    assert off_paper(rows, b.paper_setup, (), ["u.pred"]) == rows
