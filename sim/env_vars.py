"""Variables of the environment that the suite and numba read, checked when a command starts
(:func:`refuse_bad_variables`) and by ``sim.load`` (:func:`sim.api_tmp.check_env`), so that a
value they cannot read is one line naming it, not a traceback in the middle of a run nor a
run on a path the user did not ask for; and the limit of data a command starts under
(``ulimit -d``, :data:`MIN_DATA_KB`). Outside the studies' code (and its hash).
"""

from __future__ import annotations

import os
import platform
import re
import resource
import sys

from sim.threads import address_space_problem, single_threaded_blas

__all__ = [
    "MIN_DATA_KB",
    "arrow_simd_problem",
    "blas_threads_problem",
    "data_limit_problem",
    "environment_problem",
    "numba_variables_problem",
    "refuse_bad_variables",
    "sim_variables_problem",
]

#: the data (kB: ``ulimit -d``, ``RLIMIT_DATA``) below which no command starts, as
#: :data:`sim.threads.MIN_ADDRESS_SPACE_KB` for ``ulimit -v``: under about 150 MB every command
#: hung while it loaded SciPy (OpenBLAS retrying its buffers' allocation: no line, no end),
#: about 200 MB failed in llvmlite's library, and a run of brown_table1 at 40 trials failed on a
#: 10 MiB array under 450 MB ("MemoryError ... reduce trials, chunk or the sizes")
MIN_DATA_KB = 1024 * 1024


def refuse_bad_variables(prog: str) -> None:
    """Exit 2 with one line naming a variable :func:`sim_variables_problem` or
    :func:`numba_variables_problem` finds wrong, or a limit of data under :data:`MIN_DATA_KB`.
    Called by the entry points after :func:`sim.threads.refuse_bad_environment`, before they
    load SciPy."""
    if (problem := data_limit_problem()) is not None:
        sys.stderr.write(f"{prog}: error: {problem}\n")
        sys.exit(2)
    problem = (
        sim_variables_problem()
        or blas_threads_problem()
        or arrow_simd_problem()
        or numba_variables_problem()
    )
    if problem is not None:
        sys.stderr.write(f"{prog}: error: {problem}\n")
        sys.exit(2)


def data_limit_problem() -> str | None:
    """The words for a limit of data under :data:`MIN_DATA_KB`, or None (the commands exit on
    it as they start; ``sim.load`` raises it: a run of brown_table1 at 40 trials under
    ``ulimit -d 460000`` through the API failed in its middle, "MemoryError ... reduce trials,
    chunk or the sizes in the study file", of a run that small)."""
    cap = resource.getrlimit(resource.RLIMIT_DATA)[0]
    if cap == resource.RLIM_INFINITY or cap // 1024 >= MIN_DATA_KB:
        return None
    return (
        f"not enough memory: ulimit -d is {cap // 1024} kB, and the suite needs at least "
        f"{MIN_DATA_KB} kB of data (its libraries' buffers and a run's arrays)"
    )


def environment_problem() -> str | None:
    """What the commands refuse as they start, for a caller in a process of its own
    (``sim.load``, ``sim.cli.main([...])``): a ``ulimit -v`` or ``-d`` under what the suite
    needs, a ``SIM_NO_JIT`` or ``NUMBA_`` value; None when there is none. ``sim.cli.main``
    called from Python ran ``SIM_NO_JIT=0`` with the compiled kernels off, exit 0."""
    return (
        address_space_problem()
        or data_limit_problem()
        or sim_variables_problem()
        or blas_threads_problem()
        or arrow_simd_problem()
        or numba_variables_problem()
    )


def sim_variables_problem() -> str | None:
    """What is wrong with ``SIM_NO_JIT``, or None. Any value but an empty one turned the
    compiled kernels off (:func:`sim.lsq.compile.available`), ``SIM_NO_JIT=0`` too (numba's
    own ``NUMBA_DISABLE_JIT=0`` leaves them on): such a run took the slow Python path, whose
    results differ in the last digits, without a word. The variable is 1, or empty or unset."""
    v = os.environ.get("SIM_NO_JIT")
    if v is None or v in ("", "1"):
        return None
    return (
        f"SIM_NO_JIT: must be 1 (the kernels run as Python) or empty or unset (the compiled "
        f"kernels), got {v[:40]!r}"
    )


def blas_threads_problem() -> str | None:
    """What is wrong with ``OPENBLAS_NUM_THREADS``, or None. NumPy's and SciPy's OpenBLAS read
    it as C's ``atoi`` when they load, and a value read as 0 or less (``abc``, ``-1``, ``0``, an
    empty one) is taken for none given: OpenBLAS then reads ``GOTO_NUM_THREADS`` and
    ``OMP_NUM_THREADS`` the same way, else runs on every core (the suite sets 1 only where a
    variable is unset: :mod:`sim.threads`). With ``OMP_NUM_THREADS=abc`` too it ran on every
    core without a word, where the suite runs one thread a process: oversubscribed under
    ``--workers``, and a large dense solve's last digits another's (a 300 x 300 solve differs
    at one and two threads); ``1.5`` or ``2x`` were read as their leading digits. The variable
    is a whole number of threads, 1 or more (below 2**31: ``atoi`` wraps a larger one,
    ``4294967296`` read as 0 and ignored, which passed this check), or unset. The others stay
    as given, measured:
    OpenBLAS reads ``GOTO_NUM_THREADS`` and ``OMP_NUM_THREADS`` only after this one (which the
    suite sets, or this refuses), Arrow's pool takes an ``OMP_NUM_THREADS`` it cannot read for
    unset (its I/O threads: the same tables), no library of the suite reads
    ``MKL_NUM_THREADS`` (OpenBLAS, not MKL), and numba's are checked below."""
    v = os.environ.get("OPENBLAS_NUM_THREADS")
    if v is None or (v.isascii() and v.isdigit() and 1 <= _strtol(v) < 2**31):
        return None
    read = (_strtol(v) + 2**31) % 2**32 - 2**31  # atoi's reading: (int) strtol(v), wrapped
    how = (
        f"OpenBLAS would read it as {read}"
        if read >= 1
        else "OpenBLAS would ignore it (then reading GOTO_NUM_THREADS and OMP_NUM_THREADS, "
        "else running on every core)"
    )
    return (
        "OPENBLAS_NUM_THREADS: must be a whole number of threads, 1 or more (below 2**31), or "
        f"unset (the suite then runs one a process), got {v[:40]!r}: {how}"
    )


def _strtol(v: str) -> int:
    """C's ``strtol(v, NULL, 10)``: the leading whitespace skipped, a sign and the digits that
    follow, saturated at a C long's range (0 without digits). Read by Python's ``int`` whole,
    a value of more than 4,300 digits was a ValueError (its limit on such conversions), a
    traceback where the variable's one line was due."""
    m = re.match(r"[ \t\n\v\f\r]*([+-]?)0*([0-9]{0,20})", v)
    if m is None or not m[2]:
        return 0
    long = -int(m[2]) if m[1] == "-" else int(m[2])  # 20 digits or more: over a long's
    return max(min(long, 2**63 - 1), -(2**63))


#: the levels Arrow's ``ARROW_USER_SIMD_LEVEL`` takes, by machine (its ``cpu_info.cc``,
#: ``ArchParseUserSimdLevel``, compares the value upper-cased): on another machine any value
_SIMD_LEVELS = {
    "x86": ("NONE", "SSE4_2", "AVX", "AVX2", "AVX512"),
    "arm": ("NONE",),
}


def arrow_simd_problem() -> str | None:
    """What is wrong with ``ARROW_USER_SIMD_LEVEL``, or None. Arrow reads it at its first
    compute (a run's first table, not its import): another value (``bogus``, ``avx-2``, an
    empty one) was a line of Arrow's own ("cpu_info.cc:393: Invalid value for
    ARROW_USER_SIMD_LEVEL: BOGUS") in the middle of a run, which went on at the level Arrow
    detected, exit 0. The variable is one of Arrow's levels (any case), or unset."""
    v = os.environ.get("ARROW_USER_SIMD_LEVEL")
    m = platform.machine().lower()
    arch = "x86" if m in ("x86_64", "amd64", "i386", "i686", "x86") else None
    arch = "arm" if m in ("aarch64", "arm64") else arch
    if v is None or arch is None or (v.isascii() and v.upper() in _SIMD_LEVELS[arch]):
        return None
    levels = [x.lower() for x in _SIMD_LEVELS[arch]]
    return (
        f"ARROW_USER_SIMD_LEVEL: must be {', '.join(levels[:-1]) + ' or ' if len(levels) > 1 else ''}"
        f"{levels[-1]} (Arrow's levels on this machine), or unset, got {v[:40]!r}"
    )


#: numba's variables it reads as text, which it cannot fail to read: set alone (a container's
#: cache directory), numba is not loaded for them (half a second of every command)
_TEXT = frozenset({"NUMBA_CACHE_DIR"})


def numba_variables_problem() -> str | None:
    """What is wrong with the ``NUMBA_<option>`` variables, or None. numba reads them when it
    is imported (by the kernels' first call, in the middle of a run): a value it cannot parse
    (``NUMBA_OPT=fast``, ``NUMBA_DISABLE_JIT=abc``) was a warning of some ten lines carrying a
    traceback, after which the run went on with numba's default, exit 0; ``NUMBA_NUM_THREADS=0``
    failed the run at its first chunk ("ValueError: Number of threads specified must be > 0.",
    naming no variable). So numba is imported here, its warnings recorded, when such a variable
    is set and numba is not loaded yet (once loaded, it has read them); without numba installed
    the variables mean nothing. The words name the variable, without the program."""
    given = sorted(k for k in os.environ if k.startswith("NUMBA_"))
    if not set(given) - _TEXT or "numba" in sys.modules:
        return None
    import warnings

    single_threaded_blas()  # numba loads NumPy, and BLAS reads its thread variables then
    try:
        with warnings.catch_warnings(record=True) as seen:
            warnings.simplefilter("always")
            import numba  # noqa: F401 - its import reads the variables
    except ImportError:  # no numba (the NumPy paths run), or shadowed: said where it is used
        return None
    except Exception as e:  # NUMBA_NUM_THREADS=0: ValueError while numba loads
        last = (str(e).strip().splitlines() or [type(e).__name__])[-1][:200]
        return f"{', '.join(given)}: numba cannot load with {_it(given)} ({last})"
    for w in seen:
        text = str(w.message)
        m = re.match(r"Environment variable '([^']*)' is defined but its associated value", text)
        if m is None:
            warnings.warn_explicit(w.message, w.category, w.filename, w.lineno)
            continue
        why = [ln.strip() for ln in text.strip().splitlines() if ln.strip()][-1][:200]
        value = os.environ.get(m.group(1), "")
        return f"{m.group(1)}: numba cannot read its value {value[:40]!r} ({why})"
    return None


def _it(names: list) -> str:
    return "it" if len(names) == 1 else "them"
