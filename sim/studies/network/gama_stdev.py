"""The variances and standard deviations of a GNU Gama ``gama-local`` file, as ``gama-local``
reads them: a ``<cov-mat dim band>`` (diagonal only: correlated observations are refused), the
default stdevs of ``<points-observations>`` (``distance-stdev = "a b c"``: a + b D^c mm, D in
km; ``direction-stdev``, ``angle-stdev`` in cc or arcseconds by the value's form) and an
observation's ``stdev`` (mm, cc or arcseconds), within the study's range. Every refusal is one
line naming the file, the element and the attribute (:class:`~sim.studies.network.gama_vocab._File`).
The reader: :mod:`sim.studies.network.gama_read`."""

from __future__ import annotations

import math

import numpy as np

from sim.mc.numtext import UnheldError, float_text
from sim.studies.network import gama_vocab as vocab
from sim.studies.network.definition import ARCSEC
from sim.studies.network.gama_vocab import _NUM, _File
from sim.studies.network.validate import SIGMA_RANGE

__all__ = ["variances", "default_stdevs", "distance_default", "sigma"]


def variances(f: _File, cm, n: int) -> np.ndarray:
    """Variances of a ``<cov-mat dim band>`` of ``n`` observations; refuses covariances."""
    dim, band = f.integer(cm, "dim"), f.integer(cm, "band")
    if not 0 <= band < dim:
        raise f.err(cm, f"dim {dim} and band {band}: need 0 <= band < dim", "band")
    if dim != n:
        raise f.err(cm, f"dim {dim} for {n} observations", "dim")
    words = vocab.words(cm.text)
    need = dim * (band + 1) - band * (band + 1) // 2
    if len(words) != need:
        raise f.err(cm, f"{len(words)} numbers for dim {dim}, band {band} (need {need})")
    if not all(_NUM.match(w) for w in words):
        bad = next(w for w in words if not _NUM.match(w))
        raise f.err(cm, f"{vocab.said(bad)} is not a number")
    for w in words:  # 1e-400: not a variance of 0 ("must be positive"), 1e400 not inf
        try:
            float_text(w)
        except UnheldError as why:
            raise f.err(cm, str(why)) from None
    vals = iter(float(w) for w in words)
    var = np.zeros(dim)
    for r in range(dim):
        for c in range(r, min(dim, r + band + 1)):
            v = next(vals)
            if c == r:
                var[r] = v
            elif v != 0:
                raise f.err(
                    cm,
                    "correlated observations (non-zero covariance) are not supported: "
                    "give a diagonal matrix",
                )
    if not np.all(np.isfinite(var) & (var > 0)):
        raise f.err(cm, "every variance must be a positive finite number")
    return var


def default_stdevs(f: _File, po) -> dict:
    d = {}
    words = vocab.words(po.get("distance-stdev"))
    if len(words) > 3:
        raise f.err(po, "takes 'a [b [c]]' (a + b D^c mm, D in km)", "distance-stdev")
    for w in words:
        if not _NUM.match(w):
            raise f.err(po, f"{vocab.said(w)} is not a number", "distance-stdev")
        try:  # 1e-400: not a of 0 mm, silently; 1e400: not "not a number"
            float_text(w)
        except UnheldError as why:
            raise f.err(po, str(why), "distance-stdev") from None
    abc = [float(w) for w in words] + [0.0, 0.0, 1.0][len(words) :]
    d["distance"] = abc if words else None
    for k in ("direction", "angle"):
        d[k] = f.num(po, f"{k}-stdev") if po.get(f"{k}-stdev") is not None else None
    for k in ("zenith-angle", "azimuth"):  # of kinds refused here, but numbers in gama-local
        if po.get(f"{k}-stdev") is not None:
            f.num(po, f"{k}-stdev")
    return d


def distance_default(abc: list | None, d_m: float) -> float | None:
    """``distance-stdev = "a b c"``: a + b D^c mm, D the observed distance in km (None: no
    default); a power past the largest float is inf, as in gama-local's C (Python's ``**``
    raised OverflowError: ``val="1e300"`` with c = 2 ended in a traceback), and is refused
    as a standard deviation where it is used."""
    if abc is None:
        return None
    try:
        return abc[0] + abc[1] * (d_m / 1000) ** abc[2]
    except OverflowError:
        return math.inf


def sigma(f: _File, o, default, var: float | None, unit: float | None = None) -> float:
    """The standard deviation of one observation (mm, cc or arcsec; ``unit`` the angle unit
    in rad, None for mm), within the study's own range (:data:`SIGMA_RANGE`, in mm or
    arcsec: what the suite exports, it reads back), named by the element."""
    sig = _stdev(f, o, default, var)
    lo, hi = SIGMA_RANGE["mm" if unit is None else "arcsec"]
    study = sig if unit is None else sig * unit / ARCSEC
    if not lo <= study <= hi:
        what = "mm" if unit is None else f"{study:g} arcsec" if study else "under 1e-300 arcsec"
        # as written, when written: a subnormal 1e-320 was "9.99989e-321"
        text = o.get("stdev").strip() if var is None and o.get("stdev") is not None else ""
        shown = text if text and len(text) <= 40 else f"{sig:g}"
        raise f.err(
            o, f"a standard deviation of {shown} ({what}) is outside [{lo:g}, {hi:g}]", "stdev"
        )
    return sig


def _stdev(f: _File, o, default, var: float | None) -> float:
    if var is not None:  # the <cov-mat> holds; a stdev beside it is still a number there
        if o.get("stdev") is not None:
            f.num(o, "stdev")
        return math.sqrt(var)
    if o.get("stdev") is not None:
        sig = f.num(o, "stdev")
        if sig < 0:
            raise f.err(o, f"{vocab.said(o.get('stdev'))} is negative{_SQUARED}", "stdev")
        if sig == 0:
            raise f.err(o, f"{vocab.said(o.get('stdev'))} must be > 0", "stdev")
        return sig
    if default is None:
        raise f.err(o, "no stdev and no default in <points-observations>", "stdev")
    if default < 0:
        raise f.err(o, f"the default stdev {default:g} is negative{_SQUARED}", "stdev")
    if default == 0:
        raise f.err(o, "the default stdev is not positive", "stdev")
    return default


#: why a negative stdev is refused, which gama-local reads: it squares it (a variance)
_SQUARED = (
    " (gama-local squares it and adjusts as if it had no sign; this suite takes a standard "
    "deviation as a positive number: write it without the sign)"
)
