"""The classes of the sweep doors32a (brief A32: interrupts placed per phase of a run, runs
from threads, stale Results), one case each; each failed on the code before its fix.

* SIGINT or SIGTERM delivered while a run published its results (between the renames of
  :func:`sim.mc.publish.publish`: the swap of the results directory, moving the old results
  aside, removing them) ended ``sim run`` in exit 130 with "run the same command again to
  finish the missing chunks" although the new results were published and complete, and left
  the old results in a hidden directory (``.X.partial`` or ``.X.old.<pid>``) until a next run;
  the API's ``KeyboardInterrupt`` said nothing of them. A stop signal is now held while
  publishing (:func:`sim.held_stops.held_stops`) and handled once it is done: exit 130 "interrupted
  after the results were written to X/" (the API: a note saying so), nothing left beside.

Held (found right; each phase by a child process that sends itself the signal from a patched
function, with and without earlier results, by ``sim run`` and ``sim.load(...).run``):
SIGINT, SIGTERM and SIGKILL while validating, writing the first chunk (its temporary file),
between chunks, writing the tables, drawing a figure, writing the README and, SIGKILL,
between publishing's renames: the old results intact or none (with a ``.X.partial`` that
resumes), never a mixture; ``sim show`` shows what is there or says the directory does not
exist; the same command again ends with tables and figures equal to an uninterrupted run's.
Runs from threads: a run in a thread that is not the main one (no ``signal.signal``
there), two threads running two studies into two outs at once, and Ctrl-C to the main thread
while a thread runs (the main thread gets the ``KeyboardInterrupt``, the thread's run ends
with its results).
"""

from __future__ import annotations

import json
import os
import signal

import pytest

import sim
from sim.cli import main
from sim.mc import publish as publish_mod

RUN = ["run", "studies/brown_table1.toml", "--trials", "40", "--chunk", "2", "--quiet"]
RUN += ["--set", "region.points=256", "--set", "region.rounds=0", "--no-figures"]


def _signal_after_the_swap(monkeypatch, sig):
    """``sig`` sent to this process right after publishing swapped the results directory."""
    real = publish_mod._exchange

    def swap(a, b):
        done = real(a, b)
        os.kill(os.getpid(), sig)
        return done

    monkeypatch.setattr(publish_mod, "_exchange", swap)


def _claims(d):
    return sim.Results(d, "brown_table1").claims().to_pylist()


@pytest.mark.parametrize("sig", [signal.SIGINT, signal.SIGTERM])
def test_a_stop_signal_while_publishing_is_handled_once_published(
    tmp_path, monkeypatch, capsys, sig
):
    out, clean = tmp_path / "X", tmp_path / "clean"
    assert main([*RUN, "--seed", "7", "--out", str(out)]) == 0
    assert main([*RUN, "--seed", "8", "--out", str(clean)]) == 0
    _signal_after_the_swap(monkeypatch, sig)
    capsys.readouterr()
    rc = main([*RUN, "--seed", "8", "--out", str(out), "--overwrite"])
    err = capsys.readouterr().err.strip().splitlines()
    # before: "sim: interrupted; run the same command again to finish the missing chunks"
    assert (rc, err) == (130, [f"sim: interrupted after the results were written to {out}/"])
    assert sorted(p.name for p in tmp_path.iterdir()) == ["X", "clean"]  # no .X.partial
    assert json.loads((out / "run.json").read_text())["config"]["seed"] == 8
    assert _claims(out) == _claims(clean)


def test_an_interrupt_while_the_api_publishes_says_the_results_stand(tmp_path, monkeypatch):
    out = tmp_path / "X"
    st = sim.load("studies/brown_table1.toml", trials=40, chunk=2, **{"region.points": 256})
    st.run(out=out, quiet=True, figures=False)
    _signal_after_the_swap(monkeypatch, signal.SIGINT)
    with pytest.raises(KeyboardInterrupt) as e:  # before: no note, the old results in .X.partial
        st.run(out=out, seed=8, quiet=True, figures=False, overwrite=True)
    assert e.value.__notes__ == [
        f"sim: the run's results were written to {out} before the interrupt"
    ]
    assert sorted(p.name for p in tmp_path.iterdir()) == ["X"]
    assert json.loads((out / "run.json").read_text())["config"]["seed"] == 8
