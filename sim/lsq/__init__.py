"""One batched least-squares engine (in the spirit of scipy's ``optimize/_lsq``).

* :mod:`sim.lsq.problem` -- what a problem is: observation models, blocks of unknowns,
  the datum, the registry of compiled fast paths;
* :mod:`sim.lsq.normals` -- the shared numerics: the one scaled singularity rule, the
  Schur-complement elimination of the point blocks, the bordered (datum) solve;
* :mod:`sim.lsq.groups` -- group blocks (observations tying one point to one group, e.g. a
  stereomodel's similarity): pair-block reduced normals, dense or sparse;
* :mod:`sim.lsq.gauss_newton` -- the one Gauss-Newton loop, per-trial status and message;
* :mod:`sim.lsq.result` -- the one result object and its cofactor accessors;
* :mod:`sim.lsq.linear` -- the linear one-step case (affine, similarity, polynomial and line
  fits): the one linear least-squares routine, one factorisation when the design matrix is
  shared by all trials, the same scaled singularity rule and per-trial status.
Seed of the method: Brown 1968 (``004_f5bd9e86c308241f.txt``).
"""

from sim.lsq import groups
from sim.lsq.gauss_newton import degrees_of_freedom, gauss_newton
from sim.lsq.groups import GroupLinearization, GroupStructure
from sim.lsq.linear import LINEAR_STATUS, LinearFit, lstsq
from sim.lsq.normals import RCOND, scaled_rcond
from sim.lsq.problem import Datum, Linearization, register_fast_path
from sim.lsq.result import STATUS, Cofactors, Result, cofactors

__all__ = [
    "gauss_newton",
    "degrees_of_freedom",
    "RCOND",
    "scaled_rcond",
    "Datum",
    "Linearization",
    "register_fast_path",
    "STATUS",
    "Cofactors",
    "Result",
    "cofactors",
    "lstsq",
    "LinearFit",
    "LINEAR_STATUS",
    "groups",
    "GroupStructure",
    "GroupLinearization",
]
