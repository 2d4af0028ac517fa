"""Which code a study's results depend on, and whether committed results are current.

A study's *code* is the closure of the ``sim`` modules its package imports (read statically
from the sources' import lines, so nothing is imported or run), plus the data files inside its package
(the claim book). Its hash decides staleness per study: editing one study's caption re-runs
that study only, and a fresh clone (whose file times are the checkout's) does not re-run
anything that is current.

:func:`is_current` (``STUDY_FILE``, ``RESULTS_DIR``) is true when ``RESULTS_DIR/run.json``
records the study file's configuration and this code hash (the results are current); the
Makefile's ``reproduce`` uses it.
"""
from __future__ import annotations

import hashlib
import json
import re
from functools import lru_cache
from pathlib import Path

__all__ = ["study_modules", "study_files", "study_code_hash", "is_current", "not_study_code"]

ROOT = Path(__file__).resolve().parent           # .../sim
#: library files and packages (paths relative to ``sim/``) that no study result depends on (the
#: benchmark package; the verification, which the report imports for its reproducibility
#: section only)
NOT_STUDY_CODE = ("bench", "verify.py")


def not_study_code(rel: str) -> bool:
    """True for a path relative to ``sim/`` (``bench/cli.py``) that :data:`NOT_STUDY_CODE`
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


#: an import statement at the start of a line (indented or not): ``from <mod> import <names>``
#: (a parenthesised list may span lines) or ``import <mods>``
_IMPORT = re.compile(r"^[ \t]*(?:from[ \t]+(\.*[\w.]*)[ \t]+import[ \t]+(\([^)]*\)|[^\n]*)"
                     r"|import[ \t]+([^\n]*))", re.M)


def _names(text: str) -> list[str]:
    """``a.b as c, (d,\n e)  # note`` -> ``["a.b", "d", "e"]``."""
    text = re.sub(r"#[^\n]*", "", text).strip("() \t\n")
    return [w.split()[0] for w in text.split(",") if w.split()]


def _imports(f: Path) -> set[str]:
    """Absolute names of the ``sim`` modules ``f`` imports (``from . import x`` included).

    Read by a pattern over the source's lines, not by parsing it (a parse of every module
    costs most of a second per run): an import-like line inside a string counts too, which
    can only add a file to a study's code, never leave one out."""
    pkg = _module_name(f).split(".")
    if f.name != "__init__.py":
        pkg = pkg[:-1]
    out: set[str] = set()
    for m in _IMPORT.finditer(f.read_text().replace("\\\n", " ")):
        if m.group(3) is not None:
            out.update(_names(m.group(3)))
            continue
        spec = m.group(1)
        level = len(spec) - len(spec.lstrip("."))
        base = pkg[:len(pkg) - level + 1] if level else []
        mod = ".".join(base + ([p for p in spec[level:].split(".") if p]))
        out.add(mod)
        out.update(f"{mod}.{a}" for a in _names(m.group(2)))  # submodules imported by name
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
    from .studies import MODULES

    return MODULES.get(study, "sim.studies")


def study_files(study: str) -> list[Path]:
    """The files whose content decides the results of the study named ``study``: its code
    closure and the data files (claim book, tables) inside its package directory."""
    module = _study_module(study)
    files = list(study_modules(module))
    f0 = _module_file(module)
    if f0 is not None and f0.name == "__init__.py":
        files += [p for p in sorted(f0.parent.rglob("*")) if p.is_file()
                  and p.suffix in (".toml", ".csv", ".json")]
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


def is_current(study_file: str | Path, results: str | Path) -> bool:
    """True when ``results/run.json`` records the study file's resolved config and the
    study's current code hash."""
    from .config import ConfigError, StudyError, load_study

    try:
        record = json.loads((Path(results) / "run.json").read_text())
        _, cfg = load_study(study_file)
    except (OSError, ValueError, ConfigError, StudyError):
        return False
    want = study_code_hash(cfg["study"])
    return record.get("config") == json.loads(json.dumps(cfg)) and record.get("code_hash") == want

