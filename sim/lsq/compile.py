"""The one compile mechanism of the suite: a kernel written as plain Python loops, compiled by
numba when it is installed and ``SIM_NO_JIT`` is unset.

Every compiled module of the suite (the group-block reductions and solves of
:mod:`sim.lsq.group_kernel`, the linear solves of :mod:`sim.lsq.linear_kernel`, the Brown
multilateration kernel, the polynomial fit, the stress field) is compiled here and only here:

* :func:`available` -- whether compiled kernels run: numba importable (and not disabled by
  its ``NUMBA_DISABLE_JIT``) and the environment variable ``SIM_NO_JIT`` unset or empty (read at every call, so a test or the bench can
  switch it); each caller then runs its NumPy twin instead, the reference implementation;
* :func:`compiled` -- a kernel compiled once per process and cached on disk, with block
  sizes frozen into it as compile-time constants and its helper functions compiled with it;
* :data:`REASSOCIATE` -- the floating-point licences of a kernel whose long sums may be
  vectorised (deterministic, but rounded in another order than a sequential loop).

Singular matrices are decided by the engine's one rule, :func:`sim.lsq.normals.scaled_rcond`
with :data:`sim.lsq.normals.RCOND`; a kernel proves regularity with
:func:`sim.lsq.normals.block2_rcond` (2 x 2 blocks, exact) or leaves a trial undecided and
its caller applies the NumPy rule. numba is a heavy optional dependency: it is imported on
the first compile, not when the suite is imported.

Compile time counts too (every process on a cold cache: a fresh clone's tests, a user's first
run): kernels copy arrays element by element and sort slices in place, since numba compiles
an array-to-array slice assignment with its broadcasting checks and their messages (about 4 s
per process; ``tests/test_kernel_source.py``), and a lane width is an argument, not a
constant (one compile for every width). numba types a read-only array apart from a writable
one, so a read-only argument (e.g. a ``np.broadcast_to`` view of one trial, already
contiguous) would compile the whole kernel a second time (the multilateration kernel
about 11 s, the group reductions 2 s per argument pattern; about 22 s of CPU in a cold test
run): :func:`compiled` hands the kernel a writable copy of such an argument (same values,
same answers).
"""

from __future__ import annotations

import os
import types
import zlib
from pathlib import Path
from typing import Any

import numpy as np

__all__ = ["available", "compiled", "REASSOCIATE"]

#: the floating-point licences of :func:`compiled` with ``reassociate=True``: sums may be
#: reordered (vectorised) and multiply-adds fused; no licence to assume finite numbers, so
#: NaN and infinity still propagate and the non-finite checks of the kernels hold
REASSOCIATE = frozenset({"reassoc", "contract"})

_njit: list = []  # numba's njit once imported ([None] without numba)
_kernels: dict = {}  # the numba dispatchers, by kernel and constants
_callers: dict = {}  # what :func:`compiled` returns: the dispatcher behind writable arguments


def _numba():
    """numba's ``njit``, or None without numba or with numba's own ``NUMBA_DISABLE_JIT`` set:
    its ``njit`` then returns the kernel as it is, whose plain-Python loops (200 trials of
    brown_table1 in 29 s, the NumPy twins' 8 s) gave a third set of last digits, recorded as
    the compiled path's; the NumPy twins run, as under ``SIM_NO_JIT=1``."""
    if not _njit:
        try:  # heavy optional dependency: imported on first use only
            from numba import config, njit
        except ImportError:  # pragma: no cover - the NumPy paths run
            njit = None
        else:
            njit = None if getattr(config, "DISABLE_JIT", False) else njit
        _njit.append(njit)
    return _njit[0]


def available() -> bool:
    """Whether the compiled kernels run (numba installed, ``SIM_NO_JIT`` unset and numba's
    ``NUMBA_DISABLE_JIT`` not set)."""
    return not os.environ.get("SIM_NO_JIT") and _numba() is not None


def _source_tag(fn) -> str:
    """A checksum of the file that defines ``fn``: numba's disk cache sees only the kernel's
    own file, so a helper's edit must change the kernel's cached name."""
    return f"{zlib.crc32(Path(fn.__code__.co_filename).read_bytes()):08x}"


def compiled(fn, reassociate: bool = False, helpers=(), **consts):
    """``fn`` compiled by numba (once per process; cached on disk; needs :func:`available`).

    ``consts`` (e.g. block sizes ``P_TERMS``, ``W``) are frozen into its globals as
    compile-time constants (numba treats globals as such), which lets the compiler unroll and
    vectorise the small loops; each variant is compiled under its own name. Where numba
    finds no directory to cache in (a read-only clone, another user's checkout, with no
    writable ``HOME``, ``XDG_CACHE_HOME`` or ``NUMBA_CACHE_DIR``: "cannot cache function ...
    no locator available", exit 3 before this fallback) it is compiled uncached, once per
    process, the same machine code. ``helpers``:
    functions ``fn`` calls by their global name, compiled here (without ``reassociate``) and
    bound in its globals. ``reassociate``: compile ``fn`` with :data:`REASSOCIATE`. Every
    kernel has ``error_model="numpy"``: a division by zero gives inf or NaN, as in NumPy,
    and no exception branch blocks vectorisation."""
    njit = _numba()
    key = (fn.__module__, fn.__name__, reassociate)
    key += tuple(sorted(consts.items())) + tuple(h.__name__ for h in helpers)
    if key not in _kernels:
        glb = dict(fn.__globals__, **consts)
        for h in helpers:
            compiled(h)
            glb[h.__name__] = _kernels[(h.__module__, h.__name__, False)]
        parts = [str(v) for _, v in sorted(consts.items())] + [_source_tag(h) for h in helpers]
        name = "_".join([fn.__name__] + parts)
        f = types.FunctionType(fn.__code__, glb, name, fn.__defaults__, fn.__closure__)
        f.__qualname__ = name
        opts = {"fastmath": set(REASSOCIATE)} if reassociate else {}
        try:
            _kernels[key] = njit(cache=True, error_model="numpy", **opts)(f)
        except RuntimeError as e:  # no place to cache in: compiled for this process alone
            if "no locator available" not in str(e):
                raise
            _kernels[key] = njit(cache=False, error_model="numpy", **opts)(f)
        _callers[key] = _Writable(_kernels[key])
    return _callers[key]


def _writable(a: Any) -> Any:
    """``a``, or a writable copy when ``a`` is a read-only array (see the module docstring)."""
    return a.copy() if isinstance(a, np.ndarray) and not a.flags.writeable else a


class _Writable:
    """A compiled kernel called with writable arrays only: one compiled variant per kernel."""

    __slots__ = ("dispatcher",)

    def __init__(self, dispatcher) -> None:
        self.dispatcher = dispatcher

    def __call__(self, *args):
        args = tuple(_writable(a) for a in args)
        try:
            return self.dispatcher(*args)
        except OSError:  # a kernel does no I/O: numba's disk cache could not be written (a
            # full or read-only HOME: "No space left on device" ended the run); without it
            from numba.core.caching import NullCache

            if isinstance(getattr(self.dispatcher, "_cache", None), (NullCache, type(None))):
                raise
            for d in _kernels.values():  # every kernel (and helper) of the process uncached
                d._cache = NullCache()
            return self.dispatcher(*args)
