"""The classes of the sweep doors41c (brief C41: concurrency and interruption with the last
session's records -- a sweep's per-cell sha256, the values digests of ``table_shape``, the
cells' provenance checks -- under kills at each step of publishing, two writers at once, and
readers while a writer replaces results), one case each; each failed on the code before its
fix.

* Two runs of the Python API in two threads of one process, one with ``figures=False``: the
  flag that turns figures off was the process's (a ``threading.Event``), so the other run,
  into its own ``out``, drew no figure either, and published its tables with a ``run.json``
  that said its figures were drawn (no ``"figures": false``: ``--stale-only`` called them
  current) and a README.md that guessed "a run with ``--no-figures``?". The flag is now a
  context variable (:func:`sim.report.plotting.without_figures`), which the threads a study
  runs its parts in take a copy of (:func:`sim.studies.design.parts.side_by_side`).
"""

from __future__ import annotations

import dataclasses
import json
import threading
from pathlib import Path

import sim

ROOT = Path(__file__).resolve().parents[1]

NETWORK = """\
study = "network"
trials = 40
chunk = 2
[network]
points = [ { name = "A", x_mm = 0.0, y_mm = 0.0, role = "fixed" },
           { name = "B", x_mm = 1000.0, y_mm = 0.0, role = "fixed" },
           { name = "C", x_mm = 400.0, y_mm = 700.0 } ]
generate = [ { kind = "distance", from = "*", to = "*", sigma_mm = 0.01 } ]
"""


def _study(tmp_path: Path, text: str = NETWORK) -> Path:
    f = tmp_path / "net.toml"
    f.write_text(text, encoding="utf-8")
    return f


def test_a_run_without_figures_in_one_thread_leaves_another_threads_figures(tmp_path):
    h = sim.load(_study(tmp_path))
    inside, other_done = threading.Event(), threading.Event()
    real = h.study.run

    def held(cfg, d, ctx):  # the run without figures is inside its trials while the other runs
        inside.set()
        assert other_done.wait(120)
        return real(cfg, d, ctx)

    no_figures = dataclasses.replace(h, study=dataclasses.replace(h.study, run=held))
    failed: list[BaseException] = []

    def first() -> None:
        try:
            no_figures.run(out=tmp_path / "a", figures=False)
        except BaseException as e:  # noqa: BLE001 - said by the test below
            failed.append(e)

    t = threading.Thread(target=first)
    t.start()
    try:
        assert inside.wait(120)
        res = h.run(out=tmp_path / "b")
    finally:
        other_done.set()
        t.join()
    assert not failed
    rec = json.loads((res.path / "run.json").read_text(encoding="utf-8"))
    assert "figures" not in rec  # drawn, it says
    drawn = sorted(p.name for p in res.path.glob("*.png"))
    assert drawn == ["network.png", "reliability.png"]  # before: none
    assert sorted(rec["figure_sha256"]) == drawn
    assert not list((tmp_path / "a").glob("*.png"))  # and the other run drew none
