"""What the Python API keeps between the calls of one long-lived process (a notebook open for
hours, hundreds of ``sim.load(...).run(...)``): a handle's validated state, and the temporary
directory a run without ``out`` makes.

- A handle's ``config``, ``overrides`` and ``sweep`` are plain dicts (a study's workers take
  them pickled); a change made to them in place after :func:`sim.load` ran unvalidated
  (``handle.config["errors.setting_sigma_um"] = "abc"`` ended in an "internal error" from the
  model, ``config["study"] = "brown_dilution"`` ran Brown's Table 1 and published it as the
  other study's). :func:`state_sha256` is taken when the handle is made; a run, an estimate
  or ``replace`` refuses a handle whose state differs (:func:`check_state`), naming
  ``replace()``, the way to change a key.
- ``run(out=None)`` makes ``$TMPDIR/sim-<study>-XXXX/``; a run that failed or was interrupted
  left it behind, empty or holding a staging directory whose path the caller was never told
  (one per Ctrl-C or refused run: unreachable, never resumed, never removed).
  :func:`anonymous_dir` removes it when it is empty, and otherwise (finished chunks, kept
  for resumption) adds a note to the exception naming the ``out`` that resumes the run.
"""

from __future__ import annotations

import contextlib
import hashlib
import json
import os
from pathlib import Path
from typing import Any

from sim.mc.config import ConfigError

__all__ = ["state_sha256", "check_state", "anonymous_dir"]


def state_sha256(config: dict, overrides: dict, sweep: dict) -> str:
    """sha256 of a handle's validated state, in a canonical text (sorted keys; a value JSON
    cannot write by its ``repr``)."""
    try:
        text = json.dumps([config, overrides, sweep], sort_keys=True, default=repr)
    except (TypeError, ValueError):  # keys of mixed types, or a value holding itself
        text = repr([config, overrides, sweep])
    return hashlib.sha256(text.encode()).hexdigest()


def check_state(h: Any) -> None:
    """``h`` (a :class:`sim.api.StudyHandle`) as :func:`sim.load` validated it."""
    if h.state_sha256 and state_sha256(h.config, h.overrides, h.sweep) != h.state_sha256:
        raise ConfigError(
            "config",
            "the handle's config, overrides or sweep were changed in place since sim.load() "
            "(unvalidated): use handle.replace(key=value), or sim.load() again",
        )


@contextlib.contextmanager
def anonymous_dir(base: Path | None, out: Path):
    """Around a run into ``out`` inside ``base``, the temporary directory made for it
    (``None``: the caller named ``out``, nothing to do): on any failure or interrupt,
    ``base`` is removed if empty (the run's staging directory held no finished chunk and was
    removed), else the exception gets a note naming ``out`` (its finished chunks resume); a
    ``base`` that is gone gets no note (it named a directory that is not there)."""
    try:
        yield
    except BaseException as e:
        if base is not None:
            try:
                os.rmdir(base)  # only an empty directory: nothing the run kept is lost
            except FileNotFoundError:  # removed under the run (a cleaner of /tmp): no chunk
                pass  # is kept anywhere, and no out= resumes it
            except OSError:
                e.add_note(
                    f"sim: the finished chunks are kept in {base}: "
                    f"run(out={str(out)!r}) resumes the run"
                )
        raise
