"""``sim check STUDY.toml`` (:mod:`sim.cli` imports it when the command runs): the config
``sim run`` would resolve (:func:`sim.cli_load.load_run`), listed key by key with its meaning,
bounds and unit, and the work the run would do (:func:`sim.cli_check_list.listing`).

This module loads what reading the study file needs and no more: a study file refused (an
unknown key, a bad value, chunks that do not fit) is refused before the listing's module, with
the estimate's engine, the claim rules and the report, is imported (about 0.7 s of CPU)."""

from __future__ import annotations

from sim.cli_load import load_run
from sim.mc.config import check_chunks
from sim.studies import Part

__all__ = ["check"]

#: the listing, imported once the study file is read and its config resolved
LISTING = Part("sim.cli_check_list", "listing")


def check(args) -> int:
    """``sim check STUDY.toml``: the config ``sim run`` would resolve, each key with its meaning,
    bounds and unit, and the work it would do; what the run would refuse is refused here."""
    # the config sim run would resolve: --set trials= without a chunk picks the chunk
    args.trials = args.chunk = args.seed = None
    study, cfg = load_run(args)
    check_chunks(cfg)  # what sim run refuses, sim check refuses too
    return LISTING(args, study, cfg)
