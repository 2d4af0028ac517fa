"""The output doors of this session, tried with odd inputs (sweep doors23b).

A run's ``figure_sha256`` (``run.json``) is checked by ``sim show``, ``sim report``, ``make
verify`` and ``--stale-only`` (:func:`sim.mc.publish.changed_figure`). Two classes were found:

* a figure name in a hand-edited ``run.json`` that no run writes (``/proc/self/mem``,
  ``../other/network.png``) was read outside the results directory: ``sim show`` ended in
  ``sim: error: Input/output error``, naming nothing, or compared a file of another run;
* a figure whose read fails (a link to ``/proc/self/mem``; a bad sector is the same ``EIO``)
  ended in that bare ``Input/output error``, without the figure's name.

Both are now one line naming ``run.json`` or the figure. The interrupts of ``sim run``, a
sweep, ``python -m sim.batch`` and the API's ``run`` (SIGINT and SIGTERM at random moments,
then the same command again) gave results equal to an uninterrupted run in this sweep's
harness; doors19a's tests hold the resume.
"""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import pytest

from sim.cli import main
from sim.mc.publish import changed_figure
from tests.oneline import SIM_ERROR, one_line

RESULTS = Path(__file__).resolve().parents[1] / "results" / "network_plate"


@pytest.fixture
def run_dir(tmp_path) -> Path:
    d = tmp_path / "network_plate"
    shutil.copytree(RESULTS, d)
    return d


def _figures(d: Path, figures: dict) -> None:
    rec = json.loads((d / "run.json").read_text())
    (d / "run.json").write_text(json.dumps({**rec, "figure_sha256": figures}))


@pytest.mark.parametrize("name", ["/proc/self/mem", "../elsewhere/network.png", "trials", ""])
def test_a_figure_name_the_run_could_not_have_written_is_named_not_read(run_dir, name, capsys):
    _figures(run_dir, {name: "0" * 64})
    assert "names a figure outside its directory" in changed_figure(run_dir)
    one_line(capsys, main(["show", str(run_dir)]), "run.json", "outside", prefix=SIM_ERROR)


def test_the_run_s_own_figures_pass(run_dir, capsys):
    assert changed_figure(run_dir) is None
    assert main(["show", str(run_dir)]) == 0


@pytest.mark.skipif(not Path("/proc/self/mem").is_file(), reason="needs /proc/self/mem")
def test_a_figure_that_cannot_be_read_is_named(run_dir, capsys):
    (run_dir / "network.png").unlink()
    (run_dir / "network.png").symlink_to("/proc/self/mem")  # a regular file whose read is EIO
    assert "cannot be read" in changed_figure(run_dir)
    one_line(
        capsys, main(["show", str(run_dir)]), "network.png", "cannot be read", prefix=SIM_ERROR
    )


# A report embeds a figure only when it is the one the run drew (``sim.mc.publish.drawn``): a
# PNG put by hand beside the tables of a ``--no-figures`` run, or in place of a sweep's
# ``sweep.png`` (whose directory sim show checks nothing of), was shown as the run's figure.


def test_a_png_put_beside_a_no_figures_run_is_not_shown_as_the_run_s(run_dir):
    from sim.report.section import figure

    rec = json.loads((run_dir / "run.json").read_text())
    (run_dir / "run.json").write_text(json.dumps({**rec, "figures": False, "figure_sha256": {}}))
    assert (run_dir / "network.png").is_file()  # the user's picture, of that name
    assert "not drawn by this run" in figure(run_dir, "network.png", "network")
    _figures(run_dir, rec["figure_sha256"])  # the run's own: shown
    assert figure(run_dir, "network.png", "network").startswith("![network]")


SWEEP = """study = "network"
trials = 40
chunk = 2
seed = 1
[network]
grids = [ { prefix = "G", nx = 3, ny = 3, spacing_mm = 40.0, role = "observed", sigma_mm = 0.0012 } ]
generate = [ { kind = "dx", from = "G5", to = "G*", sigma_mm = 0.002 },
             { kind = "dy", from = "G5", to = "G*", sigma_mm = 0.002 } ]
[datum]
kind = "fixed"
[sweep]
"network.grids" = [
  [{ prefix = "G", nx = 3, ny = 3, spacing_mm = 40.0, role = "observed", sigma_mm = 0.0012 }],
  [{ prefix = "G", nx = 3, ny = 3, spacing_mm = 60.0, role = "observed", sigma_mm = 0.0012 }] ]
"""


@pytest.mark.long
def test_a_sweep_png_replaced_by_hand_is_not_shown_as_the_run_s(tmp_path, run_dir, capsys):
    from sim.report.sweep import sweep_markdown

    (tmp_path / "sw.toml").write_text(SWEEP)
    out = tmp_path / "sw"
    assert main(["run", str(tmp_path / "sw.toml"), "--out", str(out), "--quiet"]) == 0
    assert "sweep.png" in sweep_markdown(out, "sw")
    shutil.copyfile(run_dir / "network.png", out / "sweep.png")  # another picture
    assert "sweep.png" not in sweep_markdown(out, "sw")
