"""The progress bar (tqdm) draws on a terminal only."""

import io

from sim.mc.progress import Progress


class Tty(io.StringIO):
    def isatty(self):
        return True


def test_draws_chunks_trials_rate_and_time_left_on_a_terminal():
    s = Tty()
    with Progress(100, "study", stream=s, min_interval=0.0, chunks=4) as p:
        p.update(25, 1)
    out = s.getvalue()
    assert "study" in out and "chunk 1/4" in out and "25/100 trials" in out and "trials/s" in out
    assert "<" in out  # elapsed<remaining


def test_total_grows_when_the_estimate_was_short():
    s = Tty()
    with Progress(10, "study", stream=s, min_interval=0.0) as p:
        p.update(25)
    assert "25/25 trials" in s.getvalue()


def test_silent_when_not_a_terminal_or_quiet():
    s = io.StringIO()
    with Progress(100, "study", stream=s, min_interval=0.0) as p:
        p.update(50)
    assert s.getvalue() == ""
    t = Tty()
    with Progress(100, "study", stream=t, quiet=True, min_interval=0.0) as p:
        p.update(50)
    assert t.getvalue() == ""
