"""doors25a: a sweep of the doors built this session (lookalike names, claim ids at load,
the commands a report prints).

* two point names that look the same were refused only for Latin, Cyrillic and a few Greek
  capitals: Armenian ``օ`` beside ``o``, Cherokee ``Ꭺ`` beside ``A``, Greek ``ρ`` beside
  ``p`` or the dental click ``ǀ`` beside ``l`` were two points printed alike;
* a claim id edited in the claim book so that it still looks the same (a trailing space, a
  Cyrillic ``Ѕ``) was "claim 'X', which the study scores, is not declared", of a book that
  visibly declares X: the declared id that looks like it is now named with its code points;
* the command a results directory prints to show itself again (``sim show DIR``, in
  README.md and after a sweep) was not quoted for the shell: a directory ``my net (v2)`` gave
  a command that fails when pasted.
"""

from __future__ import annotations

import shlex
from pathlib import Path

import pytest
from oneline import one_line

from sim import cli
from sim.claims.book import ClaimBook
from sim.mc.config import ConfigError
from sim.studies.scored_ids import check_literal_ids

NET = """study = "network"
trials = 40
chunk = 2
seed = 1
[network]
points = [ {{ name = "F1", x_m = 0.0, y_m = 0.0, role = "fixed" }},
  {{ name = "F2", x_m = 100.0, y_m = 0.0, role = "fixed" }},
  {{ name = "{a}", x_m = 50.0, y_m = 60.0 }},
  {{ name = "{b}", x_m = 40.0, y_m = -50.0 }} ]
generate = [ {{ kind = "distance", from = "*", to = "*", sigma_mm = 1.0 }} ]
[datum]
kind = "fixed"
"""


@pytest.mark.parametrize(
    "a, b, codes",
    [
        ("o1", "\u05851", "U+006F against U+0585"),  # Armenian օ
        ("A1", "\u13aa1", "U+0041 against U+13AA"),  # Cherokee Ꭺ
        ("p1", "\u03c11", "U+0070 against U+03C1"),  # Greek ρ
        ("l1", "\u01c01", "U+006C against U+01C0"),  # dental click ǀ
    ],
)
def test_two_point_names_of_other_scripts_that_look_the_same_are_refused(
    tmp_path, capsys, a, b, codes
):
    p = tmp_path / "look.toml"
    p.write_text(NET.format(a=a, b=b), encoding="utf-8")
    one_line(capsys, cli.main(["check", str(p)]), "network.points", "look the same", codes)


@pytest.mark.parametrize("a, b", [("P\u00e9", "\u53171"), ("Pe", "P\u00e9"), ("\u03c1", "\u03c3")])
def test_names_that_do_not_look_the_same_are_accepted(tmp_path, capsys, a, b):
    p = tmp_path / "ok.toml"
    p.write_text(NET.format(a=a, b=b), encoding="utf-8")
    assert cli.main(["check", str(p)]) == 0, capsys.readouterr().err


SPEC = {"source": "s", "paper": "p", "kind": "finding"}


@pytest.mark.parametrize(
    "declared, codes",
    [("x.y.SY ", "U+0020 against nothing"), ("x.y.\u0405Y", "U+0405 against U+0053")],
)
def test_a_claim_id_edited_to_look_the_same_is_named(tmp_path, declared, codes):
    book = ClaimBook([{**SPEC, "id": declared}, {**SPEC, "id": "x.y.SX"}], [], "claims.toml")
    with pytest.raises(ConfigError, match="is not declared") as e:
        book.spec("x.y.SY")
    assert f"declared is {declared!r}, which looks the same: {codes}" in str(e.value)


def test_a_literal_id_of_the_code_names_a_declared_lookalike(tmp_path):
    declared = "x.y.\u0405Y"
    book = ClaimBook([{**SPEC, "id": declared}, {**SPEC, "id": "x.y.SX"}], [], "claims.toml")
    (tmp_path / "run.py").write_text('book.score("x.y.SY", 1.0)\n', encoding="utf-8")
    with pytest.raises(ConfigError, match="run.py") as e:
        check_literal_ids(book, tmp_path)
    assert f"declared is {declared!r}, which looks the same: U+0405 against U+0053" in str(e.value)


def test_an_id_removed_names_no_lookalike():
    book = ClaimBook([{**SPEC, "id": "x.y.SX"}, {**SPEC, "id": "x.y.S"}], [], "claims.toml")
    with pytest.raises(ConfigError, match=r"'x.y.SY', which the study scores, is not declared$"):
        book.spec("x.y.SY")


def test_the_show_command_a_readme_prints_is_quoted_for_the_shell(tmp_path, capsys):
    p = tmp_path / "net.toml"
    p.write_text(NET.format(a="C", b="D"), encoding="utf-8")
    out = tmp_path / "my net (v2)"
    assert cli.main(["run", str(p), "--out", str(out), "--quiet", "--no-figures"]) == 0
    capsys.readouterr()
    text = (out / "README.md").read_text(encoding="utf-8")
    line = next(x for x in text.splitlines() if "prints it again" in x)
    # its path (doors39l: outside results/ and scratch/ its name alone names another directory)
    assert f"`sim show {shlex.quote(str(out))}`" in line, line
    assert shlex.split(f"sim show {shlex.quote(str(out))}")[2] == str(out)


def test_a_plain_directory_name_is_printed_as_it_was():
    root = Path(__file__).resolve().parents[1]
    text = (root / "results" / "network_plate" / "README.md").read_text(encoding="utf-8")
    assert "(`sim show network_plate` prints it again)" in text


def test_out_beside_a_results_directory_of_another_unicode_form_is_refused(tmp_path, capsys):
    """``--out café`` (NFC) beside the results ``café`` (NFD, as macOS writes names) made a
    second results directory that ``ls`` and REPORT.md show alike."""
    p = tmp_path / "net.toml"
    p.write_text(NET.format(a="C", b="D"), encoding="utf-8")
    nfd, nfc = tmp_path / "cafe\u0301", tmp_path / "caf\u00e9"
    assert cli.main(["run", str(p), "--out", str(nfd), "--quiet", "--no-figures"]) == 0
    capsys.readouterr()
    rc = cli.main(["run", str(p), "--out", str(nfc), "--quiet", "--no-figures"])
    one_line(capsys, rc, "--out", "another Unicode form", "U+0065 U+0301 against U+00E9")
    assert not nfc.exists() and sorted(x.name for x in tmp_path.iterdir()) == [
        "cafe\u0301",
        "net.toml",
    ]
    assert cli.main(["run", str(p), "--out", str(nfd), "--quiet", "--no-figures"]) == 0


def test_a_lock_file_that_is_a_directory_is_named(tmp_path, capsys):
    """It was "cannot write to <the parent>: Is a directory", naming the wrong path."""
    p = tmp_path / "net.toml"
    p.write_text(NET.format(a="C", b="D"), encoding="utf-8")
    (tmp_path / ".o.partial" / ".lock").mkdir(parents=True)
    rc = cli.main(["run", str(p), "--out", str(tmp_path / "o"), "--quiet", "--no-figures"])
    line = one_line(capsys, rc, "--out", ".o.partial/.lock is not a lock file of sim")
    assert "Is a directory" not in line


@pytest.mark.parametrize("lock", [True, False])
def test_a_staging_directory_of_ones_own_that_cannot_be_written_is_not_another_users(
    tmp_path, lock
):
    """A user's own lock file (or staging directory) made read-only was "an unfinished run
    of another user (<the user>)". (The run itself cannot be made to fail so as root: the
    error is given.)"""
    import errno

    from sim.mc import outputs

    stage = tmp_path / ".o.partial"
    stage.mkdir()
    if lock:
        (stage / ".lock").write_text("1\n")
    e = PermissionError(errno.EACCES, "Permission denied")
    why = outputs._not_lockable(stage, tmp_path / "o", "o", e)
    assert "another user" not in why
    assert why.startswith(f"{stage / '.lock' if lock else stage} is yours"), why


def test_a_gridplate_variant_of_one_plate_is_written_in_the_singular():
    from sim.studies import load_study
    from sim.studies.gridplate.report import _intro

    root = Path(__file__).resolve().parents[1]
    _, cfg = load_study(root / "studies" / "gridplate_two_plates.toml", values={"plate.count": 1})
    assert "with 1 grid plate of 5 x 5" in _intro(cfg)
    cfg["plate.count"] = 2
    assert "with 2 grid plates of 5 x 5" in _intro(cfg)


def test_a_table_given_a_value_names_its_keys(capsys):
    """``--set plate=4`` was "plate: unknown key" of a study whose file has a [plate]."""
    brown = str(Path(__file__).resolve().parents[1] / "studies" / "brown_table1.toml")
    rc = cli.main(["check", brown, "--set", "plate=4"])
    one_line(capsys, rc, "plate: unknown key (plate is a table: give one of its keys, plate.")
    one_line(capsys, cli.main(["check", brown, "--set", "plat=4"]), "plat: unknown key")
