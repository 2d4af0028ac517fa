"""Door classes the lead fixed in the session of 2026-11-28 (03:00 UTC), from the items the
earlier sweeps left (issue 26):

* an interrupt that reached ``sim run`` wrapped in another exception (a second Ctrl-C while a
  run cleaned up after the first) was the plain line ``sim: interrupted``, without the advice
  to run the same command again that the resume needs;
* a figure linked to a huge file was hashed in full by ``sim show`` before its first line;
* ``sim show`` of a sweep, or of one of its cells, checked none of the cells' figures: a cell's
  figure replaced by hand passed as the run's (the sweep's run record holds their sha256);
* a sweep key the study does not have was answered with the file's own first error and a
  wrong hint ("... is swept but not given there, so it takes its default").
"""

import json
import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

import sim.cli as cli
import sim.mc.publish as publish
from sim.cli import main
from sim.mc.publish import FIGURE_BYTES, changed_figure
from tests.oneline import SIM_ERROR, one_line

ROOT = Path(__file__).resolve().parents[1]


def test_an_interrupt_wrapped_in_a_run_s_clean_up_says_how_to_finish(monkeypatch, capsys):
    def second_interrupt(args):
        try:
            raise KeyboardInterrupt
        except KeyboardInterrupt as e:  # as a pool's shutdown wraps it
            raise RuntimeError("cannot schedule new futures after interpreter shutdown") from e

    monkeypatch.setattr(cli, "_command", second_interrupt)
    line = one_line(capsys, main(["run", str(ROOT / "studies" / "network_plate.toml")]), code=130)
    assert line.startswith("sim: interrupted") and "run the same command again" in line


def test_a_wrapped_interrupt_of_show_gives_no_advice_to_run_again(monkeypatch, capsys):
    def wrapped(args):
        raise ImportError("initialization failed") from KeyboardInterrupt()

    monkeypatch.setattr(cli, "_command", wrapped)
    assert one_line(capsys, main(["show", "x"]), code=130) == "sim: interrupted"


@pytest.fixture
def plate(tmp_path) -> Path:
    d = tmp_path / "network_plate"
    shutil.copytree(ROOT / "results" / "network_plate", d)
    return d


def test_a_figure_larger_than_any_the_run_draws_is_not_read(plate, monkeypatch, capsys):
    big = plate.parent / "disk.img"
    with open(big, "wb") as f:
        f.truncate(FIGURE_BYTES + 1)  # sparse: no disk used
    (plate / "network.png").unlink()
    (plate / "network.png").symlink_to(big)

    def never(p):
        raise AssertionError(f"{p} was read")

    monkeypatch.setattr(publish, "file_sha256", never)
    assert "is not the figure its run drew" in changed_figure(plate)
    one_line(capsys, main(["show", str(plate)]), "network.png", "not the figure", prefix=SIM_ERROR)


SWEEP = """\
study = "brown_table1"
trials = 200
chunk = 10
[sweep]
"plate.spacing_mm" = [35.0, 45.0]
"""


@pytest.fixture(scope="module")
def sweep(tmp_path_factory) -> Path:
    d = tmp_path_factory.mktemp("sweep")
    (d / "sweep.toml").write_text(SWEEP)
    assert main(["run", str(d / "sweep.toml"), "--out", str(d / "out"), "--quiet"]) == 0
    return d / "out"


@pytest.mark.long
def test_a_sweep_s_cell_figure_replaced_by_hand_is_named(sweep, tmp_path, capsys):
    d = tmp_path / "out"
    shutil.copytree(sweep, d)
    rec = json.loads((d / "run.json").read_text())
    cell_figures = [f for f in rec["figure_sha256"] if f.startswith("cells/")]
    assert cell_figures, rec["figure_sha256"]  # the sweep's record holds its cells' figures
    assert main(["show", str(d)]) == 0 and main(["show", str(d / "cells" / "cell0000_r0")]) == 0
    capsys.readouterr()
    f = d / cell_figures[0]
    shutil.copyfile(d / "sweep.png", f)
    one_line(capsys, main(["show", str(d)]), cell_figures[0], "not the figure", prefix=SIM_ERROR)
    cell = f.parent
    one_line(capsys, main(["show", str(cell)]), f.name, "not the figure", prefix=SIM_ERROR)
    os.chdir(cell)  # named relative to where it is
    try:
        one_line(capsys, main(["show", "."]), f.name, "not the figure", prefix=SIM_ERROR)
    finally:
        os.chdir(ROOT)


def test_a_sweep_key_the_study_does_not_have_is_named_first(tmp_path, capsys):
    f = tmp_path / "sw.toml"
    text = (
        (ROOT / "studies" / "network_plate.toml").read_text().replace("chunk = 100", "chunk = 1000")
    )
    f.write_text(text + '\n[sweep]\n"network.grids.0.nx" = [4, 5]\n')
    line = one_line(capsys, main(["check", str(f)]), "sweep.network.grids.0.nx", "unknown key")
    assert "takes its default" not in line


UNGUARDED = """\
import multiprocessing as mp
import sys

if mp.get_start_method(allow_none=True) is None:  # the worker has its parent's: spawn
    mp.set_start_method("spawn")
import sim

try:  # no if __name__ == "__main__": each worker imports this file again
    sim.load({study!r}).run(out={out!r}, workers=2, trials=200)
except sim.ConfigError as e:
    print(e, file=sys.stderr)
    sys.exit(2)
"""


@pytest.mark.long
def test_a_script_without_a_main_guard_gets_one_line_and_no_worker_tracebacks(tmp_path):
    script = tmp_path / "unguarded.py"
    study = str(ROOT / "studies" / "network_plate.toml")
    script.write_text(UNGUARDED.format(study=study, out=str(tmp_path / "out")))
    p = subprocess.run(
        [sys.executable, str(script)], capture_output=True, text=True, timeout=300, cwd=tmp_path
    )
    # each worker printed multiprocessing's "bootstrapping phase" traceback before this line
    assert p.returncode == 2 and p.stderr.count("\n") == 1, p.stderr
    assert p.stderr.startswith("executor: cannot start the local executor"), p.stderr
    assert 'unguarded.py again: is the script\'s code under if __name__ == "__main__"' in p.stderr
    assert not (tmp_path / "out").exists()
