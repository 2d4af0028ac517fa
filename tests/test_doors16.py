"""The classes of the confirmation sweep doors16 (issue 26: every key of every study file,
the documented promises, GNU Gama's vocabulary), one case each; each failed on the code
before its fix.

* a network whose observations are fewer than its unknowns and leave a rank defect
  (``network.generate = []`` in ``studies/network_testfield.toml``) ended in NumPy's
  "zero-size array to reduction operation minimum" (the API's ``ValueError``, the command
  line's "sim: error: ValueError: ..." naming no key): the reduced SVD of a wide matrix
  holds no null space (:func:`sim.studies.network.schema._parameters`);
* Wolf's ``table1.file``/``table3.file`` naming a file too long for the file system raised
  pathlib's ``OSError`` from ``sim.load`` (the command line's line named no key), and one
  holding a line break gave a two-line ``ConfigError`` (:mod:`sim.studies.wolf.tables`).
"""

from __future__ import annotations

from pathlib import Path

import pytest

import sim
from sim.cli import main

ROOT = Path(__file__).resolve().parent.parent


def test_a_network_with_fewer_observations_than_unknowns_names_the_datum(capsys):
    study = str(ROOT / "studies/network_testfield.toml")
    with pytest.raises(sim.ConfigError) as e:
        sim.load(study, **{"network.generate": []})
    assert e.value.key == "datum.kind" and "rank defect of 23" in str(e.value)
    assert main(["check", study, "--set", "network.generate=[]"]) == 2
    err = capsys.readouterr().err
    assert err.startswith("sim: error: datum.kind: ") and err.count("\n") == 1, err


@pytest.mark.parametrize(
    "value,words", [("a" * 5000, "File name too long"), ("a\nb", "control character")]
)
def test_a_table_file_name_the_file_system_refuses_is_one_line_naming_the_key(value, words):
    with pytest.raises(sim.ConfigError) as e:
        sim.load(str(ROOT / "studies/wolf_polynomial.toml"), **{"table3.file": value})
    assert e.value.key == "table3.file" and words in str(e.value), str(e.value)
    assert "\n" not in str(e.value)
