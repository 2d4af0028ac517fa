"""A run off the paper's printed setup (sim.claims.rules.off_paper): when an exact input row
(a configuration value the paper prints) fails its rule, every prediction of the run is a
finding about that setup, its outcome kept; on the paper's setup nothing changes."""

import pyarrow.parquet as pq

from sim.claims.book import ClaimBook, write_claims
from sim.claims.rules import off_paper


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
