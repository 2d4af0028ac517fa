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
- A relative ``network.gama_xml`` is read from the working directory: a handle keeps the one
  of :func:`sim.load` and refuses to run or ``replace`` in another (:func:`check_cwd`).
- ``run(out=None)`` makes ``$TMPDIR/sim-<study>-XXXX/``; a run that failed or was interrupted
  left it behind, empty or holding a staging directory whose path the caller was never told
  (one per Ctrl-C or refused run: unreachable, never resumed, never removed).
  :func:`anonymous_dir` removes it when it is empty, and otherwise (finished chunks, kept
  for resumption) adds a note to the exception naming the ``out`` that resumes the run (and
  marks it :data:`sim.api_tmp.KEPT`). A run killed outright left it for good: a later
  ``run(out=None)`` of the study removes it (:mod:`sim.api_tmp`).
"""

from __future__ import annotations

import contextlib
import functools
import hashlib
import json
import os
import stat
from pathlib import Path
from typing import Any

from sim.api_paths import why_unread
from sim.api_tmp import KEPT, MARK
from sim.mc.config import ConfigError
from sim.mc.study_file import MAX_STUDY_BYTES

__all__ = [
    "state_sha256",
    "check_state",
    "check_cwd",
    "check_files",
    "working_dir",
    "anonymous_dir",
    "made_by_load",
    "unchecked",
    "study_sha256",
    "unchanged",
]

#: the config keys whose relative path is read from the working directory
_FROM_CWD = ("network.gama_xml",)
#: a config key a study fills on load with the sha256 of a file it reads, and the file's key
_DIGESTS = {
    "network.gama_sha256": "network.gama_xml",
    "table1.sha256": "table1.file",
    "table3.sha256": "table3.file",
}


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


#: why a handle is not made by hand
_BY_LOAD = (
    "is made by sim.load(study_file, **overrides), which validates its config (one built "
    "by hand or by dataclasses.replace ran a config nothing checked): use sim.load(), or "
    "handle.replace(key=value)"
)


def made_by_load(init):
    """``StudyHandle.__init__`` refusing a handle :func:`sim.load` did not make: the class is
    public (``sim.StudyHandle``), and ``sim.StudyHandle("studies/x.toml")`` ended in
    Python's TypeError naming two fields, while ``sim.StudyHandle(path, study, config)``
    with a config of the caller's (and no :func:`state_sha256`) ran and published it
    unvalidated. A handle made again from its own state (a pickle, ``copy``) is one."""

    @functools.wraps(init)
    def made(self, *args, **kwargs) -> None:
        try:
            init(self, *args, **kwargs)
        except TypeError:
            raise ConfigError("StudyHandle", _BY_LOAD) from None
        if not self.state_sha256 or not isinstance(self.path, Path):
            raise ConfigError("StudyHandle", _BY_LOAD)
        if state_sha256(self.config, self.overrides, self.sweep) != self.state_sha256:
            raise ConfigError("StudyHandle", _BY_LOAD)  # dataclasses.replace(h, config=...)

    return made


def unchecked(cls: type, **fields: Any) -> Any:
    """A ``cls`` (:class:`sim.api.StudyHandle`) made from ``fields`` without
    :func:`made_by_load`'s check: a pickled handle, as it was pickled."""
    h = object.__new__(cls)
    cls.__init__.__wrapped__(h, **fields)  # type: ignore[misc]
    return h


def working_dir() -> str:
    """The working directory ("" where it was removed)."""
    try:
        return os.getcwd()
    except OSError:
        return ""


def check_cwd(h: Any) -> None:
    """A relative path of :data:`_FROM_CWD` in ``h``'s config is read from the working
    directory of :func:`sim.load`: after an ``os.chdir`` a run read another directory's file
    of that name and said it "has changed since the study was loaded", and ``replace`` or
    ``run(trials=...)`` loaded that other file's network without a word."""
    now = working_dir()
    for key in _FROM_CWD:
        v = h.config.get(key)
        if h.cwd and now != h.cwd and isinstance(v, str) and v and not os.path.isabs(v):
            raise ConfigError(
                key,
                f"{v} is read from the working directory, {h.cwd} at sim.load() and "
                f"{now or 'gone'} now: os.chdir back, or give {key} as an absolute path",
            )


def check_files(h: Any, new: Any) -> None:
    """``new``, the handle ``h.replace(...)`` or ``h.run(trials=..., seed=...)`` loaded again,
    read the files ``h`` read as they were at :func:`sim.load`: a ``network.gama_xml`` (or
    Wolf's ``table1.file``) edited since was refused by ``h.run()`` but read anew by the
    others, one handle running two networks. A file key the new overrides change is a new
    file, read as such."""
    for digest, key in _DIGESTS.items():
        was, now = h.config.get(digest), new.config.get(digest)
        if was and now and was != now and h.config.get(key) == new.config.get(key):
            raise ConfigError(
                digest,
                f"{new.config[key]} has changed since sim.load() (sha256 {now[:12]}..., "
                f"loaded {was[:12]}...): load the study again",
            )


#: :func:`study_sha256` of a path that is no study file now (a FIFO, a device, a file over
#: :data:`sim.mc.study_file.MAX_STUDY_BYTES`): never the sha256 of the file loaded
NOT_A_STUDY_FILE = "not a study file"


def study_sha256(path: Path) -> str:
    """The study file's sha256 ("": it is gone). A file that cannot be read (EACCES, EIO) is
    one line saying so: it was taken for a file that "has changed since sim.load()" (or
    "changed while it was loaded"), and a handle loaded then checked nothing. What is no
    study file now (:data:`NOT_A_STUDY_FILE`) is not read: a handle's file replaced after
    :func:`sim.load` by a FIFO blocked ``run()`` for ever, by a link to ``/dev/zero`` read
    until memory ran out, by a disk image read whole."""
    try:
        st = os.stat(path)
        if not stat.S_ISREG(st.st_mode) or st.st_size > MAX_STUDY_BYTES:
            return NOT_A_STUDY_FILE
        return hashlib.sha256(path.read_bytes()).hexdigest()
    except FileNotFoundError:
        return ""
    except OSError as e:
        raise ConfigError("study_file", f"{path} cannot be read ({why_unread(e)})") from None


def unchanged(h: Any) -> None:
    """A handle runs the file it loaded (``replace`` and ``run(trials=...)`` read it again): an
    edited or deleted file, or a config changed in place (:func:`check_state`), is refused."""
    check_state(h)
    check_cwd(h)
    if h.file_sha256 and study_sha256(h.path) != h.file_sha256:
        state = "has changed" if h.path.is_file() else "is gone"
        if os.path.exists(h.path) and not h.path.is_file():  # never opened: it would block
            state = "is no longer a regular file (a pipe, a device or a directory now)"
        raise ConfigError("study_file", f"{h.path} {state} since sim.load(): load the study again")


@contextlib.contextmanager
def anonymous_dir(base: Path | None, out: Path):
    """Around a run into ``out`` inside ``base``, the temporary directory made for it
    (``None``: the caller named ``out``, nothing to do): on any failure or interrupt,
    ``base`` is removed if empty (the run's staging directory held no finished chunk and was
    removed), else the exception gets a note naming ``out`` (its finished chunks resume); a
    ``base`` that is gone gets no note (it named a directory that is not there). Interrupted
    once its results were published (:func:`sim.execute.execute`), the note says so."""
    try:
        yield
    except BaseException as e:
        if getattr(e, "published", None):  # interrupted as it published: the results stand
            e.add_note(f"sim: the run's results were written to {out} before the interrupt")
        elif base is not None:
            try:
                (base / MARK).unlink(missing_ok=True)  # its marker (sim.api_tmp), then
                os.rmdir(base)  # only an empty directory: nothing the run kept is lost
            except FileNotFoundError:  # removed under the run (a cleaner of /tmp): no chunk
                pass  # is kept anywhere, and no out= resumes it
            except OSError:  # marked: a later run(out=None) never clears it (sim.api_tmp)
                with contextlib.suppress(OSError):
                    (base / KEPT).write_text("finished chunks a failed run named\n")
                e.add_note(
                    f"sim: the finished chunks are kept in {base}: "
                    f"run(out={str(out)!r}) resumes the run"
                )
        raise
