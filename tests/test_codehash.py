"""Staleness per study: a study's code hash covers the modules it imports, and only those."""

import ast
from pathlib import Path

from sim.mc import codehash
from sim.mc.codehash import study_files

ROOT = Path(__file__).resolve().parent.parent


def names(study):
    return {f.relative_to(ROOT / "sim").as_posix() for f in study_files(study)}


def test_closure_follows_imports_and_stops_there():
    brown, wolf = names("brown_table1"), names("wolf_polynomial")
    assert "instruments/ranges/multilateration.py" in brown
    assert "instruments/plotter/polynomial.py" in wolf
    assert "instruments/plotter/polynomial.py" not in brown  # Brown does not import the Wolf model
    assert not any(
        n.startswith("report/verify") for n in brown | wolf
    )  # verification: not study code
    assert "claims/book.py" in brown and "mc/storage.py" in wolf


def test_every_study_has_its_own_closure():
    from sim.studies import MODULES

    for study in MODULES:
        assert any(f.startswith("studies/") for f in names(study)), study


def test_results_are_current_until_the_config_changes(tmp_path):
    from sim.batch import is_current
    from sim.cli import main

    text = (ROOT / "studies" / "brown_table1.toml").read_text()
    study = tmp_path / "brown_table1.toml"
    study.write_text(
        text.replace("trials = ", "trials = 40 # ", 1).replace("chunk = ", "chunk = 2 # ", 1)
    )
    out = tmp_path / "out"
    assert not is_current(study, out)  # nothing there yet
    assert main(["run", str(study), "--out", str(out), "--quiet", "--no-figures"]) == 0
    assert not is_current(study, out)  # results without figures: make reproduce draws them
    assert not list(out.glob("*.png")) and "not drawn" in (out / "README.md").read_text()
    assert main(["run", str(study), "--out", str(out), "--quiet"]) == 0
    assert is_current(study, out) and list(out.glob("*.png"))
    assert "not drawn" not in (out / "README.md").read_text()
    study.write_text(study.read_text().replace("seed = ", "seed = 11 # ", 1))
    assert not is_current(study, out)


def test_import_lines_are_read_in_every_form(tmp_path, monkeypatch):
    """Relative and absolute imports, aliases, lists over several lines, imports inside
    functions, comments; ``from __future__`` and other packages are not ``sim`` code."""
    import sim.mc.codehash as ch

    pkg = tmp_path / "sim" / "studies" / "demo"
    pkg.mkdir(parents=True)
    f = pkg / "run.py"
    f.write_text(
        "from __future__ import annotations\n"
        "import numpy as np, sim.mc.heap as hp  # a comment\n"
        "from ...instruments.plotter import (errorfields as ef,  # the fields\n"
        "                 polynomial,\n"
        ")\n"
        "from .model import Instrument\n"
        "from ...lsq.linear import \\\n    lstsq\n"
        "def f():\n"
        "    from ...mc import storage\n"
        "x = 'import os'  # not at a line's start: not an import\n"
    )
    monkeypatch.setattr(ch, "ROOT", tmp_path / "sim")
    assert ch._imports(f) == {
        "sim.mc.heap",
        "sim.instruments.plotter",
        "sim.instruments.plotter.errorfields",
        "sim.instruments.plotter.polynomial",
        "sim.studies.demo.model",
        "sim.studies.demo.model.Instrument",
        "sim.lsq.linear",
        "sim.lsq.linear.lstsq",
        "sim.mc",
        "sim.mc.storage",
    }


def test_the_statement_walk_finds_every_import_node():
    """``_statements`` (the code hash's import finder) yields the import nodes ``ast.walk``
    finds, in every file of ``sim/`` and in a module that imports in every kind of block."""
    nested = (
        "import sim.a\ndef f():\n    import sim.b\nclass C:\n    def g(self):\n"
        "        from sim import c\nif x:\n    pass\nelse:\n    import sim.d\n"
        "try:\n    pass\nexcept E:\n    import sim.e\nfinally:\n    import sim.f\n"
        "for i in y:\n    pass\nelse:\n    import sim.g\nwith z:\n    import sim.h\n"
        "match v:\n    case 1:\n        import sim.i\n"
    )
    sources = [nested] + [p.read_text() for p in (ROOT / "sim").rglob("*.py")]
    for src in sources:
        tree = ast.parse(src)
        kinds = (ast.Import, ast.ImportFrom)
        walked = [n for n in ast.walk(tree) if isinstance(n, kinds)]
        ours = [n for n in codehash._statements(tree.body) if isinstance(n, kinds)]
        assert {id(n) for n in ours} == {id(n) for n in walked}
    assert len([n for n in ast.walk(ast.parse(nested)) if isinstance(n, ast.Import)]) == 8


def _walked(src: str) -> list[str]:
    kinds = (ast.Import, ast.ImportFrom)
    return sorted(ast.dump(n) for n in ast.walk(ast.parse(src)) if isinstance(n, kinds))


def _scanned(src: str) -> list[str]:
    kinds = (ast.Import, ast.ImportFrom)
    return sorted(ast.dump(n) for n in codehash._import_nodes(src, "x.py") if isinstance(n, kinds))


def test_the_line_scan_reads_the_import_statements_the_parser_finds():
    """The code hash reads import lines, not whole modules (0.4 s of CPU per run): on every
    file of ``sim/`` and on sources with imports in every block, over several lines, inline
    (``if x: import y``, ``a; import y``) and a docstring line that starts like an import but
    is prose, it finds exactly the import statements of the parsed module."""
    tricky = [
        "import sim.a\ndef f():\n    import sim.b\nclass C:\n    def g(self):\n"
        "        from sim import (c,\n   d)  # )\nfrom sim.e import \\\n    f\n",
        "if x: import sim.a\nimport sim.b\n",  # inline: the whole module is parsed
        "a = 1; from sim import b\nimport sim.c\n",
        '"""Notes\nimport of sim.a is lazy (prose)\n"""\nimport sim.b\n',  # prose: parsed whole
        "try:\n    import sim.a\nexcept ImportError:\n    from sim import b as c\n",
    ]
    for src in tricky + [p.read_text() for p in (ROOT / "sim").rglob("*.py")]:
        assert _scanned(src) == _walked(src)
    assert len(_walked(tricky[1])) == 2 and len(_walked(tricky[3])) == 1


def test_an_import_line_inside_a_string_only_widens_the_closure():
    """A string line that reads as an import statement counts as one: the hash covers a file
    more than it needs, never less (a missed import would leave results current after their
    code changed)."""
    src = '"""Example:\nfrom sim import extra\n"""\nimport sim.real\n'
    assert set(_walked(src)) < set(_scanned(src))
