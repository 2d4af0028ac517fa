"""Seeded fuzz of the newer doors: the Python API's arguments and a killed run's chunk store.

Each case asserts the promised class of behaviour: a bad argument is a ``ConfigError`` whose
message starts with the argument's name (one line, nothing from pathlib or NumPy); a chunk
store damaged between a kill and the resume (chunks truncated, swapped, duplicated, taken
from another seed, left over beyond the run) resumes to results equal to a clean run's.
``TYPED`` adds TYPE confusion to every argument (a date, a timedelta, a ``Decimal`` NaN, a
complex, a bytearray, a set, a NumPy array, an integer beyond 64 bits).
``FUZZ_CASES`` sets the number of cases (``make fuzz`` raises it), ``FUZZ_DOORS_SEED`` the
arguments' seed (the chunk store's is the next number; default 20261126)."""

import datetime
import decimal
import os
import shutil
from pathlib import Path

import numpy as np
import pyarrow.parquet as pq
import pytest

import sim
from sim.mc.config import ConfigError
from sim.mc.runner import ChunkStore, run_chunks
from sim.studies import RunContext

ROOT = Path(__file__).resolve().parent.parent
STUDY = ROOT / "studies" / "brown_table1.toml"
CASES = int(os.environ.get("FUZZ_CASES", "12"))
SEED = int(os.environ.get("FUZZ_DOORS_SEED", "20261126"))

BAD = {
    "out": [5, 1.0, b"x", "", "   ", "a\0b", ["x"]],
    "workers": ["2", 2.5, 0, -1, 10_000, True, None],  # 2.0 is 2 (as trials=400.0 is 400)
    "executor": ["", "thread", None, 1, "LOCAL"],
    "trials": ["10", 1.5, True],
    "seed": ["1", 2.5, [1]],
    "scheduler": ["", "tcp://", "host", "tcp://h:0", "tcp://h:70000", 5],
    "overwrite": ["yes", 1, None],
    "quiet": ["no", 0],
}
#: TYPE confusion: values of a type no argument takes (each refused by every argument)
TYPED = [
    datetime.date(2020, 1, 1),
    datetime.timedelta(1),
    decimal.Decimal("nan"),
    complex(2, 0),
    bytearray(b"1"),
    {2},
    np.array([2]),
    -(2**70),
]
for _k in BAD:
    BAD[_k] = BAD[_k] + TYPED


@pytest.mark.parametrize("case", range(CASES))
def test_api_arguments(tmp_path, case):
    rng = np.random.default_rng([SEED, case])
    st = sim.load(STUDY, trials=20, chunk=1)
    key = sorted(BAD)[rng.integers(len(BAD))]
    value = BAD[key][rng.integers(len(BAD[key]))]
    kw = {"out": tmp_path / "o", key: value}
    if key == "scheduler":
        kw["executor"] = "dask"
    with pytest.raises(ConfigError) as e:
        st.run(**kw)
    msg = str(e.value)
    assert msg.startswith(key) and "\n" not in msg, msg
    assert not (tmp_path / "o").exists()


def _toy(rng, n):
    x = rng.normal(size=(n, 3))
    return {"rows.x0": x[:, 0], "x": x}


def _damage(rng, d: Path, other: Path) -> str:
    files = sorted(d.glob("chunk-*.parquet"))
    what = ["truncate", "swap", "duplicate", "other-seed", "beyond", "delete"][rng.integers(6)]
    a, b = (files[i] for i in rng.choice(len(files), 2, replace=False))
    if what == "truncate":
        a.write_bytes(a.read_bytes()[: int(rng.integers(1, a.stat().st_size))])
    elif what == "swap":
        t = a.with_suffix(".t")
        a.rename(t), b.rename(a), t.rename(b)
    elif what == "duplicate":
        shutil.copy(a, b)
    elif what == "other-seed":
        shutil.copy(other / a.name, a)
    elif what == "beyond":
        shutil.copy(a, d / "chunk-000099.parquet")
    else:
        a.unlink()
    return what


@pytest.mark.parametrize("case", range(CASES))
def test_damaged_chunk_store_resumes_to_the_clean_result(tmp_path, case):
    rng = np.random.default_rng([SEED + 1, case])
    clean = run_chunks(_toy, 60, 3, 10, quiet=True, keep_rows=True)
    prov = {"study": "toy", "config": {"k": 1}}
    other = ChunkStore(tmp_path / "other", prov)
    run_chunks(_toy, 60, 4, 10, ctx=RunContext(quiet=True, store=other))
    store = ChunkStore(tmp_path / "trials", prov)
    run_chunks(_toy, 60, 3, 10, ctx=RunContext(quiet=True, store=store))
    what = _damage(rng, tmp_path / "trials" / "part-0", tmp_path / "other" / "part-0")
    again = ChunkStore(tmp_path / "trials", prov)
    got = run_chunks(_toy, 60, 3, 10, ctx=RunContext(quiet=True, store=again), keep_rows=True)
    for k in clean:
        assert np.array_equal(got[k], clean[k]), what
    for p in again.strays():
        p.unlink()
    rows = sum(pq.read_metadata(p).num_rows for p in (tmp_path / "trials").rglob("*.parquet"))
    assert rows == 60, what
