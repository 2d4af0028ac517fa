"""The lead's probe at the end of session 41: ``sim.run_chunks``, which ``sim`` exports beside
``sim.load`` (doors42a wrapped it to name an argument it does not take), ended in Python's
words from inside the runner for a chunk function that is not callable (``'NoneType' object
is not callable``) or a count that is not a whole number: one ``sim.ConfigError`` naming the
argument now. A good call still runs and returns the chunks concatenated in order. The same
of ``sim.load_study`` and ``sim.write_table`` given an argument of the wrong kind (overrides
as a dict, a column that is a string)."""

from pathlib import Path

import numpy as np
import pytest

import sim

ROOT = Path(__file__).resolve().parents[1]


def _fn(rng, n):
    return {"x": rng.standard_normal(n)}


@pytest.mark.parametrize(
    "args, kwargs, key",
    [
        ((None, 4, 1, 2), {}, "fn"),
        (("f", 4, 1, 2), {}, "fn"),
        ((_fn, 2.5, 1, 2), {}, "trials"),
        ((_fn, 0, 1, 2), {}, "trials"),
        ((_fn, True, 1, 2), {}, "trials"),
        ((_fn, 4, -1, 2), {}, "seed"),
        ((_fn, 4, "1", 2), {}, "seed"),
        ((_fn, 4, 1, 0), {}, "chunk"),
        ((_fn, 4, 1, 2), {"part": -3}, "part"),
    ],
)
def test_run_chunks_names_its_argument(args, kwargs, key):
    with pytest.raises(sim.ConfigError) as e:
        sim.run_chunks(*args, **kwargs)
    assert e.value.key == key and "\n" not in str(e.value), str(e.value)


def test_run_chunks_by_keyword_and_with_numpy_counts_still_runs():
    out = sim.run_chunks(fn=_fn, trials=np.int64(5), seed=3, chunk=2, quiet=True)
    again = sim.run_chunks(_fn, 5, 3, 2, quiet=True)
    assert out["x"].shape == (5,) and np.array_equal(out["x"], again["x"])


def test_load_study_and_write_table_name_an_argument_of_the_wrong_kind(tmp_path):
    """``sim.load_study(path, {"trials": 40})`` was refused as "--set needs key=value (got
    'trials')" (the dict iterated by its keys), ``sim.load_study(path, 5)`` Python's "'int'
    object is not iterable"; ``sim.write_table`` of a string column pyarrow's "only handle
    1-dimensional arrays", of columns not a mapping an AttributeError of ``.items``."""
    study = ROOT / "studies" / "brown_table1.toml"
    prov = {"study": "x"}
    for call, key in (
        (lambda: sim.load_study(study, {"trials": 40}), "overrides"),
        (lambda: sim.load_study(study, 5), "overrides"),
        (lambda: sim.load_study(study, [5]), "overrides"),
        (lambda: sim.load_study(study, values=[("trials", 40)]), "values"),
        (lambda: sim.write_table(tmp_path / "a.parquet", {"a": "text"}, prov), "columns"),
        (lambda: sim.write_table(tmp_path / "a.parquet", {"a": np.ones((2, 2))}, prov), "columns"),
        (lambda: sim.write_table(tmp_path / "a.parquet", 5, prov), "columns"),
        (lambda: sim.write_table(tmp_path / "a.parquet", {"a": [1.0]}, "p"), "prov"),
    ):
        with pytest.raises(sim.ConfigError) as e:
            call()
        assert e.value.key == key and "\n" not in str(e.value), str(e.value)
    assert not (tmp_path / "a.parquet").exists()
    assert sim.load_study(study, ["trials=40"], values={"chunk": 2})[1]["trials"] == 40
    assert sim.write_table(tmp_path / "b.parquet", {"a": [1.0, 2.0]}, prov).exists()
