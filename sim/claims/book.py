"""Claims: a paper's statement, what the simulation produced, and a verdict with a stated rule.

A study declares its claims as data (a TOML *claim book*, see :class:`ClaimBook`): the
paper's text, where it stands, its *form*, its printed reference and the width that decides.
The study's code only supplies what the simulation produced (an estimate with its interval,
per-element intervals, or the per-plate distribution); the verdict follows from the rule
below, never from code that knows the answer.

The decision rules (forms, zones, verdicts) are in :mod:`sim.claims.rules`.

Columns of ``claims.parquet``: ``CLAIM_COLUMNS``. ``holds`` is derived from ``verdict``
(true for holds, false for fails and erratum, null otherwise). Printed numbers that are not
claims are listed, with the reason, in ``not_reproduced.parquet``.
"""

from __future__ import annotations

import math
import tomllib
from pathlib import Path
from typing import Any, Callable, Iterable, Mapping

import numpy as np

from sim.claims.declaration import toml_text
from sim.claims.intervals import plate_p, spread
from sim.claims.provenance import interval_provenance
from sim.claims.rules import (
    FORMS,
    KINDS,
    VERDICTS,
    decide,
    few_plates,
    holds_of,
    off_paper,
    printed_differs,
    short_chain,
    verdict_of,
    zone,
)
from sim.mc import tolerance as tl
from sim.mc.config import ConfigError, StudyError
from sim.mc.lookalike import alike
from sim.mc.storage import write_table

__all__ = [
    "ClaimBook",
    "decide",
    "write_claims",
    "CLAIM_COLUMNS",
    "VERDICTS",
    "KINDS",
    "FORMS",
]

CLAIM_COLUMNS = [
    "claim",
    "source",
    "paper",
    "form",
    "kind",
    "headline",
    "value",
    "value_high",
    "ci_low",
    "ci_high",
    "interval",
    "ref_low",
    "ref_high",
    "tol",
    "zone_low",
    "zone_high",
    "p_plate",
    "outcome",
    "verdict",
    "holds",
    "note",
]
NOT_REPRODUCED_COLUMNS = ["source", "printed", "why"]
#: how ``make verify`` compares ``claims.parquet`` (:mod:`sim.mc.tolerance`): the claim book's
#: columns exactly, also against a run with fewer trials; a value and its interval as a
#: Monte-Carlo statistic whose standard error its own row's 95 % interval gives (an exact row's
#: interval is its value: the arithmetic bound); a decision never changes
CLAIM_TOLERANCES = {
    **{c: tl.exact(analytic=True) for c in ("claim", "form", "kind", "headline", "interval")},
    **{c: tl.arithmetic(analytic=True) for c in ("ref_low", "ref_high", "tol")},
    **{c: tl.arithmetic(analytic=True) for c in ("zone_low", "zone_high")},
    **{c: tl.mc(ci=("ci_low", "ci_high")) for c in ("value", "value_high", "ci_low", "ci_high")},
    **{c: tl.exact() for c in ("outcome", "verdict", "holds")},
}

#: the most decimals a printed number carries here (a float has ~15 significant digits);
#: negative: rounded to tens, hundreds (design's ``-2``)
_MAX_DECIMALS = 12


def _number(x: Any) -> bool:
    """A TOML number: int or float, not a bool (``true`` is no printed value)."""
    return isinstance(x, (int, float)) and not isinstance(x, bool)


_SPEC_KEYS = {*"id source paper form ref decimals tol kind headline why paper_setup".split()}


# --------------------------------------------------------------------------- claim books
class ClaimBook:
    """A study's claims as data: ``[[claim]]`` and ``[[not_reproduced]]`` tables of a TOML file.

    Each ``[[claim]]`` has ``id``, ``source``, ``paper`` (the paper's words), ``kind`` and,
    unless the paper prints no number (``kind = "finding"`` or ``"not comparable"``),
    ``form``, ``ref`` (a number, or ``[a, b]`` for ``range``), ``decimals`` (the printed
    rounding; omit for an exact reference) and ``tol`` (the half-width beyond the rounding that
    decides; 0 lets the rounding alone decide). ``headline = true`` puts the claim in the
    report's referee summary; ``why`` is the reason of a ``not comparable`` row.
    ``paper_setup = true`` marks a ``self-check`` whose reference is a number of the paper's
    setup, not one every setup gives (:func:`sim.claims.rules.off_paper`).
    Each ``[[not_reproduced]]`` has ``source``, ``printed`` and ``why``.
    The study scores every declared claim exactly once (:meth:`check_complete`).
    """

    def __init__(self, specs: list[dict], not_reproduced: list[dict], path: str = "<claims>"):
        self.path = path
        self.specs: dict[str, dict] = {}
        for key, items in (("claim", specs), ("not_reproduced", not_reproduced)):
            if not isinstance(items, list) or not all(isinstance(s, dict) for s in items):
                raise ConfigError(key, f"{path}: [[{key}]] must be a list of tables")
        for i, s in enumerate(specs):
            where = f"{path}: claim {i + 1}"
            bad = set(s) - _SPEC_KEYS
            if bad:
                raise ConfigError(f"claim.{sorted(bad)[0]}", f"{where}: unknown key")
            for k in ("id", "source", "paper", "kind"):
                if not isinstance(s.get(k), str) or not s[k]:
                    raise ConfigError(f"claim.{k}", f"{where}: missing or not text")
            if s["kind"] not in KINDS:
                raise ConfigError(
                    "claim.kind",
                    f"{where} ({s['id']}): {s['kind']!r} is not one of {', '.join(KINDS)}",
                )
            if s["id"] in self.specs:
                raise ConfigError("claim.id", f"{where}: duplicate id {s['id']!r}")
            if "ref" in s:
                if s.get("form") not in FORMS:
                    raise ConfigError(
                        "claim.form", f"{where} ({s['id']}): form must be one of {', '.join(FORMS)}"
                    )
                ref = s["ref"]
                ref = ref if isinstance(ref, list) else [ref, ref]
                if (
                    len(ref) != 2
                    or not all(_number(r) for r in ref)
                    or not all(math.isfinite(r) for r in ref)
                    or ref[0] > ref[1]
                ):
                    raise ConfigError(
                        "claim.ref",
                        f"{where} ({s['id']}): ref must be a finite number or [low, high]",
                    )
                if (s["form"] == "range") != isinstance(s["ref"], list):
                    raise ConfigError(
                        "claim.ref",
                        f"{where} ({s['id']}): a range needs "
                        "[low, high], the other forms one number",
                    )
                if not _number(s.get("tol")) or not 0 <= s["tol"] < math.inf:
                    raise ConfigError(
                        "claim.tol",
                        f"{where} ({s['id']}): state the deciding half-width tol >= 0",
                    )
                d = s.get("decimals", 0)
                if (
                    not isinstance(d, int)
                    or isinstance(d, bool)
                    or not -_MAX_DECIMALS <= d <= _MAX_DECIMALS
                ):
                    raise ConfigError(
                        "claim.decimals",
                        f"{where} ({s['id']}): decimals is the printed rounding, a whole number "
                        f"-{_MAX_DECIMALS} to {_MAX_DECIMALS} (got {d!r})",
                    )
            elif s["kind"] in ("prediction", "paper-check"):
                raise ConfigError(
                    "claim.ref",
                    f"{where} ({s['id']}): a {s['kind']} needs the paper's number (ref)",
                )
            if not isinstance(s.get("headline", False), bool):
                raise ConfigError(
                    "claim.headline", f"{where} ({s['id']}): headline is true or false"
                )
            for k in ("form", "decimals", "tol"):
                if k in s and "ref" not in s:
                    raise ConfigError(
                        f"claim.{k}", f"{where} ({s['id']}): {k} without the paper's number (ref)"
                    )
            ps = s.get("paper_setup", False)  # true: a self-check's ref is the paper setup's
            if not isinstance(ps, bool) or ps and (s["kind"] != "self-check" or "ref" not in s):
                why = "true or false, true only on a self-check with the paper's number (ref)"
                raise ConfigError("claim.paper_setup", f"{where} ({s['id']}): {why}")
            if not isinstance(s.get("why", ""), str):
                raise ConfigError("claim.why", f"{where} ({s['id']}): why must be text")
            self.specs[s["id"]] = dict(s)
        self.not_reproduced = []
        for i, n in enumerate(not_reproduced):
            if not isinstance(n, dict) or set(n) != {"source", "printed", "why"}:
                raise ConfigError(
                    "not_reproduced", f"{path}: entry {i + 1} needs exactly source, printed and why"
                )
            if not all(isinstance(v, str) and v for v in n.values()):
                raise ConfigError(
                    "not_reproduced", f"{path}: entry {i + 1}: source, printed and why are text"
                )
            self.not_reproduced.append(dict(n))
        self._scored: set[str] = set()

    @classmethod
    def load(cls, path: str | Path) -> "ClaimBook":
        try:
            data = tomllib.loads(toml_text(Path(path)))
        except (OSError, tomllib.TOMLDecodeError) as e:
            raise ConfigError("claims", f"cannot read the claim book {path}: {e}") from None
        except UnicodeDecodeError:  # an editor that saved it in Latin-1 or UTF-16
            raise ConfigError("claims", f"the claim book {path} is not UTF-8 text") from None
        bad = set(data) - {"claim", "not_reproduced"}
        if bad:
            raise ConfigError(sorted(bad)[0], f"{path}: unknown table")
        return cls(data.get("claim", []), data.get("not_reproduced", []), str(path))

    @property
    def paper_setup(self) -> frozenset[str]:  # the self-checks of the paper's setup
        return frozenset(c for c, s in self.specs.items() if s.get("paper_setup"))

    def spec(self, cid: str) -> dict:
        if cid not in self.specs:  # the book edited: a claim the study scores removed or renamed
            why = f"claim {cid!r}, which the study scores, is not declared{alike(cid, self.specs)}"
            raise ConfigError("claim.id", f"{self.path}: {why}")
        return self.specs[cid]

    def score(
        self,
        cid: str,
        value: float | None = None,
        ci: tuple[float, float] | None = None,
        interval: str = "ci",
        note: str = "",
        *,
        value_high: float | None = None,
        elems: tuple[np.ndarray, np.ndarray] | None = None,
        samples: np.ndarray | None = None,
        chain_tau: float | None = None,
    ) -> dict[str, Any]:
        """The row of claim ``cid`` from what the simulation produced.

        value, ci : the estimate and its 95 % interval (``interval`` says which kind:
            ``ci`` Monte-Carlo confidence interval, ``spread`` 2.5-97.5 % over plates,
            ``exact`` a deterministic number; ``ci`` may then be omitted).
        elems : ``range`` claims: per-element interval arrays ``(lo, hi)``; ``value`` and
            ``value_high`` default to the smallest and largest element midpoints.
        samples : ``one-plate`` claims: the statistic over simulated plates (1-D); value is
            their median, the interval their 2.5-97.5 % spread.
        chain_tau : a sampler chain's length in tau (:data:`sim.claims.rules.MIN_CHAIN_TAU`).
        """
        s = self.spec(cid)
        if cid in self._scored:
            raise ValueError(f"claim {cid!r} scored twice")
        self._scored.add(cid)
        form = s.get("form")  # None only for a claim without a number (no "ref")
        p_plate = math.nan
        if samples is not None:
            x = np.asarray(samples)
            _finite(cid, x, "samples")
            value, ci = spread(x)
            interval = "spread"
            if "ref" in s:  # every value that prints as ref is as likely as ref itself
                h = 0.5 * 10.0 ** (-s["decimals"]) if "decimals" in s else 0.0
                p_plate = plate_p(x, float(s["ref"]), h)
        if elems is not None:
            el, eh = (np.asarray(e) for e in elems)
            _finite(cid, np.concatenate([el, eh]), "element intervals")
            mid = (el + eh) / 2
            value = float(mid.min()) if value is None else value
            value_high = float(mid.max()) if value_high is None else value_high
            ci = (float(el.min()), float(eh.max()))
        if interval == "exact" and ci is None:
            ci = (value, value)
        if value is None or ci is None:
            raise ValueError(f"claim {cid!r}: give value and ci (or elems / samples)")
        if interval not in ("ci", "spread", "exact"):
            raise ValueError(f"interval must be ci, spread or exact, not {interval!r}")
        _finite(
            cid, np.array([value, *ci] + ([value_high] if value_high is not None else [])), "value"
        )
        rlo = rhi = zlo = zhi = math.nan
        tol = math.nan
        outcome = None
        if "ref" in s:
            ref = s["ref"] if isinstance(s["ref"], list) else [s["ref"], s["ref"]]
            rlo, rhi = float(ref[0]), float(ref[1])
            half = 0.5 * 10.0 ** (-s["decimals"]) if "decimals" in s else 0.0
            tol = float(s["tol"])
            zlo, zhi = zone(form, (rlo, rhi), half, tol)
            rlo, rhi = rlo - half, rhi + half
            # a one-plate claim given no plates (e.g. an exact input) is decided as a value
            rule = "value" if form == "one-plate" and samples is None else form
            n = None if samples is None else int(np.asarray(samples).size)
            at = (float(ci[0]), float(ci[1]))
            kw = {"elems": elems, "p_plate": p_plate, "plates": n, "chain_tau": chain_tau}
            outcome = decide(rule, at, (zlo, zhi), **kw)
            if few := few_plates(n) or short_chain(chain_tau):
                note = f"{few}; {note}" if note else few
        verdict = verdict_of(s["kind"], outcome)
        if s["kind"] == "not comparable":
            note = (s.get("why", "") + " " + note).strip()
        return _row(
            s,
            form=form if "ref" in s else "",
            value=float(value),
            value_high=math.nan if value_high is None else float(value_high),
            ci=(float(ci[0]), float(ci[1])),
            interval=interval,
            ref=(rlo, rhi),
            tol=tol,
            zone=(zlo, zhi),
            p_plate=p_plate,
            outcome=outcome,
            verdict=verdict,
            note=note,
        )

    def not_comparable(self, cid: str, note: str = "") -> dict[str, Any]:
        """The row of a ``not comparable`` claim: nothing simulated, the reason in ``note``."""
        s = self.spec(cid)
        if s["kind"] != "not comparable":
            raise ValueError(f"claim {cid!r} is declared {s['kind']!r}, not 'not comparable'")
        self._scored.add(cid)
        ref = s.get("ref", math.nan)
        ref = ref if isinstance(ref, list) else [ref, ref]
        return _row(
            s,
            form=s.get("form", ""),
            value=math.nan,
            value_high=math.nan,
            ci=(math.nan, math.nan),
            interval="exact",
            ref=(float(ref[0]), float(ref[1])),
            tol=math.nan,
            zone=(math.nan, math.nan),
            p_plate=math.nan,
            outcome=None,
            verdict="not comparable",
            note=(s.get("why", "") + " " + note).strip(),
        )

    def check_complete(self) -> None:
        missing = [c for c in self.specs if c not in self._scored]
        if missing:
            raise ConfigError(
                "claim.id",
                f"{self.path}: declared claims the study does not score: {', '.join(missing)}",
            )


def _finite(cid: str, x: np.ndarray, what: str) -> None:
    if not np.all(np.isfinite(x)):
        raise StudyError(
            f"claim {cid}: the simulated {what} is not finite (NaN or infinite); "
            "the run's configuration gives no usable number here"
        )


def _row(
    s: Mapping[str, Any],
    *,
    form,
    value,
    value_high,
    ci,
    interval,
    ref,
    tol,
    zone,
    p_plate,
    outcome,
    verdict,
    note,
) -> dict[str, Any]:
    return {
        "claim": s["id"],
        "source": s["source"],
        "paper": s["paper"],
        "form": form,
        "kind": s["kind"],
        "headline": bool(s.get("headline")),
        "value": value,
        "value_high": value_high,
        "ci_low": ci[0],
        "ci_high": ci[1],
        "interval": interval,
        "ref_low": ref[0],
        "ref_high": ref[1],
        "tol": tol,
        "zone_low": zone[0],
        "zone_high": zone[1],
        "p_plate": p_plate,
        "outcome": outcome,
        "verdict": verdict,
        "holds": holds_of(verdict),
        "note": note,
    }


def write_claims(
    path,
    rows: Iterable[Mapping[str, Any]],
    prov: Mapping[str, Any],
    book: ClaimBook | None = None,
    schema: Mapping[str, Any] | None = None,
    *,
    paper_design: Iterable[str] = (),
    as_printed: Callable[[dict], Mapping[str, Any]] | None = None,
):
    """Write ``claims.parquet`` (and, with a book, ``not_reproduced.parquet`` beside it).
    With a book, every declared claim must have been scored; with the study's ``schema``, a
    ``printed`` key that differs in ``prov["config"]`` makes the run off the paper's setup.
    ``paper_design``: the predictions decided on the paper's own setup whatever the run's
    design, which keep their verdicts there (:func:`sim.claims.rules.off_paper`);
    ``as_printed``: the study's spelling of a config in the paper's keys
    (:func:`sim.claims.rules.printed_differs`)."""
    rows = list(rows)
    if book is not None:
        book.check_complete()
        nr = book.not_reproduced
        write_table(
            Path(path).with_name("not_reproduced.parquet"),
            {c: [n[c] for n in nr] for c in NOT_REPRODUCED_COLUMNS},
            prov,
        )
    cfg = prov.get("config") or {}
    differs = printed_differs(schema, cfg, as_printed) if schema is not None else []
    setup = book.paper_setup if book is not None else ()
    rows = off_paper(rows, setup, differs, paper_design)
    cols = {c: [_null(r[c]) for r in rows] for c in CLAIM_COLUMNS}
    return write_table(
        path, cols, {**prov, "intervals": interval_provenance()}, tolerances=CLAIM_TOLERANCES
    )


def _null(x):
    """NaN marks 'no number' in a row and an infinite zone side 'unbounded' (a bound's open
    side); Parquet stores both as null (missing), never as NaN or infinity."""
    return None if isinstance(x, float) and not math.isfinite(x) else x
