"""How the SEQUENCE fuzzer (tests/fuzz_sequence.py) runs a step and what it asks after it.

A step runs in a forked child (its own session, its working directory the case's, a time
bound): ``sim``'s ``main``, ``python -m sim.batch``'s, ``make verify``'s
(:mod:`sim.report.verify.cli`) or the API's ``sim.load(...).run(...)``. An interrupt is sent
by the child to itself at a marker, never after a sleep: the ``k``-th rename of a file
(``os.replace``, ``os.rename``: every chunk, table, record and the publishing of the results is
one), before it is done. A clean run of each state (study file, GNU Gama file, overrides) made
once in a directory of its own is the reference the results of any step are held to
(:class:`References`)."""

from __future__ import annotations

import hashlib
import json
import os
import select
import signal
import sys
import time
from pathlib import Path

from fuzz_run import in_child

#: the lines of standard error that are notes, not the one line of a refusal or interrupt
NOTES = ("sim: note:", "sim: resuming", "sim: starting", "sim: a run ", "sim.batch: note")
NOTES += ("sim verify: re-running ",)  # make verify's progress, on standard error


def _marker(k: int, sig) -> None:
    """At the ``k``-th rename, before it is done: send ``sig`` to this process, or, when
    ``sig`` is a pair ``(file, bytes)``, write that file (the user saving it as a run runs),
    or, when it is a :class:`Pause`, tell the parent and wait for its word to go on."""
    count = [0]
    real = {"replace": os.replace, "rename": os.rename}

    def hook(name):
        def renamed(*a, **kw):
            count[0] += 1
            if count[0] == k and isinstance(sig, Pause):
                sig.hold()
            elif count[0] == k and isinstance(sig, tuple):
                Path(sig[0]).write_bytes(sig[1])
            elif count[0] == k:
                os.kill(os.getpid(), sig)  # SIGINT/SIGTERM: raised before the next line
            return real[name](*a, **kw)

        return renamed

    os.replace, os.rename = hook("replace"), hook("rename")


class Pause:
    """A marker that holds the child at its rename until the parent says go (tests/
    fuzz_concurrent.py: the second process of a pair runs while the first waits there); two
    pipes, no sleep to order them. ``reached()`` (parent): whether the child ``pid`` got there
    within ``timeout`` seconds (False: it ended first)."""

    def __init__(self):
        self.up, self.down = os.pipe(), os.pipe()

    def hold(self) -> None:  # child
        os.write(self.up[1], b"k")
        os.read(self.down[0], 1)  # the parent's go, or its end (the pipe closed)

    def reached(self, pid: int, timeout: float) -> bool:  # parent
        os.close(self.up[1])  # (the child's copy stays open: an end of file is its end)
        t0 = time.time()
        while time.time() - t0 < timeout:
            if select.select([self.up[0]], [], [], 0.05)[0]:
                return bool(os.read(self.up[0], 1))
            try:  # ended (its workers may hold the pipe open): a zombie
                if Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[0] in "ZX":
                    return False
            except OSError:
                return False
        return False

    def go(self) -> None:  # parent
        os.write(self.down[1], b"g")
        for fd in (*self.up, *self.down):
            try:
                os.close(fd)
            except OSError:
                pass


def spawn(cwd: Path, target, log: Path, marker=None, timeout: float = 300.0):
    """``target()`` (an exit code) in a forked child in ``cwd``: ``(code, stdout, stderr)``;
    code ``"timeout"`` past ``timeout`` seconds, ``-N`` killed by signal ``N``."""
    return wait(start(cwd, target, log, marker), log, timeout)


def start(cwd: Path, target, log: Path, marker=None) -> int:
    """Fork the child that runs ``target()`` (its pid; :func:`wait` for its end)."""
    so, se = log.with_suffix(".out"), log.with_suffix(".err")
    pid = os.fork()
    if pid == 0:  # child

        def body():
            # Ctrl-C as at a terminal, however the fuzzer was started (in the background of a
            # script SIGINT is ignored, and Python then installs no KeyboardInterrupt for it)
            signal.signal(signal.SIGINT, signal.default_int_handler)
            if marker is not None:
                _marker(*marker)
            return target()

        in_child(cwd, so, se, body)
    return pid


def wait(pid: int, log: Path, timeout: float = 300.0):
    """The end of the child ``pid`` that :func:`start` forked: ``(code, stdout, stderr)``."""
    so, se = log.with_suffix(".out"), log.with_suffix(".err")
    t0, code = time.time(), "timeout"
    while time.time() - t0 < timeout:
        done, status = os.waitpid(pid, os.WNOHANG)
        if done:
            code = os.waitstatus_to_exitcode(status)
            break
        time.sleep(0.02)
    if code != "timeout" and _outlived(pid):  # a worker left running by its run
        code = f"{code}, a process of the step outlived it"
    try:
        os.killpg(pid, signal.SIGKILL)  # no process of the step may outlive it
    except ProcessLookupError:
        pass
    if code == "timeout":
        os.waitpid(pid, 0)
    read = lambda p: p.read_text(errors="replace") if p.exists() else ""  # noqa: E731
    return code, read(so), read(se)


def _alive(group: int) -> bool:
    """Whether a process of the process group ``group`` runs (a zombie does not)."""
    for st in Path("/proc").glob("[0-9]*/stat"):
        try:
            fields = st.read_text().rsplit(")", 1)[1].split()
        except (OSError, IndexError):
            continue
        if int(fields[2]) == group and fields[0] not in "ZX":
            return True
    return False


def _outlived(group: int, wait: float = 5.0) -> bool:
    """Whether a process of the ended step's group still runs ``wait`` seconds on (a worker
    whose run was killed ends when it sees its parent gone)."""
    t0 = time.time()
    while _alive(group):
        if time.time() - t0 > wait:
            return True
        time.sleep(0.05)
    return False


def sim_main(argv: list[str]):
    def target():
        from sim.cli import main

        return main(argv)

    return target


def batch_main(argv: list[str]):
    def target():
        from sim.batch import main

        return main(argv)

    return target


def verify_main(argv: list[str]):
    def target():
        from sim.report.verify.cli import main

        return main(argv)

    return target


def api_run(study: str, kw: dict, out: str, overwrite: bool):
    """``sim.load(study, **kw).run(out=out, overwrite=overwrite, quiet=True)``: 0, or one line
    and 2 for a ``ConfigError``/``StudyError``, 130 for a ``KeyboardInterrupt``."""

    def target():
        import sim

        try:
            sim.load(study, **kw).run(out=out, overwrite=overwrite, quiet=True)
        except (sim.ConfigError, sim.StudyError) as e:
            print(f"sim.api: error: {e}", file=sys.stderr)
            return 2
        except KeyboardInterrupt as e:
            print(f"sim.api: interrupted: {e}".splitlines()[0], file=sys.stderr)
            return 130
        return 0

    return target


def api_read(out: str, to: str):
    """``sim.Results(out, "network").table("claims")`` written to ``to`` (0), or one line and
    2 for a ``ConfigError``/``StudyError``."""

    def target():
        import pyarrow.parquet as pq

        import sim

        try:
            t = sim.Results(out, "network").table("claims")
        except (sim.ConfigError, sim.StudyError) as e:
            print(f"sim.api: error: {e}", file=sys.stderr)
            return 2
        pq.write_table(t.replace_schema_metadata(None), to)
        return 0

    return target


def same_claims(got: Path, ref: Path) -> bool:
    """Whether the claims table read by the API (``got``) is the reference run's."""
    import pyarrow.parquet as pq

    a = pq.read_table(got).replace_schema_metadata(None)
    return a.equals(pq.read_table(ref / "claims.parquet").replace_schema_metadata(None))


def lines(err: str) -> list[str]:
    """The lines of ``err`` that are not notes (a batch's run's named by its study file)."""
    err = "\n".join(ln.removeprefix("net.toml: ") for ln in err.splitlines())
    return [ln for ln in err.splitlines() if ln.strip() and not ln.startswith(NOTES)]


def sha256(p: Path) -> str:
    return hashlib.sha256(p.read_bytes()).hexdigest()


def record(out: Path) -> dict | None:
    try:
        rec = json.loads((out / "run.json").read_text())
    except (OSError, ValueError):
        return None
    return rec if isinstance(rec, dict) else None


def incomplete(out: Path, missing: set[str]) -> str | None:
    """What of the results ``out`` is not as their run recorded it (a file of ``files``
    missing, but those in ``missing``: removed by a step of the sequence; a table, chunk or
    figure whose sha256 is not the record's), or None."""
    rec = record(out)
    if rec is None:
        return f"{out} holds no readable run.json"
    for f in rec.get("files", []):
        if not (out / f).is_file() and f not in missing:
            return f"{f} of run.json's files is missing"
    for key in ("table_sha256", "chunk_sha256", "figure_sha256"):
        for f, h in (rec.get(key) or {}).items():
            if (out / f).is_file() and sha256(out / f) != h:
                return f"{f} is not the file its run wrote ({key})"
    return None


def claims_block(text: str) -> str:
    """``sim show``'s table of claims: its lines up to the first empty one."""
    return text.split("\n\n", 1)[0].strip()


class References:
    """A clean run of each state ``(study text, Gama file bytes, overrides)``, made once in a
    directory of its own (no figures: the tables are the same), and ``sim show`` of it."""

    def __init__(self, root: Path):
        self.root = root
        self.made: dict[tuple, tuple[dict | None, str, Path]] = {}

    def get(self, state: tuple) -> tuple[dict | None, str, Path]:
        """``(run.json, sim show's claims, directory)`` of ``state``'s clean run; the record is
        None when the state is refused (a run of it must then be refused too). Made again when
        the study's code changed since (a code hash of its own: other tables)."""
        from sim.mc.codehash import study_code_hash

        # read anew, not through its cache: filled in here, the cache would pass to every step
        # forked after (their runs recording the hash of the code as it was then)
        state = (*state, study_code_hash.__wrapped__("network"))
        if state not in self.made:
            text, xml, sets, _ = state
            d = self.root / f"ref{len(self.made):03d}"
            d.mkdir(parents=True)
            (d / "net.toml").write_text(text)
            (d / "net.xml").write_bytes(xml)
            argv = ["run", "net.toml", "--quiet", "--no-figures", "--out", "res/net"]
            argv += [a for s in sets for a in ("--set", s)]
            code, _, _ = spawn(d, sim_main(argv), d / "run")
            rec = record(d / "res" / "net") if code == 0 else None
            shown = ""
            if rec is not None:
                c, so, _ = spawn(d, sim_main(["show", "res/net"]), d / "show")
                shown = claims_block(so) if c == 0 else ""
            self.made[state] = (rec, shown, d / "res" / "net")
        return self.made[state]

    def of_config(self, run: dict) -> tuple | None:
        """The reference made so far whose run recorded the config and code hash of the run
        record ``run``, or None."""
        for rec, shown, d in self.made.values():
            if rec is not None and rec.get("config") == run.get("config"):
                if rec.get("code_hash") == run.get("code_hash"):
                    return rec, shown, d
        return None


def budgeted(run_one, n: int, seed: int, tmp: Path, seconds_env: str) -> list[str]:
    """Run ``run_one(i, seed, tmp, refs)`` for ``i`` below ``n`` (fewer when the seconds in
    the variable ``seconds_env``, 600 unless set, run out): their failures (the lines each
    returned), one reference store for all (the SEQUENCE and CONCURRENT kinds)."""
    budget = float(os.environ.get(seconds_env, "600"))
    refs, t0, failures = References(tmp / "refs"), time.time(), []
    for i in range(n):
        if time.time() - t0 > budget:
            break
        if (bad := run_one(i, seed, tmp, refs)) is not None:
            failures.append(bad)
    return failures


def against_reference(c, rec: dict, missing: set, unknown: str) -> str | None:
    """Why ``c.out``, whose run record is ``rec``, is not a complete run whose tables equal a
    clean run of the config it records (``c.refs``, asked for by ``c.asked`` as needed), or
    None; ``missing``: files a step removed on purpose; ``unknown``: how the line names a
    config no reference stands for."""
    if (why := incomplete(c.out, missing)) is not None:
        return f"res/net is not a complete run: {why}"
    ref = c.refs.of_config(rec)
    for s in reversed(c.asked):
        if ref is not None:
            break
        c.refs.get(s)
        ref = c.refs.of_config(rec)
    if ref is None:
        return f"res/net records a config {unknown}"
    for key in ("table_sha256", "chunk_sha256"):
        if rec.get(key) != ref[0].get(key):
            return f"res/net's {key} are not those of a clean run of its config"
    return None
