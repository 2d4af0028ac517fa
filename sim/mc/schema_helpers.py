"""Short constructors for the kinds of configuration key every study schema declares, and the
one-line form of a cross-key rule (:mod:`sim.mc.config` holds :class:`Field` and the
validation).

A study schema (``sim/studies/<study>/schema.py``) is a dict ``{dotted key: Field}``; most of
its keys are one of a few kinds, written here once:

* :func:`count` -- an integer in ``[lo, hi]`` (points per side, trials of a sweep cell);
* :func:`real` -- a number in ``[lo, hi]`` (either bound may be open-ended: ``None``);
* :func:`positive` -- a number ``> 0`` (a standard deviation, a scale), at most ``hi``;
* :func:`level` -- the level of a two-sided test, in ``(0, 0.5]``;
* :func:`reals`, :func:`counts` -- lists of those (the values a sweep visits);
* :func:`printed` -- marks a key whose default is a value the paper prints for its own setup
  (a run with another value is off the paper's setup: :func:`sim.claims.rules.off_paper`);
* :func:`require` -- a cross-key rule of a study's ``check``: :class:`ConfigError` naming the
  key when it does not hold.

``unit`` names the key's unit for the report (``"um"``, ``"mm"``, ``"arcsec"``); ``input``
marks a value set to match a paper. The fields are the same :class:`Field` objects a schema
would spell out (equal field by field), so validation and the report are unchanged.
"""

from __future__ import annotations

import dataclasses
from typing import Any

from sim.mc.config import ConfigError, Field

__all__ = [
    "count",
    "region_seed",
    "real",
    "positive",
    "level",
    "reals",
    "counts",
    "compared",
    "printed",
    "require",
    "recorded_sha256",
]


def count(default: int, doc: str, lo: int, hi: int | None = None, *, input: bool = False) -> Field:
    """An integer key in ``[lo, hi]``."""
    return Field(default, "int", doc, lo=lo, hi=hi, input=input)


def region_seed(default: int) -> Field:
    """``region.seed``: the stream of the exploration of a study's unprinted inputs (its
    space-filling design, refinements and draws), apart from ``seed``. The region is inferred
    from the paper's printed statements, which neither a sweep's swept key nor ``--seed``
    changes: drawn from each cell's seed, the cells of a sweep explored other regions, and a
    region row flipped (holds at 101 points in one cell, depends in the next) with nothing of
    its inputs swept. ``default``: the study file's ``seed``, which drew it before."""
    return count(
        default,
        "seed of the exploration of the unprinted inputs (the region), apart from seed: --seed, "
        "replicates and a sweep's cells share one region (sweep this key to see the "
        f"exploration's spread; {default} is the study file's seed, which drew it before)",
        lo=0,
        hi=2**63 - 1,
    )


def real(
    default: float,
    doc: str,
    lo: float | None = None,
    hi: float | None = None,
    *,
    unit: str = "",
    input: bool = False,
) -> Field:
    """A number in ``[lo, hi]`` (``None``: no bound on that side)."""
    return Field(default, "float", doc, lo=lo, hi=hi, input=input, unit=unit)


def positive(
    default: float, doc: str, hi: float | None = None, *, unit: str = "", input: bool = False
) -> Field:
    """A number ``> 0`` (and ``<= hi``): a standard deviation, a scale, a length."""
    return Field(default, "float", doc, lo=0.0, hi=hi, lo_open=True, input=input, unit=unit)


def level(default: float, doc: str) -> Field:
    """The level of a two-sided test (alpha), in ``(0, 0.5]``."""
    return Field(default, "float", doc, lo=0.0, hi=0.5, lo_open=True)


def reals(
    default: list[float],
    doc: str,
    lo: float | None = None,
    hi: float | None = None,
    *,
    lo_open: bool = False,
    min_len: int = 1,
    unit: str = "",
    input: bool = False,
) -> Field:
    """A list of at least ``min_len`` numbers, each in ``[lo, hi]`` (``(lo, hi]`` with
    ``lo_open``)."""
    return Field(
        default,
        "list[float]",
        doc,
        lo=lo,
        hi=hi,
        lo_open=lo_open,
        min_len=min_len,
        input=input,
        unit=unit,
    )


def counts(
    default: list[int], doc: str, lo: int, hi: int | None = None, *, min_len: int = 1
) -> Field:
    """A list of at least ``min_len`` integers, each in ``[lo, hi]``."""
    return Field(default, "list[int]", doc, lo=lo, hi=hi, min_len=min_len)


def compared(f: Field) -> Field:
    """``f``, a list of settings a trade-off compares, marked as such: each given once (a value
    twice gave two rows of one setting), numbers read in increasing order (``[7, 3, 5]`` was
    drawn as a zigzag line): :func:`sim.mc.config.check_value`."""
    return dataclasses.replace(f, compared=True)


def printed(f: Field) -> Field:
    """``f`` marked as a value the paper prints for its own setup (its default is the paper's
    number): a run whose resolved value differs is off the paper's setup, and its predictions
    are findings (:func:`sim.claims.rules.printed_differs`, applied by
    :func:`sim.claims.book.write_claims`)."""
    return dataclasses.replace(f, printed=True)


def require(ok: Any, key: str, message: str) -> None:
    """A cross-key rule: :class:`ConfigError` ``"<key>: <message>"`` unless ``ok``."""
    if not ok:
        raise ConfigError(key, message)


def recorded_sha256(key: str, have: Any) -> str:
    """The sha256 a study file records for a file it reads (``key``: ``table1.sha256``,
    ``network.gama_sha256``), lower-cased (``sha256sum`` prints lower case; an upper-case copy
    of the same digest was refused as "the file has changed"), ``""`` when not given; a value
    that is no sha256 at all is refused saying so (it was "has changed since the study was
    loaded (recorded abc...)")."""
    if not have:
        return ""
    if (
        not isinstance(have, str)
        or len(have) != 64
        or any(c not in "0123456789abcdef" for c in have.lower())
    ):
        raise ConfigError(
            key, "is not a sha256 (64 hexadecimal digits): leave it out, it is filled in on load"
        )
    return have.lower()
