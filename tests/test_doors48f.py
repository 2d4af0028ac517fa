"""Issue 26, helper F48: what the fresh fuzz seeds and the sweep-level fuzzer
(tests/fuzz_sweep.py) found.

* An EMPTY TABLE among a sweep's keys (``"datum.kind" = {}`` beside a swept key, or an empty
  ``[sweep.datum]``) was dropped without a word: the sweep ran its other keys' cells as if the
  user had not asked to sweep that key (alone, it was "sweep: is empty", naming no key).
"""

from __future__ import annotations

import pytest
from conftest import TRIANGLE_NETWORK

from sim.cli import main


@pytest.mark.parametrize(
    "table, named",
    [
        ('"reliability.power" = [0.8, 0.9]\n"datum.kind" = {}\n', "sweep.datum.kind"),
        ('"reliability.power" = [0.8, 0.9]\n[sweep.datum]\n', "sweep.datum"),
    ],
)
def test_an_empty_table_in_a_sweep_is_refused_naming_it(tmp_path, capsys, table, named):
    """EMPTY sweep levels: an empty table where a key's levels go was dropped, exit 0 and
    a sweep of the other key only; now one line naming the key, exit 2."""
    f = tmp_path / "s.toml"
    f.write_text(TRIANGLE_NETWORK + "[sweep]\n" + table)
    assert main(["check", str(f)]) == 2
    err = capsys.readouterr().err.strip()
    assert err.startswith(f"sim: error: {named}: is an empty table") and "\n" not in err
