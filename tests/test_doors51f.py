"""Issue 26, F52: fresh fuzz seeds, and a new mutation kind: the Python API's arguments given
in odd TYPES (tests/fuzz_api_types.py, run by tests/test_fuzz.py::test_fuzz_api_types).

The fuzz at the new seeds found a caller's own object that raises while the API reads it
passing through ``sim.load``, ``replace``, ``run`` and ``sim.Results`` as that object's
traceback, naming no argument."""

from __future__ import annotations

import pytest
from conftest import TRIANGLE_NETWORK
from fuzz_api_types import (
    BrokenArray,
    BrokenInt,
    BrokenMap,
    BrokenSeq,
    BrokenStr,
    PathTo,
    RaisingPath,
)

import sim


@pytest.fixture
def study(tmp_path):
    f = tmp_path / "tri.toml"
    f.write_text(TRIANGLE_NETWORK)
    return f


def _refused(call, arg: str) -> str:
    with pytest.raises(sim.ConfigError) as e:
        call()
    msg = str(e.value)
    assert msg.startswith(arg) and "\n" not in msg, msg
    return msg


def test_a_value_whose_reading_raises_is_refused_naming_its_key(study, tmp_path):
    """A caller's object that RAISES WHILE READ as a config value (an ``os.PathLike`` whose
    ``__fspath__`` raises, a ``Sequence`` whose ``__len__`` or items raise, a ``Mapping``
    whose ``__iter__`` raises, an ``Integral`` whose ``__int__`` raises, an array-like whose
    ``__array__`` raises a MemoryError) given to ``sim.load``, ``replace`` or ``run``: its own
    exception passed through the API as a traceback (``RuntimeError: boom``), naming no key;
    now one line naming the key and what the object raised."""
    h = sim.load(study)
    msg = _refused(lambda: sim.load(study, seed=RaisingPath(OSError)), "seed")
    assert "OSError: fspath broken" in msg and "RaisingPath" in msg
    _refused(lambda: sim.load(study, **{"network.points": BrokenSeq()}), "network.points")
    _refused(lambda: h.replace(trials=BrokenInt()), "trials")
    _refused(lambda: h.replace(seed=BrokenMap()), "seed")
    _refused(lambda: h.replace(seed=BrokenSeq(0)), "seed")
    _refused(lambda: sim.load(study, trials=BrokenArray()), "trials")
    for arg in ("seed", "quiet", "workers"):
        _refused(lambda: h.run(out=tmp_path / "o", **{arg: RaisingPath(RuntimeError)}), arg)
    assert not (tmp_path / "o").exists()


def test_a_str_subclass_is_read_as_its_text(study, tmp_path):
    """A ``str`` SUBCLASS whose ``__str__`` raises (its text is the str it holds: pathlib
    and f-strings call ``__str__``), or an ``os.PathLike`` giving one, as ``sim.load``'s study
    file, ``sim.Results``' path or study, or ``table``'s name: the subclass's RuntimeError passed through as a traceback;
    now read as the text it holds (the same handle; the same refusal as the plain str)."""
    assert sim.load(BrokenStr(str(study))).config == sim.load(study).config
    assert sim.load(PathTo(BrokenStr(str(study)))).config == sim.load(study).config
    (empty := tmp_path / "empty").mkdir()
    res = sim.Results(BrokenStr(str(empty)), BrokenStr("network"))
    assert res.path == empty and type(res.study) is str
    plain = _refused(lambda: sim.Results(empty, "network").table("points"), "path")
    assert _refused(lambda: res.table(BrokenStr("points")), "path") == plain


def test_results_fuzzer_reads_a_report_as_it_now_writes(tmp_path):
    """The RESULTS fuzzer (tests/fuzz_results.py) at seeds 5020 and 5021: every ``sim report``
    case failed, as the fuzzer's wrong expectation, not the suite's defect: the report
    rebuilds README.md (it names its directory) and records its sha256 in run.json (J50),
    which the fuzzer called "the reader changed what it read"; and its diff of a nested dict
    was itself a TypeError ("unhashable type: 'dict'") that hid the case. Now run.json is
    compared without ``readme_sha256`` (any other change still counts), never opened when it
    is no regular file (a FIFO), and the snapshot is flat."""
    import json
    import os

    from fuzz_results import _both, _sans_readme

    (rec := tmp_path / "res" / "run.json").parent.mkdir()
    rec.write_text(json.dumps({"study": "network", "readme_sha256": "a"}))
    was = _sans_readme(rec)
    rec.write_text(json.dumps({"study": "network", "readme_sha256": "b"}))
    assert _sans_readme(rec) == was
    rec.write_text(json.dumps({"study": "other", "readme_sha256": "b"}))
    assert _sans_readme(rec) != was
    os.mkfifo(fifo := tmp_path / "res" / "fifo.json")
    assert _sans_readme(fifo) is None
    (out := tmp_path / "outside").mkdir()
    (out / "copy").write_text("x")
    both = _both(tmp_path / "res", out)
    assert "outside/copy" in both and set(both.items())
