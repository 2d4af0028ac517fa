"""Chunk-store rows of the benchmark (``store.parquet``): the arrays a chunk keeps besides its
rows, saved and loaded as the store does it (:mod:`sim.mc.packed`) against the ``.npz`` the
store used before (``np.savez`` into bytes, ``np.load`` of every member).

Cases are the shapes of real chunks: ``wolf_subpart`` is a chunk of wolf_polynomial's
degree/stability parts (3,072 one-value float arrays and 64 one-value flags), ``wolf_main``
a chunk of its main part (67 floats and a flag, one trial each), ``large`` four arrays of
500 x 200 values (the format must not lose on big arrays). CPU time of this process, best of
``repeat`` rounds (:func:`benchmarks.timing.cpu_time`); both formats give the arrays back
bit for bit (checked for every row).
"""

from __future__ import annotations

import io

import numpy as np

from benchmarks.timing import cpu_time
from sim.mc.packed import pack, unpack

__all__ = ["CASES", "store_rows"]


def _case(name: str) -> dict[str, np.ndarray]:
    rng = np.random.default_rng(11)
    if name == "wolf_subpart":
        a = {f"x{i}": rng.normal(size=1) for i in range(3072)}
        return a | {f"ok{i}": rng.random(1) < 0.5 for i in range(64)}
    if name == "wolf_main":
        return {f"x{i}": rng.normal(size=1) for i in range(67)} | {"ok": np.array([True])}
    return {f"x{i}": rng.normal(size=(500, 200)) for i in range(4)}


CASES = ("wolf_subpart", "wolf_main", "large")


def _npz(arrays) -> bytes:
    buf = io.BytesIO()
    np.savez(buf, **arrays)
    return buf.getvalue()


def _from_npz(data: bytes) -> dict:
    with np.load(io.BytesIO(data)) as z:
        return {k: z[k] for k in z.files}


def store_rows(quick: bool = False) -> dict[str, list]:
    """Columns of ``store.parquet``: ``case``, ``arrays``, ``packed_bytes``, ``npz_bytes``,
    ``packed_ms`` and ``npz_ms`` (save + load of one chunk's arrays), ``speedup``."""
    repeat = 2 if quick else 5
    cols = {k: [] for k in ("case", "arrays", "packed_bytes", "npz_bytes")}
    cols |= {"packed_ms": [], "npz_ms": [], "speedup": []}
    for name in CASES:
        a = _case(name)
        p, z = pack(a), _npz(a)
        for back in (unpack(p), _from_npz(z)):
            if any(back[k].tobytes() != a[k].tobytes() for k in a):
                raise RuntimeError(f"bench store: {name}: arrays did not come back equal")
        tp = cpu_time(lambda: unpack(pack(a)), repeat)
        tz = cpu_time(lambda: _from_npz(_npz(a)), repeat)
        for k, v in (("case", name), ("arrays", len(a)), ("packed_bytes", len(p))):
            cols[k].append(v)
        cols["npz_bytes"].append(len(z))
        cols["packed_ms"].append(1e3 * tp)
        cols["npz_ms"].append(1e3 * tz)
        cols["speedup"].append(tz / tp if tp > 0 else np.inf)
    return cols
