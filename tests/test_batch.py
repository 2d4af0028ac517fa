"""make reproduce's and make rerun's driver (sim.batch): studies side by side give the same
files as one after the other, the slowest start first, up-to-date studies are skipped, a
failed run does not stop the others, and bad input is one line with exit 2 (a file whose
config its run would refuse: before any run)."""

import subprocess
import sys
from pathlib import Path

import numpy as np
import pyarrow.parquet as pq

from benchmarks.cli import tiny_overrides
from sim import batch

ROOT = Path(__file__).resolve().parent.parent


def _tiny(tmp_path, study_file: str):
    """A copy of a study file and the ``--set`` arguments of its tiny configuration."""
    src = ROOT / "studies" / study_file
    f = tmp_path / study_file
    f.write_text(src.read_text())
    return f, list(tiny_overrides(src))


def test_order_puts_the_slowest_first():
    files = [
        Path(f"studies/{s}.toml")
        for s in ("agnard_block", "network_plate", "wolf_polynomial", "brown_design")
    ]
    assert [f.stem for f in batch.order(files)] == [
        "wolf_polynomial",
        "brown_design",
        "agnard_block",
        "network_plate",
    ]


def _same_tables(a_dir: Path, b_dir: Path):
    names = sorted(p.name for p in a_dir.glob("*.parquet"))
    assert names and names == sorted(p.name for p in b_dir.glob("*.parquet"))
    for n in names:
        a = pq.read_table(a_dir / n).to_pydict()
        b = pq.read_table(b_dir / n).to_pydict()
        assert list(a) == list(b), n
        for col in a:  # NaN equal to NaN
            kind = object if any(isinstance(v, str) for v in a[col]) else None
            np.testing.assert_array_equal(
                np.array(a[col], dtype=kind), np.array(b[col], dtype=kind), err_msg=f"{n} {col}"
            )


def test_side_by_side_equals_one_after_the_other(tmp_path, monkeypatch):
    """``python -m sim.batch`` as make runs it (two runs at a time) gives the files of
    ``python -m sim run`` processes one at a time."""
    fa, sets = _tiny(tmp_path, "network_testfield.toml")
    fb, _ = _tiny(tmp_path, "network_plate.toml")  # the same study kind: the same sets
    r = subprocess.run(
        [
            sys.executable,
            "-m",
            "sim.batch",
            "--jobs",
            "2",
            "--results",
            str(tmp_path / "two"),
            str(fa),
            str(fb),
            "--",
            "--no-figures",  # the tables are compared
            *sets,
        ],
        cwd=ROOT,
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert r.returncode == 0, r.stderr
    assert r.stdout.count("results in") == 2
    one = batch.run_all([fa, fb], tmp_path / "one", 1, ["--quiet", "--no-figures", *sets])
    assert {k: v[0] for k, v in one.items()} == {fa.stem: 0, fb.stem: 0}
    for stem in (fa.stem, fb.stem):
        _same_tables(tmp_path / "one" / stem, tmp_path / "two" / stem)


def test_stale_only_skips_the_current_studies(tmp_path, monkeypatch):
    fa, sa = _tiny(tmp_path, "network_testfield.toml")
    fb, _ = _tiny(tmp_path, "brown_table1.toml")
    current = {fb.stem: None, fa.stem: "no results yet"}  # why_stale's None: current
    monkeypatch.setattr(batch, "why_stale", lambda f, res, *_: current[Path(f).stem])
    logged = []
    done = batch.run_all(
        [fa, fb], tmp_path / "r", 2, [], stale_only=True, log=logged.append, extra={fa.stem: sa}
    )
    assert list(done) == [fa.stem] and done[fa.stem][0] == 0
    assert f"{fb.stem}: up to date" in logged
    assert f"{fa.stem}: out of date (no results yet): running it" in logged
    assert not (tmp_path / "r" / fb.stem).exists()


def test_a_failed_run_does_not_stop_the_others_and_sets_the_exit_code(tmp_path, capfd):
    fa, sa = _tiny(tmp_path, "network_testfield.toml")
    bad = tmp_path / "broken.toml"
    bad.write_text("study = 'brown_table1'\nnot_a_key = 1\n")
    done = batch.run_all([bad, fa], tmp_path / "r", 2, ["--no-figures"], extra={fa.stem: sa})
    assert done["broken"][0] == 2 and done[fa.stem][0] == 0
    assert (tmp_path / "r" / fa.stem / "run.json").is_file()
    assert "not_a_key" in capfd.readouterr().err
    # the driver refuses a file whose run would refuse its config before any run starts
    # (tests/test_doors28b.py): the others are not run first
    assert (
        batch.main(["--results", str(tmp_path / "m"), str(bad), str(fa), "--", *sa, "--no-figures"])
        == 2
    )
    assert not (tmp_path / "m").exists()


def test_bad_input_is_one_line_and_exit_2(tmp_path, capsys):
    assert batch.main([str(tmp_path / "missing.toml")]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "missing.toml" in err[0]
    f, _ = _tiny(tmp_path, "network_testfield.toml")
    assert batch.main(["--jobs", "0", str(f)]) == 2
    assert "--jobs" in capsys.readouterr().err
