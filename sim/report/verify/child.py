"""The re-run's process of ``make verify``: how it is started (``python -m sim run`` with its
arguments on its command line, or through its standard input when they are too long for one)
and how its last error line reads (the system's error, another process writing its directory,
a refusal of one of the run's recorded overrides)."""

from __future__ import annotations

import errno
import json
import os
import re
import subprocess
import sys
from pathlib import Path

from sim.mc.children import child_env, child_text
from sim.mc.overrides import keys_of
from sim.report.verify.rules import VerifyError

__all__ = ["launcher", "busy_words", "names_one_of", "system_error", "refusal", "set_refusal"]

#: how the re-run's error line begins
_ERR = "sim: error: "


#: a re-run's refusal of a file the study reads (``network.gama_xml``, a ``*.file`` key) that
#: is there but is no file it can read, in the readers' words (sim.studies.network.gama_vocab,
#: sim.studies.wolf.tables)
_UNREADABLE = re.compile(
    r"sim: error: (?:network\.gama_xml|[\w.]+\.file): (?:cannot read |.* is not a regular file)"
)


def _unreadable(line: str) -> bool:
    """Whether ``line`` refuses a file the study file names as unreadable (not its content):
    it was recorded as a failed reproduction, "FAILED; nothing compared: the re-run exited
    with 2", exit 1, where B51's check of a file moved away (ENOENT) said what it is."""
    return _UNREADABLE.match(line) is not None


def refusal(
    name: str, sf: Path, line: str, target: Path, overrides: list[str] | tuple, extra: list[str]
) -> str | None:
    """What the last error line ``line`` of the re-run of results ``name`` (from the study file
    ``sf``, into ``target``) that exited with 2 means: a failure to record (returned), a bad
    request or this machine's problem (:class:`VerifyError`: nothing recorded), or None (the
    re-run's own failure, its lines shown)."""
    if system_error(line):
        # a scratch directory full or read-only, memory short: this machine's, not a failed
        # reproduction (it was recorded as one, "FAILED; nothing compared", exit 1; with
        # --trials it was "the re-run refused its options")
        raise VerifyError(f"{name}: the re-run could not run here: {line}")
    if busy := busy_words(line, target):
        raise VerifyError(f"{name}: {busy}")
    if names_one_of(line, overrides):
        # a key removed since, a value the file or the code refuses now (or edited by hand):
        # it was "the re-run exited with 2", or with --trials "the re-run refused its options"
        if os.strerror(errno.ENOENT) in line:  # a file it names (network.gama_xml)
            return (
                f"a file the run's overrides name is not here ({line}): a relative path "
                "is read from the working directory; run verify where the run was made"
            )
        return (
            f"the run's overrides no longer apply: the re-run of {sf} with them was refused "
            f"({line}): the study file or the code changed since the run (its results are "
            "stale: run it again), or its run.json was edited"
        )
    if os.strerror(errno.ENOENT) in line and re.match(r"sim: error: [^-\s][^:\s]*: ", line):
        # a file the study file names (network.gama_xml) moved away: it was recorded as a
        # failed reproduction ("FAILED; nothing compared: the re-run exited with 2", exit 1)
        raise VerifyError(
            f"{name}: a file its study file {sf} names is not here ({line.removeprefix(_ERR)}): "
            "a relative path is read from the working directory; put it back, or run verify "
            "where the run was made (nothing recorded)"
        )
    if _unreadable(line):  # a directory, a dangling link or a FIFO put in its place: as above
        raise VerifyError(
            f"{name}: a file its study file {sf} names cannot be read "
            f"({line.removeprefix(_ERR)}): put back the file the run read (nothing recorded)"
        )
    if extra or line.startswith("sim: error: --"):
        # the re-run refused the options verify passed (--trials, --set, --workers, the
        # --out under --scratch): a request error, not a failed comparison to record
        raise VerifyError(f"{name}: the re-run refused its options: {line}")
    return None


#: the longest argument, and all of them, that a re-run is given on its command line (Linux
#: takes 128 KiB an argument): the overrides of a network's thousands of points given to
#: ``sim.load`` made the re-run "Argument list too long" (exit 2: such results could not be
#: verified); longer ones go to it through its standard input
_ARG_BYTES = 1 << 16

#: ``python -m sim`` with its arguments read as JSON from standard input
_FROM_STDIN = (
    "import json, runpy, sys; sys.argv[1:] = json.loads(sys.stdin.read()); "
    "runpy.run_module('sim', run_name='__main__', alter_sys=True)"
)


def launcher(cmd: list[str]) -> tuple[list[str], str | None]:
    """``cmd`` (``python -m sim run ...``) and None, or, when its arguments are too long for
    a command line (:data:`_ARG_BYTES`), the same program reading them from its standard input
    and that input (ASCII JSON: any encoding of the pipe reads it)."""
    sizes = [len(a.encode("utf-8", "surrogateescape")) for a in cmd]
    if max(sizes) < _ARG_BYTES and sum(sizes) < 4 * _ARG_BYTES:
        return cmd, None
    return [sys.executable, "-c", _FROM_STDIN], json.dumps(cmd[3:])


#: the words of every errno, as a failing write or read of the re-run begins its line
_STRERRORS = {os.strerror(n) for n in errno.errorcode}


#: sim run's refusal of an --out another running sim holds (sim.mc.outputs)
_BUSY = re.compile(r"^sim: error: --out: .* is being written by a running sim \(pid (\d+)")


def busy_words(line: str, target: Path) -> str | None:
    """The words for a re-run refused because another process writes its directory
    ``target`` under ``--scratch``: another verify given the same ``--scratch`` (named by its
    pid, the parent of the sim run that holds the directory), else that sim run; None for
    another refusal. Both verifies said "the re-run refused its options"."""
    m = _BUSY.match(line)
    if not m:
        return None
    pid, scratch = int(m[1]), target.parent
    try:  # Linux: the holder's parent, and whether it is a verify
        ppid = int(Path(f"/proc/{pid}/stat").read_text().rpartition(")")[2].split()[1])
        theirs = b"sim.report.verify" in Path(f"/proc/{ppid}/cmdline").read_bytes()
    except (OSError, ValueError, IndexError):
        theirs = False
    who = f"another verify (pid {ppid}) re-runs" if theirs else f"a running sim (pid {pid}) writes"
    return (
        f"{who} into the same --scratch {scratch} ({target.name}); wait for it to finish or "
        "choose another --scratch"
    )


def names_one_of(line: str, overrides: list[str] | tuple) -> bool:
    """Whether the re-run's error line (``sim: error: KEY: ...``) names a key of ``overrides``,
    or an entry or a field of one (``network.points[3].role`` of ``network.points``: it was
    "the re-run exited with 2", and with ``--trials`` "the re-run refused its options")."""
    m = re.match(r"sim: error: ([^:\s]+): ", line)
    return bool(m) and any(
        m[1] == k or m[1].startswith((f"{k}[", f"{k}.")) for k in keys_of(list(overrides))
    )


def system_error(line: str) -> bool:
    """Whether the re-run's error line is the system's (``sim: error: No space left on device:
    PATH``, or not enough memory), not the study's or its options'."""
    text = line.removeprefix("sim: error: ")
    return text != line and (
        text.startswith("not enough memory")
        or text.split(": ", 1)[0] in _STRERRORS
        # "--out: cannot write to DIR: No space left on device" (its --out under --scratch)
        or (text.startswith("--out: cannot write") and text.rsplit(": ", 1)[-1] in _STRERRORS)
    )


def set_refusal(files: list[tuple[str, Path]], extra: list[str]) -> str | None:
    """Why a ``--set`` of verify's options ``extra`` would be refused by the re-run of one of
    ``files`` (results directory name, study file), asked of ``sim check`` before any re-run
    (each study's keys are its schema's, a layer above this one); None when none refuses it.
    A key one study lacks was refused by its re-run, after those before it had re-run (hours
    of ``make verify``), as ``python -m sim.batch`` refuses it before any run."""
    sets = [extra[i + 1] for i, w in enumerate(extra[:-1]) if w == "--set"]
    # the re-runs' --trials N, as sim check takes it (--set trials=N): checked at the study
    # file's trials, --trials 40000 --set chunk=1000 was refused (4,000 trials give 4 chunks)
    # and --trials 400 --set chunk=100 passed, refused by its re-run after the others
    trials = [f"--set=trials={extra[i + 1]}" for i, w in enumerate(extra[:-1]) if w == "--trials"]
    with_trials = f" (with --trials {trials[-1].rpartition('=')[2]})" if trials else ""
    checked: set[Path] = set()
    for name, sf in files if sets else ():
        if sf in checked or not sf.is_file():  # (a missing file: the re-run's own line)
            continue
        checked.add(sf)
        cmd, given = launcher(
            [sys.executable, "-m", "sim", "check", str(sf), *trials[-1:]]
            + [f"--set={s}" for s in sets]
        )
        done = subprocess.run(
            cmd,
            input=given,
            stdout=subprocess.DEVNULL,
            stderr=subprocess.PIPE,
            env=child_env(),
            **child_text(),
        )
        lines = [ln for ln in done.stderr.splitlines() if ln.strip()]
        if done.returncode == 2 and lines and names_one_of(lines[-1], sets):
            return (
                f"--set: refused by the study file of {name}, {sf}, before any re-run: "
                f"{lines[-1].removeprefix(_ERR)}{with_trials} (--study names the studies to "
                "verify)"
            )
    return None
