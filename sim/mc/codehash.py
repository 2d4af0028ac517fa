"""Which code a study's results depend on, and whether committed results are current.

A study's *code* is the closure of the ``sim`` modules the modules of its package import
(read statically from the parsed sources, so nothing is imported or run), plus the data files
inside its package (the claim book). Its hash decides staleness per study: editing one study's caption re-runs
that study only, and a fresh clone (whose file times are the checkout's) does not re-run
anything that is current.

:func:`sim.batch.is_current` (``STUDY_FILE``, ``RESULTS_DIR``) is true when
``RESULTS_DIR/run.json`` records the study file's configuration and this code hash (the results
are current); the Makefile's ``reproduce`` uses it.
"""

from __future__ import annotations

import ast
import hashlib
import re
from collections.abc import Iterator
from functools import lru_cache
from pathlib import Path

from sim.mc.registry import MODULES

__all__ = ["study_modules", "study_files", "study_code_hash", "not_study_code"]

ROOT = Path(__file__).resolve().parents[1]  # .../sim
#: library files (paths relative to ``sim/``) that no study result depends on (the
#: verification, which the report imports for its reproducibility section only)
NOT_STUDY_CODE = ("report/verify",)  # the package sim/report/verify/


def not_study_code(rel: str) -> bool:
    """True for a path relative to ``sim/`` (``report/verify/cli.py``) that :data:`NOT_STUDY_CODE`
    names or lies inside."""
    return any(rel == x or rel.startswith(x + "/") for x in NOT_STUDY_CODE)


def _module_file(name: str) -> Path | None:
    """``sim.a.b`` -> its file (module or package ``__init__``), None if not ours."""
    parts = name.split(".")
    if parts[0] != "sim":
        return None
    base = ROOT.joinpath(*parts[1:])
    for f in (base.with_suffix(".py"), base / "__init__.py"):
        if f.is_file():
            return f
    return None


def _module_name(f: Path) -> str:
    rel = f.relative_to(ROOT.parent).with_suffix("")
    parts = list(rel.parts)
    if parts[-1] == "__init__":
        parts.pop()
    return ".".join(parts)


def _statements(body: list) -> Iterator[ast.AST]:
    """Every statement of ``body`` and of the blocks nested in it (functions, classes, ``if``,
    ``try``, ``with``, loops, ``match``): an import is a statement, so this finds every import
    node ``ast.walk`` would, without visiting the expressions (most of a module's nodes)."""
    for node in body:
        yield node
        for block in ("body", "orelse", "finalbody", "handlers", "cases"):
            yield from _statements(getattr(node, block, None) or [])


#: the first line of an import statement, at any indentation (imports inside functions too)
_IMPORT = re.compile(r"^[ \t]*(?:import[ \t]+[\w.]|from[ \t]+[\w.]+[ \t]+import\b)", re.M)
#: an import that does not start its line (``if x: import y``, ``a = 1; import y``): such a
#: file is parsed whole
_INLINE = re.compile(r"[:;][ \t]*(?:import[ \t]+[\w.]+|from[ \t]+[\w.]+[ \t]+import)\b")


def _import_nodes(text: str, name: str) -> Iterator[ast.AST]:
    """The import statements of a source: each line :data:`_IMPORT` finds, with its
    continuation lines, parsed alone (parsing only these is about 40 times faster than parsing
    the module: 0.4 s of CPU per run for a study's closure). A file where one of them does not
    parse alone (such a line inside a string) or with an inline import is parsed whole."""
    if not _INLINE.search(text):
        lines = text.splitlines()
        starts = {text.count("\n", 0, m.start()) for m in _IMPORT.finditer(text)}
        nodes = []
        for i in sorted(starts):
            j, stmt = i, lines[i].strip()
            while (stmt.count("(") > stmt.count(")") or stmt.endswith("\\")) and j + 1 < len(lines):
                j += 1
                stmt += "\n" + lines[j].strip()
            try:
                nodes += ast.parse(stmt).body
            except SyntaxError:
                break
        else:
            yield from nodes
            return
    yield from _statements(ast.parse(text, name).body)


def _imports(f: Path) -> set[str]:
    """Absolute names of the ``sim`` modules ``f`` imports (``from . import x`` included, and
    imports inside functions): every ``import`` statement of the source
    (:func:`_import_nodes`; ``tests/test_codehash.py`` holds it to every import node of the
    parsed module)."""
    pkg = _module_name(f).split(".")
    if f.name != "__init__.py":
        pkg = pkg[:-1]
    out: set[str] = set()
    for node in _import_nodes(f.read_text(encoding="utf-8"), str(f)):
        if isinstance(node, ast.Import):
            out.update(a.name for a in node.names)
        elif isinstance(node, ast.ImportFrom):
            base = pkg[: len(pkg) - node.level + 1] if node.level else []
            mod = ".".join(base + (node.module.split(".") if node.module else []))
            out.add(mod)
            out.update(f"{mod}.{a.name}" for a in node.names)  # submodules imported by name
    return {m for m in out if m.split(".")[0] == "sim"}


@lru_cache(maxsize=None)
def study_modules(module: str) -> tuple[Path, ...]:
    """Every source file of ``sim`` that ``module`` (e.g. ``sim.studies.brown``) reaches,
    parent packages included."""
    seen: dict[Path, None] = {}
    todo = [module]
    while todo:
        name = todo.pop()
        parts = name.split(".")
        for k in range(1, len(parts) + 1):  # a module imports its parent packages
            f = _module_file(".".join(parts[:k]))
            if f is None or f in seen or not_study_code(f.relative_to(ROOT).as_posix()):
                continue
            seen[f] = None
            todo.extend(_imports(f))
    return tuple(sorted(seen))


def _study_module(study: str) -> str:
    return MODULES.get(study, "sim.studies")


def study_files(study: str) -> list[Path]:
    """The files whose content decides the results of the study named ``study``: the code
    closure of every module of its package directory (a package names its run and report
    modules as data, :class:`sim.studies.Part`, imported when a run needs them: the closure of
    its ``__init__`` alone missed them) and the data files (claim book, tables) inside it."""
    module = _study_module(study)
    files = list(study_modules(module))
    f0 = _module_file(module)
    if f0 is not None and f0.name == "__init__.py":
        inside = sorted(p for p in f0.parent.rglob("*") if p.is_file())
        if study in MODULES:  # (not sim.studies itself: every kind's code)
            for p in (p for p in inside if p.suffix == ".py"):
                files += study_modules(_module_name(p))
        files += [p for p in inside if p.suffix in (".toml", ".csv", ".json")]
    return sorted(set(files))


@lru_cache(maxsize=None)
def study_code_hash(study: str) -> str:
    """sha256 (16 hex digits) of :func:`study_files` of the study named ``study``
    (e.g. ``brown_table1``)."""
    h = hashlib.sha256()
    for f in study_files(study):
        h.update(f.relative_to(ROOT).as_posix().encode())
        h.update(f.read_bytes())
    return h.hexdigest()[:16]
