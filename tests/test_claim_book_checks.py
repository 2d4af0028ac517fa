"""The claim book's validation rule by rule (:class:`sim.claims.book.ClaimBook`, ``load``) and
the Wilson interval's exact bounds (:func:`sim.claims.intervals.binomial_ci`).

Each refused book is one ConfigError whose key names the offending key and whose one-line
message names the file, the claim (its number and id) and the rule; each bound is tested on
both sides (the last value allowed, the first refused). ``make mutation`` runs this file.
"""

import math

import numpy as np
import pytest
from scipy import stats

from sim.claims.book import _MAX_DECIMALS, ClaimBook
from sim.claims.intervals import binomial_ci
from sim.claims.rules import FORMS, KINDS
from sim.mc.config import ConfigError

GOOD = {
    "id": "c",
    "source": "s",
    "paper": "p",
    "kind": "prediction",
    "form": "value",
    "ref": 1.7,
    "decimals": 1,
    "tol": 0.0,
}
FINDING = {"id": "f", "source": "s", "paper": "p", "kind": "finding"}
NR = {"source": "s", "printed": "4.2", "why": "w"}


def refused(key: str, message: str, specs, not_reproduced=(), path="<b>"):
    """The book is refused with exactly this key and this one-line message."""
    with pytest.raises(ConfigError) as e:
        ClaimBook(specs if specs is not None else [], list(not_reproduced), path)
    assert e.value.key == key
    assert str(e.value) == f"{key}: {message}"


def second(edit: dict, drop: tuple = ()) -> list[dict]:
    """A good first claim and an edited second one (the message counts claims from 1)."""
    row = {k: v for k, v in {**GOOD, "id": "d", **edit}.items() if k not in drop}
    return [GOOD, row]


# --------------------------------------------------------------------------- the two lists
@pytest.mark.parametrize("bad", [5, {}, (GOOD,), [5], [GOOD, "x"], "claim"])
def test_the_claim_list_must_be_a_list_of_tables(bad):
    refused("claim", "<b>: [[claim]] must be a list of tables", bad)


@pytest.mark.parametrize("bad", [5, {}, (NR,), [5], [NR, ["x"]]])
def test_the_not_reproduced_list_must_be_a_list_of_tables(bad):
    with pytest.raises(ConfigError) as e:
        ClaimBook([GOOD], bad, "<b>")
    assert e.value.key == "not_reproduced"
    assert str(e.value) == "not_reproduced: <b>: [[not_reproduced]] must be a list of tables"


def test_a_good_book_keeps_its_claims_and_entries_as_copies():
    specs = [GOOD, FINDING, {**GOOD, "id": "r", "form": "range", "ref": [1, 2], "tol": 0.5}]
    nr = [NR, {**NR, "why": "w2"}]
    book = ClaimBook(specs, nr, "<b>")
    assert book.path == "<b>"
    assert list(book.specs) == ["c", "f", "r"]
    assert book.specs["c"] == GOOD and book.specs["c"] is not GOOD
    assert book.not_reproduced == nr and book.not_reproduced[0] is not NR
    assert ClaimBook([], []).path == "<claims>"


# --------------------------------------------------------------------------- keys and text
def test_an_unknown_key_is_named_the_first_in_order():
    refused("claim.foo", "<b>: claim 2: unknown key", second({"foo": 1}))
    refused("claim.aa", "<b>: claim 1: unknown key", [{**GOOD, "zz": 1, "aa": 2}])


@pytest.mark.parametrize("k", ["id", "source", "paper", "kind"])
@pytest.mark.parametrize("value", [None, "", 5, ["x"]])
def test_id_source_paper_and_kind_are_non_empty_text(k, value):
    edit, drop = ({}, (k,)) if value is None else ({k: value}, ())
    refused(f"claim.{k}", "<b>: claim 2: missing or not text", second(edit, drop))


@pytest.mark.parametrize("kind", ["guess", "Prediction", "finding "])
def test_the_kind_is_one_of_the_kinds(kind):
    refused(
        "claim.kind",
        f"<b>: claim 2 (d): {kind!r} is not one of {', '.join(KINDS)}",
        second({"kind": kind}),
    )


@pytest.mark.parametrize("kind", KINDS)
def test_every_kind_is_accepted(kind):
    spec = {**GOOD, "kind": kind} if kind in ("prediction", "paper-check") else {**FINDING}
    ClaimBook([{**spec, "kind": kind}], [])


def test_a_duplicate_id_is_refused():
    refused("claim.id", "<b>: claim 2: duplicate id 'c'", second({"id": "c"}))


# --------------------------------------------------------------------------- form and ref
@pytest.mark.parametrize("form", [None, "Value", "mean", 1])
def test_a_claim_with_a_number_states_one_of_the_forms(form):
    edit, drop = ({}, ("form",)) if form is None else ({"form": form}, ())
    refused(
        "claim.form",
        f"<b>: claim 2 (d): form must be one of {', '.join(FORMS)}",
        second(edit, drop),
    )


@pytest.mark.parametrize("form", FORMS)
def test_every_form_is_accepted(form):
    ref = [1.0, 2.0] if form == "range" else 1.0
    assert ClaimBook([{**GOOD, "form": form, "ref": ref}], []).specs["c"]["form"] == form


REF_MSG = "<b>: claim 2 (d): ref must be a finite number or [low, high]"


@pytest.mark.parametrize(
    "ref",
    [
        True,
        "1.7",
        [1.0],
        [1.0, 2.0, 3.0],
        [],
        [1.0, "2"],
        ["1", 2.0],
        [False, 1.0],
        [1.0, True],
        math.inf,
        -math.inf,
        math.nan,
        [math.nan, 1.0],
        [1.0, math.nan],
        [0.0, math.inf],
        [-math.inf, 0.0],
        [2.0, 1.0],
        [2.0, 1.9999999],
    ],
)
def test_the_ref_is_a_finite_number_or_an_ordered_pair(ref):
    form = "range" if isinstance(ref, list) else "value"
    refused("claim.ref", REF_MSG, second({"ref": ref, "form": form}))


@pytest.mark.parametrize("ref", [[1.0, 1.0], [-2, 3], [0, 0.5], [-1e300, 1e300]])
def test_a_range_may_be_a_point_or_any_finite_ordered_pair(ref):
    assert ClaimBook([{**GOOD, "form": "range", "ref": ref}], []).specs["c"]["ref"] == ref


@pytest.mark.parametrize("ref", [0, -3, 1e300, -1e300, 7])
def test_a_single_ref_may_be_any_finite_number(ref):
    ClaimBook([{**GOOD, "ref": ref}], [])


@pytest.mark.parametrize("form, ref", [("range", 1.0), ("value", [1.0, 2.0]), ("upper", [1, 1])])
def test_a_range_and_only_a_range_takes_a_pair(form, ref):
    refused(
        "claim.ref",
        "<b>: claim 2 (d): a range needs [low, high], the other forms one number",
        second({"form": form, "ref": ref}),
    )


@pytest.mark.parametrize("kind", ["prediction", "paper-check"])
def test_a_prediction_or_paper_check_needs_a_ref(kind):
    refused(
        "claim.ref",
        f"<b>: claim 2 (d): a {kind} needs the paper's number (ref)",
        second({"kind": kind}, drop=("ref", "form", "tol", "decimals")),
    )


@pytest.mark.parametrize("kind", ["input", "self-check", "finding", "not comparable"])
def test_the_other_kinds_may_go_without_a_ref(kind):
    ClaimBook([{**FINDING, "kind": kind}], [])


# --------------------------------------------------------------------------- tol
TOL_MSG = "<b>: claim 2 (d): state the deciding half-width tol >= 0"


@pytest.mark.parametrize("tol", [None, "0.1", True, False, -1e-300, -1.0, math.inf, math.nan])
def test_the_tol_is_a_finite_number_at_least_zero(tol):
    edit, drop = ({}, ("tol",)) if tol is None else ({"tol": tol}, ())
    refused("claim.tol", TOL_MSG, second(edit, drop))


@pytest.mark.parametrize("tol", [0, 0.0, 1e-300, 2, 1e300])
def test_a_tol_of_zero_or_any_finite_positive_number_is_accepted(tol):
    assert ClaimBook([{**GOOD, "tol": tol}], []).specs["c"]["tol"] == tol


# --------------------------------------------------------------------------- decimals
def decimals_msg(d) -> str:
    return (
        f"<b>: claim 2 (d): decimals is the printed rounding, a whole number "
        f"-{_MAX_DECIMALS} to {_MAX_DECIMALS} (got {d!r})"
    )


def test_the_decimals_bound_is_twelve():
    assert _MAX_DECIMALS == 12


@pytest.mark.parametrize("d", ["1", 1.5, 1.0, True, False, -13, 13, -400, 400, [1], None])
def test_the_decimals_are_a_whole_number_minus_12_to_12(d):
    refused("claim.decimals", decimals_msg(d), second({"decimals": d}))


@pytest.mark.parametrize("d", [-12, -2, 0, 1, 12])
def test_decimals_from_minus_12_to_12_are_accepted(d):
    assert ClaimBook([{**GOOD, "decimals": d}], []).specs["c"]["decimals"] == d


def test_the_decimals_may_be_omitted_for_an_exact_reference():
    spec = {k: v for k, v in GOOD.items() if k != "decimals"}
    assert "decimals" not in ClaimBook([spec], []).specs["c"]


# --------------------------------------------------------------------------- headline, why
@pytest.mark.parametrize("h", ["yes", 1, 0, "true", None])
def test_the_headline_is_true_or_false(h):
    refused(
        "claim.headline", "<b>: claim 2 (d): headline is true or false", second({"headline": h})
    )


@pytest.mark.parametrize("h", [True, False])
def test_a_boolean_headline_is_accepted(h):
    assert ClaimBook([{**GOOD, "headline": h}], []).specs["c"]["headline"] is h
    assert ClaimBook([{**FINDING, "headline": h}], []).specs["f"]["headline"] is h


@pytest.mark.parametrize("k, value", [("form", "value"), ("decimals", 1), ("tol", 0.0)])
def test_form_decimals_and_tol_need_the_papers_number(k, value):
    row = {**FINDING, "id": "d", k: value}
    refused(f"claim.{k}", f"<b>: claim 2 (d): {k} without the paper's number (ref)", [GOOD, row])


@pytest.mark.parametrize("why", [5, True, ["w"], None])
def test_the_why_is_text(why):
    row = {**FINDING, "id": "d", "why": why}
    refused("claim.why", "<b>: claim 2 (d): why must be text", [GOOD, row])


def test_a_text_why_is_accepted():
    spec = {**FINDING, "kind": "not comparable", "why": "no number printed"}
    assert ClaimBook([spec], []).specs["f"]["why"] == "no number printed"
    assert ClaimBook([{**FINDING, "why": ""}], []).specs["f"]["why"] == ""


# --------------------------------------------------------------------------- not_reproduced
@pytest.mark.parametrize(
    "entry",
    [{}, {"source": "s", "printed": "p"}, {**NR, "extra": "x"}, {"source": "s", "why": "w"}],
)
def test_a_not_reproduced_entry_has_exactly_source_printed_and_why(entry):
    refused("not_reproduced", "<b>: entry 2 needs exactly source, printed and why", [], [NR, entry])


@pytest.mark.parametrize("k", ["source", "printed", "why"])
@pytest.mark.parametrize("value", ["", 4.2, None, True, ["x"]])
def test_a_not_reproduced_entrys_values_are_non_empty_text(k, value):
    refused(
        "not_reproduced",
        "<b>: entry 2: source, printed and why are text",
        [],
        [NR, {**NR, k: value}],
    )


# --------------------------------------------------------------------------- load
def write(tmp_path, text: str | bytes):
    p = tmp_path / "claims.toml"
    if isinstance(text, bytes):
        p.write_bytes(text)
    else:
        p.write_text(text, encoding="utf-8")
    return p


BOOK = """
[[claim]]
id = "c"
source = "s"
paper = "p"
kind = "prediction"
form = "value"
ref = 1.7
decimals = 1
tol = 0.0

[[not_reproduced]]
source = "s"
printed = "4.2"
why = "w"
"""


def test_load_reads_the_claims_and_the_entries(tmp_path):
    p = write(tmp_path, BOOK)
    book = ClaimBook.load(p)
    assert book.path == str(p)
    assert book.specs == {"c": GOOD}
    assert book.not_reproduced == [NR]
    assert ClaimBook.load(write(tmp_path, "\ufeff" + BOOK)).specs == {"c": GOOD}


def test_load_of_an_empty_book_has_no_claims(tmp_path):
    book = ClaimBook.load(write(tmp_path, "# nothing yet\n"))
    assert book.specs == {} and book.not_reproduced == []


def test_load_names_the_file_in_the_claims_errors(tmp_path):
    p = write(tmp_path, BOOK.replace("decimals = 1", 'decimals = "1"'))
    with pytest.raises(ConfigError) as e:
        ClaimBook.load(p)
    assert str(e.value).startswith(f"claim.decimals: {p}: claim 1 (c): ")


def test_load_refuses_an_unknown_table_naming_the_first(tmp_path):
    p = write(tmp_path, BOOK + "\n[zeta]\na = 1\n[alpha]\nb = 2\n")
    with pytest.raises(ConfigError) as e:
        ClaimBook.load(p)
    assert e.value.key == "alpha"
    assert str(e.value) == f"alpha: {p}: unknown table"


def test_load_refuses_a_toml_syntax_error(tmp_path):
    p = write(tmp_path, BOOK + "\n[[claim]]\nid = \n")
    with pytest.raises(ConfigError) as e:
        ClaimBook.load(p)
    assert e.value.key == "claims"
    assert str(e.value).startswith(f"claims: cannot read the claim book {p}: ")
    assert "\n" not in str(e.value)


def test_load_refuses_a_missing_file(tmp_path):
    p = tmp_path / "absent.toml"
    with pytest.raises(ConfigError) as e:
        ClaimBook.load(p)
    assert e.value.key == "claims"
    assert str(e.value).startswith(f"claims: cannot read the claim book {p}: ")


@pytest.mark.parametrize("encoding", ["latin-1", "utf-16"])
def test_load_refuses_a_book_not_in_utf8(tmp_path, encoding):
    p = write(tmp_path, BOOK.replace('"p"', '"pérdida"').encode(encoding))
    with pytest.raises(ConfigError) as e:
        ClaimBook.load(p)
    assert e.value.key == "claims"
    assert str(e.value) == f"claims: the claim book {p} is not UTF-8 text"


# --------------------------------------------------------------------------- binomial_ci
@pytest.mark.parametrize("n", [1, 2, 16, 40, 1000])
def test_the_wilson_bounds_are_exactly_0_at_k_0_and_1_at_k_n(n):
    p, lo, hi = binomial_ci(0, n)
    assert (p, lo) == (0.0, 0.0) and 0.0 < hi < 1.0
    p, lo, hi = binomial_ci(n, n)
    assert (p, hi) == (1.0, 1.0) and 0.0 < lo < 1.0


@pytest.mark.parametrize("n", [2, 3, 16, 40, 1000])
def test_the_wilson_bounds_are_inside_0_1_strictly_for_0_lt_k_lt_n(n):
    k = np.arange(1, n)
    p, lo, hi = binomial_ci(k, n)
    assert np.all(lo > 0.0) and np.all(hi < 1.0) and np.all(lo < p) and np.all(p < hi)
    ref = [stats.binomtest(int(j), n).proportion_ci(0.95, "wilson") for j in k]
    assert np.allclose(lo, [r.low for r in ref], rtol=1e-12, atol=0)
    assert np.allclose(hi, [r.high for r in ref], rtol=1e-12, atol=0)


def test_the_exact_bounds_follow_each_element_of_an_array():
    k = np.array([0, 1, 4, 5, 0, 3])
    n = np.array([5, 5, 5, 5, 3, 3])
    p, lo, hi = binomial_ci(k, n)
    assert lo.tolist()[0] == 0.0 and lo.tolist()[4] == 0.0
    assert hi.tolist()[3] == 1.0 and hi.tolist()[5] == 1.0
    inner = [1, 2, 3, 5]
    assert np.all(lo[inner] > 0.0)
    inner = [0, 1, 2, 4]
    assert np.all(hi[inner] < 1.0)
    assert np.array_equal(p, k / n)


def test_a_scalar_count_gives_scalar_bounds():
    for k in (0, 3, 10):
        p, lo, hi = binomial_ci(k, 10)
        assert not isinstance(lo, np.ndarray) and not isinstance(hi, np.ndarray)
