"""A referee's reading of the docs against the code (sweep doors26d): statements that drift
when the code moves, held to the code they describe.

- docs/cli.md's example of make's own failure line names the Makefile line of make verify's
  command (``make: *** [Makefile:N: verify] Error 1``): a line added to the recipe above it
  (the ``shellwords`` check of VERIFY_FLAGS) moved the command to the next line, and the page
  named the check's line.
- docs/architecture.md's "Dependencies and why" names every package the project declares
  (pyproject.toml: dependencies and every extra) and every library outside the standard
  library that ``sim/`` and ``benchmarks/`` import: ruff, import-linter, mutmut and psutil
  were used and not named.
"""

import ast
import re
import sys
import tomllib
from pathlib import Path

from conftest import ROOT

#: import name -> the package that provides it, where the two differ
PROVIDER = {"distributed": "dask", "importlinter": "import-linter"}


def _section(page: Path, heading: str) -> str:
    text = page.read_text(encoding="utf-8")
    start = text.index(heading)
    end = text.find("\n## ", start + len(heading))
    return text[start : end if end >= 0 else None]


def test_cli_page_names_the_makefile_line_of_make_verify():
    page = (ROOT / "docs" / "cli.md").read_text(encoding="utf-8")
    m = re.search(r"\[Makefile:(\d+):\s*verify\]", page)
    assert m, "docs/cli.md gives an example of make's failure line of make verify"
    lines = (ROOT / "Makefile").read_text(encoding="utf-8").splitlines()
    target = next(i for i, s in enumerate(lines) if s.startswith("verify:"))
    recipe = []
    for i in range(target + 1, len(lines)):
        if not lines[i].startswith("\t"):
            break
        recipe.append(i + 1)
    command = [n for n in recipe if "-m sim.report.verify" in lines[n - 1]]
    assert command == [int(m.group(1))], (
        f"docs/cli.md names Makefile:{m.group(1)}; make verify's command is on line {command}"
    )


def _declared() -> set[str]:
    project = tomllib.loads((ROOT / "pyproject.toml").read_text(encoding="utf-8"))["project"]
    reqs = list(project["dependencies"])
    for extra in project.get("optional-dependencies", {}).values():
        reqs += extra
    return {re.match(r"[A-Za-z0-9_.-]+", r).group(0).lower() for r in reqs}


def _imported() -> set[str]:
    roots: set[str] = set()
    for folder in ("sim", "benchmarks"):
        for py in (ROOT / folder).rglob("*.py"):
            for node in ast.walk(ast.parse(py.read_text(encoding="utf-8"))):
                if isinstance(node, ast.Import):
                    roots |= {a.name.split(".")[0] for a in node.names}
                elif isinstance(node, ast.ImportFrom) and node.level == 0 and node.module:
                    roots.add(node.module.split(".")[0])
    own = {"sim", "benchmarks"}
    return {r for r in roots if r not in sys.stdlib_module_names and r not in own}


def test_dependencies_paragraph_names_every_package_declared_and_imported():
    section = _section(ROOT / "docs" / "architecture.md", "## Dependencies and why")
    named = {n.lower() for n in re.findall(r"\*\*([A-Za-z0-9_.-]+)(?:\[[^\]]*\])?\*\*", section)}
    declared = _declared()
    assert declared - named == set(), f"declared in pyproject.toml, not named: {declared - named}"
    imported = {PROVIDER.get(m, m) for m in _imported()}
    assert imported - named == set(), f"imported, not named: {imported - named}"
    assert named - declared - imported == set(), "named but neither declared nor imported"
