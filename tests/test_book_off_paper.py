"""The claim book's side of the rule for a run off the paper's setup (docs/verdict-rules.md):
``paper_setup = true`` is accepted only as true or false, and true only on a self-check with
the paper's number; ``write_claims`` given the study's schema makes a run whose printed key
differs from the paper's a run off its setup, in claims.parquet. Fast: rows built by hand."""

import pyarrow.parquet as pq
import pytest

from sim.claims.book import ClaimBook, write_claims
from sim.claims.rules import NOT_APPLICABLE
from sim.mc.config import ConfigError
from sim.mc.schema_helpers import count, positive, printed

BASE = {"source": "s", "paper": "p"}
NUMBER = {"form": "value", "ref": 1.0, "tol": 0.1}
WHY = "true or false, true only on a self-check with the paper's number (ref)"


@pytest.mark.parametrize(
    "spec",
    [
        {"kind": "prediction", **NUMBER, "paper_setup": True},  # only a self-check
        {"kind": "input", **NUMBER, "paper_setup": True},
        {"kind": "paper-check", **NUMBER, "paper_setup": True},
        {"kind": "self-check", "paper_setup": True},  # a self-check without the paper's number
        {"kind": "self-check", **NUMBER, "paper_setup": "yes"},  # not true or false
        {"kind": "self-check", **NUMBER, "paper_setup": 1},
    ],
)
def test_paper_setup_is_refused_naming_the_key_the_claim_and_what_it_may_be(spec):
    ok = {**BASE, "id": "c.ok", "kind": "finding"}
    with pytest.raises(ConfigError) as e:
        ClaimBook([ok, {**BASE, "id": "c.bad", **spec}], [], "<t>")
    assert str(e.value) == f"claim.paper_setup: <t>: claim 2 (c.bad): {WHY}"
    assert e.value.key == "claim.paper_setup"


def test_paper_setup_true_on_a_self_check_with_its_number_is_accepted_and_false_anywhere():
    book = ClaimBook(
        [
            {**BASE, "id": "c.dof", "kind": "self-check", **NUMBER, "paper_setup": True},
            {**BASE, "id": "c.mc", "kind": "self-check", **NUMBER, "paper_setup": False},
            {**BASE, "id": "c.pred", "kind": "prediction", **NUMBER, "paper_setup": False},
            {**BASE, "id": "c.found", "kind": "finding", "paper_setup": False},
            {**BASE, "id": "c.plain", "kind": "self-check", **NUMBER},
        ],
        [],
        "<t>",
    )
    assert book.paper_setup == {"c.dof"}


# ------------------------------------------------------------- write_claims with the schema
SPECS = [
    {**BASE, "id": "w.grid", "kind": "input", "form": "count", "ref": 5, "tol": 0.0},
    {**BASE, "id": "w.dof", "kind": "self-check", "form": "count", "ref": 43, "tol": 0.0}
    | {"paper_setup": True},
    {**BASE, "id": "w.pred", "kind": "prediction", **NUMBER},
]
SCHEMA = {
    "plate.n": printed(count(5, "points per side", 2)),
    "plate.spacing_mm": printed(positive(45.0, "grid spacing", unit="mm")),
    "noise_um": positive(2.0, "an amplitude set to match the paper, not printed"),
}


def _write(tmp_path, config, *, schema=SCHEMA, with_book=True, **kw):
    b = ClaimBook([dict(s) for s in SPECS], [], "<t>")
    rows = [
        b.score("w.grid", 5, interval="exact"),  # no row of the run fails its rule
        b.score("w.dof", 43, interval="exact"),
        b.score("w.pred", 1.0, (0.98, 1.02)),
    ]
    prov = {"study": "t"} if config is None else {"study": "t", "config": config}
    path = tmp_path / "claims.parquet"
    write_claims(path, rows, prov, b if with_book else None, schema, **kw)
    return pq.read_table(path).to_pydict()


def test_a_run_with_the_papers_printed_values_is_a_test_of_the_paper(tmp_path):
    for config in ({"plate.n": 5, "plate.spacing_mm": 45.0, "noise_um": 3.0}, {}, None):
        t = _write(tmp_path, config)
        assert t["verdict"] == ["input", "self-check", "holds"], config
        assert t["holds"] == [None, None, True] and t["note"] == ["", "", ""]


def test_a_printed_key_that_differs_in_the_config_makes_the_run_off_the_setup(tmp_path):
    t = _write(tmp_path, {"plate.n": 5, "plate.spacing_mm": 30.0})
    assert t["verdict"] == ["input", NOT_APPLICABLE, "finding"]
    assert t["outcome"] == ["holds", "holds", "holds"]  # the rule's outcome is kept
    assert t["holds"] == [None, None, None]
    for note in t["note"][1:]:
        assert "(plate.spacing_mm = 30 (paper: 45))" in note


def test_without_the_book_the_printed_key_still_makes_predictions_findings(tmp_path):
    t = _write(tmp_path, {"plate.n": 4}, with_book=False)
    # no book: no self-check is known to be of the paper's setup, so it is decided as ever
    assert t["verdict"] == ["input", "self-check", "finding"]
    assert "(plate.n = 4 (paper: 5))" in t["note"][2]


def test_without_the_schema_the_config_is_not_compared(tmp_path):
    t = _write(tmp_path, {"plate.n": 4}, schema=None)
    assert t["verdict"] == ["input", "self-check", "holds"]


def test_write_claims_passes_the_studys_paper_design_and_spelling_on(tmp_path):
    # paper_design: the prediction keeps its verdict off the setup, the note says why
    t = _write(tmp_path, {"plate.n": 4}, paper_design=["w.pred"])
    assert t["verdict"] == ["input", NOT_APPLICABLE, "holds"] and t["holds"][2] is True
    assert t["note"][2].startswith("the paper's verdict: decided on the paper's own setup")
    # as_printed: the study's spelling of the paper's setup is the paper's
    four_is_five = lambda cfg: {**cfg, "plate.n": 5} if cfg.get("plate.n") == 4 else cfg  # noqa: E731
    t = _write(tmp_path, {"plate.n": 4}, as_printed=four_is_five)
    assert t["verdict"] == ["input", "self-check", "holds"] and t["note"] == ["", "", ""]
