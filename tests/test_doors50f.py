"""Fresh fuzz seeds over every fuzzer (brief F50), and the mutations of a finished results
directory the fuzzers never drew (tests/fuzz_results.py); one case per class, each failed on
the code before its fix.

* A table other than the claims of a finished run replaced by a symbolic link that loops
  (``points.parquet -> points.parquet``): ``sim report`` and ``sim show --markdown`` ended in
  "sim: internal error: RuntimeError: Symlink loop from ..." (exit 3: Python 3.11's
  ``Path.resolve`` raises RuntimeError for a loop, which the reader's path check did not
  catch). The same table made a FIFO or a link that leads nowhere was "No such file or
  directory: .../points.parquet", a file that is there. Each now names the file and what
  stands there (:func:`sim.cli_tables.lost_table`), as the claims table's own check does.
"""

import os

from sim.cli import main
from tests.hand_edits import copy_of_tiny
from tests.oneline import SIM_ERROR, one_line
from tests.within import within


def test_a_table_made_a_looping_link_or_a_fifo_is_named_by_report_and_show(
    tiny_run, tmp_path, capsys
):
    """A results directory touched by hand: a table the report reads (not the claims) made a
    link to itself, or a FIFO. Before: a traceback (exit 3), or "No such file or directory"."""
    d = copy_of_tiny(tiny_run, tmp_path)
    (d / "points.parquet").unlink()
    os.symlink("points.parquet", d / "points.parquet")
    words = (str(d / "points.parquet"), "a symbolic link that leads nowhere", "not a table")
    rc = main(["report", "--results", str(d.parent)])
    one_line(capsys, rc, *words, prefix=SIM_ERROR + "--results: ")
    one_line(capsys, main(["show", "--markdown", str(d)]), *words, prefix=SIM_ERROR + "DIR: ")
    (d / "points.parquet").unlink()
    os.mkfifo(d / "summary.parquet.fifo")
    os.replace(d / "summary.parquet.fifo", d / "points.parquet")
    rc = within(60, main, ["report", "--results", str(d.parent)])
    one_line(capsys, rc, str(d / "points.parquet"), "is a FIFO (named pipe)", "not a table")
    assert (d / "points.parquet").is_fifo() and not (d.parent / "REPORT.md").exists()
