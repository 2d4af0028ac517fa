"""What an unknown key of a study was probably meant to be, in the same words at every door
(:func:`sim.mc.config.validate`: a study file, ``sim run --set``, ``sim.load(**overrides)``;
``python -m sim.batch -- --set`` before any run): the key that looks the same (another case),
the key with its unit, the closest spellings, the keys of a table given as a key, and a list's
item set by its index (``--set design.positions.0=3``: "unknown key" alone from ``sim.load``
and the batch, the list named by ``sim run`` only).
"""

from __future__ import annotations

import difflib
import re
from typing import Any, Mapping

from sim.mc.lookalike import looks
from sim.mc.message_text import near_keys
from sim.mc.toml_slips import TYPOGRAPHIC

__all__ = ["did_you_mean", "item_hint", "unknown_key_hint"]


def did_you_mean(key: str, schema: Mapping[str, Any], n: int = 2) -> list[str]:
    """The schema keys a mistyped ``key`` most likely meant (at most ``n``): the key that looks
    the same (:func:`sim.mc.lookalike.looks`: another case, white space, a lookalike letter;
    paper.positions with a Cyrillic a was "did you mean design.positions or paper.positions"),
    the key with a unit suffix (``comparator.beta`` -> ``comparator.beta_mm``), the same last
    part under another table, or the closest spellings (difflib)."""
    names = list(schema)
    same_case = [s for s in names if looks(s) == looks(key)]  # TRIALS, "trials ", triаls
    suffixed = [s for s in names if s.startswith(key + "_") and "." not in s[len(key) :]]
    last = key.split(".")[-1]
    same_last = [s for s in names if s.split(".")[-1] == last]
    close = difflib.get_close_matches(key, names, n=n, cutoff=0.75)
    return list(dict.fromkeys(same_case + suffixed + same_last + close))[:n]


#: a key that names an item of a list (``network.generate[1].sigma_arcsec``, ``...generate.1...``)
#: (any index in brackets, a negative one too: points[-1] had no hint, as Python's last item)
_ITEM = re.compile(r"^([A-Za-z_][\w.]*?)(?:\[([^\]]*)\]|\.(-?\d+))(?:\.|$)")
#: the kinds of :class:`~sim.mc.config.Field` whose value is a list
_LIST_KIND = re.compile(r"^(?:list\[|points$|records$)")


def item_hint(key: str, schema: Mapping[str, Any], swept: bool = False) -> str:
    """`` (network.generate is a list: ...)`` for an unknown ``key`` that names an item of a
    list or a field of one (``--set network.generate[1].sigma_arcsec=3``), saying to give the
    whole list; "" otherwise. Only for a key that is a list of ``schema`` (an integer
    ``plate.grid[0]``, a table ``errors.1``, a key the study lacks are no list). A field of the
    items named without an index (``network.grids.spacing_mm``) is read the same way.
    ``swept``: ``key`` is a key of a ``[sweep]`` table (``"network.grids[0].spacing_mm" =
    [40.0, 60.0]``: "unknown key" alone, a designer sweeping a plate's spacing left to read the
    code): sweep the whole list, one a cell."""
    m = _ITEM.match(key)
    parts = key.split(".")
    # a field of the items without an index (network.grids.spacing_mm): the list is named too
    heads = [".".join(parts[:i]) for i in range(len(parts) - 1, 1, -1)]
    name = m.group(1) if m else next((h for h in heads if h in schema), "")
    field = schema.get(name) if name else None
    if field is None or not _LIST_KIND.match(getattr(field, "kind", "")):
        return ""
    if swept:
        return (
            f" ({name} is a list: its items have no keys of their own; sweep the whole list,"
            f' one list a cell: "{name}" = [[...], [...]])'
        )
    return (
        f" ({name} is a list: its items have no keys of their own; give the whole list, "
        f"--set '{name}=[...]' (sim.load: {name.replace('.', '__')}=[...]), or edit the "
        "study file)"
    )


def unknown_key_hint(key: str, schema: Mapping[str, Any]) -> str:
    """`` (did you mean ...?)`` and what else tells what an unknown ``key`` of ``schema`` (a
    study's keys) meant, or "": a table given as a key (``--set plate=4``), a typographic
    quote pasted in (“plate.grid=4”), an item of a list set by its index."""
    hint = near_keys(key, did_you_mean(key, schema))  # its unit said: spacing_um for spacing_mm
    if inner := [s for s in schema if s.startswith(f"{key}.")][:3]:  # --set plate=4
        hint = f" ({key} is a table: give one of its keys, {', '.join(inner)}, ...)"
    curly = [c for c in key if c in TYPOGRAPHIC]
    if curly:  # --set “plate.grid=4” pasted from a web page or a word processor:
        # "did you mean plate.grid?" alone reads as the same key
        hint = f' (it holds the typographic quote {curly[0]}: type a plain " or none)'
    return hint + item_hint(key, schema)
