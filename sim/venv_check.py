"""Whether a virtual environment holds what ``pyproject.toml`` asks for: the Makefile's check of
``.venv`` after ``make venv`` installs into it, and before every target that uses it.

The rule: the project's own distribution is installed, and so is every requirement of its
``dependencies`` and of its ``dev`` extra (the Makefile installs ``.[dev]``) whose marker holds
here, at a version its specifier allows. pip can finish with exit 0 and install none of it
(``PIP_DRY_RUN``, ``PIP_NO_DEPS``, ``PIP_TARGET`` or the same in a ``pip.conf``), and a user can
remove a library from ``.venv`` later (``pip uninstall pyarrow``): either left a ``.venv`` that
every target took for whole and failed in (``.venv/bin/ruff: No such file or directory``,
pytest's collection errors).

Run as a file (``.venv/bin/python -I sim/venv_check.py``), standard library only (the version
rules are pip's own ``packaging``, or names alone where it is missing): it prints nothing and
exits 0 when the environment is whole, else one line naming the first thing it lacks and exits 1.
"""

from __future__ import annotations

import os
import re
import sys
import tomllib
from importlib import metadata
from pathlib import Path

try:  # pip's copy of packaging (a venv without pip: the standalone one, or names alone)
    from pip._vendor.packaging.requirements import Requirement
except ImportError:  # pragma: no cover - depends on the environment
    try:
        from packaging.requirements import Requirement
    except ImportError:
        Requirement = None

#: the extra the Makefile installs (``pip install -e ".[dev]"``)
EXTRA = "dev"


def _name(text: str) -> str:
    """The distribution name a requirement starts with (``numpy>=1.24`` -> ``numpy``)."""
    m = re.match(r"\s*([A-Za-z0-9][A-Za-z0-9._-]*)", text)
    return m.group(1) if m else text.strip()


def _lacks(text: str, extra: str = EXTRA, depth: int = 0) -> str | None:
    """What the environment lacks of one requirement ``text`` (of ``extra``), or None."""
    req = Requirement(text) if Requirement is not None else None
    if req is not None and req.marker is not None and not req.marker.evaluate({"extra": extra}):
        return None
    name = req.name if req is not None else _name(text)
    try:
        version = metadata.version(name)
    except metadata.PackageNotFoundError:
        return f"lacks {name}"
    if req is not None and req.specifier and not req.specifier.contains(version, prereleases=True):
        return f"holds {name} {version}"
    return _extras_lack(name, req.extras if req is not None and depth < 3 else (), depth)


def _extras_lack(name: str, extras, depth: int) -> str | None:
    """What the environment lacks of the requirements the ``extras`` of the installed
    distribution ``name`` add (``dask[distributed]``: ``distributed``), or None: checked by
    the name alone, ``distributed`` uninstalled was a ``.venv`` taken for whole (every
    ``--executor dask`` test failed)."""
    for text in metadata.requires(name) or [] if extras else []:
        try:
            marker = Requirement(text).marker
        except Exception:  # a line of its METADATA that is no requirement: not ours to judge
            continue
        if marker is None or "extra" not in str(marker):
            continue
        for e in extras:
            if marker.evaluate({"extra": e}) and (lacks := _lacks(text, e, depth + 1)):
                return lacks
    return None


def problem(pyproject: Path) -> str | None:
    """The words for what the running Python's environment (shown relative to the working
    directory: ``.venv``) lacks of ``pyproject``, or None."""
    where = os.path.relpath(sys.prefix)
    project = tomllib.loads(pyproject.read_text(encoding="utf-8")).get("project", {})
    wanted = [*project.get("dependencies", [])]
    wanted += project.get("optional-dependencies", {}).get(EXTRA, [])
    name = project.get("name", "")
    try:
        metadata.distribution(name)
    except (metadata.PackageNotFoundError, ValueError):
        return f"{where} lacks the project {name!r} itself"
    for text in wanted:
        lacks = _lacks(text)
        if lacks is not None:
            return f"{where} {lacks}, where {pyproject.name} asks for {text}"
    return None


#: said after an install that pip finished: what keeps pip from installing and exits 0
AFTER_PIP = (
    "pip installed less than it was asked: PIP_DRY_RUN, PIP_NO_DEPS, PIP_TARGET or a pip.conf?"
)


def main(argv: list[str]) -> int:
    """``--after-pip``: the line says what can keep pip from installing (an install just ran)."""
    words = problem(Path("pyproject.toml"))
    if words is None:
        return 0
    print(f"{words} ({AFTER_PIP})" if "--after-pip" in argv else words)
    return 1


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
