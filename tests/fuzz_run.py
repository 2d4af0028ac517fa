"""How the fuzzer (tests/test_fuzz.py) runs a case and what it asks of it: ``sim run`` in a
forked child (its own session, an address-space limit, a time bound ``FUZZ_TIMEOUT``); exit 0
with finite results, or exit 2 with one line and no traceback, and nothing left outside the
output directory but, after a failed run, its staging directory. ``FUZZ_SAVE`` keeps the
study file of every failing case."""

from __future__ import annotations

import os
import shutil
import signal
import sys
import time
from pathlib import Path

import numpy as np
from fuzz_bytes import SAME as SAME_BYTES
from fuzz_cases import make_case
from fuzz_shapes import SAME
from fuzz_values import ROOT, toml_doc

from sim.cli import main
from sim.mc.message_text import key_text

TIMEOUT = float(os.environ.get("FUZZ_TIMEOUT", "300"))


def in_child(cwd: Path, so: Path, se: Path, body) -> None:
    """In a forked child of a fuzzer: a session of its own in ``cwd``, the work limits, its
    standard output and error into ``so`` and ``se``, then ``body()``; ends the process with
    its code (98 a ``SystemExit`` of no number, 97 a traceback, printed into ``se``). The
    limits: within a case's timeout, a case asking for hours of work within the default limit
    (agnard's region.trials = 150000, 2.7e8 adjustments) is a long run, not a hang; under
    this limit it is refused in one line, as the fuzzers expect."""
    code = 99
    try:
        os.setsid()
        os.chdir(cwd)
        os.environ["SIM_MAX_MEMORY_GB"] = "2"
        os.environ["SIM_MAX_ADJUSTMENTS"] = "1e7"
        # the processes it starts (sim.batch's runs, verify's re-runs) import this checkout's
        # sim, not the one installed in the environment: a worktree sharing another's .venv
        # ran its batch steps on that checkout's code (another code hash: "res/net records a
        # config no step asked for")
        paths = [str(ROOT), *filter(None, os.environ.get("PYTHONPATH", "").split(os.pathsep))]
        os.environ["PYTHONPATH"] = os.pathsep.join(paths)
        fo = os.open(so, os.O_WRONLY | os.O_CREAT | os.O_TRUNC)
        fe = os.open(se, os.O_WRONLY | os.O_CREAT | os.O_TRUNC)
        os.dup2(fo, 1), os.dup2(fe, 2)
        sys.stdout = open(1, "w", closefd=False)
        sys.stderr = open(2, "w", closefd=False)
        code = body()
    except SystemExit as e:
        code = e.code if isinstance(e.code, int) else 98
    except BaseException:  # noqa: BLE001 - a traceback: reported as a failure
        import traceback

        traceback.print_exc()
        code = 97
    finally:
        try:
            sys.stdout.flush()
            sys.stderr.flush()
        finally:
            os._exit(code if isinstance(code, int) else 96)


def run_case(case_dir: Path, study: Path, extra: list[str], timeout: float):
    """``sim run`` in a forked child: (exit code or 'timeout', stdout, stderr, seconds)."""
    out = case_dir / "out"
    argv = ["run", str(study), "--quiet"]
    if "--out" in extra:
        j = extra.index("--out")
        extra = extra[: j + 1] + [extra[j + 1].replace("{file}", str(study))] + extra[j + 2 :]
    else:
        argv += ["--out", str(out)]
    argv += extra
    so, se = case_dir.parent / f"{case_dir.name}.out", case_dir.parent / f"{case_dir.name}.err"
    t0 = time.time()
    pid = os.fork()
    if pid == 0:  # child

        def body():
            import resource

            lim = 6 * 2**30
            resource.setrlimit(resource.RLIMIT_AS, (lim, lim))
            return main(argv)

        in_child(case_dir, so, se, body)
    code = "timeout"
    while time.time() - t0 < timeout:
        done, status = os.waitpid(pid, os.WNOHANG)
        if done:
            code = os.waitstatus_to_exitcode(status)
            break
        time.sleep(0.05)
    if code == "timeout":
        os.killpg(pid, signal.SIGKILL)
        os.waitpid(pid, 0)
    try:
        os.killpg(pid, signal.SIGKILL)  # no process of the case may outlive it
    except ProcessLookupError:
        pass
    read = lambda p: p.read_text(errors="replace") if p.exists() else ""  # noqa: E731
    return code, read(so), read(se), time.time() - t0, " ".join(argv)


def check_case(case_dir: Path, code, err: str, extra) -> str | None:
    """The contract; returns the violation or None."""
    lines = [ln for ln in err.splitlines() if ln.strip()]
    if code == "timeout":
        return f"no answer within {TIMEOUT:g} s"
    if code not in (0, 2):
        return f"exit {code}: {' | '.join(lines[-3:])[:400]}"
    if code == 2:
        if len(lines) != 1 or not lines[0].startswith("sim: error:") or "Traceback" in err:
            return f"exit 2 but stderr is not one line: {' | '.join(lines[-4:])[:400]}"
    left = {p.name for p in case_dir.iterdir()} - {"study.toml", "out"}
    if code == 2:
        left -= {".out.partial"}
    if left and "--out" not in extra:
        return f"left behind: {sorted(left)}"
    if code == 0 and "--out" not in extra:
        from sim.mc.storage import read_table

        out = case_dir / "out"
        for f in ("claims.parquet", "sweep.parquet"):
            if (out / f).is_file():
                t = read_table(out / f).to_pydict()
                # a row "not comparable" has no value by design (agnard's Table 1 when no input
                # of the simulated scanner reproduces it): not a non-finite result
                verdicts = t.get("verdict")
                for col in ("value", "ci_low", "ci_high"):
                    xs = t.get(col, [])
                    if verdicts is not None:
                        xs = [x for x, w in zip(xs, verdicts) if w != "not comparable"]
                    v = np.array([np.nan if x is None else x for x in xs], float)
                    if v.size and not np.isfinite(v).all():
                        return f"exit 0 with a non-finite {col} in {f}"
                break
        else:
            return "exit 0 but no claims.parquet or sweep.parquet"
    return None


def fuzz(n: int, tmp: Path) -> list[str]:
    before = (
        sorted(p.name for p in (ROOT / "results").iterdir()) if (ROOT / "results").is_dir() else []
    )
    top = sorted(p.name for p in ROOT.iterdir())
    failures = []
    save = os.environ.get("FUZZ_SAVE")
    for i in range(n):
        name, flat, sweep, extra, desc, raw = make_case(i)
        d = tmp / f"case{i:04d}"
        d.mkdir()
        study = d / "study.toml"
        study.write_bytes(raw if raw is not None else toml_doc(flat, sweep).encode())
        code, _, err, secs, argv = run_case(d, study, extra, TIMEOUT)
        bad = check_case(d, code, err, extra)
        named = desc.split(": key: ")[-1].split(" ", 1)[-1]  # a misspelt key: named as written
        if not bad and ": key: " in desc and (code != 2 or named not in err):
            twice = desc.split(": key: ")[1].startswith("twice") and " line " in err  # TOML's
            bad = None if twice else f"a misspelt key not refused naming {named}: exit {code}"
        edge = desc.split(": edge: ")[-1].split(" = ")[0]  # a value beyond its key's bounds
        if (
            not bad
            and desc.endswith(" beyond its bounds")
            and (code != 2 or key_text(edge) not in err)
        ):
            bad = f"a value beyond its bounds not refused naming {edge}: exit {code}"
        if not bad and ": shape: " in desc:  # the same document runs; a table twice is named
            shape = desc.split(": shape: ")[-1]
            if shape.endswith(SAME) and code != 0:
                bad = f"the same document in another shape not run: exit {code}"
            elif not shape.endswith(SAME) and (code != 2 or shape.split()[-1] not in err):
                bad = f"a table given twice not refused naming {shape.split()[-1]}: exit {code}"
        if not bad and ": splice: " in desc and ": must name " in desc:  # a key out of place
            named = desc.split(": must name ")[-1].removeprefix("one of ").split()
            if code != 2 or not any(n in err for n in named):
                bad = f"a spliced key not refused naming {' or '.join(named)}: exit {code}"
        if not bad and ": bytes: " in desc and desc.endswith(SAME_BYTES) and code != 0:
            bad = f"the same document in other bytes not run: exit {code}"
        if bad:
            where = study
            if save:
                Path(save).mkdir(parents=True, exist_ok=True)
                where = Path(save) / f"case{i:04d}.toml"
                shutil.copy(study, where)
            failures.append(
                f"case {i} ({desc}; {secs:.1f} s): {bad}\n    reproduce: sim "
                + argv.replace(str(study), str(where))
            )
        shutil.rmtree(d, ignore_errors=True)
    after = (
        sorted(p.name for p in (ROOT / "results").iterdir()) if (ROOT / "results").is_dir() else []
    )
    if after != before or sorted(p.name for p in ROOT.iterdir()) != top:
        failures.append("the repository gained or lost files")
    return failures
