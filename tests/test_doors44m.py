"""Helper m44: real sizes (brown_design with workers and Dask, the bar's time left, a GNU Gama
file read three times); one case per class found, each failing on the code before its fix
(small sizes here, the measured ones in the docstrings).

* a run of a ``network.gama_xml`` study parsed the file three times (the load's check, the
  run's network, the report's note; ``sim check`` twice), each a full parse and check of
  every element: a 6.3 MB file of 10,002 points and 80,006 observations took 4.4, 6.0 and
  4.0 s (wall, on the loaded 2-core machine) of a 74 s run of 40 trials. It is now parsed
  once per process and content (:mod:`sim.studies.network.gama_cache`, keyed by the file's
  path and the sha256 of its bytes, which are read again each time): one parse, and an edit
  of the file between two loads is still seen (parsed again, its digest recorded anew).
"""

from __future__ import annotations

from pathlib import Path

import sim
import sim.studies.network.gama_read as gama_read
from sim.studies import load_study
from sim.studies.network.definition import build
from sim.studies.network.gama import merge_gama, write_gama
from tests.conftest import TRIANGLE_NETWORK


def _gama_study(tmp_path: Path) -> tuple[Path, Path]:
    """A four-point network written as a gama-local file, and a study file that reads it."""
    text = TRIANGLE_NETWORK.replace(
        '{ name = "C", x_mm = 400.0, y_mm = 700.0 } ]',
        '{ name = "C", x_mm = 400.0, y_mm = 700.0 }, { name = "D", x_mm = 600.0, y_mm = -500.0 } ]',
    )
    src = tmp_path / "src.toml"
    src.write_text(text, encoding="utf-8")
    xml = write_gama(build(load_study(src)[1]), tmp_path / "net.xml")
    st = tmp_path / "gama.toml"
    st.write_text(
        f'study = "network"\ntrials = 40\nchunk = 2\n[network]\ngama_xml = "{xml}"\n',
        encoding="utf-8",
    )
    return st, xml


def test_a_gama_file_is_parsed_once_a_run_and_an_edit_is_seen(tmp_path, monkeypatch):
    """The load and the run of a study reading a gama-local file parse it once (three times
    before); the file edited after, the next load parses it again and records its new digest;
    the records a caller gets are its own (changed, the next reader's are not)."""
    st, xml = _gama_study(tmp_path)
    parses = []
    real = gama_read._network
    monkeypatch.setattr(gama_read, "_network", lambda *a: parses.append(1) or real(*a))
    handle = sim.load(st)
    res = handle.run(out=tmp_path / "o", figures=False)
    assert len(parses) == 1
    assert res.table("points").num_rows > 0
    sha = handle.config["network.gama_sha256"]
    first = merge_gama(handle.config)
    first["network.points"][0]["x_mm"] = 1.0  # the caller's copy, not the kept one
    assert merge_gama(handle.config)["network.points"] != first["network.points"]
    assert len(parses) == 1
    xml.write_text(xml.read_text().replace('stdev="0.01"', 'stdev="0.02"', 1), encoding="utf-8")
    again = sim.load(st)
    assert len(parses) == 2
    assert again.config["network.gama_sha256"] != sha
    sigmas = [o["sigma_mm"] for o in merge_gama(again.config)["network.observations"]]
    assert sigmas[0] == 0.02 and sigmas[1:] == [0.01] * (len(sigmas) - 1)
    assert len(parses) == 2
