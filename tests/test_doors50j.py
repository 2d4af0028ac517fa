"""The classes of the sweep doors50j (brief J50: the items session 49 left), one case each;
each failed on the code before its fix.

* Two names for one thing in hashed code: the words of a file that is no regular file were
  kept twice (``sim.mc.export_edits`` and ``sim.mc.file_kind``), and ``item_hint`` was used
  by ``sim.mc.sweep`` but missing from ``sim.mc.unknown_key.__all__``.
* A file of the user's named ``network.xml`` in the ``--out`` of a network run (one the
  earlier run there did not write): refused only when the run published, after every chunk
  was computed; now before any work, naming it.
* ``python -m sim.batch --stale-only`` over results whose network export was edited by hand:
  "up to date", exit 0 (a run of them, by ``--overwrite``, is refused while the edit is
  there); now the batch names the file before any run (exit 2), and ``why_stale`` says it.
* A GNU Gama file edited through the Python API keeping its size and modification time: its
  counts for the work estimate were cached by those two, and the old counts kept; now by
  its content.
* A sweep range without ``stop`` (``{start = 20, step = 20}``): read as a table of keys,
  "sweep.trials.start: unknown key"; now the range is named with what it lacks.
* ``make verify`` over a results directory copied under another name that no study file
  has: "run mine's own study file to replace them", a file that does not exist; now it says
  there is none, and to move the directory away.
* A ``run.json`` of this code's run forged by hand, its ``table_sha256`` and ``table_shape``
  made null, or both removed with ``files``: the claims read unchecked, an edited value
  printed as the run's; now refused in one line (an older version's record stays readable).
* A results README.md edited by hand (notes added under the suite's text): replaced by the
  same run again, or by ``sim report``, without a word. Its sha256 is recorded now: such a
  README is the user's, the run is refused before any work naming it (as an edited
  export), and ``sim report`` keeps it and says so.
"""

from __future__ import annotations

import os
import stat
from pathlib import Path

import pytest
from conftest import TRIANGLE_NETWORK

from sim.cli import main
from sim.mc.outputs import stage_dir


def _in(d: Path, argv: list[str], capsys) -> tuple[int, str]:
    """``sim`` with ``argv`` run in the directory ``d``: its exit code and standard error."""
    here = os.getcwd()
    os.chdir(d)
    try:
        capsys.readouterr()
        rc = main(argv)
    finally:
        os.chdir(here)
    return rc, capsys.readouterr().err


def test_kinds_of_files_said_once() -> None:
    """Hashed duplicates: the export's kinds of file were a copy of file_kind's (one could be
    worded anew without the other), and ``item_hint`` was not exported by its module."""
    from sim.mc import export_edits, unknown_key
    from sim.mc.file_kind import mode_kind

    assert "item_hint" in unknown_key.__all__
    assert not hasattr(export_edits, "_KINDS")
    assert mode_kind(stat.S_IFLNK) == "a symbolic link"
    assert mode_kind(stat.S_IFIFO) == "a FIFO (named pipe)"
    assert mode_kind(stat.S_IFDIR) == "a directory"


def test_own_network_xml_in_out_refused_before_any_work(tmp_path: Path, capsys) -> None:
    """A network run whose network has no gama-local form (a bias: not exported), then the
    user's own ``network.xml`` put in its results, then a run that exports, ``--overwrite``:
    before, every chunk was computed and the publish refused ("was not written by sim but
    the new run writes a file of that name"); now exit 2 before any work (no staging
    directory), one line naming the file, which is kept."""
    (tmp_path / "tri.toml").write_text(TRIANGLE_NETWORK, encoding="utf-8")
    biased = TRIANGLE_NETWORK.replace("sigma_mm = 0.01 }", "sigma_mm = 0.01, bias_mm = 0.001 }")
    (tmp_path / "biased.toml").write_text(biased, encoding="utf-8")
    opts = ["--out", "r1", "--no-figures", "--quiet"]
    assert _in(tmp_path, ["run", "biased.toml", *opts], capsys)[0] == 0
    out = tmp_path / "r1"
    assert not (out / "network.xml").exists()  # not exported
    (out / "network.xml").write_text("<mine/>\n", encoding="utf-8")
    rc, err = _in(tmp_path, ["run", "tri.toml", *opts, "--overwrite"], capsys)
    assert rc == 2, err
    assert len(err.strip().splitlines()) == 1 and "Traceback" not in err
    assert "r1/network.xml was not written by sim" in err and "export" in err
    assert not stage_dir(out).exists()  # refused before the staging directory: no work
    assert (out / "network.xml").read_text(encoding="utf-8") == "<mine/>\n"


def test_stale_only_names_an_edited_export(tmp_path: Path, capsys) -> None:
    """A batch's results of the triangle network, their ``network.xml`` edited by hand, then
    ``--stale-only`` again: before, "tri: up to date", exit 0; now exit 2 before any run, one
    line naming the edited file, and ``why_stale`` calls the results not current, naming it."""
    from sim.batch import main as batch
    from sim.batch_checks import why_stale

    (tmp_path / "tri.toml").write_text(TRIANGLE_NETWORK, encoding="utf-8")
    argv = ["run", "tri.toml", "--out", "res/tri", "--no-figures", "--quiet"]
    assert _in(tmp_path, argv, capsys)[0] == 0
    xml = tmp_path / "res" / "tri" / "network.xml"
    xml.write_bytes(xml.read_bytes() + b"<!-- mine -->\n")
    args = ["--stale-only", "--jobs", "1", "--results", "res", "tri.toml", "--", "--no-figures"]
    here = os.getcwd()
    os.chdir(tmp_path)
    try:
        capsys.readouterr()
        rc = batch(args)
        out, err = capsys.readouterr()
        why = why_stale("tri.toml", "res/tri", ["--no-figures"])
    finally:
        os.chdir(here)
    assert rc == 2, out + err
    assert "up to date" not in out
    assert len(err.strip().splitlines()) == 1 and "Traceback" not in err, err
    assert "network.xml was changed after the run that wrote it" in err
    assert why is not None and why.startswith("network.xml was changed after the run")
    assert xml.read_bytes().endswith(b"<!-- mine -->\n")


def test_gama_counts_follow_an_edit_that_keeps_size_and_mtime(tmp_path: Path) -> None:
    """An observation of a gama-local file turned into a comment of its length, the file's
    modification time put back: before, ``gama_counts`` gave the cached counts of the file
    as it was (the observation still counted); now the counts of what the file holds."""
    from sim.mc.gama_count import gama_counts

    src = Path(__file__).parent / "data" / "gama" / "directions_free.xml"
    f = tmp_path / "net.xml"
    text = src.read_text(encoding="utf-8")
    f.write_text(text, encoding="utf-8")
    before = gama_counts(f)
    st = os.stat(f)
    obs = '<direction to="P2" val="4.76572592091002" stdev="6.172839506172839" />'
    assert obs in text
    f.write_text(text.replace(obs, "<!--" + " " * (len(obs) - 7) + "-->", 1), encoding="utf-8")
    os.utime(f, ns=(st.st_atime_ns, st.st_mtime_ns))
    assert os.stat(f).st_size == st.st_size and os.stat(f).st_mtime_ns == st.st_mtime_ns
    after = gama_counts(f)
    assert before is not None and after is not None
    assert after.rows["direction"] == before.rows["direction"] - 1


def test_sweep_range_without_stop_names_it(tmp_path: Path) -> None:
    """``[sweep] trials = {start = 20, step = 20}``: before, flattened into the keys
    ``trials.start`` and ``trials.step`` ("sweep.trials.start: unknown key"); now
    "sweep.trials: a range needs start and stop (it has no stop)"."""
    from sim.mc.config import ConfigError
    from sim.mc.sweep import read_sweep
    from sim.studies import get_study

    f = tmp_path / "sw.toml"
    f.write_text(TRIANGLE_NETWORK + "[sweep]\ntrials = {start = 20, step = 20}\n")
    with pytest.raises(ConfigError) as e:
        read_sweep(f, get_study("network").schema)
    assert str(e.value) == "sweep.trials: a range needs start and stop (it has no stop)"


def test_verify_copy_without_its_study_file(tmp_path: Path, capsys) -> None:
    """A run's results copied to ``R/mine`` beside ``R/tri``, ``studies/`` holding only
    ``tri.toml``: verify said "run mine's own study file to replace them"; now "there is no
    studies/mine.toml to replace them: move R/mine away" (nothing re-run)."""
    import shutil

    from sim.report.verify.rerun import verify

    (tmp_path / "studies").mkdir()
    (tmp_path / "studies" / "tri.toml").write_text(TRIANGLE_NETWORK, encoding="utf-8")
    argv = ["run", "studies/tri.toml", "--out", "R/tri", "--no-figures", "--quiet"]
    assert _in(tmp_path, argv, capsys)[0] == 0
    shutil.copytree(tmp_path / "R" / "tri", tmp_path / "R" / "mine")
    studies = tmp_path / "studies"
    (comp,) = verify(tmp_path / "R", tmp_path / "S", only=["mine"], studies=studies)
    (why,) = comp.failures
    assert "run mine's own study file" not in why
    assert f"there is no {studies / 'mine'}.toml to replace them" in why
    assert not (tmp_path / "S" / "mine").exists()


def test_forged_record_of_this_code_is_refused(tmp_path: Path, capsys, monkeypatch) -> None:
    """A claim's value edited and the record's integrity fields nulled (``table_sha256``,
    ``table_shape``) or removed with ``files``: before, ``sim show`` printed the edited value,
    exit 0 (only both removed with ``files`` kept was refused); now exit 2, one line naming
    what the record lacks. The same record read by another version of the code (an older
    record of a version that wrote no such fields) is read as before."""
    import json

    from hand_edits import edit_first_value

    (tmp_path / "tri.toml").write_text(TRIANGLE_NETWORK, encoding="utf-8")
    assert (
        _in(tmp_path, ["run", "tri.toml", "--out", "r", "--no-figures", "--quiet"], capsys)[0] == 0
    )
    d = tmp_path / "r"
    rec = json.loads((d / "run.json").read_text(encoding="utf-8"))
    claims = (d / "claims.parquet").read_bytes()
    edit_first_value(d)
    nulled = {**rec, "table_sha256": None, "table_shape": None}
    removed = {k: v for k, v in rec.items() if k not in ("table_sha256", "table_shape", "files")}
    for forged, words in ((nulled, "neither table_sha256 nor table_shape"), (removed, "nor files")):
        (d / "run.json").write_text(json.dumps(forged), encoding="utf-8")
        rc, err = _in(tmp_path, ["show", "r"], capsys)
        assert rc == 2, err
        assert len(err.strip().splitlines()) == 1 and "Traceback" not in err, err
        assert words in err and "removed by hand?" in err
    (d / "claims.parquet").write_bytes(claims)  # the record, read by a later version:
    monkeypatch.setattr("sim.mc.table_shape.code_hash", lambda study: "0" * 64)
    rc, err = _in(tmp_path, ["show", "r"], capsys)
    assert rc == 0, err


def test_edited_readme_is_kept_and_named(tmp_path: Path, capsys) -> None:
    """A line of the user's added to a run's README.md, then the same command again with
    ``--overwrite``, then ``sim report``: before, exit 0 both, the line gone; now the run is
    refused before any work (one line naming README.md), and the report keeps the README
    and says so in a note."""
    (tmp_path / "tri.toml").write_text(TRIANGLE_NETWORK, encoding="utf-8")
    argv = ["run", "tri.toml", "--out", "res/tri", "--no-figures", "--quiet", "--overwrite"]
    assert _in(tmp_path, argv, capsys)[0] == 0
    readme = tmp_path / "res" / "tri" / "README.md"
    edited = readme.read_text(encoding="utf-8") + "\nMy notes on this run.\n"
    readme.write_text(edited, encoding="utf-8")
    rc, err = _in(tmp_path, argv, capsys)
    assert rc == 2, err
    assert len(err.strip().splitlines()) == 1 and "Traceback" not in err, err
    assert "README.md was changed after the run that wrote it" in err
    assert not stage_dir(readme.parent).exists()
    rc, err = _in(tmp_path, ["report", "--results", "res"], capsys)
    assert rc == 0, err
    assert f"{Path('res') / 'tri' / 'README.md'} was changed after the run" in err
    assert readme.read_text(encoding="utf-8") == edited
