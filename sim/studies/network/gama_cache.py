"""A ``gama-local`` file parsed once per process and content (:func:`read_gama`).

One run reads its ``network.gama_xml`` three times (the load's check, the run's network and
the report's note), ``sim check`` twice; each a full parse and check of every element by
:func:`sim.studies.network.gama_read.read_gama` (a 6 MB file of 10,000 points and 80,000
observations: 4 to 12 s each on the loaded reference machine). The parsed records are kept
here under the file's path, the key it is read for and the sha256 of its bytes, which are read
and hashed on every call (20 ms there): a file edited between two loads has another digest and
is parsed again, so an edit is always seen (the config records the digest too). Each caller
gets its own copy of the records (a caller may change them); a file that is refused is not
kept (the next call refuses it again, in the same words). At most :data:`KEPT` files are kept.
The kept records are taken and put back under a lock: threads loading network studies at once
(``sim.load`` in a thread pool) ended in "RuntimeError: dictionary changed size during
iteration" as one dropped the oldest while another put one in (a parse runs unlocked).
A parse of a file of :data:`SHOWN_FROM_BYTES` or more is shown on a terminal as the steps
after it are (:func:`sim.mc.progress.phase`): a 10,000-point mesh's 4.5 MB took 5.4 s of one
core, and ``sim run`` drew nothing for its first 31 s on the loaded machine (the first step
shown was "building").
"""

from __future__ import annotations

import hashlib
import threading
from pathlib import Path

from sim.mc.progress import phase
from sim.studies.network.gama_read import read_bytes
from sim.studies.network.gama_read import read_gama as _parse

__all__ = ["read_gama", "gama_digest", "KEPT", "SHOWN_FROM_BYTES"]

#: the parsed files kept (the last ones read): about 25 MB each at 10,000 points
KEPT = 2
#: the size from which a parse is shown (about 1.2 s of one core a MiB, measured)
SHOWN_FROM_BYTES = 2 * 1024**2
_PARSED: dict[tuple, dict] = {}
_LOCK = threading.Lock()


def _fresh(x):
    """A copy of the records ``x`` (dicts and lists copied, their scalars shared)."""
    if isinstance(x, dict):
        return {k: _fresh(v) for k, v in x.items()}
    if isinstance(x, list):
        return [_fresh(v) for v in x]
    return x


def gama_digest(path: str | Path, key: str = "network.gama_xml") -> str:
    """sha256 of the file's bytes (the file is read as :func:`read_gama` reads it)."""
    return hashlib.sha256(read_bytes(Path(path), key)).hexdigest()


def read_gama(path: str | Path, key: str = "network.gama_xml", sha256: str | None = None) -> dict:
    """:func:`sim.studies.network.gama_read.read_gama` of the file's present bytes, parsed once
    per process and content (see the module doc)."""
    data = read_bytes(Path(path), key)
    digest = hashlib.sha256(data).hexdigest()
    if sha256 and sha256 != digest:
        return _parse(path, key, sha256)  # the file changed since the load: refused there
    at = (str(path), key, digest)
    with _LOCK:
        rec = _PARSED.pop(at, None)
    if rec is None:  # edited since this read: refused, read again next
        with phase(f"network: reading {Path(path).name}", len(data) >= SHOWN_FROM_BYTES):
            rec = _parse(path, key, digest)
    with _LOCK:
        _PARSED[at] = rec  # the last read kept last
        while len(_PARSED) > KEPT:
            del _PARSED[next(iter(_PARSED))]
    return _fresh(rec)
