"""A declared point that no observation reaches is named, in every datum kind (issue 26, left3).

A GNU Gama file of a free network (inner datum) with a fixed point nothing observes was
refused with "a rank defect ... that the datum does not cover: ... or use datum.kind = inner",
the datum it already had; with a fixed datum the message blamed the observed points ("tied to
the datum by no observation"), with constraints it blamed their number. Now the point is
named, as fixed or free, with the file that declares it; an unused fixed point of a network
held otherwise (a list of control points, some unused) is still accepted. An ``adj`` point of a
GNU Gama file that nothing observes is left out since doors44l, as ``gama-local`` removes it
("singular coordinates"), and the report's note names it.
"""

from pathlib import Path

import pytest
from oneline import one_line

from sim.cli import main

ROOT = Path(__file__).resolve().parent.parent
GAMA = ROOT / "tests" / "data" / "gama"
Q = {
    "fixed": '<point id="Q" x="100.0" y="100.0" fix="xy" />',
    "free": '<point id="Q" x="100.0" y="100.0" adj="xy" />',
    "inner": '<point id="Q" x="100.0" y="100.0" adj="XY" />',
}
DATUM = {
    "file": "",  # the file's own: inner (adj="XY" points, no fixed one) or fixed
    "inner": '[datum]\nkind = "inner"\n',
    "fixed": '[datum]\nkind = "fixed"\n',
    "constraints": '[datum]\nkind = "constraints"\nconstraints = [ { "P1.x" = 1.0 }, '
    '{ "P1.y" = 1.0 }, { "P2.x" = 1.0 }, { "P2.y" = 1.0 } ]\n',
}


def _study(tmp_path: Path, source: str, point: str, datum: str) -> str:
    """A study of ``source`` (a reference gama-local file) with the point Q added after its
    first point; Q is in no observation."""
    text = (GAMA / source).read_text()
    i = text.index("<point ")
    (tmp_path / "net.xml").write_text(text[:i] + point + "\n      " + text[i:])
    f = tmp_path / "net.toml"
    f.write_text(
        f'study = "network"\ntrials = 200\nchunk = 10\n[network]\ngama_xml = "{tmp_path / "net.xml"}"\n'
        + datum
    )
    return str(f)


@pytest.mark.parametrize("datum", DATUM)
@pytest.mark.parametrize("role", Q)
def test_a_point_of_a_free_gama_network_nothing_observes_is_named(tmp_path, capsys, role, datum):
    f = _study(tmp_path, "directions_free.xml", Q[role], DATUM[datum])
    if datum == "fixed":  # fewer than two fixed points: the datum given is refused first
        fixed = int(role == "fixed")
        one_line(capsys, main(["check", f]), "datum.kind", f"net.xml has {fixed} fixed point")
        return
    if role != "fixed":  # an adj one: left out, as gama-local removes it (doors44l)
        assert main(["check", f]) == 0, capsys.readouterr().err
        return
    err = one_line(capsys, main(["check", f]), "network.gama_xml", "'Q'", "net.xml")
    assert "declared in" in err and "no observation reaches it" in err, err
    assert err.count("fixed point 'Q'") == (role == "fixed"), err
    assert "datum.kind = inner" not in err, err  # never the datum it has (nor a guess)


def test_an_unused_fixed_point_of_a_network_held_otherwise_is_accepted(tmp_path, capsys):
    f = _study(tmp_path, "testfield.xml", Q["fixed"], "")
    assert main(["check", f]) == 0, capsys.readouterr().err
    f = _study(tmp_path, "testfield.xml", Q["free"], "")  # a free one: left out, as gama-local
    assert main(["check", f]) == 0, capsys.readouterr().err


@pytest.mark.parametrize("kind", ["inner", "fixed"])
def test_a_fixed_point_nothing_observes_in_a_study_file_is_named(tmp_path, capsys, kind):
    f = tmp_path / "net.toml"
    f.write_text(
        'study = "network"\ntrials = 200\nchunk = 10\n[network]\npoints = [\n'
        '  { name = "A", x_mm = 0.0, y_mm = 0.0, role = "fixed" },\n'
        '  { name = "B", x_mm = 400.0, y_mm = 0.0 }, { name = "C", x_mm = 400.0, y_mm = 300.0 },\n'
        '  { name = "D", x_mm = 0.0, y_mm = 300.0 }, { name = "P", x_mm = 150.0, y_mm = 120.0 } ]\n'
        'generate = [ { kind = "distance", from = ["B", "C", "D"], to = ["B", "C", "D", "P"], '
        "sigma_mm = 0.002 } ]\n"
        f'[datum]\nkind = "{kind}"\n'
    )
    err = one_line(capsys, main(["check", str(f)]), "network.points", "fixed point 'A'")
    assert "declared in the study file but no observation reaches it" in err, err
