"""The chunk store's packed arrays (sim/mc/packed.py): every array comes back equal in dtype,
shape and bits; what is not a packed value is refused, so a chunk file of another format is
computed again rather than misread."""

from __future__ import annotations

import io

import numpy as np
import pyarrow.parquet as pq
import pytest

from sim.mc.packed import pack, unpack
from sim.mc.runner import ChunkStore


def arrays() -> dict[str, np.ndarray]:
    rng = np.random.default_rng(7)
    return {
        "scalar": np.float64(3.5) * np.ones(()),
        "one": rng.normal(size=1),
        "matrix_view": np.arange(24.0).reshape(4, 6)[:, ::2],  # not contiguous
        "fortran": np.asfortranarray(rng.normal(size=(3, 5))),
        "big_endian": np.arange(5, dtype=">i4"),
        "flags": rng.random(7) < 0.5,
        "empty": np.zeros((0, 3)),
        "text": np.array(["ab", "cde", ""]),
        "nan_inf": np.array([np.nan, np.inf, -np.inf, -0.0]),
        "int8": np.array([-128, 127], np.int8),
        "complex": np.array([1 + 2j]),
    }


def test_every_array_comes_back_equal_in_dtype_shape_and_bits():
    a = arrays()
    b = unpack(pack(a))
    assert list(b) == list(a)
    for k in a:
        assert b[k].dtype == a[k].dtype and b[k].shape == a[k].shape, k
        assert np.ascontiguousarray(b[k]).tobytes() == np.ascontiguousarray(a[k]).tobytes(), k
        assert b[k].flags.writeable, k


def test_many_small_arrays_are_smaller_than_an_npz_of_them():
    """Wolf's smaller parts keep about 3,000 one-value arrays a chunk: the packed value holds
    each one's 8 bytes and a short header entry, an .npz a zip member of ~200 bytes each."""
    a = {f"v{i}": np.array([float(i)]) for i in range(3000)}
    buf = io.BytesIO()
    np.savez(buf, **a)
    packed = pack(a)
    assert len(packed) < len(buf.getvalue()) / 4
    back = unpack(packed)  # once: unpacked per key, the test took 100 s
    assert back.keys() == a.keys() and all(back[k][0] == a[k][0] for k in a)


def test_an_object_array_is_refused_naming_it():
    with pytest.raises(TypeError, match="odd holds Python objects"):
        pack({"fine": np.ones(2), "odd": np.array([None, 1], object)})


@pytest.mark.parametrize(
    ("data", "why"),
    [
        (b"PK\x03\x04 an npz is a zip", "not a packed value"),
        (pack({"x": np.arange(4.0)})[:-1], "cut short"),
        (pack({"x": np.arange(4.0)}) + b"\0", "trailing bytes"),
    ],
)
def test_what_is_not_a_whole_packed_value_is_refused(data, why):
    with pytest.raises(ValueError, match=why):
        unpack(data)


def test_a_chunk_round_trips_and_an_npz_chunk_of_the_old_format_is_computed_again(tmp_path):
    prov = {"study": "t", "config": {"a": 1}, "code_hash": "c"}
    store = ChunkStore(tmp_path, prov)
    data = {"rows.r": np.arange(3.0), "sums": np.array([[1.0, 2.0]]), "per_trial": np.ones(3)}
    store.save(0, 0, 3, data, seed=5)
    back = store.load(0, 0, keep_rows=True, n=3, seed=5)
    assert set(back) == set(data) and all(np.array_equal(back[k], data[k]) for k in data)
    # the same file with its arrays as an .npz (the format before packing): not misread
    p = store.path(0, 0)
    t = pq.read_table(p)
    buf = io.BytesIO()
    np.savez(buf, sums=data["sums"], per_trial=data["per_trial"])
    meta = dict(t.schema.metadata)
    meta[b"sim.arrays"] = buf.getvalue()
    pq.write_table(t.replace_schema_metadata(meta), p)
    assert store.load(0, 0, n=3, seed=5) is None
