"""A small progress bar: trials done, trials per second, time left.

Drawn on standard error only when it is a terminal (and not ``quiet``); silent otherwise,
so logs and CI output stay clean.
"""
from __future__ import annotations

import sys
import time

__all__ = ["Progress"]


class Progress:
    """``with Progress(total, label) as p: p.update(n)``."""

    def __init__(self, total: int, label: str = "", quiet: bool = False, stream=None,
                 min_interval: float = 0.2, chunks: int = 0):
        self.total = int(total)
        self.chunks = int(chunks)
        self.chunks_done = 0
        self.label = label
        self.stream = stream if stream is not None else sys.stderr
        self.enabled = not quiet and hasattr(self.stream, "isatty") and self.stream.isatty()
        self.done = 0
        self.t0 = time.perf_counter()
        self._last = 0.0
        self.min_interval = min_interval

    def __enter__(self) -> "Progress":
        return self

    def __exit__(self, *exc) -> None:
        if self.enabled:
            self._draw(force=True)
            self.stream.write("\n")
            self.stream.flush()

    def update(self, n: int, chunks: int = 0) -> None:
        self.done += int(n)
        self.chunks_done += int(chunks)
        if self.enabled:
            self._draw()

    def _draw(self, force: bool = False) -> None:
        now = time.perf_counter()
        if not force and now - self._last < self.min_interval:
            return
        self._last = now
        el = max(now - self.t0, 1e-9)
        rate = self.done / el
        left = (self.total - self.done) / rate if rate > 0 else float("nan")
        frac = self.done / self.total if self.total else 1.0
        bar = "#" * int(30 * frac) + "-" * (30 - int(30 * frac))
        ch = f"chunk {self.chunks_done}/{self.chunks}, " if self.chunks else ""
        self.stream.write(f"\r{self.label} [{bar}] {ch}{self.done}/{self.total} trials, "
                          f"{rate:,.0f}/s, {left:,.0f} s left ")
        self.stream.flush()
