"""Agnard et al.'s Table 1 (seed ``003_5ce730a990a7ebc5.txt``: the scanner's residuals in
metres with and without its grid correction) as claim rows: *not comparable*, because no vector
of the scanner's unprinted inputs (``scanner.toml``) reproduces it, each row's note giving the
simulated values over the explored vectors (m) and the conflicting statements. Used by
:func:`sim.studies.agnard.claims.claim_rows`."""

from __future__ import annotations

import numpy as np

from sim.claims.book import ClaimBook
from sim.claims.inference import FAILS, Region
from sim.claims.intervals import spread

__all__ = ["table1_rows"]


def _over(region: Region, stats: list[dict], cid: str) -> str:
    """A Table 1 row over the scanner region: the range of its per-vector medians and of the
    blocks' 95 % spread, and at how many vectors the printed number is contradicted."""
    med = np.array([np.median(p[cid]) for p in stats])
    lo = min(spread(p[cid])[1][0] for p in stats)
    hi = max(spread(p[cid])[1][1] for p in stats)
    j = [st.id for st in region.statements].index(cid)
    k = int((region.status[:, j] == FAILS).sum())
    return (
        f"simulated median {med.min():.2f}-{med.max():.2f} m over the {len(stats)} explored "
        f"scanner vectors (95 % of blocks within {lo:.2f}-{hi:.2f} m); the printed "
        f"{_ref_of(region, cid):g} m is contradicted at {k} of {len(stats)}"
    )


def _ref_of(region: Region, cid: str) -> float:
    return next(st.ref[0] for st in region.statements if st.id == cid)


def table1_rows(book: ClaimBook, region: Region, stats: list[dict]) -> list[dict]:
    """Table 1: not comparable because no scanner vector reproduces it (the region of
    ``scanner.toml`` is empty, the conflicting statements named in every note), with each
    row's simulated values over the explored vectors. Should a run's region not be empty
    (another configuration), the note says that the claim book's reason fails for it."""
    conf = "; ".join(" + ".join(c.split(".")[-1] for c in cs) for cs in region.conflicts)
    head = (
        f"Scanner region (scanner.toml: {region.describe(np.ones(region.n, bool))}, "
        f"{region.n} vectors explored jointly): "
        + (
            f"empty, no vector reproduces Table 1 (conflicting: {conf})"
            if region.empty
            else f"{int(region.accepted.sum())} vectors consistent ({region.describe()}): the "
            "claim book's reason for 'not comparable' (an empty region) does not hold in this run"
        )
    )
    rows = []
    for w in ("ctrl", "check"):
        for c in ("x", "y"):
            for tag in ("with", "without"):
                cid = f"agnard.table1.{tag}_{w}_{c}_m"
                rows.append(
                    book.not_comparable(cid, note=f"{head}. This row: {_over(region, stats, cid)}.")
                )
            ratio = [
                np.median(
                    p[f"agnard.table1.without_{w}_{c}_m"] / p[f"agnard.table1.with_{w}_{c}_m"]
                )
                for p in stats
            ]
            rows.append(
                book.not_comparable(
                    f"agnard.table1.ratio_{w}_{c}",
                    note=(
                        f"{head}. The simulated per-block ratio without / with the grid "
                        f"correction has median {min(ratio):.2f}-{max(ratio):.2f} over the "
                        "explored vectors."
                    ),
                )
            )
    return rows
