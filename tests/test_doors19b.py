"""The classes of the sweep doors19b (issue 26: the suite's own data files edited by a user to
try a variant of a paper study: the claim books and the region declarations), one case each;
each failed on the code before its fix.

* the claim book was read only when the run scored its claims, after the whole simulation: a
  syntax error, a duplicate id or a bad form in ``claims.toml``, or a bound of ``region.toml``
  reversed, passed ``sim check`` and ended the run minutes later; the study's ``data`` hook
  (:func:`sim.studies.data_check`) reads the book and its region declarations when the study
  file is loaded (``sim check``, the start of ``sim run``);
* a claim the study scores removed or renamed ended the run in "KeyError ... is not declared"
  (exit 3): one line naming the book and the claim id, exit 2;
* ``decimals = "1"`` was a TypeError at scoring, ``decimals = 1.5`` and ``true`` and
  ``ref = true`` (read as 1) and ``headline = "yes"`` were accepted, ``tol = inf`` made every
  zone the whole line (every claim held), ``printed = 4.2`` in ``[[not_reproduced]]`` was an
  ArrowTypeError, and ``claim = 5`` a TypeError: each is refused naming the key;
* a region declaration's errors did not name the file (``inputs.relief_mm: high 0.5 < low
  20.0`` reads as a key of the study file), and a claim listed twice, or both a constraint
  and a prediction, was accepted.
"""

import pytest
from oneline import one_line
from test_claim_book_checks import GOOD  # a claim every rule accepts

from sim import cli
from sim.claims.book import ClaimBook
from sim.claims.book_region import load_declaration
from sim.mc.config import ConfigError
from sim.studies import data_check, load_study
from sim.studies.salsig import claims as salsig_claims
from sim.studies.salsig import region as salsig_region
from sim.studies.salsig.region import DECLARATION, nominal

SALSIG = "studies/salsig_encoders.toml"


@pytest.mark.parametrize(
    "edit, key",
    [
        ({"decimals": "1"}, "claim.decimals"),
        ({"decimals": 1.5}, "claim.decimals"),
        ({"decimals": True}, "claim.decimals"),
        ({"decimals": -400}, "claim.decimals"),
        ({"ref": True}, "claim.ref"),
        ({"tol": float("inf")}, "claim.tol"),
        ({"headline": "yes"}, "claim.headline"),
    ],
)
def test_a_claims_printed_number_is_validated_naming_the_key(edit, key):
    with pytest.raises(ConfigError, match=rf"^{key}: <b>: claim 1 \(c\): "):
        ClaimBook([{**GOOD, **edit}], [], "<b>")
    ClaimBook([GOOD], [], "<b>")  # the unedited row is a claim


def test_a_not_reproduced_entry_and_the_claim_list_are_validated():
    with pytest.raises(ConfigError, match=r"^not_reproduced: <b>: entry 1: .* are text$"):
        ClaimBook([], [{"source": "s", "printed": 4.2, "why": "w"}], "<b>")
    with pytest.raises(ConfigError, match=r"^claim: <b>: \[\[claim\]\] must be a list of tables"):
        ClaimBook(5, [], "<b>")


def test_a_scored_claim_missing_from_the_book_is_one_config_error():
    with pytest.raises(ConfigError, match=r"^claim.id: <b>: claim 'x', which the study scores"):
        ClaimBook([GOOD], [], "<b>").spec("x")


def test_sim_check_reads_the_claim_book(tmp_path, monkeypatch, capsys):
    book = tmp_path / "claims.toml"
    text = salsig_claims.BOOK.read_text(encoding="utf-8")
    monkeypatch.setattr(salsig_claims, "BOOK", book)
    book.write_text(text + "\n[[claim]]\nid = \n", encoding="utf-8")
    one_line(capsys, cli.main(["check", SALSIG]), str(book), "Invalid value")
    first = text.index("decimals = ")
    book.write_text(text[:first] + 'decimals = "3"\n' + text[first:].split("\n", 1)[1])
    one_line(capsys, cli.main(["check", SALSIG]), str(book), "claim.decimals")
    book.write_text(text, encoding="utf-8")  # the same book, read from elsewhere, is accepted
    assert cli.main(["check", SALSIG]) == 0


@pytest.mark.parametrize(
    "old, new, needle",
    [
        ("low = 0.5\nhigh = 20.0", "low = 20.0\nhigh = 0.5", "inputs.relief_mm: high 0.5 < low"),
        (
            '"salsig.vertical_halved.dramatic_vertical",',
            '"salsig.vertical_halved.rms_ratio",',
            "'salsig.vertical_halved.rms_ratio' is listed twice",
        ),
        (
            '"salsig.vertical_halved.dramatic_vertical",',
            '"salsig.vertical_halved.dramatic_horizontal",',
            "'salsig.vertical_halved.dramatic_horizontal' is listed twice",
        ),
    ],
)
def test_a_region_declaration_error_names_its_file(tmp_path, old, new, needle):
    text = DECLARATION.read_text(encoding="utf-8")
    assert old in text
    region = tmp_path / "region.toml"
    region.write_text(text.replace(old, new, 1), encoding="utf-8")
    with pytest.raises(ConfigError) as e:
        data_check(salsig_claims.load_book, region)({})
    assert str(e.value).startswith(f"{region}: ") and needle in str(e.value)
    assert "\n" not in str(e.value)
    load_declaration(DECLARATION, salsig_claims.load_book())  # the committed one is accepted


def test_a_claim_book_or_region_saved_in_latin1_or_with_a_bom(tmp_path, monkeypatch, capsys):
    """Latin-1 was "sim: error: UnicodeDecodeError: ..." naming no file (exit 3); a Windows
    editor's BOM refused the unchanged book at line 1, column 1."""
    book = tmp_path / "claims.toml"
    text = salsig_claims.BOOK.read_text(encoding="utf-8")
    monkeypatch.setattr(salsig_claims, "BOOK", book)
    book.write_bytes(text.encode("utf-8") + "# café\n".encode("latin-1"))
    one_line(capsys, cli.main(["check", SALSIG]), str(book), "not UTF-8 text")
    book.write_bytes(b"\xef\xbb\xbf" + text.encode("utf-8"))
    assert cli.main(["check", SALSIG]) == 0
    region = tmp_path / "region.toml"
    region.write_bytes(DECLARATION.read_bytes() + "# café\n".encode("latin-1"))
    with pytest.raises(ConfigError, match="region declaration is not UTF-8 text"):
        data_check(salsig_claims.load_book, region)({})
    region.write_bytes(b"\xef\xbb\xbf" + DECLARATION.read_bytes())
    data_check(salsig_claims.load_book, region)({})


@pytest.mark.parametrize(
    "edit, needle",
    [
        (("[inputs.relief_mm]", "[inputs.relief_m]"), "inputs.relief_mm: "),
        (("", '\n[inputs.extra_mm]\nlow = 1.0\nhigh = 2.0\nwhy = "w"\n'), "inputs.extra_mm: "),
    ],
)
def test_a_region_input_the_code_does_not_read_is_refused(tmp_path, edit, needle):
    """An input renamed was "KeyError: 'relief_mm'" in the run's region part (exit 3); one
    added was explored as a dimension no code reads."""
    _, cfg = load_study(SALSIG)
    text = DECLARATION.read_text(encoding="utf-8")
    region = tmp_path / "region.toml"
    old, new = edit
    region.write_text(text.replace(old, new, 1) if old else text + new, encoding="utf-8")
    with pytest.raises(ConfigError) as e:
        data_check(salsig_claims.load_book, (region, nominal, {}))(cfg)
    assert str(e.value).startswith(needle) and str(region) in str(e.value)
    data_check(salsig_claims.load_book, (DECLARATION, nominal, {}))(cfg)


@pytest.mark.parametrize(
    "old, new, needle",
    [
        ("low = 10.0\nhigh = 200.0", "low = -10.0\nhigh = 200.0", "inputs.sigma_z_um.low: "),
        ("low = 4\nhigh = 20", "low = 0\nhigh = 20", "inputs.control_1.low: "),
        ("low = 0.5\nhigh = 20.0", "low = 0.5\nhigh = 1e300", "inputs.relief_mm.high: "),
    ],
)
def test_a_region_range_keeps_the_bounds_of_the_key_it_sets(tmp_path, old, new, needle):
    """A negative sigma, no control points or a relief of 1e300 mm were explored without a
    word (the region verdicts over them, exit 0)."""
    study, cfg = load_study(SALSIG)
    keys = {**salsig_region._KEYS, "control_1": "vertical.control"}
    text = DECLARATION.read_text(encoding="utf-8")
    assert old in text
    region = tmp_path / "region.toml"
    region.write_text(text.replace(old, new, 1), encoding="utf-8")
    with pytest.raises(ConfigError) as e:
        data_check(salsig_claims.load_book, (region, nominal, keys))(cfg, study.schema)
    assert str(e.value).startswith(needle) and "outside vertical." in str(e.value)
    study.data(cfg, study.schema)  # the committed declaration keeps them
