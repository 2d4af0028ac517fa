"""Markdown table cells of names a user chose (doors22b left it): a point name ending in a
backslash before a pipe (``Pé\\|``) was written ``Pé\\\\|``, which GitHub reads as a
backslash and a cell's end: the row got one cell more and every column after it moved."""

from __future__ import annotations

import pytest

from sim.report.tables import md_table


def gfm_cells(line: str) -> list[str]:
    """A table row split as GitHub's table extension splits it: a backslash escapes the next
    character (so ``\\\\|`` is an escaped backslash and then a delimiter), an unescaped pipe
    ends a cell; each cell's escapes then read as the characters they escape."""
    cells, cur, k = [], "", 0
    body = line.strip()[1:-1]
    while k < len(body):
        c = body[k]
        if c == "\\" and k + 1 < len(body):
            cur += c + body[k + 1]
            k += 2
            continue
        if c == "|":
            cells.append(cur)
            cur = ""
        else:
            cur += c
        k += 1
    cells.append(cur)
    unescape = lambda s: s.strip().replace("\\|", "|").replace("\\\\", "\\")  # noqa: E731
    return [unescape(x) for x in cells]


@pytest.mark.parametrize("name", ["P\\|", "Pé\\\\|x", "a|b", "plain", "ends\\", "\\|\\|"])
def test_a_cell_with_pipes_and_backslashes_is_one_cell_read_back_as_written(name):
    row = md_table(["point", "sigma"], [[name, "0.1"]]).splitlines()[2]
    cells = gfm_cells(row)
    assert len(cells) == 2 and cells[1] == "0.1", row
    if "|" in name:  # the cell's own escapes read back as the name (a backslash before a
        assert cells[0] == name, row  # pipe doubled; other backslashes are left as written


# A name that reads as HTML outside a code span (doors22b left it): a point ``<D>`` vanished
# from a README's table (GitHub drops an unknown tag) and ``&lt;`` showed as ``<``; the
# suite's own ``<br>`` and every code span stay as written.
@pytest.mark.parametrize(
    ("text", "written"),
    [
        ("<D>", "&lt;D>"),
        ("</x>", "&lt;/x>"),
        ("<!-- c -->", "&lt;!-- c -->"),
        ("&lt;", "&amp;lt;"),
        ("&#60;", "&amp;#60;"),
        ("`<D>` and <D>", "`<D>` and &lt;D>"),
        ("`a`<br>`b`", "`a`<br>`b`"),
        ("B&L Macroscope", "B&L Macroscope"),
        ("x < y", "x < y"),
        ("``a ` <D>``", "``a ` <D>``"),
    ],
)
def test_a_name_that_reads_as_html_is_escaped_outside_code_spans(text, written):
    assert md_table(["point"], [[text]]).splitlines()[2] == f"| {written} |"
