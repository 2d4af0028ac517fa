"""doors24c: every text the suite reads or writes, in every encoding (a sweep of the doors).

* a GNU Gama file's values were trimmed and split with Python's ``strip()``/``split()``, which
  also take a no-break space and the other Unicode spaces: ``id="A\\u00a0"`` was the point
  ``A`` here and another point in gama-local (which trims XML white space only), and
  ``x="150.0\\u00a0"``, a number gama-local refuses, was read;
* two point names that look the same (Latin ``A`` and Cyrillic ``А``, a precomposed ``É`` and
  ``E`` + U+0301) were two points printed alike in every table, figure and exported file;
  an observation to one when the other was declared was "no point named 'A'", of a network
  that visibly had an ``A``;
* a message quoted text that looked right: ``--set triаls=5`` (a Cyrillic ``а``) was
  "unknown key (did you mean trials?)", ``plate.grid=５`` "must be an integer (got '５')", a
  malformed study file "at line 6, column 4" of an invisible or lookalike character, a file
  of lone CR line ends one line of 86 columns, a Latin-1 file "not UTF-8 text" with no place;
* a user's names were written into README.md as Markdown: a point ``<b>&amp;`` was HTML there
  (bold, an ``&``), a name with a backtick ended its code span, a results directory named
  ``*x*`` an italic title;
* Wolf's table in Excel's "CSV UTF-8" (a byte-order mark) was "missing column(s) plate, ..."
  of a header that has them, and a row with a decimal comma (``33,221``) was read with every
  later value one column on (silently: each stayed under 1000 mm).
"""

from __future__ import annotations

import re
from pathlib import Path

import pytest
from oneline import one_line

from sim import cli
from sim.mc.config import ConfigError, read_toml
from sim.mc.lookalike import note, skeleton
from sim.report.tables import md_code, md_table, md_text
from sim.studies.network.gama_read import read_gama
from sim.studies.wolf.tables import load_table1

ROOT = Path(__file__).resolve().parents[1]
TWO_SETS = ROOT / "tests" / "data" / "gama" / "two_sets.xml"
BROWN = ROOT / "studies" / "brown_table1.toml"
TABLE1 = ROOT / "studies" / "data" / "wolf_table1.csv"


def _gama(tmp_path: Path, *edits: tuple[str, str]) -> Path:
    text = TWO_SETS.read_text(encoding="utf-8")
    for old, new in edits:
        assert old in text
        text = text.replace(old, new)
    p = tmp_path / "net.xml"
    p.write_text(text, encoding="utf-8")
    return p


@pytest.mark.parametrize(
    "edit, needle",
    [
        (('<point id="A"', '<point id="A\u00a0"'), "'A\\xa0'"),
        (('<distance to="B"', '<distance to="\u00a0B"'), "'\\xa0B'"),
        (('x="150.0"', 'x="150.0\u00a0"'), "'150.0\\xa0' is not a number"),
        (('stdev="2.0"', 'stdev="2.0\u2003"'), "is not a number"),
        (('axes-xy="ne"', 'axes-xy="ne\u00a0"'), "is not one of"),
    ],
)
def test_a_gama_value_keeps_a_unicode_space_as_gama_local_does(tmp_path, edit, needle):
    """gama-local 2.03 reads ``id="A\\u00a0"`` as a point other than ``A`` (the observations
    to ``A`` then lack their point) and refuses ``x="150.0\\u00a0"``; here both were ``A`` and
    150.0. The id is now no point name (it ends in a space) and the number no number."""
    with pytest.raises(ConfigError, match=re.escape(needle)):
        read_gama(_gama(tmp_path, edit))


def test_a_cov_mat_is_split_at_xml_white_space_only(tmp_path):
    cov = '<cov-mat dim="3" band="0">4.0 4.0\u00a04.0</cov-mat>\n      </obs>\n      <obs from="B">'
    p = _gama(tmp_path, ('</obs>\n      <obs from="B">', cov))
    with pytest.raises(ConfigError, match=r"<cov-mat>: 2 numbers for dim 3"):  # not 3
        read_gama(p)


def test_xml_white_space_around_a_gama_value_is_still_trimmed(tmp_path):
    """What gama-local trims (ASCII spaces, a tab, a line break), the suite still trims."""
    base = read_gama(TWO_SETS)
    p = _gama(tmp_path, ('<point id="A"', '<point id=" A\t"'), ('x="150.0"', 'x=" 150.0\n"'))
    assert read_gama(p)["network.points"] == base["network.points"]


NET = """study = "network"
trials = 200
chunk = 10
[network]
points = [ {{ name = "F1", x_mm = 0.0, y_mm = 0.0, role = "fixed" }},
  {{ name = "F2", x_mm = 500000.0, y_mm = 0.0, role = "fixed" }},
  {{ name = "{a}", x_mm = 150000.0, y_mm = 120000.0 }},
  {{ name = "{b}", x_mm = 350000.0, y_mm = 140000.0 }} ]
generate = [ {{ kind = "distance", from = "*", to = "*", sigma_mm = 2.0 }},
  {{ kind = "direction", from = "{c}", to = "*", sigma_arcsec = 3.0 }},
  {{ kind = "direction", from = "F1", to = "*", sigma_arcsec = 3.0 }} ]
"""


@pytest.mark.parametrize(
    "a, b, codes",
    [
        ("A", "\u0410", "U+0041 against U+0410"),  # Latin A, Cyrillic А
        ("\u00c9", "E\u0301", "U+00C9 against U+0045 U+0301"),  # NFC and NFD É
        ("P1", "\uff301", "U+0050 against U+FF30"),  # full-width Ｐ
    ],
)
def test_two_point_names_that_look_the_same_are_refused(tmp_path, capsys, a, b, codes):
    """They were two points that every output printed alike (one point split in two)."""
    p = tmp_path / "look.toml"
    p.write_text(NET.format(a=a, b=b, c=a), encoding="utf-8")
    one_line(capsys, cli.main(["check", str(p)]), "network.points", "look the same", codes)


def test_a_name_not_found_that_looks_like_a_point_names_the_code_points(tmp_path, capsys):
    p = tmp_path / "look.toml"
    p.write_text(NET.format(a="\u0410", b="B", c="A"), encoding="utf-8")  # declared Cyrillic
    line = one_line(capsys, cli.main(["check", str(p)]), "no point named 'A'")
    assert "a point 'А' looks the same: U+0410 against U+0041 here" in line
    gama = _gama(tmp_path, ('<point id="A"', '<point id="\u0410"'))
    with pytest.raises(ConfigError, match="no such <point> .a point 'А' looks the same: U"):
        read_gama(gama)


def test_two_gama_ids_that_look_the_same_are_refused_naming_the_file(tmp_path, capsys):
    extra = '<point id="\u0410" x="10.0" y="-50.0" adj="xy"/><point id="B"'
    obs = '<distance to="\u0410" val="1" stdev="2"/><direction to="\u0410" val="1" stdev="2"/>'
    gama = _gama(  # val="1": no value of these points, kept under a tol-abs of 1e9 mm
        tmp_path,
        ('<point id="B"', extra),
        ('<distance to="F2"', obs + '<distance to="F2"'),
        ('sigma-act="apriori"', 'sigma-act="apriori" tol-abs="1e9"'),
    )
    study = tmp_path / "g.toml"
    study.write_text(
        f'study = "network"\ntrials = 200\nchunk = 10\n[network]\ngama_xml = "{gama}"\n'
    )
    one_line(capsys, cli.main(["check", str(study)]), str(gama), "'A' and 'А' look the same")


@pytest.mark.parametrize(
    "override, needle",
    [
        ("tri\u0430ls=5", "'а' is U+0430 CYRILLIC SMALL LETTER A"),
        ("plate.grid=\uff15", "'５' is U+FF15 FULLWIDTH DIGIT FIVE"),
        ("comparator.beta_mm=\u22121.0", "'−' is U+2212 MINUS SIGN"),
    ],
)
def test_a_message_names_a_character_that_looks_like_ascii(capsys, override, needle):
    one_line(capsys, cli.main(["check", str(BROWN), "--set", override]), needle)


def test_a_wholly_non_latin_word_or_plain_text_gets_no_note():
    """A Cyrillic name is no mistake, and the suite's own text holds no lookalike."""
    assert note("/home/Алексей/x.toml: no such study file") == ""
    assert note("plate.grid: must be an integer (got 'x')") == ""
    assert skeleton("\u0410") == skeleton("A") and skeleton("Алексей") != "Алексей"


@pytest.mark.parametrize(
    "edit, needle",
    [
        (lambda t: t.replace("trials", "tri\u0430ls", 1), "U+0430 CYRILLIC SMALL LETTER A"),
        (lambda t: t.replace("trials =", "trials\u00a0=", 1), "U+00A0 NO-BREAK SPACE"),
        (lambda t: "\u200b" + t, "U+200B ZERO WIDTH SPACE"),
        (lambda t: "\ufeff\ufeff" + t, "U+FEFF ZERO WIDTH NO-BREAK SPACE"),  # two signatures
        (lambda t: t.replace("\n", "\r"), "a lone CR ends the line"),
    ],
)
def test_malformed_toml_names_the_character_it_stops_at(tmp_path, edit, needle):
    p = tmp_path / "s.toml"
    p.write_bytes(edit(BROWN.read_text(encoding="utf-8")).encode("utf-8"))
    with pytest.raises(ConfigError, match=re.escape(needle)):
        read_toml(p)


def test_a_latin1_study_file_is_named_by_its_byte_and_line(tmp_path):
    p = tmp_path / "s.toml"
    p.write_bytes(BROWN.read_bytes() + "# café\n".encode("latin-1"))
    line = BROWN.read_bytes().count(b"\n") + 1
    with pytest.raises(ConfigError, match=rf"byte 0xe9 at line {line}: saved as Latin-1"):
        read_toml(p)


def _shown(md: str) -> str:
    """What CommonMark shows of inline text with backslash escapes and no markup: a
    backslash before ASCII punctuation is dropped; any other markup character left is a
    failure (it would be read as markup)."""
    out, k = "", 0
    while k < len(md):
        c = md[k]
        if c == "\\" and k + 1 < len(md) and md[k + 1] in "\\`*_[]<>&~|$":
            out, k = out + md[k + 1], k + 2
            continue
        assert c not in "`*[]<>&~|$\\", (md, k)  # unescaped: read as markup
        out, k = out + c, k + 1
    return out


@pytest.mark.parametrize("name", ["<b>&amp;", "*x*", "a`b", "_P_", "A\\|B", "P_1", "É😀", "$x$"])
def test_a_users_name_in_markdown_shows_as_written(name):
    assert _shown(md_text(name)) == name
    row = md_table(["point"], [[md_text(name)]]).splitlines()[2]
    assert _shown(row[2:-2]) == name
    assert md_text("P_1") == "P_1" and md_text("G17") == "G17"  # committed names unchanged
    code = md_code(name)
    fence = re.match(r"`+", code)[0]
    assert code.strip("`").strip() == name and fence not in name


def test_a_network_readme_shows_a_point_named_like_html_as_written(tmp_path, capsys):
    """A point named ``<b>&amp;`` was raw HTML in README.md: bold, and an ``&``."""
    p = tmp_path / "html.toml"
    p.write_text(NET.format(a="<b>&amp;", b="B", c="B"), encoding="utf-8")
    out = tmp_path / "out *x*"
    assert cli.main(["run", str(p), "--out", str(out), "--quiet", "--no-figures"]) == 0
    capsys.readouterr()
    text = (out / "README.md").read_text(encoding="utf-8")
    rows = [r for r in text.splitlines() if r.startswith("| ") and "amp" in r]
    assert rows and all("<b>" not in r and "\\<b\\>\\&amp;" in r for r in rows), rows
    assert "# out \\*x\\*: " in text


def test_wolfs_table_with_a_byte_order_mark_is_read(tmp_path):
    p = tmp_path / "t1.csv"
    p.write_bytes(b"\xef\xbb\xbf" + TABLE1.read_bytes())
    a, b = load_table1(p), load_table1(TABLE1)
    assert a.keys() == b.keys() and all((a[k] == b[k]).all() for k in a)


def test_wolfs_table_with_a_decimal_comma_is_refused_not_shifted(tmp_path):
    text = TABLE1.read_text(encoding="utf-8")
    row = next(r for r in text.splitlines() if r.startswith("003,2,"))
    p = tmp_path / "t1.csv"
    p.write_text(text.replace(row, row.replace("33.221", "33,221", 1)), encoding="utf-8")
    with pytest.raises(ConfigError, match=r"data row 2 has 10 cells for the header's 9"):
        load_table1(p)


def test_a_path_in_another_unicode_form_than_the_files_name_is_named(tmp_path, capsys):
    """``café.xml`` typed precomposed (NFC) for a file saved decomposed (NFD, as macOS writes
    names) is another name to Linux: it was "no such file" of a name ``ls`` shows alike."""
    nfc, nfd = "caf\u00e9", "cafe\u0301"
    (tmp_path / f"{nfd}.xml").write_bytes(TWO_SETS.read_bytes())
    (tmp_path / f"{nfd}.toml").write_bytes(BROWN.read_bytes())
    (tmp_path / f"{nfd}.csv").write_bytes(TABLE1.read_bytes())
    why = "its name in another Unicode form (U+0065 U+0301 against U+00E9)"
    one_line(capsys, cli.main(["check", str(tmp_path / f"{nfc}.toml")]), why)
    with pytest.raises(ConfigError, match=re.escape(why)):
        read_gama(tmp_path / f"{nfc}.xml")
    with pytest.raises(ConfigError, match=re.escape(why)):
        load_table1(tmp_path / f"{nfc}.csv")


def test_a_network_name_with_dollars_is_drawn_as_written(tmp_path, capsys):
    """matplotlib reads text between two ``$`` as mathtext: ``net $\\alpha$`` was titled
    "net α", and ``$\\foo{$`` failed the run at its figure, after every trial (exit 2)."""
    from matplotlib.text import Text

    from sim.studies.network.figures import literal

    name = "net $\\foo{$ $\\alpha$ a\\$b"
    assert Text()._preprocess_math(literal(name)) == (name, False)  # no math, as written
    p = tmp_path / "dollar.toml"
    p.write_text(
        NET.format(a="A", b="B", c="B").replace("[network]", f"[network]\nname = '{name}'")
    )
    assert cli.main(["run", str(p), "--out", str(tmp_path / "o"), "--quiet"]) == 0
    assert (tmp_path / "o" / "network.png").is_file()


def test_report_links_a_results_directory_of_any_name(tmp_path, capsys):
    """``[my net (v2)*](my net (v2)*/README.md)`` was no link (a space ends a link's target)
    and its star began emphasis; the committed names are written as they were."""
    import shutil

    shutil.copytree(ROOT / "results" / "network_plate", tmp_path / "my net (v2)*")
    shutil.copytree(ROOT / "results" / "network_plate", tmp_path / "network_plate")
    assert cli.main(["report", "--results", str(tmp_path)]) == 0
    capsys.readouterr()
    text = (tmp_path / "REPORT.md").read_text(encoding="utf-8")
    assert "[my net (v2)\\*](my%20net%20%28v2%29%2A/README.md)" in text
    assert "(my net" not in text and "[network_plate](network_plate/README.md)" in text
