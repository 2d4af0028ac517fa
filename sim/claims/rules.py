"""The decision rules of the claims layer: a paper's claim, an interval, a verdict.

:mod:`sim.claims.book` holds the claim books (the paper's words and numbers as data) and
writes ``claims.parquet``; this module holds the one place where a verdict is decided from an
interval and the decision zone (:func:`zone`, :func:`decide`), how the outcome becomes a
verdict per kind (:func:`verdict_of`, :func:`holds_of`), and the rule for a run whose printed
inputs differ from the paper's (:func:`off_paper`). Over a consistent region of unprinted
inputs the verdict comes from :func:`sim.claims.region.region_verdict`.

Forms (``form``)
================
``value``      a printed number: it stands for ``ref`` +- half a unit of its last printed
               decimal (``decimals``); the *decision zone* widens that by ``tol``.
``share``      a printed proportion (0-1), as ``value``.
``count``      a printed count, as ``value``.
``upper``      a bound "at most ``ref``" (zone ``(-inf, ref + rounding + tol]``).
``lower``      a bound "at least ``ref``" (zone ``[ref - rounding - tol, inf)``).
``range``      "from a to b": every element (e.g. every point's dilution) is to lie in
               ``[a, b]`` (widened by the rounding and ``tol``).
``one-plate``  the paper's number is one plate's statistic (one observed rms, one count):
               the simulation gives its distribution over plates.

Verdicts (``verdict``)
======================
With ``I`` the simulated interval and ``Z`` the decision zone:

* ``value``/``share``/``count``/``upper``/``lower``: **holds** iff ``I`` lies inside ``Z``;
  **fails** iff ``I`` and ``Z`` do not meet; otherwise **inconclusive** (the interval covers
  both values that agree and values that contradict the claim). An ``exact`` interval (a
  deterministic computation) is a point, so it is never inconclusive, unless it is
  recomputed from printed numbers and carries their rounding (``ci`` given: the range over
  it), which is decided as any interval.
* ``range``: **holds** iff every element's interval lies inside ``Z``; **fails** iff some
  element's interval lies wholly outside ``Z``; otherwise **inconclusive**.
* ``one-plate``: with ``q`` the simulated probability of a plate at or below the paper's
  value, ``p = 2 min(q, 1 - q)`` is the probability of a plate at least as extreme.
  **fails** iff ``p < 0.05``; **holds** iff ``p >= 0.05`` and the central 95 % of plates lies
  inside ``Z`` (the simulation is sharp enough to decide); otherwise **inconclusive**.
* An interval from a sampler chain (MCMC) shorter than :data:`MIN_CHAIN_TAU` integrated
  autocorrelation times is **inconclusive**, whatever the forms above give: its standard
  error rests on a tau the chain is too short to estimate (emcee's rule).

Over a consistent region of unprinted inputs (:mod:`sim.claims.region`) a prediction is
**holds** / **fails** at every input of the region, **depends** (holds for part of it and
fails for another; the note says where), **holds or undecided** / **fails or undecided**
(holds, resp. fails, for part of it, the opposite nowhere, undecided at the rest) or
**undecidable** (no input of the region decides it); the rule is
:func:`sim.claims.region.region_verdict`.

The rule's result is the ``outcome`` column. The ``verdict`` is the outcome for
``kind = "prediction"`` and for ``"paper-check"`` (where a failing outcome is an
**erratum**: the paper contradicts its own printed data, and ``value`` is the recomputation
from that data); the other kinds are counted apart: ``input`` (a simulation input set to
match the paper: agreement by construction), ``self-check`` (Monte Carlo against analytic,
coverage, posterior against least squares), ``finding`` (the project's own result, no paper
number) and ``not comparable`` (the paper's number comes from a setup its text does not let
us simulate; ``note`` says why).

Off the paper's setup
=====================
A prediction is a test of the paper only on a run whose printed inputs are the paper's. When
an ``input`` row with an exact value (a configuration value the paper prints) fails its own
rule, the run simulates another setup (e.g. a larger block): :func:`off_paper` keeps every
prediction's ``outcome`` but makes its ``verdict`` a **finding** (about that setup, not the
paper) and names the differing inputs in the note. A configuration key of the study's schema
marked ``printed`` (:func:`sim.mc.schema_helpers.printed`: its default is the paper's own
number, e.g. brown_table1's 5 x 5 grid at 45 mm) whose resolved value differs is such an
input too (:func:`printed_differs`): a run on another plate is off the paper's setup without
any row of its own failing.

A self-check whose reference is a number of the paper's setup, not one every setup gives
(``paper_setup = true`` in the claim book: Brown's 43 degrees of freedom are 2(25) - 7 of the
paper's 25 points), is **not applicable** on a run off that setup: its ``outcome`` is kept
(the rule's result against the paper's number), its ``verdict`` is ``not applicable``, and it
is counted apart, never as a failed self-check. An exact one that fails its rule is itself a
differing printed input (its value is computed from the run's setup alone), so it makes the
run off the paper's setup as an exact ``input`` row does. A self-check without the flag (an
identity, Monte Carlo against analytic) must hold on any setup and is decided as ever.

A prediction the study decides on the paper's own setup whatever the run's design (Brown's
Table 1 and Concept rows, decided over the region on Table 1's plate and the built
comparator, which read no key of the run's design) is no finding about the run's setup: it
keeps its verdict, the paper's, on a run off the setup, and its note says so (the study
passes these ids to :func:`sim.claims.book.write_claims` as ``paper_design``).
"""

from __future__ import annotations

import math
from typing import Any, Callable, Iterable, Mapping

import numpy as np

from sim.mc.numtext import shown

__all__ = [
    "FORMS",
    "KINDS",
    "VERDICTS",
    "P_FAIL",
    "MIN_PLATES",
    "few_plates",
    "MIN_CHAIN_TAU",
    "short_chain",
    "zone",
    "decide",
    "verdict_of",
    "holds_of",
    "off_paper",
    "printed_differs",
    "NOT_APPLICABLE",
]

FORMS = ("value", "share", "count", "upper", "lower", "range", "one-plate")
KINDS = ("prediction", "input", "self-check", "paper-check", "finding", "not comparable")
#: the verdicts a prediction can get (in the order reports count them)
PREDICTION_VERDICTS = (
    "holds",
    "fails",
    "inconclusive",
    "depends",
    "holds or undecided",
    "fails or undecided",
    "undecidable",
)
VERDICTS = (
    *PREDICTION_VERDICTS,
    "erratum",
    "input",
    "self-check",
    "finding",
    "not comparable",
    "not applicable",
)
#: the verdict of a ``paper_setup`` self-check on a run off the paper's setup (:func:`off_paper`)
NOT_APPLICABLE = "not applicable"
#: the probability of a plate at least as extreme below which a one-plate claim fails
P_FAIL = 0.05
#: the fewest simulated plates a statistic over plates (a one-plate claim, a spread) is decided
#: on: with fewer, even no plate on the paper's side leaves the Monte-Carlo test's p,
#: 2 (k + 1) / (n + 1) (:func:`sim.claims.family.mc_p`), at 2 / (n + 1) >= 0.05: the plates
#: cannot show the paper's plate rare (the plug-in 2 k / n is 0 whenever every plate lies on
#: one side: 2 plates "failed" a claim whose paper plate is typical), nor their 2.5-97.5 %
#: points the spread of one plate. Fewer: inconclusive (over a region: undecided there)
MIN_PLATES = 40


def few_plates(n: int | None) -> str:
    """What a claim's note says of a statistic over fewer than :data:`MIN_PLATES` simulated
    plates (``""``: none given, or enough)."""
    if n is None or n >= MIN_PLATES:
        return ""
    return f"inconclusive on {n} simulated plates: a verdict over plates needs {MIN_PLATES}"


#: the shortest sampler chain (MCMC) a Monte-Carlo interval is decided on, in integrated
#: autocorrelation times tau of its slowest parameter: emcee's own reliability rule (its
#: ``integrated_time`` refuses a chain shorter than ``tol = 50`` tau; the suite computes tau
#: itself, about the ensemble's mean, :mod:`sim.instruments.ranges.autocorr`, which errs on the
#: long side where emcee's errs short). Shorter, tau itself is underestimated, and
#: so the standard error from ``N_eff = steps x walkers / tau``: brown_design's posterior gave
#: tau = 27 steps on 375 kept steps, 55 on 1,500 and 73 on 6,000, and at 375 the spread of
#: 16 independent chains was up to 1.4 times the standard error from tau. Fewer: inconclusive
MIN_CHAIN_TAU = 50


def short_chain(n_tau: float | None) -> str:
    """What a claim's note says of a Monte-Carlo interval from a sampler chain of ``n_tau``
    autocorrelation times, fewer than :data:`MIN_CHAIN_TAU` (``""``: none given, or enough)."""
    if n_tau is None or n_tau >= MIN_CHAIN_TAU:
        return ""
    got = f"{n_tau:.1f}" if math.isfinite(n_tau) else "an unknown number of"
    return (
        f"inconclusive on a chain of {got} autocorrelation times: a verdict on a sampler's "
        f"chain needs {MIN_CHAIN_TAU} (emcee's rule; raise its steps)"
    )


def zone(form: str, ref: tuple[float, float], half: float, tol: float) -> tuple[float, float]:
    lo, hi = ref[0] - half - tol, ref[1] + half + tol
    if form == "upper":
        lo = -math.inf
    elif form == "lower":
        hi = math.inf
    return lo, hi


def decide(
    form: str,
    interval: tuple[float, float],
    zone: tuple[float, float],
    *,
    elems: tuple[np.ndarray, np.ndarray] | None = None,
    p_plate: float | None = None,
    plates: int | None = None,
    chain_tau: float | None = None,
) -> str:
    """The outcome ``holds`` / ``fails`` / ``inconclusive`` of one claim (see the module doc).

    interval : (lo, hi) of the simulated value (a confidence interval, the 2.5-97.5 % spread
        of a one-plate statistic, or (v, v) for an exact value).
    zone : the decision zone (lo, hi), possibly half-infinite.
    elems : for ``range``, the per-element intervals ``(lo[k], hi[k])``.
    p_plate : for ``one-plate``, the probability of a plate at least as extreme.
    plates : the number of simulated plates the interval (a spread) and ``p_plate`` come
        from, if they do: fewer than :data:`MIN_PLATES` decide nothing (inconclusive).
    chain_tau : the length in autocorrelation times of the sampler chain the interval comes
        from, if it does (the shortest chain's, at its slowest parameter): fewer than
        :data:`MIN_CHAIN_TAU` decide nothing (inconclusive).
    """
    if form not in FORMS:
        raise ValueError(f"form must be one of {', '.join(FORMS)}, not {form!r}")
    if (plates is not None and plates < MIN_PLATES) or short_chain(chain_tau):
        return "inconclusive"
    zl, zh = zone
    if form == "range":
        if elems is None:
            elems = (np.array([interval[0]]), np.array([interval[1]]))
        lo, hi = (np.asarray(e) for e in elems)
        if np.any((hi < zl) | (lo > zh)):
            return "fails"
        return "holds" if np.all((lo >= zl) & (hi <= zh)) else "inconclusive"
    lo, hi = interval
    if form == "one-plate":
        if p_plate is None or not math.isfinite(p_plate):
            raise ValueError("a one-plate claim needs p_plate")
        if p_plate < P_FAIL:
            return "fails"
        return "holds" if (lo >= zl and hi <= zh) else "inconclusive"
    if hi < zl or lo > zh:
        return "fails"
    return "holds" if (lo >= zl and hi <= zh) else "inconclusive"


def verdict_of(kind: str, outcome: str | None) -> str:
    if kind == "prediction":
        return outcome or "finding"
    if kind == "paper-check":
        return {"fails": "erratum"}.get(outcome, outcome or "finding")
    return kind


def holds_of(verdict: str):  # depends / undecidable (over a region, sim.claims.region): null
    return {"holds": True, "fails": False, "erratum": False}.get(verdict)


def printed_differs(
    schema: Mapping[str, Any],
    cfg: Mapping[str, Any],
    as_printed: Callable[[dict], Mapping[str, Any]] | None = None,
) -> list[str]:
    """The keys of ``schema`` marked ``printed`` (their default is the paper's own number)
    whose value in the resolved ``cfg`` differs, each as ``"key = value (paper: default)"``,
    in the schema's order; ``[]`` on the paper's setup. A key the configuration leaves out
    (one not read under its switch) has its default. ``as_printed``: the study's spelling of
    ``cfg`` in the paper's keys where it resolves to the paper's setup by another spelling
    (brown's list of exactly Table 1's 25 points, :func:`sim.studies.brown.schema.as_printed`).
    A value differs when it shows differently (12 significant digits): a swept 1.1 + 0.6 =
    1.7000000000000002 is the paper's 1.7, and made the run off the paper's setup with the
    note "1.7 (paper: 1.7)"."""
    cfg = as_printed(dict(cfg)) if as_printed is not None else cfg
    out = []
    for k, f in schema.items():
        if getattr(f, "printed", False) and shown(cfg.get(k, f.default)) != shown(f.default):
            out.append(f"{k} = {shown(cfg[k])} (paper: {shown(f.default)})")
    return out


def off_paper(
    rows: Iterable[dict[str, Any]],
    paper_setup: Iterable[str] = (),
    differs: Iterable[str] = (),
    paper_design: Iterable[str] = (),
) -> list[dict[str, Any]]:
    """The rows of a run, with every prediction a **finding** when the run's printed inputs
    differ from the paper's (an exact ``input`` row, or an exact self-check of ``paper_setup``,
    that fails its rule, or a ``printed`` configuration key named in ``differs``, from
    :func:`printed_differs`), and every self-check of ``paper_setup`` (the ids whose
    reference is the paper's setup) **not applicable** then; see the module doc. A prediction
    of ``paper_design`` (the ids the study decides on the paper's own setup whatever the run's
    design: Brown's region rows, on Table 1's plate and the built comparator) keeps its
    verdict, the paper's, and its note says so. Rows of a run on the paper's setup come back
    unchanged."""
    rows = list(rows)
    setup, design = set(paper_setup), set(paper_design)
    bad = [
        r["claim"]
        for r in rows
        if (r["kind"] == "input" or (r["kind"] == "self-check" and r["claim"] in setup))
        and r["interval"] == "exact"
        and r["outcome"] == "fails"
    ] + list(differs)
    if not bad:
        return rows
    why = (
        "not a test of the paper: this run's printed inputs differ from the paper's ("
        + ", ".join(bad)
        + "), so the rule's outcome ({}) is a finding about this run's setup"
    )
    aside = (
        "not applicable: its reference is a number of the paper's setup, and this run's printed inputs "
        "differ from the paper's (" + ", ".join(bad) + "); against that number the rule gives: {}"
    )
    kept = (
        "the paper's verdict: decided on the paper's own setup, independent of this run's "
        "design, whose printed inputs differ (" + ", ".join(bad) + ")"
    )
    out = []
    for r in rows:
        if r["kind"] == "prediction" and r["claim"] in design:
            r = {**r, "note": kept + ("; " + r["note"] if r["note"] else "")}
        elif r["kind"] == "prediction" and r["verdict"] != "finding":
            note = why.format(r["outcome"]) + ("; " + r["note"] if r["note"] else "")
            r = {**r, "verdict": "finding", "holds": None, "note": note}
        elif r["kind"] == "self-check" and r["claim"] in setup:
            note = aside.format(r["outcome"]) + ("; " + r["note"] if r["note"] else "")
            r = {**r, "verdict": NOT_APPLICABLE, "holds": None, "note": note}
        out.append(r)
    return out
