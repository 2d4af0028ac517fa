"""Tables the suite writes hold no infinite statistic: :func:`check_finite_table`, called by
:func:`sim.mc.storage.write_table` before anything is written.

An infinity is refused wherever a float stands in a column -- at its top level, inside a
list (``list<double>``, a fixed-size list), inside a struct, or nested deeper -- one line
naming the table, the column and the row. (A list column was written with ``inf`` inside it
while the same number at the top level was refused.) NaN may mean "missing" except in a
claims table's value and interval.
"""

from __future__ import annotations

import numpy as np
import pyarrow as pa
import pyarrow.compute as pc

__all__ = ["NonFiniteError", "CLAIM_NUMBERS", "check_finite_table", "nested_inf"]


class NonFiniteError(ValueError):
    """A statistic that must be a number is NaN or infinite (one line naming the table and
    column)."""


#: columns of a claims table that must hold finite numbers (a NaN reference is "no number")
CLAIM_NUMBERS = ("value", "ci_low", "ci_high")


def _listlike(t: pa.DataType) -> bool:
    return pa.types.is_list(t) or pa.types.is_large_list(t) or pa.types.is_fixed_size_list(t)


def _first_inf(arr: pa.Array) -> tuple[int, float] | None:
    """``(row, value)`` of the first row of ``arr`` holding an infinite float anywhere in its
    nesting (lists, fixed-size lists, maps, structs), or None."""
    t = arr.type
    if pa.types.is_floating(t):
        v = np.asarray(arr.to_numpy(zero_copy_only=False), dtype=float)
        hit = np.flatnonzero(np.isinf(v))
        return (int(hit[0]), float(v[hit[0]])) if hit.size else None
    if pa.types.is_dictionary(t):
        return _first_inf(arr.dictionary_decode())
    if pa.types.is_map(t):  # a list of key-item structs (Arrow's list kernels take no map)
        return _first_inf(arr.cast(pa.list_(pa.struct([t.key_field, t.item_field]))))
    if _listlike(t):
        inner = pc.list_flatten(arr)  # the items of every row, in order; their rows below
        found = _first_inf(inner)
        if found is None:
            return None
        return int(pc.list_parent_indices(arr)[found[0]].as_py()), found[1]
    if pa.types.is_struct(t):
        hits = [h for child in arr.flatten() if (h := _first_inf(child)) is not None]
        return min(hits) if hits else None
    return None


def nested_inf(column: pa.ChunkedArray | pa.Array) -> tuple[int, float] | None:
    """``(row, value)`` of the first infinite float held inside the list or struct column
    ``column`` (rows counted across its chunks), or None."""
    chunks = column.chunks if isinstance(column, pa.ChunkedArray) else [column]
    start = 0
    for chunk in chunks:
        if (found := _first_inf(chunk)) is not None:
            return start + found[0], found[1]
        start += len(chunk)
    return None


def check_finite_table(name: str, table: pa.Table) -> None:
    """No float may hold +-inf, at a column's top level or inside its lists and structs (NaN
    may mean "missing"), and a claims table's value and interval must be finite: a
    non-finite verdict is an error, never a result (a null, e.g. in a ``not comparable`` row,
    is "no number" and allowed)."""
    is_claims = {"claim", *CLAIM_NUMBERS} <= set(table.column_names)
    for col, arr in zip(table.column_names, table.columns):
        if not pa.types.is_floating(arr.type):
            if (hit := nested_inf(arr)) is not None:
                raise NonFiniteError(
                    f"{name}: column {col} holds {hit[1]} inside its row {hit[0]}: a statistic "
                    "that must be a number is not finite"
                )
            continue
        v = arr.to_numpy(zero_copy_only=False).astype(float)
        valid = np.asarray(arr.is_valid())  # a null is "no number" (a not-comparable claim)
        bad = np.isinf(v) | (np.isnan(v) & valid if is_claims and col in CLAIM_NUMBERS else False)
        if bad.any():
            i = int(np.flatnonzero(bad)[0])
            what = f" (claim {table.column('claim')[i].as_py()})" if is_claims else f" (row {i})"
            raise NonFiniteError(
                f"{name}: column {col} is {v[i]}{what}: a statistic that must "
                "be a number is not finite"
            )
