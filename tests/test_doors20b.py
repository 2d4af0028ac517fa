"""The classes of the sweep doors20b (issue 26: a designer's trade-off study end to end, with
``[sweep]`` tables), one case each; each failed on the code before its fix.

* an interrupted sweep was not resumable: its finished cells' chunks lie under
  ``cells/<label>/trials/``, which the staging directory's chunk count did not look at, so
  Ctrl-C or SIGTERM found "no finished chunk" and deleted the whole staging directory (while
  saying "run the same command again to finish the missing chunks");
"""

from pathlib import Path

import sim.execute
from sim.cli import main

NETWORK = """study = "network"
trials = 40
chunk = 2
[network]
name = "n"
points = [
  { name = "A", x_mm = 0.0, y_mm = 0.0, role = "fixed" },
  { name = "B", x_mm = 1000.0, y_mm = 0.0, role = "fixed" },
  { name = "C", x_mm = 400.0, y_mm = 700.0 },
]
generate = [ { kind = "distance", from = "*", to = "*", sigma_mm = 0.01 } ]
"""


def _study(tmp_path: Path, sweep: str, text: str = NETWORK) -> Path:
    f = tmp_path / "s.toml"
    f.write_text(text + "[sweep]\n" + sweep)
    return f


def test_an_interrupted_sweep_keeps_its_finished_cells_and_resumes(tmp_path, capsys, monkeypatch):
    f = _study(tmp_path, '"network.scale_ppm" = [0.0, 10.0, 20.0]\n')
    out = tmp_path / "out"
    calls = []
    real = sim.execute.cell_config

    def stop_at_the_third_cell(*a, **k):
        calls.append(1)
        if len(calls) == 3:
            raise KeyboardInterrupt
        return real(*a, **k)

    monkeypatch.setattr(sim.execute, "cell_config", stop_at_the_third_cell)
    assert main(["run", str(f), "--out", str(out), "--quiet", "--no-figures"]) == 130
    stage = tmp_path / ".out.partial"
    done = sorted(stage.glob("cells/*/trials/part-*/chunk-*.parquet"))
    assert len(done) == 40  # two cells of 20 chunks each, kept for the resumption
    stamps = {p: p.stat().st_mtime_ns for p in done}
    monkeypatch.setattr(sim.execute, "cell_config", real)
    capsys.readouterr()
    assert main(["run", str(f), "--out", str(out), "--quiet", "--no-figures"]) == 0
    assert "resuming network: 40 finished chunks found" in capsys.readouterr().err
    for p, t in stamps.items():  # read again, not computed again
        q = out / p.relative_to(stage)
        assert q.stat().st_mtime_ns == t
    assert len(list(out.glob("cells/*/claims.parquet"))) == 3
