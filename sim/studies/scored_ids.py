"""The claim ids a study's code names as literals, checked against its claim book on load.

A study scores each claim of its book by id (:meth:`sim.claims.book.ClaimBook.score`); an id
the book no longer declares (a claim removed or renamed by a user trying a variant) ended the
run, after the whole simulation. The ids the code writes out as string literals
(``book.score("salsig.recovery.SX", ...)``, a table of ids) are read here from the study
package's source, statically (nothing is imported or run), so that ``sim check`` and the start
of ``sim run`` refuse such a book naming the claim and the file that scores it.

The ids the code builds (an f-string over a loop, a transcribed table's rows) are listed by
the study itself, from its resolved config and without running a trial (``scored`` of
:func:`sim.studies.data_check`), and :func:`check_scored` holds that list against the book
both ways: a listed id the book does not declare, and a declared id nobody scores, are
refused at load as they would be at the end of the run. The ids of a region declaration are
checked by :mod:`sim.claims.book_region`.
"""

from __future__ import annotations

import ast
import re
from functools import lru_cache
from pathlib import Path
from typing import Callable, Iterable

from sim.mc.config import ConfigError
from sim.mc.lookalike import alike

__all__ = ["literal_ids", "check_literal_ids", "check_scored", "named_ids"]

#: a claim id: dotted words (``salsig.recovery.SX``)
_ID = re.compile(r"[A-Za-z]\w*(?:\.\w+)+")
#: dotted words that name a file, not a claim (``bayes.parquet``)
_FILES = (".parquet", ".png", ".toml", ".csv", ".json", ".md", ".txt", ".py")


@lru_cache(maxsize=16)
def _literals(directory: str) -> tuple[tuple[str, str], ...]:
    """``(text, file name)`` of every string literal that reads as a dotted id in the ``.py``
    files of ``directory`` (a study package), the parts of f-strings left out (an id built
    from them is not one the code names)."""
    out: dict[str, str] = {}
    for f in sorted(Path(directory).glob("*.py")):
        tree = ast.parse(f.read_text(encoding="utf-8"), str(f))
        parts = {id(v) for n in ast.walk(tree) if isinstance(n, ast.JoinedStr) for v in n.values}
        for n in ast.walk(tree):
            if (
                isinstance(n, ast.Constant)
                and isinstance(n.value, str)
                and id(n) not in parts
                and _ID.fullmatch(n.value)
                and not n.value.endswith(_FILES)
            ):
                out.setdefault(n.value, f.name)
    return tuple(out.items())


def literal_ids(directory: Path, groups: set[str]) -> dict[str, str]:
    """The ids the code of the study package ``directory`` names as literals, each with the
    file naming it: dotted literals in one of ``groups`` (the ids of a book without their last
    part, ``salsig.recovery``; an id of another book, a config key or a file name is not)."""
    return {t: f for t, f in _literals(str(directory)) if t.rsplit(".", 1)[0] in groups}


def check_literal_ids(
    book,
    package: Path,
    keys: Iterable[str] = (),
    scores: Callable[[str], bool] | None = None,
) -> None:
    """Refuse ``book`` (a :class:`sim.claims.book.ClaimBook`) when the code of the study
    ``package`` (its directory) names a claim id the book does not declare: a literal in a
    group of the book's ids that is not one of the study's config ``keys`` (``bayes.chains``),
    a file name (``bayes.parquet``) or the start of a declared id (``"agnard.table1.ratio_" +
    ...``). ``scores``: which of the package's ids this study scores (two studies sharing a
    package and a book split it)."""
    declared = set(book.specs)
    groups = {c.rsplit(".", 1)[0] for c in declared}
    keys = set(keys)
    for cid, name in sorted(literal_ids(package, groups).items()):
        if cid in declared or cid in keys or (scores is not None and not scores(cid)):
            continue
        if not any(d.startswith(cid) for d in declared):
            raise ConfigError(
                "claim.id",
                f"{book.path}: claim {cid!r}, which the study scores ({name}), is not declared"
                + alike(cid, declared),
            )


def named_ids(book, package: Path, scores: Callable[[str], bool] | None = None) -> list[str]:
    """The declared ids of ``book`` that the code of ``package`` names as literals (and this
    study scores, ``scores``), in the book's order."""
    named = literal_ids(package, {c.rsplit(".", 1)[0] for c in book.specs})
    return [c for c in book.specs if c in named and (scores is None or scores(c))]


def check_scored(book, ids: Iterable[str]) -> None:
    """Refuse ``book`` (a :class:`sim.claims.book.ClaimBook`) unless ``ids``, the claims the
    study's run scores (listed from its config), are exactly the ones it declares: the two
    errors the end of the run gives (:meth:`~sim.claims.book.ClaimBook.spec`,
    :meth:`~sim.claims.book.ClaimBook.check_complete`), at load."""
    ids = list(ids)
    for cid in ids:
        book.spec(cid)  # a claim the study scores, not declared: named with the book
    listed = set(ids)
    missing = [c for c in book.specs if c not in listed]
    if missing:
        raise ConfigError(
            "claim.id",
            f"{book.path}: declared claims the study does not score: {', '.join(missing)}",
        )
