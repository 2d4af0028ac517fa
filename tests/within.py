"""``within(seconds, fn, *args)``: ``fn(*args)``, failing the test after ``seconds`` (a FIFO
opened by a reader blocks for good; tests/test_doors46h.py, 47k.py). SIGALRM's handler is given
back by the conftest."""

from __future__ import annotations

import signal


def within(seconds: int, fn, *args):
    """``fn(*args)``, or an AssertionError after ``seconds``."""

    def hung(*_):
        raise AssertionError(f"{fn.__name__}{args} still blocked after {seconds} s")

    signal.signal(signal.SIGALRM, hung)
    signal.alarm(seconds)
    try:
        return fn(*args)
    finally:
        signal.alarm(0)
