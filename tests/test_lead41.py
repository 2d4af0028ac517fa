"""The lead's probe at the end of session 41: ``sim.run_chunks``, which ``sim`` exports beside
``sim.load`` (doors42a wrapped it to name an argument it does not take), ended in Python's
words from inside the runner for a chunk function that is not callable (``'NoneType' object
is not callable``) or a count that is not a whole number: one ``sim.ConfigError`` naming the
argument now. A good call still runs and returns the chunks concatenated in order."""

import numpy as np
import pytest

import sim


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
