"""A short sweep of the configuration doors built in the session of 2026-11-28 (keys a study
never reads, claim ids, wolf's table sha256, study files outside studies/, the network's
national grid), one case per class found; each failed on the code before its fix.

* switching a file's pattern by an override (``--set plate.pattern=random`` on a study file
  with ``grid = 5``, or ``sim.load(..., plate__pattern="random")``) was refused naming the
  file's grid keys ("leave it out"), which no option can leave out: the shipped studies'
  pattern could not be changed without copying the file. The file's keys of a switch the
  user overrides are not refused; a key the override itself sets where it is not read is;
* ``sim check`` of a study file with a ``[sweep]`` listed the sweep as a comment
  (``# [sweep] plate.pattern``): saved as a study file, the listing (documented to give the
  same config) lost its sweep and was refused (the file's key of the random pattern, which
  the sweep's random cells read, is not read by the grid of the file's own values). The
  listing ends with the file's ``[sweep]`` table, and a key unread by the configuration but
  by no cell of the sweep is commented out even when not at its default;
* the network refused ``datum.points`` (and ``datum.constraints``) under another
  ``datum.kind`` in its own cross-key check, besides the schema's ``read_when``: a sweep of
  ``datum.kind`` over a file with ``datum.points`` was refused ("the values outside [sweep] are
  checked first"), or, with the file's kind ``inner``, its ``fixed`` cell recorded infeasible
  (a brown sweep of ``plate.pattern`` runs the cell that does not read ``plate.n_random``),
  and an override of the file's ``datum.kind`` was refused. The ``read_when`` alone decides;
* a recorded sha256 (``table1.sha256``, ``network.gama_sha256``) in upper case, the same
  digest, was refused as "has changed since the study was loaded", and one that is no sha256
  at all ("abc") was refused with the same words: it is compared in lower case, and a value
  of another form is refused saying what a sha256 is.
"""

from __future__ import annotations

import hashlib
from pathlib import Path

import pytest
from oneline import SIM_ERROR, one_line

import sim
from sim.cli import main
from sim.mc.config import ConfigError
from sim.studies import load_study

ROOT = Path(__file__).resolve().parent.parent
DILUTION = ROOT / "studies" / "brown_dilution.toml"


def test_an_override_of_the_pattern_leaves_the_files_grid_keys_unread(capsys):
    _, cfg = load_study(DILUTION, ['plate.pattern="random"', "plate.n_random=30"])
    assert cfg["plate.pattern"] == "random" and cfg["plate.n_random"] == 30
    h = sim.load(DILUTION, plate__pattern="random", plate__n_random=12)
    assert h.config["plate.n_random"] == 12
    # the listing saved loads as the same study: the grid's keys commented out
    assert main(["check", str(DILUTION), "--set", 'plate.pattern="random"']) == 0
    out = capsys.readouterr().out
    assert "\n# plate.grid = 5 " in out and "\nplate.n_random = 25 " in out, out
    # a key the override sets where it is not read is still refused
    one_line(
        capsys,
        main(["check", str(DILUTION), "--set", "plate.n_random=30"]),
        "plate.n_random: is not read when plate.pattern = 'grid'",
        prefix=SIM_ERROR,
    )
    with pytest.raises(ConfigError, match=r"^plate.points: is not read"):
        sim.load(DILUTION, plate__pattern="random", plate__points=[[0.0, 0.0]])


def test_the_check_listing_of_a_sweep_saved_is_the_same_sweep(tmp_path, capsys):
    f = tmp_path / "sweep.toml"
    f.write_text(
        'study = "brown_dilution"\ntrials = 40\nchunk = 2\nplate.n_random = 30\n'
        '[sweep]\n"plate.pattern" = ["grid", "random"]\n'
    )
    assert main(["check", str(f)]) == 0
    listing = capsys.readouterr().out
    assert '\n[sweep]\n"plate.pattern" = ["grid", "random"]\n' in listing, listing
    saved = tmp_path / "saved.toml"
    saved.write_text(listing)
    assert main(["check", str(saved)]) == 0
    assert capsys.readouterr().out == listing
    assert load_study(saved)[1] == load_study(f)[1]


NETWORK = """study = "network"
trials = 40
chunk = 2
[network]
points = [ { name = "A", x_mm = 0.0, y_mm = 0.0, role = "fixed" },
           { name = "B", x_mm = 400.0, y_mm = 0.0, role = "fixed" },
           { name = "C", x_mm = 400.0, y_mm = 300.0 }, { name = "P", x_mm = 150.0, y_mm = 120.0 } ]
generate = [ { kind = "distance", from = ["A", "B", "C"], to = "*", sigma_mm = 0.002 },
             { kind = "direction", from = ["A", "B", "C"], to = "*", sigma_arcsec = 2.0 } ]
[datum]
KIND
points = ["A", "B", "C"]
"""


@pytest.mark.parametrize("kind", ["", 'kind = "inner"', 'kind = "fixed"'])
def test_a_sweep_of_the_datum_kind_runs_every_cell(tmp_path, capsys, kind):
    f = tmp_path / "net.toml"
    f.write_text(NETWORK.replace("KIND", kind) + '[sweep]\n"datum.kind" = ["fixed", "inner"]\n')
    if "inner" in kind:  # the file's own datum, checked first: inner on fixed A, B (s37)
        one_line(capsys, main(["check", str(f)]), "nothing to constrain", prefix=SIM_ERROR)
        return
    assert main(["check", str(f)]) == 0
    err = capsys.readouterr().err  # datum.points read in the inner cell, unread in the fixed
    assert "is not read" not in err  # one; the inner cell on fixed A, B: refused (s37)
    assert "1 of 2 cells are infeasible" in err and "nothing to constrain" in err


def test_an_override_of_the_network_datum_kind_leaves_the_files_points_unread(tmp_path, capsys):
    f = tmp_path / "net.toml"
    f.write_text(NETWORK.replace("KIND", 'kind = "inner"'))
    _, cfg = load_study(f, ['datum.kind="fixed"'])
    assert cfg["datum.kind"] == "fixed"
    f.write_text(NETWORK.replace("KIND", 'kind = "fixed"'))  # the file's own kind: refused
    one_line(
        capsys,
        main(["check", str(f)]),
        "datum.points: is not read when datum.kind = 'fixed'",
        prefix=SIM_ERROR,
    )


WOLF = ROOT / "studies" / "wolf_polynomial.toml"


def test_a_recorded_sha256_in_upper_case_is_the_same_digest(capsys):
    sha = hashlib.sha256((ROOT / "studies/data/wolf_table1.csv").read_bytes()).hexdigest()
    _, cfg = load_study(WOLF, [f'table1.sha256="{sha.upper()}"'])
    assert cfg["table1.sha256"] == sha
    one_line(
        capsys,
        main(["check", str(WOLF), "--set", 'table1.sha256="abc"']),
        "table1.sha256: is not a sha256 (64 hexadecimal digits)",
        prefix=SIM_ERROR,
    )
    other = ("0" if sha[0] != "0" else "1") + sha[1:]
    with pytest.raises(ConfigError, match="has changed since the study was loaded"):
        load_study(WOLF, [f'table1.sha256="{other}"'])


def test_a_key_the_files_own_values_do_not_read_says_they_are_checked_first(tmp_path, capsys):
    """doors23a left it: ``network.constant_mm`` with ``network.generate`` swept between
    directions alone (the file's own value) and distances read "is not read: the network has
    none", of a network that one cell has: the line now says the values outside [sweep] are
    checked first, as a study of their own, and what to give there."""
    dirs = '[ { kind = "direction", from = ["A", "B", "C"], to = "*", sigma_arcsec = 2.0 } ]'
    dist = '[ { kind = "distance", from = ["A", "B", "C"], to = "*", sigma_mm = 0.002 } ]'
    text = NETWORK.replace("KIND", 'kind = "fixed"').replace('points = ["A", "B", "C"]\n', "")
    head, rest = text.split("generate = ", 1)
    rest = rest.split("\n[datum]", 1)[1]
    f = tmp_path / "net.toml"
    f.write_text(
        f"{head}constant_mm = 0.5\ngenerate = {dirs}\n[datum]{rest}"
        f'[sweep]\n"network.generate" = [{dirs}, {dist}]\n'
    )
    one_line(
        capsys,
        main(["check", str(f)]),
        "network.constant_mm",
        "checked first, as a study of their own, with network.generate as given there",
        prefix=SIM_ERROR,
    )


@pytest.mark.parametrize("what", ["directory", "fifo", "device"])
def test_a_table_path_that_is_no_regular_file_is_named_so(tmp_path, capsys, what):
    """doors23a left it: ``table1.file`` naming a directory, a FIFO or ``/dev/zero`` read "no
    such file" of a path that exists."""
    import os

    p = {"directory": tmp_path, "device": Path("/dev/zero"), "fifo": tmp_path / "t.csv"}[what]
    if what == "fifo":
        os.mkfifo(p)
    rc = main(["check", str(WOLF), "--set", f"table1.file={str(p)!r}"])
    one_line(capsys, rc, "table1.file", "is not a regular file", prefix=SIM_ERROR)
