"""Many small NumPy arrays packed into one ``bytes`` value, and back (the chunk store's format).

A chunk function returns a dict of arrays; besides its per-trial rows, the store keeps the
other arrays of a chunk in the chunk file's metadata. Wolf's smaller parts return about three
thousand one-value arrays per chunk: as an ``.npz`` (a zip member, header and CRC per array)
saving and loading them cost tens of milliseconds a chunk, most of a run of many small chunks
(``make bench``, section ``store``). Here they are one buffer: a magic, the length of a JSON
header ``[[name, dtype, shape], ...]``, the header, then each array's C-ordered bytes in that
order. Only fixed-size dtypes (numbers, booleans, fixed-width strings); an object array is
refused.
"""

from __future__ import annotations

import json
from typing import Mapping

import numpy as np

__all__ = ["pack", "unpack"]

_MAGIC = b"simpack1"


def pack(arrays: Mapping[str, np.ndarray]) -> bytes:
    """``arrays`` (name -> array) as one bytes value; :func:`unpack` gives them back equal in
    dtype, shape and every bit. ``TypeError`` for an array of Python objects."""
    header, body = [], []
    for name, a in arrays.items():
        a = np.asarray(a)
        if a.dtype.hasobject:
            raise TypeError(f"packed arrays: {name} holds Python objects ({a.dtype})")
        header.append([str(name), a.dtype.str, list(a.shape)])
        body.append(np.ascontiguousarray(a).tobytes())
    head = json.dumps(header, separators=(",", ":")).encode()
    return b"".join([_MAGIC, len(head).to_bytes(8, "little"), head, *body])


def unpack(data: bytes) -> dict[str, np.ndarray]:
    """The arrays of :func:`pack` (each its own writable copy). ``ValueError`` when ``data`` is
    not a packed value, is cut short or runs on past its last array."""
    if data[: len(_MAGIC)] != _MAGIC:
        raise ValueError("packed arrays: not a packed value")
    start = len(_MAGIC) + 8
    size = int.from_bytes(data[len(_MAGIC) : start], "little")
    header = json.loads(data[start : start + size])
    at, out = start + size, {}
    view = memoryview(data)
    for name, dtype, shape in header:
        dt = np.dtype(dtype)
        count = int(np.prod(shape, dtype=np.int64))
        nbytes = count * dt.itemsize
        if at + nbytes > len(data):
            raise ValueError("packed arrays: cut short")
        out[name] = np.frombuffer(view[at : at + nbytes], dt, count).reshape(shape).copy()
        at += nbytes
    if at != len(data):
        raise ValueError("packed arrays: trailing bytes")
    return out
