"""What a process pays before it does anything: the suite's modules load without matplotlib,
scipy.stats or numba (about 0.5 s, 0.5 s and 0.3 s of CPU each, measured), which a process loads only when
it draws a figure (sim.report.mpl), explores a region (its Sobol design) or compiles a kernel
(sim.lsq.compile). A `sim check`, a `--no-figures` run, a pool or Dask worker and every
re-run of `make verify` start faster for it; a test run starts dozens of such processes."""

import subprocess
import sys

from conftest import ROOT

from sim.studies import MODULES

HEAVY = ("matplotlib", "scipy.stats", "numba")


def test_importing_every_study_and_door_loads_no_heavy_module():
    mods = ["sim.cli", "sim.batch", "sim.api", "sim.report.verify", "sim.report.markdown"]
    mods += [f"{m}.run" for m in sorted(set(MODULES.values()))]
    code = "import importlib, sys\n"
    code += f"for m in {mods!r}: importlib.import_module(m)\n"
    code += f"print(' '.join(h for h in {HEAVY!r} if h in sys.modules))"
    r = subprocess.run([sys.executable, "-c", code], cwd=ROOT, capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    assert r.stdout.split() == [], f"loaded on import: {r.stdout.strip()}"


def test_the_first_figure_sets_the_style_on_an_agg_canvas_without_pyplot():
    code = (
        "import sys\n"
        "from sim.report import mpl\n"
        "from sim.report.plotting import plt\n"
        "fig, ax = plt.subplots()\n"
        "import matplotlib\n"
        "print(type(fig.canvas).__name__, matplotlib.rcParams['font.size'],\n"
        "      'matplotlib.pyplot' in sys.modules, matplotlib.rcParams._get_backend_or_none())\n"
    )
    r = subprocess.run([sys.executable, "-c", code], cwd=ROOT, capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    # no backend chosen for the process (a notebook's stays its own), pyplot never loaded
    assert r.stdout.split() == ["FigureCanvasAgg", "9.0", "False", "None"], r.stdout
