"""The classes of the sweep doors28d (brief D28d: files from the suite's own past, kept by a
user who upgrades), one case each; each failed on the code before its fix.

* a study file kept from before 2026-11-26 (every shipped file's version of that week) holds
  the sweep of the unprinted inputs that ``[region]`` replaced: ``[consistency]`` (Brown's,
  the grid plates', Salsig's), ``[unprinted]`` lists (brown_design, Wolf), agnard's
  ``sweep.*`` keys, Brown's ``dilution.offsets_mm``. It was refused with a guess that is not
  the replacement and that the file already sets (``consistency.grid: unknown key (did you
  mean plate.grid?)``, ``unprinted.offsets_mm`` -> ``design.offsets_mm``) or, for agnard's
  ``"sweep.trials"``, as "a key of" seven other studies. The line now says the key is an older
  version's, what it was, and what replaced it, with how many of the file's keys are such
  (:mod:`sim.studies.retired`, applied by :func:`sim.studies.ported.foreign_key`).

The other 36 distinct versions of the shipped study files (``git log -- studies/``) run, or
are refused by a key whose bound or rule changed, one line naming it (``region.plate_points:
must be >= 256``, a ``pugging.gross_px`` no longer read at ``gross_rate = 0``).

* ``sim report --results`` over the results tree of an older commit (``git archive a9e864d9
  results``: ``sim show`` reads each directory, with its note) said of agnard_block's claims
  table that it "is not as sim wrote it (... KeyError ...); run its study again" and then
  named another directory (network_testfield, the first listed) as made by another version:
  a hand edit blamed for what an older version wrote, and the wrong study named. The line now
  says the table's own directory was made by another version of the suite's code
  (:func:`sim.cli_tables.not_as_written`). Results of older commits were otherwise read
  right: ``sim show`` with its note, ``sim report`` of the day before's tree.
"""

from __future__ import annotations

import hashlib
import json
import shutil
from pathlib import Path

import pyarrow.compute as pc
import pyarrow.parquet as pq
import pytest

import sim
from sim.cli import main
from sim.mc.config import ConfigError, flatten, read_toml
from sim.studies import get_study
from sim.studies.retired import RETIRED
from tests.oneline import SIM_ERROR, one_line

ROOT = Path(__file__).resolve().parents[1]
STUDIES = ROOT / "studies"


def _old_file(tmp_path: Path, name: str, extra: str, top: bool = False) -> Path:
    text = (STUDIES / f"{name}.toml").read_text()
    if top:  # top-level keys go before the first table
        head, sep, rest = text.partition("\n[")
        text = head + extra + sep + rest
    else:
        text += extra
    p = tmp_path / f"{name}.toml"
    p.write_text(text)
    return p


CASES = [
    (
        "gridplate_two_plates",
        "\n[consistency]\ngrid = [3, 4]\nspacing_mm = [10.0]\n",
        False,
        "consistency.grid",
        "2 such keys",
    ),
    (
        "agnard_block_104",
        '\n"sweep.trials" = 4\n"sweep.five_inset" = [0.0, 0.17]\n',
        True,
        "sweep.trials",
        "2 such keys",
    ),
    (
        "wolf_polynomial",
        "pointing_sigmas_um = [2.0, 3.0]\n",
        False,
        "unprinted.pointing_sigmas_um",
        "[region]",
    ),
]


@pytest.mark.parametrize("name, extra, top, key, needle", CASES)
def test_a_key_of_an_older_version_is_named_so_with_what_replaced_it(
    tmp_path, capsys, name, extra, top, key, needle
):
    if name == "wolf_polynomial":  # the [unprinted] table is still there, with fewer keys
        text = (
            (STUDIES / f"{name}.toml")
            .read_text()
            .replace("[unprinted]", f"[unprinted]\n{extra}", 1)
        )
        path = tmp_path / f"{name}.toml"
        path.write_text(text)
    else:
        path = _old_file(tmp_path, name, extra, top)
    line = one_line(
        capsys,
        main(["check", str(path)]),
        f"{key}: a key of an older version",
        "gone since 2026-11-26",
        needle,
        prefix=SIM_ERROR,
    )
    assert "did you mean" not in line and "a key of brown" not in line, line
    with pytest.raises(ConfigError, match="older version of the suite"):  # the Python API too
        sim.load(path)


def test_the_table_of_retired_keys_names_no_key_a_study_reads_now():
    """A key read again (or a study renamed) must leave the table: the note would then lie."""
    for study, keys in RETIRED.items():
        schema = get_study(study).schema
        assert keys and not [k for k in keys if k in schema], study
    for f in STUDIES.glob("*.toml"):  # no shipped file holds one
        doc = read_toml(f)
        assert not set(flatten(doc)) & set(RETIRED.get(doc["study"], {})), f


def _older_tree(tmp_path: Path) -> Path:
    """Committed results of two studies, agnard_block's claims table without the rows of a
    claim this version's book scores (as a version before that claim wrote it)."""
    root = tmp_path / "results"
    for name in ("agnard_block", "brown_table1"):
        shutil.copytree(ROOT / "results" / name, root / name)
    f = root / "agnard_block" / "claims.parquet"
    t = pq.read_table(f)  # (its metadata kept: the provenance of the run)
    pq.write_table(t.filter(pc.invert(pc.starts_with(t["claim"], "agnard.control_21"))), f)
    record = json.loads((f.parent / "run.json").read_text("utf-8"))
    record.pop("table_shape", None)  # a version before the record of its tables' shapes
    sha = hashlib.sha256(f.read_bytes()).hexdigest()  # and recorded the table it wrote (a
    record["table_sha256"]["claims.parquet"] = sha  # sha256 of another is an edit: doors46h)
    (f.parent / "run.json").write_text(json.dumps(record), "utf-8")
    return root


def test_report_over_an_older_versions_results_says_so_of_the_tables_own_study(
    tmp_path, capsys, monkeypatch
):
    root = _older_tree(tmp_path)
    line = one_line(capsys, main(["report", "--results", str(root)]), "agnard_block/claims")
    assert "not as sim wrote it" in line and "another version" not in line  # a hand edit
    monkeypatch.setattr("sim.stale.study_code_hash", lambda study: "f" * 16)  # upgraded
    line = one_line(
        capsys,
        main(["report", "--results", str(root)]),
        "agnard_block/claims.parquet under",
        "was made by another version of the suite's code",
        "--overwrite makes them current (not make reproduce)",  # not the project's results/
        prefix=SIM_ERROR,
    )
    assert "not as sim wrote it" not in line and "brown_table1" not in line, line
