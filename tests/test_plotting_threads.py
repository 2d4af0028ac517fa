"""Figures drawn from two threads never overlap: matplotlib is not thread-safe, and a
study may run its parts in threads (brown_design with a remote Dask scheduler drew two
figures at once and failed in matplotlib's text parser)."""

import threading
import time

from sim.report import plotting

EVENTS = []


def _job(name):
    EVENTS.append(("in", name))
    time.sleep(0.05)  # long enough for the other thread to start its figure
    EVENTS.append(("out", name))


def test_figures_drawn_from_two_threads_do_not_overlap():
    EVENTS.clear()
    go = threading.Barrier(2)

    def part(name):
        go.wait()
        plotting.draw([(_job, (name,)), (_job, (name + "2",))])

    threads = [threading.Thread(target=part, args=(n,)) for n in ("a", "b")]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert len(EVENTS) == 8
    for k in range(0, 8, 2):  # every figure ends before the next begins
        assert EVENTS[k][0] == "in" and EVENTS[k + 1] == ("out", EVENTS[k][1])
    assert not plotting.DRAWING.locked()
