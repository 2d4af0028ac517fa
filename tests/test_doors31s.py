"""doors31s: what the suite shows about a run that is not the paper's default config.

A run with ``--set``, ``--trials``, ``--seed`` or of an edited copy of a study file, read in
its README.md, ``sim show`` (table and ``--markdown``), REPORT.md and claims.parquet: a
sentence true only of the study file's design is silent nonsense there. Classes: the run's
README and ``sim show`` did not say the run changed its study file's config, and REPORT.md said
it only for a directory named like a study file; the claim books' static text said an unprinted
input "is set so that" the paper's number matches and "the row shows the setting reproduces the
paper" (salsig, agnard), that the time model is calibrated to "the paper's 60 and 90 minutes"
(brown_design) and spoke of "a 12.500/12.700 vertical scale error" (salsig), whatever the run's
value of the key; two notes said the run's input was the paper's (agnard's parallax error,
brown's setting sigma). The results directory is a copy of a committed one whose tables'
provenance and run record say the overrides (no run), so the file stays fast."""

from __future__ import annotations

import json
import re
import shutil
import tomllib
from pathlib import Path

import numpy as np
import pyarrow.parquet as pq

from sim.cli import main

REPO = Path(__file__).resolve().parents[1]
CHANGED = {"trials": 40, "errors.comparator_sigma_um": 2.0}


def _overridden(tmp_path: Path, name: str) -> Path:
    """results/brown_table1 copied as ``name``, its tables and run record saying a run with
    :data:`CHANGED` (what ``sim run ... --trials 40 --set errors.comparator_sigma_um=2`` records)."""
    d = tmp_path / name
    shutil.copytree(REPO / "results" / "brown_table1", d)
    for p in d.glob("*.parquet"):
        t = pq.read_table(p)
        meta = dict(t.schema.metadata)
        prov = json.loads(meta[b"sim.provenance"])
        prov["config"].update(CHANGED)
        meta[b"sim.provenance"] = json.dumps(prov).encode()
        pq.write_table(t.replace_schema_metadata(meta), p)
    rec = json.loads((d / "run.json").read_text())
    rec["config"].update(CHANGED)
    (d / "run.json").write_text(json.dumps(rec))
    return d


def test_a_runs_readme_and_sim_show_name_what_it_changed_from_its_study_file(tmp_path, capsys):
    """`sim show` (both forms) of a run with --trials 40 --set errors.comparator_sigma_um=2 printed
    the verdicts as the study file's: it names the keys, the run's and the file's values."""
    d = _overridden(tmp_path, "mine")
    file_cfg = tomllib.loads((REPO / "studies" / "brown_table1.toml").read_text())
    for args in (["show", str(d)], ["show", str(d), "--markdown"]):
        assert main(args) == 0
        out = capsys.readouterr().out
        assert "Not the configuration of `studies/brown_table1.toml`" in out
        assert f"`trials` = 40 (the file: {file_cfg['trials']})" in out
        assert "`errors.comparator_sigma_um` = 2.0 (the file: 1.1)" in out
    # the committed results, the study file's config: no such line
    assert main(["show", str(REPO / "results" / "brown_table1"), "--markdown"]) == 0
    assert "Not the configuration" not in capsys.readouterr().out


def _book_texts() -> list[str]:
    out = []
    for p in sorted((REPO / "sim" / "studies").glob("*/claims.toml")):
        book = tomllib.loads(p.read_text(encoding="utf-8"))
        for row in book.get("claim", []) + book.get("not_reproduced", []):
            out += [row[k] for k in ("paper", "why", "printed") if isinstance(row.get(k), str)]
    return out


def test_claim_books_say_what_the_default_is_set_to_not_what_every_run_has():
    """The books' static text is shown for every run: it said the unprinted inputs are set
    to the paper's match (and the row shows it) and the time model is calibrated to the
    paper's 60 and 90 minutes on runs that set other values. It now says the default does,
    naming the key."""
    stale = re.compile(
        r"is not printed and is set|the row shows the setting|calibrated to the paper's"
        r"|a 12\.500/12\.700"
    )
    texts = _book_texts()
    assert not [t for t in texts if stale.search(t)]
    for key in ("b8.sigma_um", "comparator.sigma_um", "pugging.recentre_px", "time.single_min"):
        assert any(key in t and "default" in t for t in texts), key


def test_report_names_the_overrides_of_a_directory_not_named_like_a_study_file(tmp_path, capsys):
    """REPORT.md named a run's changed keys only when its directory was named like a study
    file (``--out .../brown_table1``); ``--out .../mine`` was read as the paper's design. It is
    now compared with its study's file, in REPORT.md and in the README sim report rewrites."""
    d = _overridden(tmp_path / "r", "mine")
    assert main(["report", "--results", str(d.parent)]) == 0
    capsys.readouterr()
    report = (d.parent / "REPORT.md").read_text(encoding="utf-8")
    assert "did not run the configuration of `studies/brown_table1.toml`: `errors." in report
    assert "Not the configuration of `studies/brown_table1.toml`" in (d / "README.md").read_text()


def test_agnard_height_budget_note_says_the_runs_parallax_error_is_not_the_papers():
    """The model_z_cm note said 'measure.parallax_px set from the paper's 22 cm' on a run
    with --set measure.parallax_px=1 (44 cm): it names the run's value and the default's."""
    import sim.studies.agnard.claims as C
    from sim.studies.agnard.schema import SCHEMA

    cfg = {k: f.default for k, f in SCHEMA.items()}
    note = lambda c: C.budget_rows(C.load_book(), c)["agnard.budget.model_z_cm"].note  # noqa: E731
    assert "(measure.parallax_px set from the paper's 22 cm)" in note(cfg)
    off = note({**cfg, "measure.parallax_px": 1.0})
    assert "this run's measure.parallax_px 1 px; the default 0.5 px is set from" in off


def test_brown_setting_sigma_note_says_whose_setting_sigma_the_run_simulated():
    """The table1_setting note said 'the simulated setting sigma is the paper's value' on a
    run with --set errors.setting_sigma_um=3: it names the run's value and the paper's."""
    import sim.studies.brown.claims as C

    t1 = {"setting_sigma_um": np.linspace(1.5, 1.9, 50)}
    cfg = {"errors.settings": 2, "errors.setting_sigma_um": 1.7}
    assert "is 1.7 um, the paper's" in C._setting(cfg, t1).note
    note = C._setting({**cfg, "errors.setting_sigma_um": 3.0}, t1).note
    assert "is 3 um, this run's, not the paper's 1.7 um" in note
