"""Likely slips of the Python API answered by what to use (D46's left items): a method of
:class:`sim.api.Results` used as its value (``res.claims.num_rows``: "'function' object has no
attribute 'num_rows'", which named neither ``claims`` nor the call it lacked), and an attribute
``Results`` does not have (``res.trials``, ``res.tables``: Python's bare AttributeError). Each
answer is an :class:`AttributeError` still, so ``hasattr()`` and ``getattr(x, name, default)``
work as before, in one line saying what to use."""

from __future__ import annotations

import functools

__all__ = ["Method", "missing"]


class _Bound:
    """A bound method of ``Results`` that says, when an attribute of its value is asked of
    it, to call it first; called, it is the method."""

    __slots__ = ("_method", "_name", "__dict__")

    def __init__(self, method, name: str):
        self._method, self._name = method, name
        functools.update_wrapper(self, method)  # help(), inspect.signature: the method's

    def __call__(self, *args, **kwargs):
        return self._method(*args, **kwargs)

    def __getattr__(self, attr: str):
        if attr in ("_method", "_name"):  # not set yet (copy's or pickle's bare instance)
            raise AttributeError(attr)
        if attr.startswith("__"):
            return getattr(self._method, attr)
        raise AttributeError(
            f"Results.{self._name} is a method, not its table: call it, res.{self._name}().{attr}"
        )

    def __reduce__(self):  # pickled (a Pool's task) as the method of its Results
        return getattr, (self._method.__self__, self._name)

    def __eq__(self, other):
        return self._method == (other._method if isinstance(other, _Bound) else other)

    def __hash__(self) -> int:
        return hash(self._method)

    def __repr__(self) -> str:
        return repr(self._method)


class Method:
    """A method of ``Results`` (:class:`_Bound` on an instance, the function on the class)."""

    def __init__(self, fn):
        self.fn = fn
        functools.update_wrapper(self, fn)

    def __set_name__(self, owner, name: str) -> None:
        self.name = name

    def __get__(self, obj, cls=None):
        return self.fn if obj is None else _Bound(self.fn.__get__(obj, cls), self.name)


#: attributes a user likely asks of ``Results``, and what gives them
_MEANT = {
    "tables": "res.names() lists its tables, res.table(NAME) reads one",
    "config": "sim.read_provenance(TABLE_FILE) reads the config a table was made with",
    "provenance": "sim.read_provenance(TABLE_FILE) reads a table's provenance",
    "verdicts": "res.claims() is the claims table, with each claim's verdict",
}


def results_attribute(name: str) -> AttributeError:
    """The AttributeError for ``res.<name>``, which ``Results`` does not have: a dunder or
    private name (``copy``'s and ``pickle``'s look-ups) in Python's words, another with what
    to use (a table read by its name: ``res.trials`` -> ``res.table('trials')``)."""
    text = f"'Results' object has no attribute {name!r}"
    if name.startswith("_"):
        return AttributeError(text)
    return AttributeError(
        f"{text}: {_MEANT.get(name) or f'res.table({name!r}) reads a table by its name'}"
    )


def missing(self, name: str):
    """``Results.__getattr__``: :func:`results_attribute` raised."""
    raise results_attribute(name)
