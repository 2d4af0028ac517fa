"""The Python API's arguments checked as its config keys are: an argument a function of
:mod:`sim.api` does not take, one given twice, too many or one missing is one
:class:`sim.mc.config.ConfigError` line naming it and the ones the function takes, not
Python's ``TypeError``; a ``str`` subclass is read as the text it holds."""

from __future__ import annotations

import functools
import inspect
import os
from pathlib import PurePath
from typing import Any

import numpy as np

from sim.long_words import clipped
from sim.mc.config import ConfigError
from sim.mc.pyvalue import as_config_value

__all__ = ["arguments", "count", "dotted", "flag", "keyed", "no_none", "one_line"]


def dotted(k: str) -> str:
    """A keyword argument's name as the config key it stands for (``__`` is the dot)."""
    return k.replace("__", ".")


def keyed(overrides: dict) -> dict:
    """``overrides`` by their dotted keys; a key given twice (``**{"datum.kind": ...}`` beside
    ``datum__kind=...``) is refused, as ``--set`` twice is: one value would be dropped."""
    out: dict = {}
    seen: dict = {}
    for k, v in overrides.items():
        d = dotted(k) if isinstance(k, str) else k
        if d in out:
            raise ConfigError(d, f"given twice ({seen[d]!r} and {k!r}): one value would be dropped")
        out[d], seen[d] = v, k
    return out


#: what a caller of each function does instead of giving a key ``None``
_INSTEAD = {
    "run": "leave it out for the handle's value",
    "replace": (
        "replace() drops no override (left out, the key keeps the handle's value): "
        "sim.load() the study without it for the file's value"
    ),
}


def no_none(given: dict, of: str) -> None:
    """``given`` (the keys given to ``run`` or ``replace``, ``of``) holds no ``None``, which
    no study file holds: refused naming the key and what to do for the value meant.
    ``handle.replace(trials=None)`` (meant: drop the override) said "leave it out for the
    file's value", where left out of ``replace()`` it is the handle's."""
    for k, v in given.items():
        if v is None:
            raise ConfigError(k, f"is None, which no study file holds: {_INSTEAD[of]}")


#: where a user gets the object a method is called on
_MADE_BY = {
    "Results": "the Results run() returned, or sim.Results(path, study)",
    "StudyHandle": "the handle sim.load(...) returned",
}


#: NumPy's default floating-point error handling, under which the studies are written
NUMPY_DEFAULTS = {"divide": "warn", "over": "warn", "under": "ignore", "invalid": "warn"}


def arguments(fn):
    """``fn`` refusing an argument it does not take with one ConfigError line that names the
    argument and the ones it takes (Python's TypeError named the function only: ``run()
    got an unexpected keyword argument 'chunk'``); a config key given to ``run()`` is pointed
    to ``sim.load()`` and ``replace()``. It runs under NumPy's default error handling.
    """
    sig = inspect.signature(fn)
    P = inspect.Parameter
    method = next(iter(sig.parameters), "") == "self"
    params = list(sig.parameters.values())[method:]
    named = [p for p in params if p.kind not in (P.VAR_POSITIONAL, P.VAR_KEYWORD)]
    positional = [p.name for p in named if p.kind != P.KEYWORD_ONLY]
    parts = [", ".join(p.name for p in named)] if named else []
    parts += ["config keys by name"] if any(p.kind == P.VAR_KEYWORD for p in params) else []
    takes = " and ".join(parts) or "no argument"
    known = None if any(p.kind == P.VAR_KEYWORD for p in params) else {p.name for p in named}
    what = f"{fn.__qualname__.removesuffix('.__init__')}()"

    owner = fn.__qualname__.rpartition(".")[0].removesuffix(".__init__")

    def refusal(args: tuple, kwargs: dict) -> ConfigError:
        if method and not (args and any(c.__qualname__ == owner for c in type(args[0]).__mro__)):
            # Results.claims() on the class: "missing: ... needs it (it takes no argument)"
            made = _MADE_BY.get(owner, "an instance")
            return ConfigError(what, f"is called on the class {owner}: call it on {made}")
        for k in kwargs:
            if (known is not None and k not in known) or (method and k == "self"):
                cfg = getattr(args[0], "config", None) if method and args else None
                hint = (
                    f"; {dotted(k)} is a config key: give it to sim.load() or replace()"
                    if isinstance(cfg, dict) and dotted(k) in cfg
                    else ""
                )
                return ConfigError(k, f"{what} takes no argument {k!r} (it takes {takes}){hint}")
        given = args[method:]
        for name in positional[: len(given)]:
            if name in kwargs:
                return ConfigError(name, f"{what} was given {name} twice")
        if len(given) > len(positional):
            at_most = (
                f"at most {len(positional)} positional ({', '.join(positional)})"
                if positional
                else "no positional argument"
            )
            return ConfigError(what, f"takes {at_most}, got {len(given)} (it takes {takes})")
        missing = [
            p.name
            for i, p in enumerate(named)
            if p.default is P.empty and p.name not in kwargs and i >= len(given)
        ]
        return ConfigError(
            missing[0] if missing else what, f"missing: {what} needs it (it takes {takes})"
        )

    @functools.wraps(fn)
    def checked(*args, **kwargs):
        try:
            bound = sig.bind(*args, **kwargs)
        except TypeError:
            raise refusal(args, kwargs) from None
        args, kwargs = tuple(map(_plain, args)), {k: _plain(v) for k, v in kwargs.items()}
        try:  # under NumPy's default error handling, whatever the caller set (a notebook's
            with np.errstate(**NUMPY_DEFAULTS):  # np.seterr(all="raise") made an underflow
                return fn(*args, **kwargs)  # the suite ignores a FloatingPointError)
        except ConfigError as e:
            if len(str(e).splitlines()) < 2 and clipped(str(e)) == str(e):
                raise
            raise one_line(e) from None
        except Exception as e:
            if (unshown := _unshown(bound, e)) is not None:
                raise unshown from None
            raise

    return checked


def _plain(v: Any) -> Any:
    """``v``, or the ``str`` a ``str`` subclass holds (a ``StrEnum`` member, ``np.str_``), also
    as an ``os.PathLike``'s path: the API reads its text, not its ``__str__`` (a caller's
    subclass whose ``__str__`` raised passed through ``sim.load``, ``run(out=...)`` and
    ``Results.table`` as a traceback; a PathLike whose ``__fspath__`` raises is left to the
    check of its argument, which names it)."""
    if isinstance(v, os.PathLike) and not isinstance(v, PurePath):
        try:
            text = os.fspath(v)
        except Exception:  # noqa: BLE001 - refused by the argument's check, naming it
            return v
        v = text if isinstance(text, str) and type(text) is not str else v
    return str.__str__(v) if isinstance(v, str) and type(v) is not str else v


def _unshown(bound: inspect.BoundArguments, e: Exception) -> ConfigError | None:
    """The refusal of an argument whose ``repr`` raises ``e`` (an object of the caller's
    whose ``__repr__`` is broken), or None: the line that refuses a value quotes it, and the
    object's own exception passed through the API as a traceback, naming nothing."""
    P = inspect.Parameter
    named: list[tuple[str, object]] = []
    for name, v in bound.arguments.items():
        kind = bound.signature.parameters[name].kind
        if name == "self":
            continue
        named += list(v.items()) if kind == P.VAR_KEYWORD else [(name, v)]
    for name, v in named:
        try:
            repr(v)
        except Exception as r:  # the same failure as the one that ended the call
            if type(r) is type(e) and str(r) == str(e):
                return ConfigError(
                    dotted(name),
                    f"cannot be quoted in a message: repr() of its {type(v).__name__} raised "
                    f"{type(r).__name__} (give a plain value: a number, a str or a list)",
                )
    return None


def count(name: str, v: Any) -> Any:
    """``v`` (a count such as ``run(workers=...)``) read as a config key's number is
    (:func:`sim.mc.pyvalue.as_config_value`: ``np.array(2)``, ``Decimal("2")``, ``Fraction(2)``
    are 2; it was "must be an integer (got array(2))" where ``trials=np.array(2)`` is 2); a
    value that reading refuses is left as it is, to the caller's own check of ``name``."""
    try:
        r = as_config_value(name, v)
    except ConfigError:
        return v
    # a whole float is the integer, as trials=400.0 is 400 (workers=1.0 was "must be an integer")
    return int(r) if isinstance(r, float) and r.is_integer() and abs(r) < 2**53 else r


def flag(name: str, v: Any) -> bool:
    """A flag of ``run()``: a bool, or a NumPy bool (``np.True_``, from a mask), as a config
    key takes it (it was refused as "must be True or False (got np.True_)")."""
    if not isinstance(b := as_config_value(name, v), bool):
        raise ConfigError(name, f"must be True or False (got {v!r})")
    return b


def one_line(e: ConfigError) -> ConfigError:
    """``e`` in one line: a refusal that quotes a value of the caller's by its ``repr`` (an
    object of a library whose repr spans lines, ``got Bad(\n...)``) spanned as many."""
    flat = ConfigError(e.key, "")
    flat.__dict__.update(e.__dict__)
    flat.args = (clipped(" ".join(t.strip() for t in str(e).splitlines() if t.strip())),)
    return flat
