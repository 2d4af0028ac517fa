"""SEQUENCE, a mutation kind of the fuzzer (tests/test_fuzz.py): orders of operations.

A seeded random sequence of 4-8 steps on one small study (a network read from a GNU Gama file,
``net.toml`` and ``net.xml``, 40 trials in chunks of 2) and one output directory
``res/net`` (what ``python -m sim.batch --results res`` writes for it), each step drawn from:
``sim run``, ``sim run --overwrite``, a run interrupted (SIGINT, SIGTERM or SIGKILL at a
marker: the ``k``-th rename of a file, tests/fuzz_sequence_run.py), the same command again
(resume), an edit of the study file (``trials``, ``seed``, ``test.alpha``, a ``[sweep]``) or of
its Gama file (a standard deviation, a comment), a run with ``--set``, ``--trials`` or
``--seed``, ``sim show``, ``sim report --results``, ``make verify``'s verify of ``res``, a
sweep, ``python -m sim.batch --stale-only``, a hand edit of the results (a figure deleted, a
table touched, a file of the user's added) and the API's ``sim.load(...).run(out=...)``.

After each step: exit 0 or one line and exit 2 (130 or SIGKILL's for an interrupt; 1 for a
verify whose comparison failed), never a traceback; the output directory, when it holds a run
record, is that run complete (every file it lists, each table, chunk and figure its sha256)
and its tables and chunks are those of a clean run of the config it records, a config one of
the sequence's steps asked for; a run, batch or API call that ends with exit 0 leaves the
config it was asked for there and no staging or swap directory beside it; ``--stale-only``
never calls other results current; ``make verify`` passes only results of the study file's
config; ``sim show`` prints the claims of the clean run of the config the directory records;
``sim show`` and verify change nothing in it, ``sim report`` only its README.md; a file of the
user's is never deleted or changed. ``FUZZ_CASES`` sets the number of sequences (one a ten
cases, at least 2), ``FUZZ_SEQ_SECONDS`` the time after which no new one starts."""

from __future__ import annotations

import os
import random
import re
import shutil
import signal
import time
from pathlib import Path

from fuzz_sequence_run import (
    References,
    against_reference,
    api_read,
    api_run,
    batch_main,
    budgeted,
    claims_block,
    lines,
    record,
    same_claims,
    sha256,
    sim_main,
    spawn,
    verify_main,
)
from fuzz_values import ROOT

GAMA = ROOT / "tests" / "data" / "gama" / "one_fixed.xml"
#: the Gama file's versions: as shipped, its distances' standard deviation changed, a comment
XMLS = [
    GAMA.read_bytes(),
    GAMA.read_bytes().replace(b'stdev="2.0"', b'stdev="2.5"'),
    GAMA.read_bytes().replace(b"<network ", b"<!-- moved pillar B -->\n  <network ", 1),
]
#: the overrides a step may give (``--set``, ``--trials``, ``--seed``; the API's keywords)
SETS = ["test.alpha=0.1", "seed=7", "trials=60", "reliability.power=0.9"]
OPS = ["run"] * 3 + ["overwrite"] * 2 + ["interrupt"] * 3 + ["resume"] * 2 + ["edit_study"] * 2
OPS += [
    "edit_input",
    "edit_during",
    "set",
    "show",
    "report",
    "verify",
    "sweep",
    "batch",
    "hand",
    "api",
] + [
    "hand",
    "show",
]
WRITERS = {"run", "overwrite", "interrupt", "resume", "set", "sweep", "api", "edit_during"}
SIGNALS = [signal.SIGINT, signal.SIGTERM, signal.SIGKILL]


def study_text(m: dict) -> str:
    """The study file of the model ``m`` (its trials, seed, test.alpha, sweep)."""
    doc = ['study = "network"', f"trials = {m['trials']}", "chunk = 2"]
    doc += [f"seed = {m['seed']}"] * bool(m["seed"])
    doc += ["[network]", 'gama_xml = "net.xml"']
    doc += ["[test]", f"alpha = {m['alpha']}"] * bool(m["alpha"])
    doc += ["[sweep]", "reliability.power = [0.8, 0.9]"] * m["sweep"]
    return "\n".join(doc) + "\n"


class Case:
    """One sequence's directory, its files' models and what the steps asked for."""

    def __init__(self, d: Path, refs: References):
        self.d, self.refs = d, refs
        self.res, self.out = d / "res", d / "res" / "net"
        self.model = {"trials": 40, "seed": 0, "alpha": 0, "sweep": False}
        self.xml = 0
        self.asked: list[tuple] = []  # every state a step ran or compared
        self.users: dict[str, bytes] = {}  # files of the user's in out
        self.missing: set[str] = set()  # files of the run removed by a hand edit
        self.interrupted: tuple | None = None  # the last interrupted step, to resume
        self.had = False  # out held results once
        self.n = 0
        d.mkdir(parents=True)
        self.write()

    def write(self) -> None:
        (self.d / "net.toml").write_text(study_text(self.model))
        (self.d / "net.xml").write_bytes(XMLS[self.xml])

    def state(self, sets=()) -> tuple:
        s = (study_text(self.model), XMLS[self.xml], tuple(sorted(sets)))
        self.asked.append(s)
        return s

    def log(self) -> Path:
        self.n += 1
        return self.d / f"step{self.n}"

    def snapshot(self) -> dict[str, str]:
        if not self.out.is_dir():
            return {}
        return {str(p.relative_to(self.out)): sha256(p) for p in self.out.rglob("*") if p.is_file()}


def _spelt(rng: random.Random, c: Case) -> str:
    """The output directory as a step spells it (one directory whatever the spelling)."""
    return rng.choice(["res/net"] * 4 + ["./res/net", "res/net/", str(c.out), "res/../res/net"])


def _run_argv(rng: random.Random, c: Case, sets: list[str], overwrite: bool) -> list[str]:
    argv = ["run", "net.toml", "--quiet", "--out", _spelt(rng, c)]
    for s in sets:
        k, v = s.split("=")
        form = rng.random()
        argv += [f"--{k}", v] if k in ("trials", "seed") and form < 0.5 else ["--set", s]
    argv += ["--no-figures"] * (rng.random() < 0.2) + ["--workers", "2"] * (rng.random() < 0.15)
    return argv + ["--overwrite"] * overwrite


def _api_kw(sets: list[str]) -> dict:
    import tomllib

    return {k: tomllib.loads(f"v = {v}")["v"] for k, v in (s.split("=") for s in sets)}


def step(rng: random.Random, c: Case, op: str):
    """Do ``op`` on the case: ``(description, code, stdout, stderr, state asked or None,
    allowed codes)``."""
    sets = [rng.choice(SETS)] if rng.random() < 0.35 or op == "set" else []
    if op == "resume" and c.interrupted is not None:
        desc, target, sets = c.interrupted
        state = c.state(sets)  # the files as they are now: the command reads them again
        code, so, se = spawn(c.d, target, c.log())
        c.interrupted = None
        return f"resume ({desc})", code, so, se, state, {0, 2}
    if op == "edit_during":  # a run, its Gama or study file saved anew at a marker
        argv = _run_argv(rng, c, sets, rng.random() < 0.7)
        state, target = c.state(sets), sim_main(argv)
        model = {**c.model, "trials": 100 - c.model["trials"]}
        xml = rng.choice([i for i in range(len(XMLS)) if i != c.xml])
        what = ("net.xml", XMLS[xml]) if rng.random() < 0.6 else ("net.toml", study_text(model))
        k = rng.randint(1, 60)
        code, so, se = spawn(
            c.d,
            target,
            c.log(),
            marker=(k, (what[0], bytes(what[1], "utf-8") if isinstance(what[1], str) else what[1])),
        )
        if (c.d / "net.xml").read_bytes() != XMLS[c.xml]:
            c.xml = xml
        if (c.d / "net.toml").read_text() != study_text(c.model):
            c.model = model
        desc = f"{op}: sim " + " ".join(argv) + f" ({what[0]} saved anew at rename {k})"
        return desc, code, so, se, state, {0, 2}
    if op in ("run", "overwrite", "interrupt", "set", "sweep", "resume"):
        if op == "sweep":
            c.model["sweep"] = True
            c.write()
        overwrite = op == "overwrite" or (op in ("interrupt", "sweep") and rng.random() < 0.7)
        argv = _run_argv(rng, c, sets, overwrite)
        state, target = c.state(sets), sim_main(argv)
        marker = (rng.randint(1, 60), rng.choice(SIGNALS)) if op == "interrupt" else None
        code, so, se = spawn(c.d, target, c.log(), marker=marker)
        desc = f"{op}: sim " + " ".join(argv)
        if marker:
            desc += f" ({signal.Signals(marker[1]).name} at rename {marker[0]})"
        if marker:
            c.interrupted = (" ".join(argv), target, sets)
        return desc, code, so, se, state, {0, 2, 130, -9} if marker else {0, 2}
    if op == "api":  # interrupted at a marker one time in three
        overwrite = rng.random() < 0.5
        state = c.state(sets)
        target = api_run("net.toml", _api_kw(sets), _spelt(rng, c), overwrite)
        marker = (rng.randint(1, 60), rng.choice(SIGNALS)) if rng.random() < 0.33 else None
        code, so, se = spawn(c.d, target, c.log(), marker=marker)
        desc = f"api: sim.load(net.toml, {sets}).run(overwrite={overwrite})"
        if marker:
            desc += f" ({signal.Signals(marker[1]).name} at rename {marker[0]})"
            c.interrupted = (desc, target, sets)
        # SIGTERM ends a Python process as SIGKILL does unless it set a handler: the API sets
        # none in its caller's process (the commands do)
        return desc, code, so, se, state, {0, 2, 130, -9, -15} if marker else {0, 2}
    if op == "batch":
        argv = [str(c.d / "net.toml"), "--results", "res", "--stale-only", "--jobs", "1"]
        argv += ["--", "--set", sets[0]] if sets else []
        state = c.state(sets)
        code, so, se = spawn(c.d, batch_main(argv), c.log())
        return "batch: python -m sim.batch " + " ".join(argv), code, so, se, state, {0, 2}
    if op == "edit_study":
        key = rng.choice(["trials", "seed", "alpha", "sweep"])
        new = {"trials": 100 - c.model["trials"], "seed": 7 - c.model["seed"]}
        new |= {"alpha": 0.1 if not c.model["alpha"] else 0, "sweep": not c.model["sweep"]}
        c.model[key] = new[key]
        c.write()
        return f"edit net.toml: {key} = {new[key]}", 0, "", "", None, {0}
    if op == "edit_input":
        c.xml = rng.choice([i for i in range(len(XMLS)) if i != c.xml])
        c.write()
        return f"edit net.xml: version {c.xml}", 0, "", "", None, {0}
    if op == "hand":
        return _hand(rng, c) + ("", "", None, {0})
    if op == "results":  # the API's reader of a results directory
        out = _spelt(rng, c)
        code, so, se = spawn(c.d, api_read(out, "claims.got"), c.log())
        return f"sim.Results({out!r}).table('claims')", code, so, se, None, {0, 2}
    if op == "show":
        argv = ["show", _spelt(rng, c)]
        code, so, se = spawn(c.d, sim_main(argv), c.log())
        return "sim " + " ".join(argv), code, so, se, None, {0, 2}
    # a report or verify interrupted one time in four, at one of the few files it writes
    marker = (rng.randint(1, 3), rng.choice(SIGNALS)) if rng.random() < 0.25 else None
    how = f" ({signal.Signals(marker[1]).name} at rename {marker[0]})" if marker else ""
    if op == "report":
        code, so, se = spawn(c.d, sim_main(["report", "--results", "res"]), c.log(), marker)
        return "sim report --results res" + how, code, so, se, None, {0, 2, 130, -9}
    argv = ["--results", "res", "--studies", ".", "--scratch", "vs"]
    argv += ["--no-record"] * (rng.random() < 0.5)
    code, so, se = spawn(c.d, verify_main(argv), c.log(), marker)
    return "verify " + " ".join(argv) + how, code, so, se, None, {0, 1, 2, 130, -9}


def _hand(rng: random.Random, c: Case) -> tuple[str, int]:
    """A hand edit of the results: a figure deleted, a table touched, a file of the user's."""
    if record(c.out) is None:
        return "hand: nothing to edit", 0
    what = rng.choice(["figure", "touch", "user", "user"])
    figs = sorted(p.relative_to(c.out).as_posix() for p in c.out.rglob("*.png"))  # cells' too
    if what == "figure" and figs:
        f = rng.choice(figs)
        (c.out / f).unlink()
        c.missing.add(f)
        return f"hand: rm {f}", 0
    tables = sorted(p for p in c.out.rglob("*.parquet") if "trials" not in p.parts)
    if what == "touch" and tables:
        p = rng.choice(tables)
        os.utime(p, (time.time() + 3600, time.time() + 3600))
        return f"hand: touch {p.relative_to(c.out)}", 0
    cells = sorted(p.relative_to(c.out).as_posix() for p in c.out.glob("cells/*"))
    name = rng.choice(["notes.txt", "mine/plot.py", "notes.txt"] + [f"{x}/notes.md" for x in cells])
    data = f"{name}: {rng.random()}\n".encode()
    (c.out / name).parent.mkdir(parents=True, exist_ok=True)
    (c.out / name).write_bytes(data)
    c.users[name] = data
    return f"hand: add {name}", 0


def check(c: Case, op, desc, code, so, se, state, codes, before) -> str | None:
    """The invariants after a step (module docstring), or None."""
    if "Traceback" in so + se:
        return f"a traceback: {se[-600:]}"
    if code not in codes:
        return f"exit {code}: {' | '.join(lines(se)[-3:])[:400]}"
    if code in (2, 130) and len(lines(se)) != 1:
        return f"exit {code} with {len(lines(se))} lines: {' | '.join(lines(se))[:400]}"
    for name, data in c.users.items():
        if not (c.out / name).is_file() or (c.out / name).read_bytes() != data:
            return f"the user's file {name} was deleted or changed"
    rec = record(c.out)
    if c.had and rec is None:
        return "the results were lost (no run.json in res/net)"
    c.had = c.had or rec is not None
    if rec is not None and (bad := against_reference(c, rec, c.missing, "no step asked for")):
        return bad
    writer = op in WRITERS or op == "batch"
    if writer and code == 0 and state is not None:
        want = c.refs.get(state)[0]
        if want is None:
            return "ran a state whose clean run is refused"
        if rec is None or rec.get("config") != want.get("config"):
            return "exit 0 but res/net does not hold the config the step asked for"
        left = [p.name for p in c.res.iterdir() if p.name.startswith(".net.")]
        if left and not (op == "batch" and "up to date" in so):  # (an unfinished run's: kept)
            return f"exit 0 but {left} left beside res/net"
        tmps = [str(p.relative_to(c.out)) for p in c.out.rglob("*.tmp")]
        if tmps and "up to date" not in so:  # a killed writer's, carried into new results
            return f"exit 0 but the temporary {tmps[0]} is in res/net"
        c.missing.clear()
    if op in ("show", "verify", "report"):
        after = c.snapshot()
        if op == "report":
            after.pop("README.md", None), before.pop("README.md", None)
        tmp = re.compile(r"(.*/)?\.[^/]+\.\d+\.tmp")  # of a README.md a kill cut short:
        after = {f: h for f, h in after.items() if not tmp.fullmatch(f)}  # the suite's (the
        before = {f: h for f, h in before.items() if not tmp.fullmatch(f)}  # next removes it)
        if after != before:
            return f"{op} changed res/net: {sorted(set(after.items()) ^ set(before.items()))[:3]}"
    if op == "results" and code == 0:
        ref = c.refs.of_config(rec) if rec else None
        got = c.d / "claims.got"
        if ref is None or (ref[2] / "claims.parquet").is_file() and not same_claims(got, ref[2]):
            return "sim.Results read a claims table other than its run's"
        got.unlink()
    if op == "show" and code == 0:
        ref = c.refs.of_config(rec) if rec else None
        if ref is None or claims_block(so) != ref[1]:
            return f"sim show printed claims other than its run's:\n{claims_block(so)[:600]}"
    if op == "verify" and code == 0:
        want = c.refs.get(c.state(rec.get("overrides", [])) if rec else c.state())[0]
        if rec is None or want is None or rec.get("config") != want.get("config"):
            return "verify passed results that are not of the study file's config"
    return None


def run_sequence(i: int, seed: int, tmp: Path, refs: References) -> str | None:
    rng = random.Random(seed * 100_003 + 88_888 + i)
    c = Case(tmp / f"seq{i:03d}", refs)
    ops = [rng.choice(["run", "run", "api", "batch"])]
    ops += [rng.choice(OPS) for _ in range(rng.randint(4, 8) - 1)]
    done = []
    for op in ops:
        before = c.snapshot()
        desc, code, so, se, state, codes = step(rng, c, op)
        done.append(f"{desc} -> {code}")
        bad = check(c, op, desc, code, so, se, state, codes, before)
        if bad:
            return f"sequence {i} (seed {seed}) step {len(done)}: {bad}\n    " + "\n    ".join(done)
    shutil.rmtree(c.d, ignore_errors=True)
    return None


def sequences(n: int, seed: int, tmp: Path) -> list[str]:
    """Run ``n`` sequences (fewer when ``FUZZ_SEQ_SECONDS`` run out): their failures."""
    return budgeted(run_sequence, n, seed, tmp, "FUZZ_SEQ_SECONDS")
