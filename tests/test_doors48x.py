"""The classes of the sweep doors48x (brief X48: GNU Gama files both ways, at real sizes and in
real forms: every input of GNU Gama's own tree, round trips of the committed network studies and
of 2,500-point grids through ``gama-local`` 2.03, the export into awkward places and names), one
case each; each failed on the code before its fix.

* A ``gama-local`` file that lists many points nothing observes (a coordinate list exported
  whole beside a small network: 150,000 ``<point id=.. adj="xy"/>`` in a 5.6 MB file, under the
  16 MiB the reader takes) held ``sim check`` for more than five minutes: the reader left such
  points out with a list's ``in`` per point (quadratic). A set now: seconds.
* The same file's work and memory estimate counted every declared point (last session's left
  item "the gama estimate counting declared points"): 300,008 unknowns on the sparse path and
  0.547 GiB for a 3-point network, as ``sim check`` printed it. It counts the points the
  reader keeps now (observed, or fixed with coordinates): 8 unknowns, 5 KiB.
* A study reading a results directory's own ``network.xml`` (the export, edited by hand),
  run with ``--out`` that directory and ``--overwrite``, replaced the file it read with its
  export: the user's file lost, exit 0. Refused now before any work, naming the key and file.
* gama-local's own output (``<gama-local-adjustment>``, kept beside each input in Gama's tree)
  given as the input: the line says what it is now (and gama-g3's ``<gnu-gama-data>``).
"""

from __future__ import annotations

import time
from pathlib import Path

import pytest
from conftest import TRIANGLE_NETWORK
from gama_triangle import triangle

from sim.cli import main
from sim.mc.config import ConfigError
from sim.mc.gama_count import gama_counts
from sim.mc.network_size import network_counts
from sim.studies.network.gama_read import read_gama


def _file(tmp_path: Path, name: str, extra: str) -> Path:
    p = tmp_path / name
    p.write_text(triangle(extra=extra), encoding="utf-8")
    return p


def _unused(n: int) -> str:
    return "".join(f'      <point id="U{i}" adj="xy" />\n' for i in range(n))


def test_many_unobserved_points_are_left_out_in_linear_time(tmp_path):
    """Hang: points nothing observes (here without coordinates) were left out with a list's
    ``in`` per point: 30,000 of them took 16 s of CPU (150,000, a 5.6 MB file, over five
    minutes). Ten times the points now take about ten times the CPU, not a hundred."""
    cpu = []
    for n in (2_000, 20_000):
        p = _file(tmp_path, f"u{n}.xml", _unused(n))
        t = time.process_time()
        rec = read_gama(p)
        cpu.append(time.process_time() - t)
        assert [r["name"] for r in rec["network.points"]] == ["A", "B", "C"]
        assert "'U0', 'U1', 'U2', 'U3', 'U4' and " in rec["note"]
    assert cpu[1] < 30 * cpu[0] + 0.5, cpu  # quadratic: about 100 times (7 s)


def test_the_estimate_counts_the_points_the_reader_keeps(tmp_path):
    """Silent nonsense in the estimate: every declared point was counted, kept or not (100
    unobserved ``adj`` points, with or without coordinates, and 2 unobserved fixed ones: 105
    points). The reader keeps 5 (A, B, C and the two fixed ones, which it holds as fixed
    points), and the count says 5; so a 3-point network with 150,000 unobserved points is
    estimated at its 3 points, not 300,008 unknowns on the sparse path."""
    extra = (
        _unused(50)
        + "".join(f'      <point id="V{i}" x="{i}" y="1" adj="xy" />\n' for i in range(50))
        + '      <point id="F1" x="5" y="5" fix="xy" />\n'
        + '      <point id=" F2 " x="6" y="5" fix="XY" />\n'  # (gama-local: fix is xy or XY)
        + '      <point id="F3" fix="xy" />\n'  # no coordinates: left out
    )
    p = _file(tmp_path, "m.xml", extra)
    kept = [r["name"] for r in read_gama(p)["network.points"]]
    assert sorted(kept) == ["A", "B", "C", "F1", "F2"]
    assert gama_counts(p).points == len(kept)
    c = network_counts({"network.gama_xml": str(p), "solver.max_iter": 20})
    assert not c.sparse and c.points == 5


def test_a_run_never_replaces_the_gama_file_its_study_reads(tmp_path, monkeypatch, capsys):
    """Data loss: a study reading a results directory's own ``network.xml`` (the export, edited
    by hand with the field's values), run with ``--out`` that directory and ``--overwrite``,
    read the file, then replaced it with its export: the user's file was gone, exit 0. Refused
    now before any work, naming the key and the file, which is left as it was."""
    monkeypatch.chdir(tmp_path)
    (tmp_path / "tri.toml").write_text(TRIANGLE_NETWORK)
    assert main(["run", "tri.toml", "--out", "r1", "--no-figures", "--quiet"]) == 0
    mine = (tmp_path / "r1/network.xml").read_text().replace("<description>", "<description>field ")
    (tmp_path / "r1/network.xml").write_text(mine)
    (tmp_path / "own.toml").write_text(
        'study = "network"\ntrials = 40\nchunk = 2\n[network]\ngama_xml = "r1/network.xml"\n'
    )
    capsys.readouterr()
    rc = main(["run", "own.toml", "--out", "r1", "--overwrite", "--no-figures", "--quiet"])
    err = capsys.readouterr().err.strip()
    assert rc == 2 and len(err.splitlines()) == 1, err
    assert err.startswith("sim: error: network.gama_xml: r1/network.xml is network.xml of --out r1")
    assert (tmp_path / "r1/network.xml").read_text() == mine


def test_gama_locals_output_given_as_its_input_says_so(tmp_path):
    """Unclear message: GNU Gama's tree keeps each input beside its adjustment (``x.gkf``,
    ``x.xml``); the ``.xml`` given as ``network.gama_xml`` was refused as "the root element is
    <gama-local-adjustment>, not <gama-local>", leaving the user to know what that is. The line
    says it is gama-local's output now, and to give the input it read."""
    p = tmp_path / "x.xml"
    p.write_text(
        '<?xml version="1.0" ?>\n<gama-local-adjustment xmlns="http://www.gnu.org/software/'
        'gama/gama-local-adjustment"><description/></gama-local-adjustment>\n'
    )
    with pytest.raises(ConfigError, match=r"not <gama-local> \(gama-local's output, its --xml"):
        read_gama(p)
