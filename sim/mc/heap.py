"""Keep freed memory in the process heap (glibc ``mallopt``), for chunks that allocate and
free many large NumPy temporaries.

By default glibc serves each allocation above 128 KiB (a threshold it raises as such blocks
are freed, up to 32 MiB) by a fresh ``mmap`` and returns freed heap memory above 128 KiB to
the system at once. Every new temporary then costs one page fault per 4 KiB page touched,
which on a virtual machine is dear: the block adjustment of :mod:`sim.instruments.block.independent_models`
spent about a third of its time there. :func:`keep_heap` sets the ``mmap`` threshold to
32 MiB (arrays below it come from the heap), keeps up to ``trim_mib`` of freed memory for
reuse and grows the heap in steps of 16 MiB. The numbers computed are the same; only where
the memory comes from changes. No effect (and no error) where glibc is absent.
"""

from __future__ import annotations

import ctypes
import ctypes.util

__all__ = ["keep_heap"]

_M_TRIM_THRESHOLD, _M_TOP_PAD, _M_MMAP_THRESHOLD = -1, -2, -3
_done = False


def keep_heap(trim_mib: int = 128) -> bool:
    """Tune this process's allocator once (later calls do nothing); True if glibc took it."""
    global _done
    if _done:
        return True
    try:
        libc = ctypes.CDLL(ctypes.util.find_library("c") or "libc.so.6")
        mallopt = libc.mallopt
    except (OSError, AttributeError):
        return False
    mib = 1 << 20
    ok = (mallopt(_M_MMAP_THRESHOLD, 32 * mib) == 1) & (mallopt(_M_TOP_PAD, 16 * mib) == 1)
    ok &= mallopt(_M_TRIM_THRESHOLD, int(trim_mib) * mib) == 1
    _done = bool(ok)
    return _done
