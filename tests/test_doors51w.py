"""Issue 26 item 1 (W52): the work and memory estimate against what runs really take.

``python -m sim.batch --jobs J`` checked each run's estimate alone against the memory limit,
so J large runs side by side could hold J times the limit (B51's left item): the batch now
starts a run only while its estimate fits beside those of the runs going
(:mod:`sim.batch_memory`)."""

import json
import threading
from pathlib import Path

from sim import batch
from sim.batch_memory import MemoryGate
from tests.conftest import grid_network

ROOT = Path(__file__).resolve().parent.parent


def _two_grids(tmp_path):
    """Two copies of a 6 x 6 trilateration grid (``a.toml``, ``b.toml``) and the bytes one
    run's estimate needs."""
    src, need = grid_network(tmp_path, side=6)
    a, b = tmp_path / "a.toml", tmp_path / "b.toml"
    a.write_text(src.read_text())
    b.write_text(src.read_text())
    return a, b, need


def test_jobs_do_not_hold_more_than_the_memory_limit_together(tmp_path, capsys):
    """Runs side by side over the memory limit together (``--jobs 2``, each run's estimate
    under the limit, two of them over it): both started at once before, each checked alone
    (J runs of a large network could need J x the limit); the second now starts when the
    first has ended, with one line saying why, and both run (nothing refused)."""
    a, b, need = _two_grids(tmp_path)
    gb = 1.5 * need / 2**30  # one run fits, two do not
    timings = tmp_path / "t.json"
    args = ["--jobs", "2", "--results", str(tmp_path / "r"), "--timings", str(timings)]
    rc = batch.main([*args, str(a), str(b), "--", "--no-figures", "--max-memory-gb", repr(gb)])
    err = capsys.readouterr().err
    assert rc == 0, err
    done = json.loads(timings.read_text())  # {stem: [exit code, wall s, start s]}
    assert {k: v[0] for k, v in done.items()} == {"a": 0, "b": 0}
    first, second = sorted(done.values(), key=lambda v: v[2])
    assert second[2] >= first[2] + first[1]  # started after the first ended
    assert "waits for a run to end" in err and "--max-memory-gb" in err


def test_the_gate_admits_a_lone_run_and_lets_go_on_a_stop():
    """A run larger than the limit alone is admitted (its own check bounded it: refusing it
    here would hang the batch), and a run waiting for room returns when the batch is
    interrupted (held bytes given back each time)."""
    said: list[str] = []
    gate = MemoryGate({"big": 2.0 * 2**30, "small": 1.0}, 1.0, said.append)
    stop = threading.Event()
    assert gate.enter("big", 2.0 * 2**30, stop)  # alone: admitted
    stop.set()
    assert not gate.enter("small", 2**30, stop)  # would wait: stopped
    gate.leave(2.0 * 2**30)
    assert gate.held == 0.0 and said == []  # stopped before it said it waits
    assert gate.around("small", threading.Event(), lambda f: f, lambda: None) == "small"


def test_without_estimates_nothing_waits():
    """run_all called without estimates (tests, benchmarks) holds no gate."""
    gate = MemoryGate({}, None)
    assert gate.enter("x", 1e30, threading.Event()) and gate.enter("y", 1e30, threading.Event())


def test_wolf_estimate_counts_the_trade_off_chunks_the_run_takes():
    """An estimate too high (a run that fits refused): Wolf's trade-offs run in chunks of
    :func:`sim.studies.wolf.chunks.sub_chunk` (at least four chunks: 100 of its 400 trials),
    but were counted in chunks of ``min(trade.trials, chunk)`` (400): the paper's setup was
    estimated at 1.09 GiB for a run measured at 0.39 GiB at its peak (the whole process).
    The estimate now follows the study's rule, so it no longer grows with ``chunk`` past
    a quarter of ``trade.trials``."""
    import sim
    from sim.mc.estimate import estimate, wolf_sub_chunk
    from sim.studies.wolf.chunks import sub_chunk

    for t, ch in [(400, 500), (3, 500), (1000, 10), (1, 1), (7, 2)]:
        assert wolf_sub_chunk(t, ch) == sub_chunk(t, ch)
    cfg = dict(sim.load(ROOT / "studies" / "wolf_polynomial.toml").config)
    assert (cfg["trade.trials"], cfg["chunk"]) == (400, 500)  # the case measured
    at_500 = estimate(cfg).bytes
    assert at_500 == estimate({**cfg, "chunk": 100}).bytes  # the trade chunk is 100 in both
    assert at_500 < 0.4 * 2**30


def test_a_span_just_over_1000_km_is_named_with_the_digits_that_put_it_over(tmp_path, capsys):
    """An unclear message: a 5,000-leg traverse of 200 m legs with its end points (1000.2 km)
    was refused as "the network spans 1000 km: over 1000 km" (four digits); the span is now
    printed with the digits that put it over the bound."""
    from sim.cli import main

    st = tmp_path / "long.toml"
    st.write_text(
        'study = "network"\ntrials = 40\nchunk = 2\n[network]\npoints = [ '
        '{ name = "A", x_mm = 0.0, y_mm = 0.0, role = "fixed" }, '
        '{ name = "B", x_mm = 1000200000.0, y_mm = 0.0, role = "fixed" }, '
        '{ name = "C", x_mm = 500000000.0, y_mm = 1000.0 } ]\n'
        'generate = [ { kind = "distance", from = "*", to = "*", sigma_mm = 1.0 } ]\n'
    )
    assert main(["check", str(st)]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "spans 1000.2 km: over 1000 km" in err, err
