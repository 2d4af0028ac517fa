"""Helper d53: the docs this session changed, read on the code. Two classes of false statement
a page can make without any run are checked here mechanically, in well under a second:

* a path of the project a page names (``sim/mc/sweep.py``, ``tests/test_verify.py``,
  ``benchmarks/startup.py``) that does not exist: a module moved or split leaves its old name
  in the pages (architecture.md's tree names ~70 modules, most by their bare file name);
* a dependency ``pyproject.toml`` declares that docs/architecture.md's *Dependencies and why*
  does not name (in bold): a library added without its reason.

What the reading found false, fixed in the pages: docs/architecture.md credited
``escapes.py`` with escaping the characters a stream's encoding lacks (``standard_error.py``
does, ``escapes.py`` the control codes); docs/sweeps.md said a sweep table shows each swept
level "as written" (its shortest text: a level written ``1e-5`` shows ``1e-05``).
"""

from __future__ import annotations

import re
import tomllib
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
PAGES = [ROOT / "README.md", *sorted((ROOT / "docs").rglob("*.md"))]

#: paths the pages name as deleted (docs/benchmark.md: "Deleted because no row justified
#: them"), or as a user's own file in an example: each must be absent
NAMED_ABSENT = {
    "sim/mc/heap.py",
    "studies/brown_tabel1.toml",  # cli.md: a mistyped study file, answered with a guess
    "studies/x.xml",  # gama.md: a user's file
}
#: bare module names docs/benchmark.md names as deleted
DELETED_MODULES = {"positions_kernel.py", "similarity_jit.py", "figure_jobs.py"}

_PATH = re.compile(r"(?<![\w./-])((?:sim|tests|benchmarks|studies)/[\w/.-]*\w)")
_MODULE = re.compile(r"(?<![\w./-])(\w+\.py)\b")


def _modules() -> set[str]:
    return {p.name for d in ("sim", "benchmarks", "tests") for p in (ROOT / d).rglob("*.py")}


def test_every_project_path_a_page_names_exists():
    """A page naming a file of the project that is not there (a module moved, split or
    renamed since the page was written): every ``sim/``, ``tests/``, ``benchmarks/`` and
    ``studies/`` path of README.md and docs/ exists (a glob, ``sim/cli*.py``, matches one),
    but those the pages name as deleted or as the user's own, which must be absent."""
    missing, named = [], set()
    for page in PAGES:
        for path in set(_PATH.findall(page.read_text(encoding="utf-8"))):
            if "<" in path or path in NAMED_ABSENT:
                named.add(path)
                continue
            if not (ROOT / path).exists() and not list(ROOT.glob(path + "*")):
                missing.append(f"{page.relative_to(ROOT)}: {path}")
    assert not missing, missing
    assert not [p for p in NAMED_ABSENT if (ROOT / p).exists()]
    assert NAMED_ABSENT <= named  # each still named: else drop it from the list


def test_every_module_the_layout_names_exists():
    """docs/architecture.md's and README.md's layout name modules by their bare file name
    (``ends.py``, ``cli_args.py``, ``plotting.py``): each is a module of the project (those
    named as deleted must be absent)."""
    have = _modules()
    missing = []
    for page in [ROOT / "README.md", ROOT / "docs" / "architecture.md"]:
        for name in set(_MODULE.findall(page.read_text(encoding="utf-8"))):
            if name not in have:
                missing.append(f"{page.name}: {name}")
    assert not missing, missing
    assert not DELETED_MODULES & have


def test_every_declared_dependency_has_its_reason():
    """A library ``pyproject.toml`` declares (its dependencies and every extra) that
    docs/architecture.md's *Dependencies and why* does not name in bold: added without the
    reason a reader is promised there."""
    project = tomllib.loads((ROOT / "pyproject.toml").read_text(encoding="utf-8"))["project"]
    declared = [*project["dependencies"]]
    declared += [d for extra in project["optional-dependencies"].values() for d in extra]
    text = (ROOT / "docs" / "architecture.md").read_text(encoding="utf-8")
    section = text.split("## Dependencies and why", 1)[1]
    bold = set(re.findall(r"\*\*([^*]+)\*\*", section))
    names = {re.split(r"[<>=!~ ;]", d, maxsplit=1)[0] for d in declared}
    assert names and not names - bold, sorted(names - bold)
