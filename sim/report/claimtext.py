"""A claim's numbers as text: the simulated value and its 95 % interval at the precision the
interval supports (two significant digits of its half-width), deterministic values with as
many digits as it takes to stay on their side of the decision zone's edges, and the zone.
Shared by ``results/REPORT.md``, each results directory's ``README.md`` and ``sim show``."""

from __future__ import annotations

import math

from sim.report.tables import fmt

__all__ = ["decimals_for", "fmt_at", "ref_text", "sim_text", "interval_text", "exact_text"]


def ref_text(r) -> str:
    """The paper's reference as the decision zone it stands for."""
    lo, hi = r.get("zone_low"), r.get("zone_high")
    none = lambda x: x is None or (isinstance(x, float) and not math.isfinite(x))  # noqa: E731
    if none(lo) and none(hi):
        return ""
    f = (lambda x: f"{x:.10g}") if r["interval"] == "exact" else (lambda x: fmt(x, 4))  # noqa: E731
    form = r.get("form") or ""
    if form == "upper" or none(lo):
        return f"≤ {f(hi)}"
    if form == "lower" or none(hi):
        return f"≥ {f(lo)}"
    return f(lo) if lo == hi else f"{f(lo)}–{f(hi)}"


def decimals_for(lo, hi) -> int | None:
    """Decimal places an interval ``[lo, hi]`` supports: two significant digits of its
    half-width (negative: tens, hundreds...; more than nine: printed by :func:`fmt_at` in
    significant digits); None for a missing or zero-width interval."""
    if lo is None or hi is None:
        return None
    w = (float(hi) - float(lo)) / 2
    if not math.isfinite(w) or w <= 0:
        return None
    return 1 - math.floor(math.log10(w))


def fmt_at(x, dec: int | None, digits: int = 3) -> str:
    """``x`` with ``dec`` decimal places (see :func:`decimals_for`), or ``digits``
    significant digits when ``dec`` is None."""
    if dec is None or x is None or not isinstance(x, (int, float)) or not math.isfinite(x):
        return fmt(x, digits)
    if dec <= 0:
        return f"{round(float(x), dec):.0f}"
    if dec > 9 and x != 0 and abs(x) < 1e-4:  # 1.23e-11 at those decimals, never 0.000000000
        return f"{float(x):.{max(0, dec + math.floor(math.log10(abs(x))))}e}"
    return f"{float(x):.{dec}f}"


def _exact(x, r=None) -> str:
    """A deterministic number with 4 significant digits, or as many more (up to 10) as it
    takes to stay on the same side of each edge of the claim's decision zone (an erratum in
    the 9th decimal shows its 9th decimal)."""
    if not isinstance(x, (int, float)) or not math.isfinite(x):
        return fmt(x)
    edges = [
        float(b)
        for b in ((r or {}).get("zone_low"), (r or {}).get("zone_high"))
        if isinstance(b, (int, float)) and math.isfinite(b)
    ]
    for k in range(4, 11):
        text = f"{x:.{k}g}"
        y = float(text)
        if all((y < b) == (x < b) and (y > b) == (x > b) for b in edges):
            return text
    return f"{x:.10g}"


exact_text = _exact


def sim_text(r) -> str:
    if r["interval"] == "exact":
        val = _exact(r["value"], r)
        vh = r.get("value_high")
        if vh is not None and math.isfinite(vh) and vh != r["value"]:
            val += f"–{_exact(vh, r)}"
        return val
    dec = decimals_for(r.get("ci_low"), r.get("ci_high"))
    val = fmt_at(r["value"], dec)
    vh = r.get("value_high")
    if vh is not None and math.isfinite(vh) and vh != r["value"]:  # not "2.00–2.00"
        val += f"–{fmt_at(vh, dec)}"
    return val


def interval_text(r) -> str:
    if r["interval"] == "exact":
        return "exact"
    if r.get("ci_low") is None and r.get("ci_high") is None:
        return "—"  # a region row with no point to take values from (not "[, ]")
    dec = decimals_for(r.get("ci_low"), r.get("ci_high"))
    out = f"[{fmt_at(r['ci_low'], dec)}, {fmt_at(r['ci_high'], dec)}]" + (
        " plates" if r["interval"] == "spread" else ""
    )
    p = r.get("p_plate")
    if p is not None and math.isfinite(p):
        out += f", p = {fmt(p, 2)}"
    return out
