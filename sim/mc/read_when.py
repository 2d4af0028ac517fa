"""Keys a study reads only under a condition, and the refusal of one set where it is not read.

A key of a schema may be read only when another key, its *switch*, has some value: a point
pattern (``plate.n_random`` only for ``plate.pattern = "random"``), a datum kind
(``datum.constraints`` only for ``datum.kind = "constraints"``), the rate that turns an optional
part on (``pugging.gross_px`` only when ``pugging.gross_rate`` is not 0). Its :class:`Field`
says so with ``read_when`` (a :class:`When`, written with :func:`when` or :func:`unless`).

A key the user set (the file, ``--set``, the Python API, a sweep) that the resolved
configuration does not read is refused by :func:`refuse_unread` (one line naming the key, the
switch and its value): the run, or a sweep's cells, would differ only by seed, and the user
would believe they varied something. A key left at its default is never refused. A sweep is
judged over its cells: a key is refused when no cell reads it (a swept key inert in every
cell, or a key of the file whose switch the sweep sets to values that never read it).
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from typing import Any, Iterable, Mapping

from sim.mc.config import ConfigError, Field

__all__ = ["When", "when", "unless", "unread", "read_in_a_cell", "refuse_unread"]


@dataclass(frozen=True)
class When:
    """A key is read only when ``cfg[switch]`` is one of ``values`` (with ``negate``: none of
    them). ``says``: how a message words when it is read (default: from the switch and the
    values)."""

    switch: str
    values: tuple
    negate: bool = False
    says: str = ""

    def reads(self, value: Any) -> bool:
        """Whether the key is read when the switch has ``value``."""
        return any(_same(value, v) for v in self.values) != self.negate

    def read_text(self) -> str:
        """When the key is read, as a message says it."""
        if self.says:
            return self.says
        values = " or ".join(_shown(v) for v in self.values)
        return f"when {self.switch} {'is not' if self.negate else '='} {values}"


def _same(a: Any, b: Any) -> bool:
    """A switch's value and a declared one are one value (``0`` and ``0.0``; not ``True``
    and ``1``)."""
    return isinstance(a, bool) == isinstance(b, bool) and a == b


def _shown(v: Any) -> str:
    text = repr(v)
    return text if len(text) <= 80 else text[:77] + "..."


def when(field: Field, switch: str, *values: Any, says: str = "") -> Field:
    """``field``, read only when ``switch`` is one of ``values``."""
    return dataclasses.replace(field, read_when=When(switch, tuple(values), says=says))


def unless(field: Field, switch: str, *values: Any, says: str = "") -> Field:
    """``field``, read only when ``switch`` is none of ``values`` (an optional part whose
    switch is off at one value: a rate of 0, an empty path)."""
    return dataclasses.replace(field, read_when=When(switch, tuple(values), True, says))


def unread(schema: Mapping[str, Field], cfg: Mapping[str, Any]) -> dict[str, str]:
    """The keys of ``schema`` that the resolved ``cfg`` does not read, each with why
    (``plate.pattern = 'grid'``): ``sim check`` lists those at their default commented out (set,
    one would be refused, unless a sweep's cells read it)."""
    out = {}
    for key, f in schema.items():
        w = getattr(f, "read_when", None)
        if w is not None and not w.reads(cfg.get(w.switch)):
            out[key] = f"{w.switch} = {_shown(cfg.get(w.switch))}"
    return out


def read_in_a_cell(field: Field, cfg: Mapping[str, Any], cells: list[Mapping[str, Any]]) -> bool:
    """Whether some cell of a sweep over ``cfg`` (``cells``: each cell's ``{key: value}``)
    reads the key of ``field``, which ``cfg`` does not read: ``sim check`` lists it as set."""
    w = getattr(field, "read_when", None)
    return w is not None and any(w.reads(c.get(w.switch, cfg.get(w.switch))) for c in cells)


def refuse_unread(
    schema: Mapping[str, Field],
    cfg: Mapping[str, Any],
    given: Iterable[str],
    cells: list[Mapping[str, Any]] | None = None,
) -> None:
    """Refuse the first key of ``given`` (the keys the user set) that ``cfg`` (resolved) does
    not read: :class:`ConfigError` naming it, its switch and the switch's value. With
    ``cells`` (the ``{key: value}`` of each cell of a sweep over ``cfg``), a key is refused
    when no cell reads it; a swept key is named ``sweep.<key>``."""
    given = set(given)
    swept = set().union(*cells) if cells else set()
    for key, f in schema.items():
        w = getattr(f, "read_when", None)
        if w is None or key not in given | swept:
            continue
        seen = [c.get(w.switch, cfg.get(w.switch)) for c in cells] if cells else [cfg.get(w.switch)]
        if any(w.reads(v) for v in seen):
            continue
        values = " or ".join(dict.fromkeys(_shown(v) for v in seen))
        where = " in every cell of the sweep" if cells and len(cells) > 1 else ""
        raise ConfigError(
            f"sweep.{key}" if key in swept else key,
            f"is not read when {w.switch} = {values}{where} (it is read only {w.read_text()}): "
            f"leave it out, or change {w.switch}",
        )
