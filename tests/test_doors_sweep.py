"""The failure classes of the second sweep of bad inputs over every door (issue 26), one
parametrised case per class: each is refused with exit 2 and one line naming the key or the
argument, and nothing is written.

* a ``--set`` value that carries a line break (a second key smuggled in with the first);
* a value written as an empty table ``{}`` (it vanished when the file was flattened, and the
  default was used); an empty section stays allowed;
* ``sim report --results DIR`` on a directory of the user's without study results (it wrote
  ``REPORT.md`` into it);
* a datum constraint whose coefficients are all zero (it was dropped, and the rank defect
  blamed);
* ``make verify --no-rerun`` with a scratch directory that holds no re-run (it recorded a
  failed comparison over the committed record), and a ``--set`` of ``make verify`` that the
  re-run refuses (a failed comparison, exit 1);
* ``sim show`` on a directory whose ``claims.parquet`` is someone else's table (a KeyError);
* ``python -m sim.batch``: argparse's two-line usage errors, ``--timings`` naming a directory
  (a traceback after every run) or a file of the user's (overwritten).

The third and fourth sweeps follow, each marked by a section comment (one case per class).
"""

import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pyarrow as pa
import pyarrow.parquet as pq
import pytest
from oneline import SIM_ERROR, VERIFY_ERROR, one_line

import sim
from sim import ConfigError
from sim.batch import is_current
from sim.batch import main as batch_main
from sim.cli import main
from sim.mc.storage import write_record, write_table
from sim.report.verify import main as verify_main

ROOT = Path(__file__).resolve().parent.parent
BROWN = ROOT / "studies" / "brown_table1.toml"

NETWORK = """study = "network"
trials = 40
chunk = 2
[network]
name = "n"
points = [
  { name = "A", x_mm = 0.0, y_mm = 0.0 },
  { name = "B", x_mm = 1000.0, y_mm = 0.0 },
  { name = "C", x_mm = 400.0, y_mm = 700.0 },
]
generate = [ { kind = "distance", from = "*", to = "*", sigma_mm = 0.01 },
             { kind = "direction", from = "*", to = "*", sigma_arcsec = 1.0 } ]
[datum]
kind = "constraints"
constraints = [ { "A.x" = COEF }, { "A.y" = 1.0 }, { "B.y" = 1.0 } ]
"""


@pytest.mark.parametrize(
    "value, key",
    [("40\nchunk=2", "trials"), ("40\rseed=3", "trials"), ("[3,\n5]", "dilution.grids")],
)
def test_a_set_value_is_one_line(capsys, value, key):
    one_line(
        capsys,
        main(["check", str(BROWN), "--set", f"{key}={value}"]),
        key,
        "one line",
        prefix=SIM_ERROR,
    )


@pytest.mark.parametrize(
    "text, key", [("[plate]\ngrid = {}\n", "plate.grid"), ("trials = {}\n", "trials")]
)
def test_an_empty_table_is_not_a_value(tmp_path, capsys, text, key):
    f = tmp_path / "s.toml"
    f.write_text('study = "brown_table1"\n' + text)
    one_line(capsys, main(["check", str(f)]), key, "{}", prefix=SIM_ERROR)
    f.write_text('study = "brown_table1"\n[plate]\n[errors]\nsettings = 2\n')  # empty section
    assert main(["check", str(f)]) == 0
    capsys.readouterr()
    one_line(
        capsys,
        main(["check", str(BROWN), "--set", "plate={}"]),
        "plate",
        "unknown key",
        prefix=SIM_ERROR,
    )


def test_report_refuses_a_directory_without_study_results(tmp_path, capsys):
    (tmp_path / "mine").mkdir()
    (tmp_path / "mine" / "notes.txt").write_text("mine\n")
    one_line(
        capsys,
        main(["report", "--results", str(tmp_path / "mine")]),
        "no study results",
        prefix=SIM_ERROR,
    )
    assert [p.name for p in (tmp_path / "mine").iterdir()] == ["notes.txt"]


@pytest.mark.parametrize("coef", ["0.0", "0"])
def test_an_all_zero_datum_constraint_is_named(tmp_path, capsys, coef):
    f = tmp_path / "n.toml"
    f.write_text(NETWORK.replace("COEF", coef))
    one_line(capsys, main(["check", str(f)]), "datum.constraints[0]", "zero", prefix=SIM_ERROR)
    f.write_text(NETWORK.replace("COEF", "1.0"))
    assert main(["check", str(f)]) == 0


def _results(tmp_path: Path, name: str = "brown_table1") -> Path:
    """A results directory whose one study holds a claims table (nothing else is read)."""
    d = tmp_path / "res" / name
    d.mkdir(parents=True)
    _claims_with_record(d, name)
    return d.parent


def _claims_with_record(d: Path, study: str) -> None:
    """A one-claim table of ``study`` in ``d`` and the run record every run writes beside it
    (a directory without one is refused by every reader: its run.json deleted)."""
    run = {"config": {"study": study}, "code_hash": "0" * 16}
    write_table(
        d / "claims.parquet", {"claim": ["x"], "verdict": ["holds"]}, {"study": study, **run}
    )
    write_record(d, run)


def test_verify_no_rerun_without_the_reruns_records_nothing(tmp_path, capsys):
    res = _results(tmp_path)
    (tmp_path / "scratch").mkdir()
    argv = ["--results", str(res), "--scratch", str(tmp_path / "scratch"), "--no-rerun"]
    one_line(capsys, verify_main(argv), "no re-run of brown_table1", prefix=VERIFY_ERROR)
    assert sorted(p.name for p in res.iterdir()) == ["brown_table1"]  # no record written


def test_verify_names_a_rerun_option_the_study_refuses(tmp_path, capsys, monkeypatch):
    res = _results(tmp_path)
    monkeypatch.chdir(ROOT)  # the re-run reads studies/<study>.toml
    argv = ["--results", str(res), "--scratch", str(tmp_path / "s"), "--trials", "400"]
    assert verify_main([*argv, "--set", "nosuch.key=1"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert "nosuch.key" in err[-1] and "refused" in err[-1], err
    assert sorted(p.name for p in res.iterdir()) == ["brown_table1"]


def test_show_names_a_claims_table_that_is_not_ours(tmp_path, capsys):
    d = tmp_path / "r"
    d.mkdir()
    pq.write_table(pa.table({"a": [1, 2]}), d / "claims.parquet")
    one_line(capsys, main(["show", str(d)]), "not a claims table", prefix=SIM_ERROR)
    (d / "claims.parquet").write_bytes(b"PAR1 truncated")
    one_line(capsys, main(["show", str(d)]), "cannot be read", prefix=SIM_ERROR)


@pytest.mark.parametrize(
    "argv, words",
    [
        ([], "required: files"),
        (["--jobs", "x", str(BROWN)], "--jobs"),
        (["--timings", "DIR", str(BROWN)], "not a regular file"),
        (["--timings", "MINE", str(BROWN)], "not a timings file"),
    ],
)
def test_batch_refuses_in_one_line_before_running(tmp_path, capsys, argv, words):
    (tmp_path / "mine.txt").write_text("mine\n")
    argv = [
        str(tmp_path) if a == "DIR" else str(tmp_path / "mine.txt") if a == "MINE" else a
        for a in argv
    ]
    one_line(
        capsys, batch_main([*argv, "--results", str(tmp_path / "r")]), words, prefix="sim.batch: "
    )
    assert not (tmp_path / "r").exists() and (tmp_path / "mine.txt").read_text() == "mine\n"


# --- the third sweep (issue 26): one case per class -----------------------------------------

THIRD = NETWORK.replace("COEF", "1.0")
C_PT = '{ name = "C", x_mm = 400.0, y_mm = 700.0 }'


@pytest.mark.parametrize(
    "old, new, key",
    [
        ('name = "n"', 'name = ""', "network.name"),
        ('name = "n"', 'name = "a\\nb"', "network.name"),
        ('name = "n"', 'name = "' + "x" * 300 + '"', "network.name"),
        (C_PT, C_PT.replace('"C"', '"C*"'), "network.points[2].name"),
        (C_PT, C_PT.replace('"C"', '" C"'), "network.points[2].name"),
        (C_PT, C_PT.replace('"C"', '"C\\u0000"'), "network.points[2].name"),
    ],
)
def test_names_are_one_printable_line_without_patterns(tmp_path, capsys, old, new, key):
    f = tmp_path / "n.toml"
    f.write_text(THIRD.replace(old, new))
    one_line(capsys, main(["check", str(f)]), key, prefix=SIM_ERROR)


def test_a_deeply_nested_or_huge_study_file_is_one_line(tmp_path, capsys):
    deep = "[" * 50_000 + "]" * 50_000
    one_line(
        capsys,
        main(["check", str(BROWN), "--set", f"dilution.grids={deep}"]),
        "nested",
        prefix=SIM_ERROR,
    )
    f = tmp_path / "s.toml"
    f.write_text(f"trials = {deep}\n")
    one_line(capsys, main(["check", str(f)]), "s.toml", "nested", prefix=SIM_ERROR)
    with f.open("wb") as fh:  # sparse: 17 MiB of nothing, never read
        fh.truncate(17 * 1024**2)
    one_line(capsys, main(["check", str(f)]), "s.toml", "MiB", prefix=SIM_ERROR)


def test_show_and_report_name_a_table_replaced_by_hand(tmp_path, capsys):
    d = tmp_path / "res" / "network"
    assert main(["run", str(_net(tmp_path)), "--out", str(d), "--quiet"]) == 0
    capsys.readouterr()
    before = (d / "README.md").read_bytes()
    (d / "summary.parquet").write_bytes((d / "datums.parquet").read_bytes())
    one_line(capsys, main(["show", str(d), "--markdown"]), "not as sim wrote it", prefix=SIM_ERROR)
    one_line(
        capsys,
        main(["report", "--results", str(d.parent)]),
        "not as sim wrote it",
        prefix=SIM_ERROR,
    )
    assert (d / "README.md").read_bytes() == before and not (d.parent / "REPORT.md").exists()


def _net(tmp_path: Path, text: str = THIRD) -> Path:
    f = tmp_path / "n.toml"
    f.write_text(text)
    return f


def test_an_output_path_with_a_control_character_is_refused(tmp_path, capsys):
    out = str(tmp_path / "a\nb")
    one_line(
        capsys,
        main(["run", str(BROWN), "--out", out]),
        "--out",
        "control character",
        prefix=SIM_ERROR,
    )
    with pytest.raises(ConfigError, match="out"):
        sim.load(BROWN, trials=40, chunk=2).run(out=out)
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize(
    "extra, key",
    [('points = ["A"]\n', "datum.points"), ('[compare]\nfix = ["C"]\n', "compare.fix")],
)
def test_a_key_without_effect_or_object_is_refused(tmp_path, capsys, extra, key):
    text = THIRD.split("[datum]")[0].replace('"A", x_mm', '"A", role = "fixed", x_mm')
    text = text.replace('"B", x_mm', '"B", role = "fixed", x_mm') + '[datum]\nkind = "fixed"\n'
    assert main(["check", str(_net(tmp_path, text))]) == 0
    capsys.readouterr()
    one_line(capsys, main(["check", str(_net(tmp_path, text + extra))]), key, prefix=SIM_ERROR)


GAMA = ROOT / "tests" / "data" / "gama" / "one_fixed.xml"


@pytest.mark.parametrize(
    "old, new, words",
    [
        ("gnu.org/software/gama/gama-local", "example.org/x", ["namespace"]),
        ('stdev="2.0"', 'stdev="1e-300"', ["<distance>", "'stdev'"]),
        ('x="250.0"', 'x="1e200"', ["<point>", "'x'"]),
        ('id="B"', 'id="B*"', ["<point>", "'id'"]),
    ],
)
def test_a_gama_value_out_of_range_names_the_file_and_element(tmp_path, capsys, old, new, words):
    xml = tmp_path / "n.xml"
    xml.write_text(GAMA.read_text().replace(old, new, 1))
    f = _net(
        tmp_path, f'study = "network"\n[network]\ngama_xml = "{xml}"\n[datum]\nkind = "inner"\n'
    )
    one_line(capsys, main(["check", str(f)]), "n.xml", *words, prefix=SIM_ERROR)


@pytest.mark.parametrize(
    "field, key",
    [
        ("settings = 1000000000000000", "settings"),
        ("bias_mm = 1e300", "bias_mm"),
        ('kind = "direction", set = ""', "set"),
    ],
)
def test_weights_stay_in_range_after_settings_and_bias(tmp_path, capsys, field, key):
    obs = f'observations = [ {{ kind = "distance", from = "C", to = "B", sigma_mm = 0.01, {field} }} ]'
    if "direction" in field:
        obs = obs.replace('kind = "distance", ', "").replace("sigma_mm", "sigma_arcsec")
    f = _net(tmp_path, THIRD.replace("[datum]", obs + "\n[datum]"))
    one_line(capsys, main(["check", str(f)]), f"network.observations[0].{key}", prefix=SIM_ERROR)


def test_a_failing_run_in_a_batch_names_its_study_file(tmp_path):
    bad = tmp_path / "mine_bad.toml"
    bad.write_text("study = 5\n")
    r = subprocess.run(
        [sys.executable, "-m", "sim.batch", str(bad), "--results", str(tmp_path / "r")],
        capture_output=True,
        text=True,
        cwd=ROOT,
    )
    assert r.returncode == 2 and r.stderr.count("\n") == 1, r.stderr
    # refused by the driver before any run (tests/test_doors28b.py), the file named first
    assert r.stderr.startswith(f"sim.batch: {bad}: study"), r.stderr


def test_api_takes_numpy_scalars_and_names_a_damaged_table(tmp_path):
    st = sim.load(_net(tmp_path), trials=np.int64(40), chunk=np.int32(2))
    assert st.config["trials"] == 40 and type(st.config["trials"]) is int
    res = st.run(out=tmp_path / "o")
    assert res.table("trials").num_rows == 40
    chunk = tmp_path / "o" / "trials" / "part-0" / "chunk-000003.parquet"
    chunk.write_bytes(chunk.read_bytes()[:40])
    with pytest.raises(ConfigError, match="chunk-000003.parquet is not the file the run wrote"):
        res.table("trials")
    chunk.unlink()
    with pytest.raises(ConfigError, match="chunk-000003.parquet is missing"):
        res.table("trials")
    (tmp_path / "o" / "points.parquet").write_bytes(b"PAR1 truncated")
    with pytest.raises(ConfigError, match="points.parquet cannot be read"):
        res.table("points")


def test_an_empty_results_directory_name_is_not_the_working_directory(
    tmp_path, capsys, monkeypatch
):
    monkeypatch.chdir(tmp_path)  # "" would have been read as "." and written here
    assert batch_main([str(BROWN), "--results", ""]) == 2
    assert "--results" in capsys.readouterr().err
    assert verify_main(["--results", "", "--no-record"]) == 2
    assert "--results" in capsys.readouterr().err
    one_line(capsys, main(["report", "--results", ""]), "--results", prefix=SIM_ERROR)
    assert list(tmp_path.iterdir()) == []


# --- the fourth sweep (issue 26): one case per class -----------------------------------------

FIXED = THIRD.split("[datum]")[0].replace('"A", x_mm', '"A", role = "fixed", x_mm')
FIXED = FIXED.replace('"B", x_mm', '"B", role = "fixed", x_mm') + "[datum]\n"
DIST = 'generate = [ { kind = "distance", from = "*", to = "*", sigma_mm = 0.01 },\n'


@pytest.mark.parametrize(
    "old, new, key",
    [
        ("[datum]\n", '[datum]\nkind = "fixed"\nconstraints = [ { "C.x" = 1.0 } ]\n', "kind ="),
        (
            "[datum]\n",
            '[datum]\nkind = "constraints"\nconstraints = [ { "C.x" = 1.0 } ]\n',
            "defect",
        ),
        ("[datum]\n", '[compare]\nfix = ["A"]\n[datum]\n', "only fixed points"),
        ('from = "*", to = "*", sigma_mm', 'from = "C", to = "C", sigma_mm', "generate[0]"),
        (DIST, "estimate_constant = true\ngenerate = [\n", "estimate_constant"),
        (DIST, "estimate_scale = true\ngenerate = [\n", "estimate_scale"),
        ("generate = [", "constant_mm = 1e6\ngenerate = [", "would read -"),
    ],
)
def test_a_network_key_without_effect_is_named(tmp_path, capsys, old, new, key):
    """Keys that did nothing (constraints of a fixed datum, more constraints than the datum
    defect, a comparison fixing what is fixed, a generator with no pair) or were blamed on
    the datum (a constant or scale to estimate in a network without distances)."""
    assert old in FIXED and main(["check", str(_net(tmp_path, FIXED))]) == 0
    capsys.readouterr()
    one_line(
        capsys,
        main(["check", str(_net(tmp_path, FIXED.replace(old, new, 1)))]),
        key,
        prefix=SIM_ERROR,
    )


def test_an_empty_dir_or_a_deleted_working_directory_is_named(tmp_path, capsys, monkeypatch):
    """``sim show ""`` read the working directory; a deleted one gave a bare OSError text."""
    one_line(capsys, main(["show", ""]), "DIR", "not a directory name", prefix=SIM_ERROR)
    gone = tmp_path / "gone"
    gone.mkdir()
    monkeypatch.chdir(gone)
    gone.rmdir()
    one_line(
        capsys, main(["run", str(BROWN), "--out", "out"]), "working directory", prefix=SIM_ERROR
    )


def test_trials_pick_the_chunk_when_the_files_chunk_is_too_large(tmp_path, capsys):
    """``--trials`` picks a chunk giving MIN_CHUNKS chunks (``sim run -h``), also when the
    file's own chunk leaves fewer than two (it was refused, and so was ``make verify
    --trials``)."""
    f = _net(tmp_path, THIRD.replace("chunk = 2", "chunk = 30"))
    assert main(["run", str(f), "--trials", "40", "--out", str(tmp_path / "o"), "--quiet"]) == 0
    assert pq.read_table(tmp_path / "o" / "claims.parquet").num_rows > 0
    assert len(list((tmp_path / "o" / "trials").rglob("chunk-*.parquet"))) == 20


def test_verify_names_a_record_it_cannot_write_and_leaves_no_temporary(tmp_path, capsys):
    res = _results(tmp_path)
    scratch = tmp_path / "s"
    scratch.mkdir()
    (scratch / "brown_table1").symlink_to(res / "brown_table1")
    (res / "reproducibility.parquet").mkdir()  # a directory where the record goes
    argv = ["--results", str(res), "--scratch", str(scratch), "--no-rerun"]
    assert verify_main(argv) == 2
    err = capsys.readouterr().err  # refused before the comparisons now (doors51s)
    assert "reproducibility.parquet is a directory" in err and "Traceback" not in err
    assert sorted(p.name for p in res.iterdir()) == ["brown_table1", "reproducibility.parquet"]


class _BytesPath:
    def __fspath__(self):
        return b"/tmp/x.toml"


def test_api_paths_keys_and_results_are_checked(tmp_path):
    """An os.PathLike giving bytes (a pathlib TypeError), an empty override key (an unnamed
    "unknown key") and ``sim.Results`` made with a str path (a TypeError on the first table)."""
    with pytest.raises(ConfigError, match="study_file: must be a path"):
        sim.load(_BytesPath())
    with pytest.raises(ConfigError, match="'': is not a config key"):
        sim.load(BROWN, **{"": 1})
    d = tmp_path / "r"
    d.mkdir()
    _claims_with_record(d, "x")
    assert sim.Results(str(d), "x").claims().num_rows == 1
    with pytest.raises(ConfigError, match="path: must be a path"):
        sim.Results(5, "x")


@pytest.mark.parametrize(
    "sweep, key",
    [("[nan]", "must be finite"), ("[0.0, -1.0]", "must be >= 0"), ('["1"]', "a number")],
)
def test_a_swept_value_its_key_refuses_is_refused_by_check(tmp_path, capsys, sweep, key):
    """``sim check`` passed a sweep whose every cell then failed at run time."""
    f = _net(tmp_path, THIRD + f'[sweep]\n"network.offset_mm" = {sweep}\n')
    one_line(capsys, main(["check", str(f)]), "sweep.network.offset_mm", key, prefix=SIM_ERROR)


def test_a_run_of_too_many_chunk_files_is_refused_before_it_starts(tmp_path, capsys):
    """Two million trials in chunks of one ran for hours, writing a file per chunk."""
    argv = ["--set", "trials=2000000", "--set", "chunk=1"]
    one_line(
        capsys,
        main(["check", str(_net(tmp_path)), *argv]),
        "chunk",
        "at most 100,000",
        prefix=SIM_ERROR,
    )
    out = tmp_path / "o"
    one_line(
        capsys,
        main(["run", str(_net(tmp_path)), *argv, "--out", str(out)]),
        "chunk files",
        prefix=SIM_ERROR,
    )
    assert not out.exists()


def test_batch_stale_only_reads_a_run_record_of_another_shape_as_stale(tmp_path, capsys):
    f = _net(tmp_path)
    (tmp_path / "r" / "n").mkdir(parents=True)
    (tmp_path / "r" / "n" / "run.json").write_text("[]")  # valid JSON, not a record
    assert is_current(f, tmp_path / "r" / "n") is False


@pytest.mark.long
def test_a_run_record_listing_its_files_wrongly_is_named_not_a_traceback(tmp_path, capsys):
    """run.json edited into valid JSON of another shape (``"files": 3``) gave a TypeError
    after the whole re-run, when the new results replaced the old."""
    out = tmp_path / "o"
    assert main(["run", str(_net(tmp_path)), "--out", str(out), "--quiet"]) == 0
    rec = json.loads((out / "run.json").read_text())
    (out / "run.json").write_text(json.dumps({**rec, "files": 3}))
    capsys.readouterr()
    argv = ["run", str(_net(tmp_path)), "--out", str(out), "--quiet", "--overwrite", "--seed", "7"]
    one_line(capsys, main(argv), "run.json", "does not list the files", prefix=SIM_ERROR)
    assert json.loads((out / "run.json").read_text())["files"] == 3  # nothing replaced


def test_a_chunk_hash_map_of_another_shape_is_not_read_as_no_check(tmp_path):
    """``chunk_sha256`` edited into a list: ``Results.table("trials")`` returned the trials
    unchecked, as for a run recorded before chunks were hashed."""
    res = sim.load(_net(tmp_path)).run(out=tmp_path / "o")
    rec = json.loads((tmp_path / "o" / "run.json").read_text())
    (tmp_path / "o" / "run.json").write_text(json.dumps({**rec, "chunk_sha256": [1]}))
    with pytest.raises(ConfigError, match="does not map the chunk files"):
        res.table("trials")


@pytest.mark.parametrize("drop", ["chunk_sha256", "config", "code_hash"])
def test_trials_whose_record_cannot_check_them_are_refused(tmp_path, drop):
    """``run.json`` with its chunk hashes, its config or its code hash deleted by hand (so no
    longer a run record that lists the chunks): the trials were returned unchecked; now the
    chunks that cannot be checked are refused, naming the record."""
    res = sim.load(_net(tmp_path)).run(out=tmp_path / "o")
    assert res.table("trials").num_rows > 0
    rec = json.loads((tmp_path / "o" / "run.json").read_text())
    del rec[drop]
    (tmp_path / "o" / "run.json").write_text(json.dumps(rec))
    with pytest.raises(ConfigError, match="run.json"):
        res.table("trials")
