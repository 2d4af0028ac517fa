"""What the sessions left under issue 26 (notes/note11.md, "Left, with the reasons"), one case
each; each failed on the code before its fix.

* a key the study never reads was accepted (``plate.n_random`` with ``plate.pattern =
  "grid"``, in the file, by ``--set``, by the Python API or swept): the run, or the sweep's
  cells, differed only by seed while the user believed they varied something. A schema says
  when a key is read (``Field.read_when``, :mod:`sim.mc.read_when`), and a key the user set
  where it is not read is refused at load, one line naming the key, the switch and its value;
  a sweep is judged over its cells. The network refuses the keys of the distances in a
  network without one (a condition of its observations, not of a switch);
* a claim removed from a claim book was caught at the end of the run (the study scores an id
  the book no longer declares): the ids the study's code names as literals (120 of the 334
  scored ids) are read from its package's source and checked against the book when the file is
  loaded (``sim check``, the start of ``sim run``; :mod:`sim.studies.scored_ids`); the ids the
  code builds (f-strings over loops, a transcribed table's rows) are still caught at the end;
* a network with a group of points tied to nothing under ``datum.kind = "constraints"`` was
  refused blaming "a datum defect of 0" (the fixed points hold the rest: the count of the
  constraints was blamed), or "a rank defect of 6" when no point is held; the group is named
  and said to be tied to nothing, and the advice, followed, loads.
"""

from __future__ import annotations

from pathlib import Path

import pytest
from oneline import SIM_ERROR, one_line

import sim
from sim.cli import main
from sim.mc.config import ConfigError, check_value
from sim.mc.read_when import When
from sim.mc.registry import MODULES
from sim.studies import get_study, load_study
from sim.studies.salsig import claims as salsig_claims
from sim.studies.scored_ids import check_literal_ids

ROOT = Path(__file__).resolve().parent.parent
DILUTION = ROOT / "studies" / "brown_dilution.toml"
TABLE1 = ROOT / "studies" / "brown_table1.toml"
AGNARD = ROOT / "studies" / "agnard_block.toml"
PLATE = ROOT / "studies" / "network_plate.toml"  # dx, dy and observed coordinates: no distance
FIELD = ROOT / "studies" / "network_testfield.toml"  # distances and directions, fixed datum
GAMA_XML = ROOT / "tests" / "data" / "gama" / "one_fixed.xml"
SALSIG = ROOT / "studies" / "salsig_encoders.toml"


# ------------------------------------------------------------------ 1. keys a study never reads


def test_a_random_pattern_key_set_by_option_for_a_grid_is_refused(capsys):
    line = one_line(
        capsys,
        main(["check", str(DILUTION), "--set", "plate.n_random=40"]),
        "plate.n_random: is not read when plate.pattern = 'grid'",
        "read only when plate.pattern = 'random'",
        prefix=SIM_ERROR,
    )
    assert line.count("plate.n_random") == 1, line


def test_a_grid_key_in_the_file_of_a_random_pattern_is_refused(tmp_path, capsys):
    f = tmp_path / "random.toml"  # the file keeps grid = 5 and spacing_mm = 45.0
    f.write_text(TABLE1.read_text().replace('pattern = "grid"', 'pattern = "random"'))
    argv = ["check", str(f), "--set", "plate.random_half_extent_mm=80"]
    one_line(
        capsys,
        main(argv),
        "plate.grid: is not read when plate.pattern = 'random'",
        prefix=SIM_ERROR,
    )
    # without the grid's keys the random pattern loads, reading what it is given
    f.write_text(f.read_text().replace("grid = 5\n", "").replace("spacing_mm = 45.0\n", ""))
    _, cfg = load_study(f, ["plate.random_half_extent_mm=80", "plate.n_random=30"])
    assert cfg["plate.pattern"] == "random" and cfg["plate.n_random"] == 30


def test_the_python_api_refuses_a_key_it_would_not_read():
    with pytest.raises(
        ConfigError, match=r"^plate.points: is not read when plate.pattern = 'grid'"
    ):
        sim.load(DILUTION, plate__points=[[0.0, 0.0], [50.0, 0.0], [0.0, 50.0], [50.0, 50.0]])


def test_a_swept_key_read_in_no_cell_is_refused_before_the_sweep_runs(tmp_path, capsys):
    f = tmp_path / "sweep.toml"
    f.write_text(TABLE1.read_text() + '[sweep]\n"plate.n_random" = [10, 20]\n')
    one_line(
        capsys,
        main(["run", str(f), "--out", str(tmp_path / "out"), "--trials", "40", "--quiet"]),
        "sweep.plate.n_random: is not read when plate.pattern = 'grid' in every cell",
        prefix=SIM_ERROR,
    )
    assert not (tmp_path / "out").exists()


def test_a_key_of_the_file_is_judged_over_the_cells_that_set_its_switch(tmp_path, capsys):
    text = TABLE1.read_text().replace("grid = 5\n", "").replace("spacing_mm = 45.0\n", "")
    text = text.replace('pattern = "grid"\n', "n_random = 30\nrandom_half_extent_mm = 80.0\n")
    f = tmp_path / "sweep.toml"
    f.write_text(text + '[sweep]\n"plate.pattern" = ["grid", "list"]\n')
    one_line(
        capsys,
        main(["check", str(f)]),
        "plate.n_random: is not read when plate.pattern = 'grid' or 'list' in every cell",
        prefix=SIM_ERROR,
    )
    # a cell that reads it: the sweep is accepted (its grid cell runs the default grid), and
    # the listing keeps the value its random cells read (not commented out as unread)
    f.write_text(text + '[sweep]\n"plate.pattern" = ["grid", "random"]\n')
    assert main(["check", str(f)]) == 0, capsys.readouterr().err
    assert "\nplate.n_random = 30  # " in capsys.readouterr().out


def test_an_optional_part_switched_off_does_not_read_its_keys(capsys):
    one_line(
        capsys,
        main(["check", str(AGNARD), "--set", "pugging.gross_px=[1.0, 9.0]"]),
        "pugging.gross_px: is not read when pugging.gross_rate = 0.0",
        prefix=SIM_ERROR,
    )
    _, cfg = load_study(AGNARD, ["pugging.gross_px=[1.0, 9.0]", "pugging.gross_rate=0.01"])
    assert cfg["pugging.gross_px"] == [1.0, 9.0]


@pytest.mark.parametrize(
    "setting, key, switch",
    [
        ("datum.constraints=[]", "datum.constraints", "datum.kind = 'fixed'"),
        ("datum.points=[]", "datum.points", "datum.kind = 'fixed'"),
        ('network.gama_sha256=""', "network.gama_sha256", "network.gama_xml = ''"),
    ],
)
def test_a_network_key_of_another_datum_or_of_an_imported_file_is_refused(
    capsys, setting, key, switch
):
    argv = ["check", str(FIELD), "--set", setting]
    one_line(capsys, main(argv), f"{key}: is not read when {switch}", prefix=SIM_ERROR)


def test_the_network_of_the_study_file_is_not_read_beside_an_imported_one(tmp_path, capsys):
    f = tmp_path / "gama.toml"
    f.write_text(f'study = "network"\ntrials = 40\nchunk = 2\n[network]\ngama_xml = "{GAMA_XML}"\n')
    assert main(["check", str(f)]) == 0, capsys.readouterr().err
    capsys.readouterr()
    one_line(
        capsys,
        main(["check", str(f), "--set", "network.generate=[]"]),
        "network.generate: is not read when network.gama_xml = ",
        "read only without network.gama_xml",
        prefix=SIM_ERROR,
    )


@pytest.mark.parametrize(
    "key, value",
    [
        ("network.constant_mm", "0.5"),
        ("network.offset_mm", "1.0"),
        ("network.scale_ppm", "20.0"),
        ("network.estimate_scale", "false"),
    ],
)
def test_a_key_of_the_distances_in_a_network_without_one_is_refused(capsys, key, value):
    argv = ["check", str(PLATE), "--set", f"{key}={value}"]
    one_line(capsys, main(argv), f"{key}: is not read", "has none", prefix=SIM_ERROR)
    assert main(["check", str(FIELD), "--set", f"{key}={value}"]) == 0  # it has distances
    capsys.readouterr()


def test_a_swept_key_of_the_distances_in_a_network_without_one_is_refused(tmp_path, capsys):
    f = tmp_path / "sweep.toml"
    f.write_text(PLATE.read_text() + '[sweep]\n"network.scale_ppm" = [0.0, 20.0]\n')
    one_line(
        capsys, main(["check", str(f)]), "sweep.network.scale_ppm", "has none", prefix=SIM_ERROR
    )


@pytest.mark.parametrize("study_file", sorted((ROOT / "studies").glob("*.toml")), ids=str)
def test_every_shipped_study_file_sets_only_keys_it_reads(study_file):
    load_study(study_file)  # a key left at its default is never refused; none set is inert


def _schemas():
    for name in sorted(MODULES):
        study = get_study(name)
        for key, f in study.schema.items():
            if f.read_when is not None:
                yield name, study.schema, key, f.read_when


def test_every_declared_condition_names_a_switch_of_its_schema_and_values_it_takes():
    seen = 0
    for name, schema, key, w in _schemas():
        assert isinstance(w, When) and w.switch in schema and w.switch != key, (name, key)
        for v in w.values:  # each value one the switch takes (a choice of a pattern or a kind)
            assert check_value(w.switch, schema[w.switch], v) == v, (name, key, v)
        seen += 1
    assert seen >= 12  # brown's pattern keys (both studies), agnard's, the network's


def test_a_condition_tells_a_number_from_a_bool():
    w = When("pugging.gross_rate", (0.0,), negate=True)
    assert not w.reads(0) and not w.reads(0.0) and w.reads(0.01)
    assert When("x", (1,)).reads(1.0) and not When("x", (1,)).reads(True)


def test_the_check_listing_comments_out_what_the_configuration_does_not_read(capsys):
    """Saved as a study file, the listing gives the same config (test_check_toml): a key not
    read is listed commented out, saying why, or the listing would be refused."""
    assert main(["check", str(TABLE1)]) == 0
    out = capsys.readouterr().out.splitlines()
    assert any(x.startswith("# plate.n_random = 25  # ") for x in out), out
    assert any(x.startswith("plate.grid = 5  # ") for x in out), out
    n_random = next(x for x in out if x.startswith("# plate.n_random"))
    assert n_random.endswith("not read: plate.pattern = 'grid')"), n_random
    assert main(["check", str(PLATE)]) == 0
    out = capsys.readouterr().out
    assert "# network.constant_mm = 0.0  # " in out and "the network has none" in out


# ----------------------------------------------------------- 2. a claim removed from the book


def _without(text: str, cid: str) -> str:
    """The claim book ``text`` without the ``[[claim]]`` table of ``cid``."""
    parts = text.split("[[claim]]")
    kept = [p for p in parts[1:] if f'id = "{cid}"' not in p]
    assert len(kept) == len(parts) - 2, cid  # exactly one table removed
    return "[[claim]]".join([parts[0], *kept])


@pytest.mark.parametrize("cid", ["salsig.recovery.SX", "salsig.vertical_halved.rms_ratio"])
def test_a_claim_the_code_names_removed_from_the_book_is_refused_by_sim_check(
    tmp_path, monkeypatch, capsys, cid
):
    book = tmp_path / "claims.toml"
    book.write_text(_without(salsig_claims.BOOK.read_text(encoding="utf-8"), cid))
    monkeypatch.setattr(salsig_claims, "BOOK", book)
    one_line(
        capsys,
        main(["check", str(SALSIG)]),
        f"claim.id: {book}: claim '{cid}', which the study scores (",
        "is not declared",
        prefix=SIM_ERROR,
    )


def test_the_check_of_the_named_ids_reads_the_package_not_the_book_directory(tmp_path):
    """A book read from elsewhere (a user's copy) is checked against the study's own code."""
    package = Path(salsig_claims.__file__).parent
    book = salsig_claims.load_book()
    check_literal_ids(book, package)  # the shipped book declares every id the code names
    del book.specs["salsig.recovery.SY"]
    with pytest.raises(ConfigError, match=r"claim 'salsig.recovery.SY', .* \(claims.py\)"):
        check_literal_ids(book, package)
    check_literal_ids(book, tmp_path)  # no code there: nothing named


def test_the_two_studies_of_one_book_check_only_the_ids_each_scores(tmp_path, monkeypatch):
    """brown_dilution and brown_table1 split one book: a Table 1 claim removed is refused by
    brown_table1, not by brown_dilution (whose code never scores it)."""
    from sim.studies.brown import claims as brown_claims

    cid = "brown.table1_closure.rms_um"
    book = tmp_path / "claims.toml"
    book.write_text(_without(brown_claims.BOOK.read_text(encoding="utf-8"), cid))
    monkeypatch.setattr(brown_claims, "BOOK", book)
    load_study(DILUTION)
    with pytest.raises(ConfigError, match=f"claim '{cid}', which the study scores"):
        load_study(TABLE1)


# ------------------------------------------- 3. a group tied to nothing under minimal constraints

ISLAND = """study = "network"
trials = 40
chunk = 2
seed = 1

[network]
points = [ { name = "A", x_mm = 0.0, y_mm = 0.0, role = "fixed" },
  { name = "B", x_mm = 100.0, y_mm = 0.0, role = "fixed" }, { name = "C", x_mm = 50.0, y_mm = 80.0 },
  { name = "D", x_mm = 500.0, y_mm = 500.0 }, { name = "E", x_mm = 600.0, y_mm = 500.0 } ]
observations = [ { kind = "distance", from = "A", to = "C", sigma_mm = 0.01 },
  { kind = "distance", from = "B", to = "C", sigma_mm = 0.01 },
  { kind = "distance", from = "D", to = "E", sigma_mm = 0.01 } ]
[datum]
kind = "constraints"
constraints = [ { "D.x" = 1.0 }, { "D.y" = 1.0 }, { "E.y" = 1.0 } ]
"""


def test_a_group_tied_to_nothing_under_constraints_is_named(tmp_path, capsys):
    f = tmp_path / "island.toml"
    f.write_text(ISLAND)
    line = one_line(
        capsys,
        main(["check", str(f)]),
        "datum.constraints: points 'D', 'E' are tied to the datum by no observation",
        "cannot hold such a part",
        prefix=SIM_ERROR,
    )
    assert "minimal constraints are as many as the defect" not in line, line
    # the advice followed: fix two of its points, the fixed datum without constraints
    fixed = ISLAND.replace("y_mm = 500.0 }", 'y_mm = 500.0, role = "fixed" }')
    fixed = fixed.replace('kind = "constraints"', 'kind = "fixed"').split("constraints = ")[0]
    f.write_text(fixed)
    assert main(["check", str(f)]) == 0, capsys.readouterr().err
    capsys.readouterr()


def test_the_part_the_constraints_do_not_name_is_the_one_tied_to_nothing(tmp_path, capsys):
    """No point held: the constraints hold the part they name (D, E, F); the other part is
    named, where "a rank defect of 6" was said."""
    f = tmp_path / "parts.toml"
    text = ISLAND.replace(', role = "fixed"', "").replace(
        "observations = [",
        'observations = [ { kind = "distance", from = "A", to = "B", sigma_mm = 0.01 },\n'
        '  { kind = "distance", from = "E", to = "F", sigma_mm = 0.01 },\n'
        '  { kind = "distance", from = "D", to = "F", sigma_mm = 0.01 },',
    )
    text = text.replace(
        '{ name = "E", x_mm = 600.0, y_mm = 500.0 } ]',
        '{ name = "E", x_mm = 600.0, y_mm = 500.0 }, { name = "F", x_mm = 550.0, y_mm = 580.0 } ]',
    )
    f.write_text(text)
    one_line(
        capsys,
        main(["check", str(f)]),
        "points 'A', 'B', 'C' are tied to the datum by no observation",
        prefix=SIM_ERROR,
    )
