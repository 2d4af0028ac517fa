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


def test_a_terminal_of_no_width_still_gets_a_bar_and_a_wide_one_a_bounded_line(monkeypatch):
    """A pseudo-terminal whose size was never set reports 0 columns: tqdm drew no bar at all;
    at 2,000 columns every redraw was a line of 5.8 kB (doors22b)."""
    for cols, lo, hi in ((0, 40, 80), (2000, 100, 200)):
        monkeypatch.setattr("sim.mc.progress._columns", lambda stream, c=cols: c)
        s = Tty()
        with Progress(100, "study", stream=s, min_interval=0.0, chunks=4) as p:
            p.update(25, 1)
        lines = [x for x in s.getvalue().split("\r") if "trials" in x]
        assert lines and all(lo <= len(x.strip()) <= hi for x in lines), (cols, lines)


def test_no_bar_on_a_dumb_terminal(monkeypatch):
    """TERM=dumb (an editor's shell buffer) cannot move back: each redraw would stay."""
    monkeypatch.setenv("TERM", "dumb")
    s = Tty()
    with Progress(100, "study", stream=s, min_interval=0.0) as p:
        p.update(50)
    assert s.getvalue() == ""
