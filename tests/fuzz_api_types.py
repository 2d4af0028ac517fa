"""API TYPES, a mutation kind of the fuzzer (tests/test_fuzz.py): seeded call sequences of the
Python API (``sim.load``, ``replace``, ``run``, ``sim.Results``, ``table``) with odd argument
types mixed in, one argument a call.

The other door fuzzers give an argument a wrong *value* of a plain type (tests/
test_fuzz_doors.py: ``workers="2"``, ``out=5``); here an argument is given a value of an odd
*type*: the same value in another type (``np.int64(20)``, ``Fraction(20, 1)``, a 0-d array,
``np.True_``, ``np.str_``, a ``pathlib.Path``, a ``str`` subclass whose ``__str__`` raises),
which must give what the plain value gives, or a value no argument takes (bytes and bytearray
paths, an ``os.PathLike`` whose ``__fspath__`` raises or gives bytes, an int or None, a bool for
a count, a ``Sequence`` whose ``__len__`` raises, an ``Integral`` whose ``__int__`` raises, an
array-like whose ``__array__`` raises, a ``Mapping`` whose ``__iter__`` raises), which must be
refused by one :class:`sim.ConfigError` line that starts with the argument's name (or key):
never another exception (the caller's own object's included), never a second line.

:func:`case` draws one call; :func:`check` makes it and says what broke the contract, or None.
"""

from __future__ import annotations

import decimal
import fractions
import numbers
import os
import random
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Callable

import numpy as np

import sim

EQ, BAD = "same", "refused"


class RaisingPath(os.PathLike):
    """An ``os.PathLike`` whose ``__fspath__`` raises (a caller's broken object)."""

    def __init__(self, exc: type[Exception]) -> None:
        self.exc = exc

    def __fspath__(self) -> str:
        raise self.exc("fspath broken")

    def __repr__(self) -> str:
        return f"RaisingPath({self.exc.__name__})"


class PathTo(os.PathLike):
    """An ``os.PathLike`` whose ``__fspath__`` gives ``value`` (bytes, an int, None)."""

    def __init__(self, value: Any) -> None:
        self.value = value

    def __fspath__(self) -> Any:
        return self.value

    def __repr__(self) -> str:
        return f"PathTo({self.value!r})"


class BrokenStr(str):
    """A ``str`` subclass whose ``__str__`` raises: its text is what it holds."""

    def __str__(self) -> str:
        raise RuntimeError("str broken")


class BrokenInt(numbers.Integral):
    """An ``Integral`` (registered by subclassing) whose every number method raises."""

    def __repr__(self) -> str:
        return "BrokenInt()"

    def __hash__(self) -> int:
        return 1


def _raise(self, *a):
    raise ArithmeticError("int broken")


for _m in ("__int__ __index__ __float__ __complex__ __abs__ __neg__ __pos__ __invert__ __round__ "
           "__trunc__ __floor__ __ceil__ __eq__ __lt__ __le__ __add__ __radd__ __sub__ __rsub__ "
           "__mul__ __rmul__ __truediv__ __rtruediv__ __floordiv__ __rfloordiv__ __mod__ "
           "__rmod__ __pow__ __rpow__ __lshift__ __rlshift__ __rshift__ __rrshift__ __and__ "
           "__rand__ __or__ __ror__ __xor__ __rxor__").split():  # fmt: skip
    setattr(BrokenInt, _m, _raise)
BrokenInt.__abstractmethods__ = frozenset()


class BrokenSeq(Sequence):
    """A ``Sequence`` whose ``__len__`` (``at=None``) or items raise."""

    def __init__(self, at: int | None = None) -> None:
        self.at = at

    def __len__(self) -> int:
        if self.at is None:
            raise OSError("len broken")
        return 3

    def __getitem__(self, i):
        if isinstance(i, int) and not 0 <= i < 3:
            raise IndexError(i)
        raise LookupError("item broken")

    def __repr__(self) -> str:
        return f"BrokenSeq({self.at})"


class BrokenMap(Mapping):
    """A ``Mapping`` whose ``__iter__`` raises."""

    def __len__(self) -> int:
        return 1

    def __iter__(self):
        raise RuntimeError("iter broken")

    def __getitem__(self, k):
        raise KeyError(k)

    def __repr__(self) -> str:
        return "BrokenMap()"


class BrokenArray:
    """An array-like whose ``__array__`` raises something other than a TypeError."""

    def __array__(self, *a, **k):
        raise MemoryError("array broken")

    def __repr__(self) -> str:
        return "BrokenArray()"


def _hostile() -> list:
    """Objects that raise when read, whatever the argument."""
    return [RaisingPath(RuntimeError), RaisingPath(OSError), BrokenInt(), BrokenSeq()]


def ints(n: int) -> list[tuple[Any, str]]:
    """``n`` (a count or a seed) in odd types, each marked EQ or BAD."""
    same = [np.int64(n), np.uint32(n), np.int8(n) if n <= 127 else np.int32(n)]
    same += [np.array(n), fractions.Fraction(2 * n, 2), decimal.Decimal(n), float(n)]
    same += [np.float32(n)] if n < 2**24 else []  # float32 holds every integer up to 2**24
    bad = [True, np.True_, np.float64(n + 0.5), str(n), str(n).encode(), bytearray(b"1")]
    bad += [complex(n, 1), [n], np.array([n]), None, b"", *_hostile()]
    bad += [BrokenSeq(0), BrokenMap(), BrokenArray(), decimal.Decimal("sNaN")]
    return [(v, EQ) for v in same] + [(v, BAD) for v in bad]


def flags(b: bool) -> list[tuple[Any, str]]:
    """``b`` (a flag of ``run``) in odd types."""
    bad = [int(b), "yes", "", None, np.array([b]), b"1", *_hostile(), BrokenArray()]
    return [(np.bool_(b), EQ), (np.array(b), EQ)] + [(v, BAD) for v in bad]


def paths(p: Path) -> list[tuple[Any, str]]:
    """The existing path ``p`` in odd types."""
    same = [p, str(p), np.str_(str(p)), BrokenStr(str(p)), PathTo(str(p))]
    same += [PathTo(BrokenStr(str(p)))]
    bad = [str(p).encode(), bytearray(str(p).encode()), memoryview(str(p).encode())]
    bad += [PathTo(str(p).encode()), PathTo(None), PathTo(5), 5, 2.5, [str(p)], ""]
    bad += [RaisingPath(RuntimeError), RaisingPath(ValueError), RaisingPath(KeyError)]
    bad += [BrokenInt(), BrokenSeq(), BrokenMap(), np.array([str(p)])]
    return [(v, EQ) for v in same] + [(v, BAD) for v in bad]


def names(n: str) -> list[tuple[Any, str]]:
    """The name ``n`` (a study's or a table's) in odd types."""
    same = [np.str_(n), BrokenStr(n), np.array(n)[()]]
    bad = [n.encode(), bytearray(n.encode()), 5, None, [n], Path(n), RaisingPath(RuntimeError)]
    bad += [BrokenInt(), BrokenSeq(), BrokenMap()]
    return [(v, EQ) for v in same] + [(v, BAD) for v in bad]


@dataclass
class Case:
    """One call: ``call(value)`` and ``call(plain)`` are compared (EQ), or ``call(value)`` must
    be refused naming ``arg`` (BAD); ``key(result)`` is what is compared."""

    desc: str
    arg: str
    value: Any
    plain: Any
    mark: str
    call: Callable[[Any], Any]
    key: Callable[[Any], Any]


def case(rng: random.Random, study: Path, out: Path, res: sim.Results) -> Case:
    """A seeded call of one of the API's doors with one argument of an odd type; ``res`` is a
    finished run of ``study`` in ``out`` (``trials``, ``seed`` as the study file's)."""
    h = sim.load(study)
    trials, seed = h.config["trials"], h.config["seed"]
    door = rng.choice(["load", "override", "replace", "run", "results", "table"])
    if door == "load":
        pool, arg, plain = paths(study), "study_file", study
        call, key = (lambda v: sim.load(v)), (lambda r: r.config)
    elif door in ("override", "replace"):
        arg = rng.choice(["trials", "seed"])
        plain = {"trials": trials, "seed": seed}[arg]
        pool = ints(plain)
        if door == "override":
            call = lambda v: sim.load(study, **{arg: v})  # noqa: E731
        else:
            call = lambda v: h.replace(**{arg: v})  # noqa: E731
        key = lambda r: r.config  # noqa: E731
    elif door == "run":
        arg = rng.choice(["out", "workers", "trials", "seed", "overwrite", "quiet", "figures"])
        plain = {"out": out, "workers": 1, "trials": trials, "seed": seed}.get(arg, arg == "quiet")
        if arg == "out":
            pool = paths(out)
        elif arg in ("overwrite", "quiet", "figures"):
            pool = flags(plain)
        else:
            pool = ints(plain)
        kw = {"out": out, "figures": False, "quiet": True}

        def call(v):  # the run of the study into out again: its results, not a new run
            return h.run(**{**kw, arg: v})

        key = lambda r: (r.path, r.run_sha256)  # noqa: E731
    elif door == "results":
        arg = rng.choice(["path", "study"])
        pool = paths(out) if arg == "path" else names(res.study)
        plain = out if arg == "path" else res.study
        if arg == "path":
            call = lambda v: sim.Results(v, res.study)  # noqa: E731
        else:
            call = lambda v: sim.Results(out, v)  # noqa: E731
        key = lambda r: (r.path, r.study, r.names())  # noqa: E731
    else:
        arg, plain = "table", "points"
        pool = names("points")
        call, key = (lambda v: res.table(v)), (lambda t: repr(t.to_pylist()))  # NaN == NaN
    value, mark = rng.choice(pool)
    return Case(f"{door}: {arg}={value!r}"[:120], arg, value, plain, mark, call, key)


def check(c: Case) -> str | None:
    """What the call of ``c`` did against the contract (module docstring), or None."""
    try:
        got = ("ok", c.key(c.call(c.value)))
    except sim.ConfigError as e:
        got = ("refused", str(e))
    except Exception as e:  # noqa: BLE001 - what the fuzzer is looking for
        return f"{type(e).__name__}: {str(e)[:200]}"
    if got[0] == "refused":
        msg = got[1]
        if "\n" in msg or not msg.startswith(c.arg):
            return f"refused, but not in one line naming {c.arg}: {msg[:300]}"
    if c.mark == EQ:
        try:
            want = ("ok", c.key(c.call(c.plain)))
        except sim.ConfigError as e:
            want = ("refused", str(e))
        if got != want:
            return f"not what the plain value gives: {str(got)[:200]} vs {str(want)[:200]}"
    elif got[0] != "refused":
        return "accepted"
    return None
