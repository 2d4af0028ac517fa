"""The study-file contract: validation, one-line errors, outputs, provenance, determinism."""

import subprocess
import sys
from pathlib import Path

import numpy as np
import pyarrow.parquet as pq
import pytest
from oneline import one_line

from sim.cli import main
from sim.mc.config import ConfigError, parse_override
from sim.mc.storage import read_provenance
from sim.studies import load_study

ROOT = Path(__file__).resolve().parent.parent
BROWN = ROOT / "studies" / "brown_table1.toml"


def write(tmp_path, text, name="study.toml"):
    p = tmp_path / name
    p.write_text(text)
    return p


BASE = 'study = "brown_table1"\ntrials = 20\nchunk = 1\n'


@pytest.mark.parametrize(
    "body, key",
    [
        ("[plate]\ngird = 5\n", "plate.gird"),  # unknown key
        ("bogus = 1\n", "bogus"),
        ("[errors]\nsetting_sigma_um = -1.0\n", "errors.setting_sigma_um"),  # negative sigma
        ("[errors]\nsetting_sigma_um = 0.0\n", "errors.setting_sigma_um"),  # zero sigma
        ("[errors]\ncomparator_sigma_um = nan\n", "errors.comparator_sigma_um"),
        ("[errors]\nsettings = 0\n", "errors.settings"),
        ("[errors]\nsettings = 1.5\n", "errors.settings"),  # wrong type
        ('[plate]\ngrid = "five"\n', "plate.grid"),
        ("[plate]\ngrid = 1\n", "plate.grid"),  # fewer than 3 points
        ('[plate]\npattern = "list"\npoints = [[0.0, 0.0], [10.0, 0.0]]\n', "plate.points"),
        (
            '[plate]\npattern = "list"\npoints = [[0.0, 0.0], [10.0, 0.0], [20.0, 0.0], [30.0, 0.0]]\n',
            "plate.points",
        ),  # collinear
        (
            '[plate]\npattern = "list"\npoints = [[0.0, 0.0], [10.0, 5.0], [10.0, 5.0], [3.0, 30.0]]\n',
            "plate.points",
        ),  # duplicate
        (
            '[plate]\npattern = "list"\npoints = [[0.0, 0.0], [10.0, 5.0], [200.0, 5.0], [3.0, 30.0]]\n',
            "plate.points",
        ),  # outside the format
        ("[plate]\nspacing_mm = 80.0\n", "plate.spacing_mm"),  # grid outside the format
        ('[plate]\npattern = "hexagon"\n', "plate.pattern"),
        ("[comparator]\nstation_offset_mm = 0.0\n", "comparator.station_offset_mm"),  # inside
        ("[comparator]\nbeta_mm = inf\n", "comparator.beta_mm"),
    ],
)
def test_bad_config_names_the_key(tmp_path, body, key):
    p = write(tmp_path, BASE + body)
    with pytest.raises(ConfigError) as e:
        load_study(p)
    assert e.value.key == key
    assert "\n" not in str(e.value)


def test_cli_bad_input_one_line_exit_2_no_output(tmp_path, capsys):
    p = write(tmp_path, BASE + "[plate]\ngird = 5\n")
    out = tmp_path / "res"
    one_line(capsys, main(["run", str(p), "--out", str(out), "--quiet"]), "plate.gird")
    assert not out.exists() and not list(tmp_path.glob(".res*"))


@pytest.mark.parametrize(
    "args, needle",
    [
        (["run", "nonexistent.toml"], "no such study file"),
        (["run", "{bad}"], "malformed TOML"),
        (["run", "{ok}", "--set", "plate.grid=1"], "plate.grid"),
        (["run", "{ok}", "--set", "nokey"], "key=value"),
        (["run", "{ok}", "--trials", "1"], "trials"),
        (["run", "{unknown_study}"], "unknown study"),
    ],
)
def test_cli_errors(tmp_path, capsys, args, needle):
    files = {
        "bad": write(tmp_path, "study = \n", "bad.toml"),
        "ok": write(tmp_path, BASE, "ok.toml"),
        "unknown_study": write(tmp_path, 'study = "nope"\n', "u.toml"),
    }
    args = [a.format(**files) for a in args]
    one_line(capsys, main(args + ["--out", str(tmp_path / "o"), "--quiet"]), needle)


def test_unwritable_output_directory(tmp_path, capsys):
    """The output's parent is a regular file: cannot be created (fails for root too)."""
    blocker = tmp_path / "file"
    blocker.write_text("not a directory")
    p = write(tmp_path, BASE)
    one_line(capsys, main(["run", str(p), "--out", str(blocker / "res"), "--quiet"]), "--out")


def test_overrides_parse_toml_values():
    assert parse_override("plate.grid=6") == ("plate.grid", 6)
    assert parse_override("plate.pattern=random") == ("plate.pattern", "random")
    assert parse_override("dilution.grids=[3, 4]") == ("dilution.grids", [3, 4])


def test_run_writes_contract_files_with_provenance(tmp_path):
    out = tmp_path / "t1"
    assert (
        main(
            ["run", str(BROWN), "--out", str(out), "--trials", "60", "--quiet", "--set", "chunk=3"]
        )
        == 0
    )
    pts = pq.read_table(out / "points.parquet").to_pydict()
    for col in (
        "model",
        "point",
        "x_mm",
        "y_mm",
        "sigma_x_um",
        "sigma_y_um",
        "mc_sigma_x_um",
        "mc_sigma_y_um",
        "mc_trials",
    ):
        assert col in pts
    assert set(pts["model"]) == {"known", "stations", "pivot"}
    claims = pq.read_table(out / "claims.parquet").to_pydict()
    for col in ("claim", "source", "paper", "value", "ci_low", "ci_high", "holds", "kind", "note"):
        assert col in claims
    from sim.claims.book import KINDS

    assert set(claims["kind"]) <= set(KINDS)
    trials = pq.read_table(out / "trials").to_pydict()  # partitioned dataset, one file a chunk
    assert len(trials["chunk"]) == 60 and sorted(set(trials["chunk"])) == list(range(20))
    for m in ("known", "stations", "pivot"):
        assert {f"{m}_converged", f"{m}_iterations", f"{m}_sigma0_um", f"{m}_status"} <= set(trials)
    assert {"pivot_alpha_mm", "pivot_beta2_mm2", "stations_y1_mm"} <= set(trials)
    prov = read_provenance(out / "points.parquet")
    assert prov["config"]["trials"] == 60 and prov["seed"] == 1967
    assert {"numpy", "pyarrow", "numba", "emcee"} <= set(prov["versions"]) and prov["git_commit"]
    assert (out / "table1.png").stat().st_size > 1000


def test_a_new_seed_gives_new_trials(tmp_path):
    # two runs with the same seed give the same files byte for byte: test_all_studies.py shows
    # it for every study (one worker against two, killed and resumed); here a new seed
    a = tmp_path / "a"
    assert (
        main(["run", str(BROWN), "--out", str(a), "--trials", "40", "--quiet", "--no-figures"]) == 0
    )
    c = tmp_path / "c"
    assert (
        main(
            [
                "run",
                str(BROWN),
                "--out",
                str(c),
                "--trials",
                "40",
                "--seed",
                "5",
                "--quiet",
                "--no-figures",
            ]
        )
        == 0
    )
    ta = pq.read_table(a / "trials").column("pivot_sigma0_um").to_numpy()
    tc = pq.read_table(c / "trials").column("pivot_sigma0_um").to_numpy()
    assert not np.allclose(ta, tc)


def test_python_dash_m_entry_point(tmp_path):
    r = subprocess.run(
        [sys.executable, "-m", "sim", "check", str(BROWN)], capture_output=True, text=True, cwd=ROOT
    )
    assert r.returncode == 0 and "plate.spacing_mm = 45.0" in r.stdout


# --- nothing the suite did not write is replaced; one-line option errors -------------------


def _run(tmp_path, out, *extra):
    p = write(tmp_path, BASE, "ok.toml")
    return main(["run", str(p), "--out", str(out), "--quiet", *extra])


@pytest.mark.parametrize("overwrite", [[], ["--overwrite"]])
def test_a_file_or_a_foreign_directory_is_never_replaced(tmp_path, capsys, overwrite):
    f = tmp_path / "notes.txt"
    f.write_text("mine")
    d = tmp_path / "mine"
    d.mkdir()
    (d / "a.txt").write_text("mine too")
    for out, needle in ((f, "is a file"), (d, "no sim run record")):
        one_line(capsys, _run(tmp_path, out, *overwrite), needle)
    assert f.read_text() == "mine" and (d / "a.txt").read_text() == "mine too"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["mine", "notes.txt", "ok.toml"]


def test_a_symlink_and_a_foreign_staging_directory_are_never_replaced(tmp_path, capsys):
    target = tmp_path / "target"
    target.mkdir()
    (target / "keep").write_text("x")
    (tmp_path / "link").symlink_to(target)
    assert _run(tmp_path, tmp_path / "link", "--overwrite") == 2
    stage = tmp_path / ".res.partial"
    stage.mkdir()
    (stage / "keep").write_text("y")
    assert _run(tmp_path, tmp_path / "res", "--overwrite") == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 2 and "symbolic link" in err[0] and "no sim run record" in err[1]
    assert (target / "keep").read_text() == "x" and (stage / "keep").read_text() == "y"


def test_an_empty_directory_and_our_own_results_are_replaced(tmp_path):
    out = tmp_path / "res"
    out.mkdir()
    assert _run(tmp_path, out, "--no-figures") == 0  # where the run writes, not what
    assert (out / "run.json").is_file() and not (out / ".lock").exists()
    assert _run(tmp_path, out, "--seed", "3", "--overwrite", "--no-figures") == 0
    assert sorted(p.name for p in tmp_path.iterdir()) == ["ok.toml", "res"]


@pytest.mark.parametrize(
    "args, needle",
    [
        (["--out", ""], "--out: is empty"),
        (["--trials", "2.5"], "argument --trials: must be an integer (got 2.5)"),
        (["--workers", "0"], "--workers"),
        (["--scheduler", "not an address", "--executor", "dask"], "--scheduler"),
        (["--scheduler", "tcp://127.0.0.1:8786"], "needs --executor dask"),
        (["--trials", "20", "--set", "chunk=20"], "need at least 20"),
        (["--max-memory-gb", "nan"], "--max-memory-gb"),
        (["--bogus"], "unrecognized arguments"),
    ],
)
def test_option_errors_are_one_line(tmp_path, capsys, args, needle):
    p = write(tmp_path, BASE, "ok.toml")
    argv = ["run", str(p), "--quiet", *args]
    if "--out" not in args:
        argv += ["--out", str(tmp_path / "o")]
    one_line(capsys, main(argv), needle)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["ok.toml"]


def test_a_live_lock_stops_a_second_run_and_overwrite(tmp_path, capsys):
    """A run holding the staging directory's lock: a second run into the same --out, with or
    without --overwrite, stops at once naming the holder, and removes nothing."""

    from sim.mc.storage import StageLock

    out = tmp_path / "res"
    stage = tmp_path / ".res.partial"
    lock = StageLock(stage).acquire()
    (stage / "trials").mkdir()
    (stage / "trials" / "half-written").write_text("x")
    try:
        for extra in ([], ["--overwrite"]):
            one_line(capsys, _run(tmp_path, out, *extra), "running sim", "in this process")
        assert (stage / "trials" / "half-written").is_file() and not out.exists()
    finally:
        lock.release()
    assert _run(tmp_path, out) == 0 and (out / "claims.parquet").is_file()


def test_a_failed_run_says_where_and_does_not_block_the_corrected_command(
    tmp_path, capsys, monkeypatch
):
    import dataclasses

    import sim.studies as studies

    real = studies.get_study

    def failing(name):
        st = real(name)

        def run(cfg, out, ctx):
            from sim.mc.runner import ChunkStore

            ChunkStore(out / "trials").save(0, 0, 2, {"x": np.zeros(2)})  # one finished chunk
            if cfg["errors.settings"] == 2:
                raise np.linalg.LinAlgError("SVD did not converge")
            return st.run(cfg, out, ctx)

        return dataclasses.replace(st, run=run)

    monkeypatch.setattr(studies, "get_study", failing)
    out = tmp_path / "res"
    one_line(
        capsys,
        _run(tmp_path, out, "--set", "errors.settings=2"),
        "LinAlgError: SVD did not converge",
    )
    assert (tmp_path / ".res.partial" / "run.json").is_file()  # kept: it holds a chunk
    monkeypatch.setattr(studies, "get_study", real)
    assert _run(tmp_path, out, "--set", "errors.settings=3") == 0  # corrected: replaces it
    assert not (tmp_path / ".res.partial").exists()


@pytest.mark.parametrize(
    ("argv", "line"),
    [
        (
            ["check", "studies/wolf_polynomial.toml", "--trials", "20"],
            "sim: error: --trials: an option of sim run, not of sim check: sim check --set "
            "trials=20 checks what sim run --trials 20 runs (see sim check --help)",
        ),
        (
            ["show", "results/wolf_polynomial", "-x"],
            "sim: error: unrecognized arguments: -x (see sim show --help)",
        ),
        (["--bogus"], "sim: error: unrecognized arguments: --bogus (see sim --help)"),
    ],
)
def test_an_option_no_command_takes_names_the_program_once_and_the_commands_help(
    capsys, argv, line
):
    # the top parser reported it as "sim: error: sim: unrecognized arguments: ... (see sim --help)"
    assert one_line(capsys, main(argv)) == line


def test_show_names_both_places_a_study_name_is_looked_for(tmp_path, capsys, monkeypatch):
    # `sim show nosuch` said only "nosuch is not a directory", though a name is also read as
    # results/<name> (sim show --help)
    monkeypatch.chdir(tmp_path)
    line = one_line(capsys, main(["show", "nosuch"]))
    assert (
        line == "sim: error: DIR: nosuch does not exist "
        "(nor is there a directory results/nosuch or scratch/nosuch)"
    )
    line = one_line(capsys, main(["show", str(tmp_path / "nosuch")]))
    assert line == f"sim: error: DIR: {tmp_path / 'nosuch'} does not exist"
