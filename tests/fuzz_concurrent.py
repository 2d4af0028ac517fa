"""CONCURRENT, a mutation kind of the fuzzer (tests/test_fuzz.py): two processes at once.

A seeded pair of operations on the small study of tests/fuzz_sequence.py (``net.toml`` reading
``net.xml``, 40 trials in chunks of 2) and its output directory ``res/net``, which holds
nothing, a run of the study file, a run of another config or a killed run's staging directory
(and at times a file of the user's) when the pair starts. The first is ``sim run`` (with
``--overwrite``, ``--set``, ``--trials``, ``--seed``), the API's ``run``, ``python -m sim.batch
--stale-only``, a sweep, ``sim report`` or verify; the second is one of them, ``sim show``, a
run of one of the sweep's cells, or the study file or its Gama file saved anew. The
second starts with the first (at once) or while the first waits at a marker, the ``k``-th
rename of a file, until the second has ended (tests/fuzz_sequence_run.py's ``Pause``: pipes,
no sleep).

After both: each exits 0 or 2 with one line (verify 1 for a failed comparison), never a
traceback; a run refused because of the other names it or its lock; ``res/net``, when it holds
a run record, is that run complete with the tables and chunks of a clean run of the config it
records, a config one of the two (or the results before) stood for; a writer that ended with
exit 0 alone (the other refused, or a reader) left its config; results there before are not
lost; a file of the user's is never deleted or changed; ``sim show`` prints the claims of a
run that ``res/net`` held; verify passes only results of the study file's config; and the
next ``sim run --overwrite`` of the study file runs, leaving no staging or swap directory.
``FUZZ_CASES`` sets the number of pairs (one a seven cases, at least 2),
``FUZZ_PAIR_SECONDS`` the time after which no new one starts."""

from __future__ import annotations

import random
import shutil
from pathlib import Path

from fuzz_sequence import XMLS, Case, _api_kw, _run_argv, study_text
from fuzz_sequence_run import (
    Pause,
    References,
    against_reference,
    api_run,
    batch_main,
    budgeted,
    claims_block,
    incomplete,
    lines,
    record,
    sim_main,
    spawn,
    start,
    verify_main,
    wait,
)

FIRST = ["run", "run", "overwrite", "api", "batch", "sweep", "report", "verify"]
SECOND = ["run", "overwrite", "api", "batch", "show", "report", "verify", "edit", "cell"]
#: what a run refused because of the other says (its lock, its results or its unfinished run)
BUSY = ("being written by a running sim", "results of", "an unfinished run of")
OTHER_SETS = ["trials=60", "seed=7", "test.alpha=0.1"]


class Op:
    """One process of a pair: its words, what it runs, the state it asks for (None for a
    reader), the exit codes allowed, and whether it writes ``res/net``."""

    def __init__(self, desc, target, state, codes, writer, sets=()):
        self.desc, self.target, self.state = desc, target, state
        self.codes, self.writer, self.sets = codes, writer, list(sets)
        self.code, self.so, self.se = None, "", ""


def _sweep_text(c: Case) -> str:
    return study_text({**c.model, "sweep": True})


def make_op(rng: random.Random, c: Case, kind: str) -> Op:
    """The operation ``kind`` with seeded arguments."""
    sets = [rng.choice(OTHER_SETS)] if rng.random() < 0.3 else []
    if kind in ("run", "overwrite"):
        argv = _run_argv(rng, c, sets, kind == "overwrite" or rng.random() < 0.3)
        desc = "sim " + " ".join(argv)
        return Op(desc, sim_main(argv), c.state(sets), {0, 2}, True, sets)
    if kind == "api":
        ow = rng.random() < 0.5
        target = api_run("net.toml", _api_kw(sets), "res/net", ow)
        desc = f"api: sim.load(net.toml, {sets}).run(out='res/net', overwrite={ow})"
        return Op(desc, target, c.state(sets), {0, 2}, True, sets)
    if kind == "batch":
        argv = ["net.toml", "--results", "res", "--stale-only", "--jobs", "1"]
        argv += ["--", "--set", sets[0]] if sets else []
        desc = "python -m sim.batch " + " ".join(argv)
        return Op(desc, batch_main(argv), c.state(sets), {0, 2}, True, sets)
    if kind == "sweep":  # a file of its own: the other process reads net.toml
        (c.d / "sweep.toml").write_text(_sweep_text(c))
        argv = ["run", "sweep.toml", "--quiet", "--out", "res/net", "--no-figures"]
        argv += ["--overwrite"] * (rng.random() < 0.7)
        state = (_sweep_text(c), XMLS[c.xml], ())
        c.asked.append(state)
        return Op("sim " + " ".join(argv), sim_main(argv), state, {0, 2}, True)
    if kind == "cell":  # a run of one of the sweep's cells, into the sweep's out or a cell's
        sets = [f"reliability.power={rng.choice(['0.8', '0.9'])}"]
        out = rng.choice(["res/net", "res/net", "res/net/cells/cell0000_r0"])
        argv = ["run", "net.toml", "--quiet", "--out", out, "--set", sets[0]]
        argv += ["--overwrite"] * (rng.random() < 0.5)
        return Op(
            "sim " + " ".join(argv), sim_main(argv), c.state(sets), {0, 2}, out == "res/net", sets
        )
    if kind == "show":
        return Op("sim show res/net", sim_main(["show", "res/net"]), None, {0, 2}, False)
    if kind == "report":
        target = sim_main(["report", "--results", "res"])
        return Op("sim report --results res", target, None, {0, 2}, False)
    if kind == "verify":
        argv = ["--results", "res", "--studies", ".", "--scratch", "vs", "--no-record"]
        return Op("verify " + " ".join(argv), verify_main(argv), None, {0, 1, 2}, False)
    # edit: the study file or its Gama file saved anew (in place, as an editor may)
    if rng.random() < 0.5:
        xml = rng.choice([i for i in range(len(XMLS)) if i != c.xml])
        name, data = "net.xml", XMLS[xml]
        new = (study_text(c.model), XMLS[xml], ())
    else:
        model = {**c.model, "trials": 100 - c.model["trials"]}
        name, data = "net.toml", study_text(model).encode()
        new = (study_text(model), XMLS[c.xml], ())

    def edit():
        Path(name).write_bytes(data)
        return 0

    op = Op(f"edit {name}", edit, None, {0}, False)
    op.new = new
    return op


def _prepare(rng: random.Random, c: Case) -> str:
    """What ``res/net`` holds when the pair starts."""
    what = rng.choice(["nothing", "run", "run", "other", "killed"])
    if what == "nothing":
        return what
    sets = [rng.choice(OTHER_SETS)] if what == "other" else []
    argv = ["run", "net.toml", "--quiet", "--no-figures", "--out", "res/net"]
    argv += [a for s in sets for a in ("--set", s)]
    c.state(sets)
    marker = (rng.randint(2, 20), 9) if what == "killed" else None
    code, _, se = spawn(c.d, sim_main(argv), c.log(), marker=marker)
    if code not in (0, -9):
        raise AssertionError(f"preparing {what}: exit {code}: {se[-300:]}")
    if what != "killed" and rng.random() < 0.5:
        (c.out / "notes.txt").write_bytes(b"mine\n")
        c.users["notes.txt"] = b"mine\n"
    return what + (f" ({sets[0]})" if sets else "")


def run_pair(i: int, seed: int, tmp: Path, refs: References) -> str | None:
    """One pair: its failure, or None."""
    rng = random.Random(seed * 100_003 + 99_999 + i)
    c = Case(tmp / f"pair{i:03d}", refs)
    (c.d / "res").mkdir()
    before = _prepare(rng, c)
    old = record(c.out)
    a = make_op(rng, c, rng.choice(FIRST))
    kind = rng.choice(SECOND)
    if kind == "cell" and "sweep.toml" not in a.desc:
        kind = "run"
    b = make_op(rng, c, kind)
    at = rng.choice([None, rng.randint(1, 40)])
    when = "at once" if at is None else f"at rename {at} of the first"
    story = f"pair {i} (seed {seed}; res/net: {before}): {a.desc} | {b.desc} ({when})"
    _both(c, a, b, at)
    if getattr(b, "new", None) is not None:  # the edit: a later read sees the new file
        c.asked += [b.new, *(_read_as(a.state, b) if a.state else [])]
        c.model = {**c.model, "trials": 100 - c.model["trials"]} if "toml" in b.desc else c.model
        c.xml = XMLS.index(b.new[1])
    bad = check_pair(c, a, b, old)
    if bad is None and (b.writer or b.code != 0 or "cells/" not in b.desc):  # (else res/net
        # holds a run of the user's inside it: never replaced)
        bad = _next_run(c)
    if bad is not None:
        return f"{story}: {bad}\n    exits: {a.code}, {b.code}"
    shutil.rmtree(c.d, ignore_errors=True)
    return None


def _both(c: Case, a: Op, b: Op, at: int | None, timeout: float = 300.0) -> None:
    """Run ``a`` and ``b`` together: at once, or ``b`` while ``a`` waits at rename ``at``."""
    la, lb = c.log(), c.log()
    pause = Pause() if at is not None else None
    pa = start(c.d, a.target, la, marker=(at, pause) if pause else None)
    if pause is not None:
        pause.reached(pa, timeout)
    pb = start(c.d, b.target, lb)
    if pause is not None:
        b.code, b.so, b.se = wait(pb, lb, timeout / 2)
        pause.go()
    a.code, a.so, a.se = wait(pa, la, timeout)
    if pause is None:
        b.code, b.so, b.se = wait(pb, lb, timeout)


def _read_as(state: tuple, b: Op) -> list[tuple]:
    """The states a process asked for ``state`` may have read: it, and with the file that the
    edit ``b`` saved anew (a study file of a sweep keeps its own)."""
    new = getattr(b, "new", None)
    if new is None:
        return [state]
    if new[1] != state[1]:
        return [state, (state[0], new[1], state[2])]
    return [state] if "[sweep]" in state[0] else [state, (new[0], state[1], state[2])]


def _config(c: Case, state) -> dict | None:
    rec = c.refs.get(state)[0]
    return rec.get("config") if rec else None


def check_pair(c: Case, a: Op, b: Op, old: dict | None) -> str | None:
    """The invariants after both ended (module docstring), or None."""
    for op in (a, b):
        if "Traceback" in op.so + op.se:
            return f"a traceback in {op.desc}: {op.se[-600:]}"
        if op.code not in op.codes:
            return f"{op.desc}: exit {op.code}: {' | '.join(lines(op.se)[-3:])[:400]}"
        if op.code == 2 and len(lines(op.se)) != 1:
            return f"{op.desc}: exit 2 with lines: {' | '.join(lines(op.se))[:400]}"
    for name, data in c.users.items():
        if not (c.out / name).is_file() or (c.out / name).read_bytes() != data:
            return f"the user's file {name} was deleted or changed"
    rec = record(c.out)
    if old is not None and rec is None:
        return "the results in res/net were lost (no run.json)"
    if rec is not None and (
        bad := against_reference(c, rec, set(), "neither process nor the results before stood for")
    ):
        return bad
    ok = [op for op in (a, b) if op.writer and op.code == 0]
    for op in (a, b):
        if op.writer and op.code == 2 and c.refs.get(op.state)[0] is not None:
            other = b if op is a else a
            line = lines(op.se)[0]
            if other.writer and not any(w in line for w in BUSY):
                return f"{op.desc} refused without naming the other run: {line[:300]}"
    if len(ok) == 1:
        want = [_config(c, s) for s in _read_as(ok[0].state, b)]
        if rec is None or rec.get("config") not in want:
            return f"{ok[0].desc} ended with exit 0 but res/net holds another config"
    held = [old] + [c.refs.get(op.state)[0] for op in ok]
    configs = [r.get("config") for r in held if r]
    for op in (a, b):
        if op.desc.startswith("sim show") and op.code == 0:
            shown = [c.refs.of_config(r) for r in held if r]
            if claims_block(op.so) not in [s[1] for s in shown if s]:
                return (
                    f"sim show printed claims of no run res/net held:\n{claims_block(op.so)[:400]}"
                )
        if op.desc.startswith("verify") and op.code == 0 and not hasattr(b, "new"):
            file = (study_text(c.model), XMLS[c.xml])  # with the overrides the run recorded
            mine = [_config(c, (*file, tuple(sorted(r.get("overrides", []))))) for r in held if r]
            if not any(m is not None and m in configs for m in mine):
                return "verify passed results that are not of the study file's config"
    return None


def _next_run(c: Case) -> str | None:
    """The next ``sim run --overwrite`` of the study file runs, and leaves nothing beside."""
    argv = ["run", "net.toml", "--quiet", "--no-figures", "--overwrite", "--out", "res/net"]
    code, so, se = spawn(c.d, sim_main(argv), c.log())
    if code != 0:
        return f"the next sim run --overwrite: exit {code}: {' | '.join(lines(se))[:400]}"
    left = [p.name for p in c.res.iterdir() if p.name.startswith(".net.")]
    if left:
        return f"the next run left {left} beside res/net"
    rec, want = record(c.out), _config(c, c.state())
    if rec is None or rec.get("config") != want or incomplete(c.out, set()):
        return "the next run did not leave the study file's complete results"
    return None


def pairs(n: int, seed: int, tmp: Path) -> list[str]:
    """Run ``n`` pairs (fewer when ``FUZZ_PAIR_SECONDS`` run out): their failures."""
    return budgeted(run_pair, n, seed, tmp, "FUZZ_PAIR_SECONDS")
