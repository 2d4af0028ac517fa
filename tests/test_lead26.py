"""Door classes the lead fixed in the session of 2026-11-28 (05:48 UTC), from the items the
earlier sweeps left (issue 26):

* a Brown plate point no farther from a station than the tangential offset beta (its range
  sqrt(d^2 - beta^2) - alpha undefined) was accepted by ``sim check`` (every trial failed at
  run time, after a NumPy warning) or blamed on a singular normal matrix or on the scale;
* ``python -m sim.batch --results DIR`` relayed a run's refusal of its output directory in the
  run's own words, "--out: ... (choose another --out)": the batch has no ``--out`` (it refuses
  one), the user gave ``--results``.
"""

import subprocess
import sys
import threading
from pathlib import Path

import pytest

from tests.oneline import SIM_ERROR, one_line

ROOT = Path(__file__).resolve().parents[1]


def test_a_batch_names_its_results_option_not_the_run_s_out(tmp_path):
    res = tmp_path / "res"
    res.mkdir()
    (res / "network_plate").write_text("the user's file\n")  # where the study's results go
    study = ROOT / "studies" / "network_plate.toml"
    cmd = [sys.executable, "-m", "sim.batch", "--results", str(res), str(study)]
    p = subprocess.run([*cmd, "--", "--trials", "40"], capture_output=True, text=True, cwd=ROOT)
    lines = p.stderr.splitlines()
    assert p.returncode == 2 and len(lines) == 1 and "Traceback" not in p.stderr, p.stderr
    # refused by the driver before any run (tests/test_doors28b.py), the file named first
    assert lines[0].startswith(f"sim.batch: {study}: --results: "), lines
    assert "choose another --results" in lines[0] and "--out" not in lines[0], lines
    assert (res / "network_plate").read_text() == "the user's file\n"


def test_the_commands_main_returns_help_s_code_and_runs_in_a_thread(tmp_path, capsys):
    """``sim.cli.main``, ``sim.batch.main`` and ``sim.report.verify.cli.main`` called in a
    notebook: ``--help``/``--version`` raised SystemExit into the caller (the kernel showed an
    error), and the batch and verify mains called from a thread of the caller's ended in
    "ValueError: signal only works in main thread" (they set and put back signal handlers)."""
    import sim.batch as batch
    import sim.report.verify.cli as verify
    from sim.cli import main

    for m, argv in ((main, ["--help"]), (main, ["--version"]), (main, ["show", "--help"])):
        assert m(argv) == 0
    assert batch.main(["--help"]) == 0 and verify.main(["--help"]) == 0
    capsys.readouterr()
    got = {}
    study = str(ROOT / "studies" / "network_plate.toml")

    def in_a_thread():
        got["batch"] = batch.main(["--results", str(tmp_path / "nosuch" / "x"), "-x.toml"])
        got["verify"] = verify.main(["--results", str(tmp_path / "nosuch")])
        got["check"] = main(["check", study])

    t = threading.Thread(target=in_a_thread)
    t.start()
    t.join()
    err = capsys.readouterr().err
    assert got == {"batch": 2, "verify": 2, "check": 0}, (got, err)
    assert "Traceback" not in err and "signal only works" not in err, err


def test_a_bar_asked_for_is_drawn_in_a_jupyter_notebook():
    """The API's ``run(quiet=False)`` in a notebook drew no bar (a kernel's output stream is
    no terminal), though its front end redraws a line ended by a carriage return; a stream of
    any other kind that is no terminal (a log file, a StringIO) still gets nothing."""
    import io

    from sim.mc.progress import Progress

    class OutStream(io.StringIO):  # as ipykernel's, by its module
        __module__ = "ipykernel.iostream"

    for stream, quiet, drawn in (
        (OutStream(), False, True),
        (OutStream(), True, False),
        (io.StringIO(), False, False),
    ):
        with Progress(400, "network", quiet=quiet, stream=stream, min_interval=0) as p:
            p.update(200)
            p.update(200)
        text = stream.getvalue()
        assert ("200/400 trials" in text) == drawn and ("\r" in text) == drawn, (quiet, text)


def test_a_handle_shows_its_overrides():
    """A notebook shows a handle by its repr: two handles of one file with other overrides
    (``trials=200``, ``datum__kind="inner"``) looked alike, ``StudyHandle(path=...)``."""
    import sim

    study = ROOT / "studies" / "network_brown.toml"  # (the plate's datum: refused as inner)
    plain, other = sim.load(study), sim.load(study, trials=200, datum__kind="inner")
    assert repr(plain) != repr(other)
    assert "'trials': 200" in repr(other) and "'datum.kind': 'inner'" in repr(other)


@pytest.mark.parametrize(
    "points, scale, needle",
    [
        ("[[0,122.3],[10,-20],[-30,40],[50,50],[-60,-70]]", 0, "point 1 (0, 122.3) mm lies 0.7 mm"),
        ("[[0,122],[10,-20],[-30,40],[50,50],[-60,-70]]", 0, "point 1 (0, 122) mm lies 1 mm"),
        ("[[10,-20],[-30,40],[0.3,122.5],[50,50],[-60,-70]]", 261, "point 3 (0.3, 122.5)"),
    ],
)
def test_a_brown_point_within_beta_of_a_station_is_named(points, scale, needle, capsys):
    from sim.cli import main

    sets = {
        "plate.pattern": "list",
        "plate.points": points,
        "comparator.station_offset_mm": 0.5,  # the stations 0.5 mm outside the format
        "comparator.beta_mm": 1,
        "comparator.scale_length_mm": scale,
    }
    argv = ["check", str(ROOT / "studies" / "brown_table1.toml")]
    argv += [a for k, v in sets.items() for a in ("--set", f"{k}={v}")]
    line = one_line(capsys, main(argv), SIM_ERROR + "plate.points: ", needle)
    assert "station 1 (0, 123)" in line and "beta = 1 mm" in line, line


def test_a_method_called_on_the_class_says_so():
    """``sim.Results.claims()`` (the class, not an instance) said "missing: Results.claims()
    needs it (it takes no argument)": Python's missing ``self`` in the API's argument words."""
    import sim
    from sim.mc.config import ConfigError

    for call, needle in (
        (lambda: sim.Results.claims(), "call it on the Results run() returned"),
        (lambda: sim.Results.table("claims"), "sim.Results(path, study)"),
        (lambda: sim.api.StudyHandle.run(), "the handle sim.load(...) returned"),
    ):
        with pytest.raises(ConfigError) as e:
            call()
        assert "is called on the class" in str(e.value) and needle in str(e.value), e.value
    with pytest.raises(ConfigError, match="missing"):  # on an instance: the argument's words
        sim.Results(ROOT / "results" / "network_plate", "network").table()
