"""Design items left under issue 26 (note12), closed by left7.

1. A self-check whose reference is the paper's setup (``paper_setup = true`` in the claim book)
   is *not applicable* on a run off that setup: brown_table1 on a 4 x 4 grid scored
   ``brown.table1_closure.dof`` 25 against the book's 43 and counted "1 self-check failed",
   and its predictions stayed tests of the paper. A self-check that must hold on any setup
   (gridplate's ``closed_form``) still fails on any.
2. The claim ids a study's code builds (214 of 334: an f-string over a loop, a table's rows)
   were checked against its book only at the end of the run; each study now lists them from
   its resolved config (``sim.studies.claim_ids``) and ``sim check`` holds them against the
   book both ways.
3. ``Study.run(chunk=...)`` and every other argument the Python API does not take ended in
   Python's own TypeError; it is one ConfigError line naming the argument and the ones taken.
"""

from __future__ import annotations

from pathlib import Path

import pyarrow.parquet as pq
import pytest
from oneline import one_line

import sim
from sim.claims.book import ClaimBook, write_claims
from sim.claims.rules import NOT_APPLICABLE, VERDICTS, off_paper
from sim.cli import main
from sim.mc.config import ConfigError
from sim.report.markdown import verdict_counts
from sim.report.run_summary import verdict_line
from sim.studies import claim_ids, load_study
from sim.studies.agnard import claims as agnard_claims
from sim.studies.brown import claims as brown_claims
from sim.studies.brown.claims import full_book
from sim.studies.design import claims as design_claims
from sim.studies.gridplate import claims as gridplate_claims
from sim.studies.network.claims import _book as network_book
from sim.studies.network.claims import _self_checks as network_checks
from sim.studies.salsig import claims as salsig_claims
from sim.studies.wolf import claims as wolf_claims

ROOT = Path(__file__).resolve().parents[1]
STUDIES = ROOT / "sim" / "studies"

# ------------------------------------------------------------------ 1. a self-check of the setup
BASE = {"source": "s", "paper": "p", "tol": 0.0}
SPECS = [
    {**BASE, "id": "t.input.grid", "kind": "input", "form": "count", "ref": 5},
    {**BASE, "id": "t.dof", "kind": "self-check", "form": "count", "ref": 43, "paper_setup": True},
    {**BASE, "id": "t.mc", "kind": "self-check", "form": "value", "ref": 1.0, "paper_setup": True},
    {**BASE, "id": "t.identity", "kind": "self-check", "form": "upper", "ref": 1e-6},
    {**BASE, "id": "t.pred", "kind": "prediction", "form": "value", "ref": 2.0, "tol": 0.5},
]


def _rows(grid: int, dof: int, mc: float, identity: float):
    b = ClaimBook([dict(s) for s in SPECS], [], "<t>")
    return b, [
        b.score("t.input.grid", grid, interval="exact"),
        b.score("t.dof", dof, interval="exact"),
        b.score("t.mc", mc, (mc - 0.01, mc + 0.01)),
        b.score("t.identity", identity, interval="exact"),
        b.score("t.pred", 2.1, (2.0, 2.2)),
    ]


def test_the_book_names_its_paper_setup_self_checks():
    b, _ = _rows(5, 43, 1.0, 0.0)
    assert b.paper_setup == {"t.dof", "t.mc"}
    assert NOT_APPLICABLE in VERDICTS


def test_on_the_papers_setup_a_paper_setup_self_check_is_decided_as_any():
    b, rows = _rows(5, 43, 1.5, 0.0)  # the Monte-Carlo one fails its rule on the paper's setup
    out = off_paper(rows, b.paper_setup)
    assert out == rows
    assert [(r["verdict"], r["outcome"]) for r in out[1:4]] == [
        ("self-check", "holds"),
        ("self-check", "fails"),  # a failure on the paper's setup stays a failure
        ("self-check", "holds"),
    ]
    assert verdict_counts(out)["self-check failed"] == 1


def test_off_the_papers_setup_it_is_not_applicable_with_its_value_and_outcome(tmp_path):
    b, rows = _rows(4, 43, 1.5, 1e-3)  # a differing printed input; the identity broken
    out = off_paper(rows, b.paper_setup)
    mc, ident, pred = out[2], out[3], out[4]
    assert (mc["verdict"], mc["outcome"], mc["holds"], mc["value"]) == (
        "not applicable",
        "fails",
        None,
        1.5,
    )
    assert mc["note"].startswith("not applicable:") and "t.input.grid" in mc["note"]
    assert out[1]["verdict"] == "not applicable" and out[1]["outcome"] == "holds"
    # an identity must hold on any setup: it still fails, and is counted failed
    assert (ident["verdict"], ident["outcome"]) == ("self-check", "fails")
    assert pred["verdict"] == "finding" and pred["outcome"] == "holds"
    c = verdict_counts(out)
    assert (c["self-check"], c["self-check failed"], c["self-check not applicable"]) == (3, 1, 2)
    assert verdict_line(out) == (
        "5 claims: 1 input, 1 self-check failed, 2 self-check not applicable, 1 finding"
    )
    write_claims(tmp_path / "claims.parquet", rows, {"study": "t"}, b)
    t = pq.read_table(tmp_path / "claims.parquet").to_pydict()
    assert t["verdict"] == ["input", "not applicable", "not applicable", "self-check", "finding"]


def test_an_exact_paper_setup_self_check_that_fails_is_itself_a_differing_input():
    b, rows = _rows(5, 25, 1.0, 0.0)  # the configured inputs match; the design's count does not
    out = off_paper(rows, b.paper_setup)
    assert out[1]["verdict"] == "not applicable" and out[1]["value"] == 25
    assert out[2]["verdict"] == "not applicable" and out[2]["outcome"] == rows[2]["outcome"]
    assert out[4]["verdict"] == "finding" and "(t.dof)" in out[4]["note"]
    # without the flag the same row is a failed self-check and the run stays on the paper
    plain = off_paper(rows)
    assert plain == rows and plain[1]["verdict"] == "self-check"


@pytest.mark.parametrize(
    "spec, needle",
    [
        ({"kind": "prediction", "form": "value", "ref": 1.0}, "only on a self-check"),
        ({"kind": "input", "form": "value", "ref": 1.0}, "only on a self-check"),
        ({"kind": "self-check"}, "with the paper's number (ref)"),
        (
            {"kind": "self-check", "form": "value", "ref": 1.0, "paper_setup": "yes"},
            "true or false",
        ),
    ],
)
def test_the_flag_belongs_to_a_self_check_with_a_reference(spec, needle):
    s = {"id": "t.x", "source": "s", "paper": "p", "tol": 0.0, "paper_setup": True, **spec}
    if "ref" not in s:
        del s["tol"]
    with pytest.raises(ConfigError) as e:
        ClaimBook([s], [], "<b>")
    assert e.value.key == "claim.paper_setup" and needle in str(e.value)
    assert "\n" not in str(e.value) and "<b>: claim 1 (t.x)" in str(e.value)


def _books() -> dict[str, ClaimBook]:
    out = {"brown": full_book(), "network": network_book(network_checks(0.05, 10), [])}
    for d in ("agnard", "design", "gridplate", "salsig", "wolf"):
        out[d] = ClaimBook.load(STUDIES / d / "claims.toml")
    return out


#: every self-check of every book, surveyed: True where its reference is the paper's setup's
SURVEY = {
    "brown": {
        "brown.mc_agreement.known.mean_ratio": False,  # Monte Carlo / analytic: any setup
        "brown.mc_agreement.stations.mean_ratio": False,
        "brown.mc_agreement.pivot.mean_ratio": False,
        "brown.table1_closure.dof": True,  # 2(25) - 7: the paper's 25 points
        "brown.table1_mc_agreement.pivot.mean_ratio": False,
    },
    "design": {
        "brown.budget.table1_model_mc_vs_linear": False,  # Monte Carlo / linearised model
        "brown.design.mc_agreement.pooled_ratio": False,
        **{
            f"coverage.{m}.{k}": False  # the nominal 95 %, the test's level, E[s0] = c4 sigma
            for m in ("pivot", "affine")
            for k in ("coverage_known", "coverage_f", "false_alarm", "sigma0_over_c4")
        },
        **{  # the posterior against least squares of the same plate
            f"bayes.brown_agreement.{p}": False
            for p in ("y1", "x2", "y2", "y3", "x4", "alpha", "beta2", "max_corr_diff")
        },
    },
    "gridplate": {
        "twoplate.self_check.closed_form": False,  # an identity: the iterated adjustment
        "twoplate.self_check.affine_sigma_analytic": False,  # against its chi-square law
    },
    "network": {
        "network.mc_agreement.mean_ratio": False,
        "network.coverage95.mean": False,
        "network.global_test.false_alarm": False,
        "network.redundancy.sum": False,  # the run's own degrees of freedom: an identity
    },
    "agnard": {},
    "salsig": {},
    "wolf": {},
}


def test_every_self_check_of_every_book_is_surveyed():
    """A new self-check (or a flag added or dropped) changes this survey: decide it here."""
    found = {
        name: {c: c in b.paper_setup for c, s in b.specs.items() if s["kind"] == "self-check"}
        for name, b in _books().items()
    }
    assert found == SURVEY


def test_brown_table1_on_a_4_by_4_grid_is_off_the_papers_setup(tmp_path, capsys):
    tiny = (ROOT / "tests" / "data" / "tiny" / "brown_table1.txt").read_text().splitlines()
    sets = [x for kv in [*tiny, "plate.grid=4"] for x in ("--set", kv)]
    out = tmp_path / "bt1"
    assert main(["run", str(ROOT / "studies" / "brown_table1.toml"), "--out", str(out), *sets]) == 0
    rows = {r["claim"]: r for r in pq.read_table(out / "claims.parquet").to_pylist()}
    dof = rows["brown.table1_closure.dof"]
    assert (dof["value"], dof["outcome"], dof["verdict"]) == (25.0, "fails", "not applicable")
    preds = [r for r in rows.values() if r["kind"] == "prediction"]
    # Table 1's predictions are decided on the paper's own plate: they keep the paper's
    # verdicts (left12); the note names the failed self-check and the printed key (left8)
    assert preds and all(r["verdict"] != "finding" for r in preds)
    named = "whose printed inputs differ (brown.table1_closure.dof, plate.grid = 4 (paper: 5))"
    assert all(named in r["note"] for r in preds)
    line = verdict_line(list(rows.values()))
    assert "1 self-check not applicable" in line and "self-check failed" not in line
    assert "self-check not applicable" in capsys.readouterr().out
    readme = (out / "README.md").read_text()
    assert "| not applicable (fails) |" in readme


# ------------------------------------------------------ 2. the claim ids a study's run will score
#: the study files whose shipped results hold the claims their run scored
SHIPPED = sorted(
    f.stem
    for f in (ROOT / "studies").glob("*.toml")
    if (ROOT / "results" / f.stem / "claims.parquet").is_file()
)


@pytest.mark.parametrize("name", SHIPPED)
def test_each_study_lists_the_ids_its_shipped_run_scored(name):
    """The listing (from the resolved config, no trial run) is the claims column of the
    study's committed results: every id once, none missing, none more."""
    study, cfg = load_study(ROOT / "studies" / f"{name}.toml")
    ids = claim_ids(study, cfg)
    shipped = pq.read_table(ROOT / "results" / name / "claims.parquet").column("claim")
    if study.name == "network":  # its book is built by its code from the same lists
        assert ids is None
        return
    assert ids is not None and len(ids) == len(set(ids))
    # a declared claim the run handles without a row (nothing simulated: a resolution not in
    # agnard's tradeoff.dpis, doors24d) is listed, as the end of the run counts it scored
    rowless = {
        f"agnard.scanner.gain_{d}dpi_pct"
        for d in (300, 600)
        if study.name.startswith("agnard") and float(d) not in cfg["tradeoff.dpis"]
    }
    assert sorted(set(ids) - rowless) == sorted(shipped.to_pylist())


def _edited(text: str, cid: str, new: str | None = None) -> str:
    """The claim book ``text`` without the ``[[claim]]`` table of ``cid``, or with a copy of
    it declared as ``new``."""
    parts = text.split("[[claim]]")
    (hit,) = [p for p in parts[1:] if f'id = "{cid}"' in p]
    if new is not None:
        return text + "\n[[claim]]" + hit.replace(f'id = "{cid}"', f'id = "{new}"')
    return "[[claim]]".join([parts[0], *(p for p in parts[1:] if p is not hit)])


#: (study file, the module holding its BOOK, a claim id the study's code builds)
BUILT = [
    ("wolf_polynomial", wolf_claims, "wolf.table1.p003.max_x_um"),
    ("wolf_polynomial", wolf_claims, "wolf.table2_check.p005.set2.rms_y_um"),
    ("agnard_block", agnard_claims, "agnard.table1.ratio_check_y"),
    ("agnard_block", agnard_claims, "agnard.input.control_5_check_n"),
    ("gridplate_two_plates", gridplate_claims, "twoplate.beyond.coverage_S2_wpri"),
    ("brown_design", design_claims, "bayes.brown_agreement.alpha"),
    ("salsig_encoders", salsig_claims, "salsig.decompose_b8.E"),
    ("brown_table1", brown_claims, "brown.table1_point_sigma.together"),
    ("brown_dilution", brown_claims, "brown.mc_agreement.pivot.mean_ratio"),
]


@pytest.mark.parametrize("name, module, cid", BUILT)
def test_a_built_claim_removed_from_the_book_is_refused_by_sim_check(
    tmp_path, monkeypatch, capsys, name, module, cid
):
    book = tmp_path / "claims.toml"
    book.write_text(_edited(module.BOOK.read_text(encoding="utf-8"), cid))
    monkeypatch.setattr(module, "BOOK", book)
    rc = main(["check", str(ROOT / "studies" / f"{name}.toml")])
    one_line(capsys, rc, f"claim '{cid}', which the study scores, is not declared", str(book))


@pytest.mark.parametrize(
    "cid, new",
    [
        ("wolf.table1.p003.max_x_um", "wolf.table1.p007.max_x_um"),  # a plate Table 1 lacks
        ("wolf.before.max_x_um", "wolf.before.median_x_um"),  # a statistic nobody computes
    ],
)
def test_a_claim_no_code_scores_is_refused_by_sim_check(tmp_path, monkeypatch, capsys, cid, new):
    book = tmp_path / "claims.toml"
    book.write_text(_edited(wolf_claims.BOOK.read_text(encoding="utf-8"), cid, new))
    monkeypatch.setattr(wolf_claims, "BOOK", book)
    rc = main(["check", str(ROOT / "studies" / "wolf_polynomial.toml")])
    one_line(capsys, rc, f"declared claims the study does not score: {new}", str(book))


# ------------------------------------------------ 3. an argument the Python API does not take
@pytest.fixture(scope="module")
def handle():
    return sim.load(ROOT / "studies" / "brown_table1.toml", trials=40, chunk=2)


RESULTS = ROOT / "results" / "brown_table1"


@pytest.mark.parametrize(
    "call, key, needles",
    [
        (lambda h: h.run(chunk=5), "chunk", ["run() takes no argument 'chunk'", "replace()"]),
        (lambda h: h.run(plate__grid=4), "plate__grid", ["plate.grid is a config key"]),
        (lambda h: h.run(workerz=2), "workerz", ["(it takes out, executor, workers, trials"]),
        (lambda h: h.run("o", "local", 1, None, None, "x"), "StudyHandle.run()", ["at most 5"]),
        (lambda h: h.run("o", out="p"), "out", ["was given out twice"]),
        (lambda h: h.estimate(1), "StudyHandle.estimate()", ["no positional argument"]),
        (lambda h: h.replace(1), "StudyHandle.replace()", ["config keys by name"]),
        (lambda h: sim.load(), "study_file", ["missing: load() needs it"]),
        (lambda h: sim.load("a", "b", trials=4), "load()", ["at most 1 positional"]),
        (lambda h: sim.Results(RESULTS, name="x"), "name", ["Results() takes no argument"]),
        (lambda h: sim.Results(RESULTS), "study", ["missing: Results() needs it"]),
        (
            lambda h: sim.Results(RESULTS, "brown_table1").table("claims", columns=["claim"]),
            "columns",
            ["Results.table() takes no argument 'columns' (it takes name)"],
        ),
        (lambda h: sim.Results(RESULTS, "brown_table1").claims(True), "Results.claims()", []),
    ],
)
def test_an_argument_the_api_does_not_take_is_one_config_error_line(handle, call, key, needles):
    with pytest.raises(ConfigError) as e:
        call(handle)
    assert e.value.key == key and "\n" not in str(e.value)
    assert all(n in str(e.value) for n in needles), str(e.value)


def test_the_api_still_takes_its_own_arguments(handle):
    assert handle.replace(trials=60).config["trials"] == 60 and handle.estimate() is not None
    r = sim.Results(path=RESULTS, study="brown_table1")
    assert r.table(name="claims").num_rows == r.claims().num_rows > 0
    assert "claims" in r.names()
