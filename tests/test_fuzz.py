"""Fuzz: mutated study files, overrides and options for all seven studies.

A seeded generator (``random.Random``) takes each study's file, shrinks it to a tiny run and
mutates it: a key's value (wrong types, magnitudes from 1e-300 to 1e300, NaN and infinities,
empty and huge lists, unicode, paths), the file's structure (unknown keys and studies,
garbage, a ``[sweep]`` table with bad ranges; a well-formed key in the wrong place: written in
table form with the key moved into another table or to the top level, its table an array of
tables or declared twice, the key itself an array of tables), its TOML type (a number as
a string, a bool, a date or time, a table or array for a scalar, a mixed, empty or nested
array, an integer beyond 64 bits, ``-0``, ``0x10``, ``1_000``; ``FUZZ_TYPE_WEIGHT`` sets its
share), a key's spelling (another case, a lookalike letter, white space or an invisible
character in a quoted key, ``-`` for ``_``, the key given twice through two spellings:
tests/fuzz_keys.py; ``FUZZ_KEY_WEIGHT`` sets its share: such a case must be refused, naming
the key as written) or the command line (``--trials``, ``--seed``, ``--workers``, ``--out``,
``--scheduler``). Every case runs ``sim run`` in a forked child
(its own session, an address-space limit, a time bound) and must give exit 0 with finite
results, or exit 2 with exactly one line on standard error and no traceback, and leave
nothing outside the output directory but, after a failed run, its staging directory.

``make test`` runs a few cases per study; ``make fuzz`` runs ``FUZZ_CASES`` (default 300).
``FUZZ_SEED`` picks the generator's seed, ``FUZZ_TIMEOUT`` the bound per case in seconds,
``FUZZ_SAVE`` a directory that keeps the study file of every failing case (the failure
message prints the command that reproduces it).
"""

from __future__ import annotations

import json
import math
import os
import random
import shutil
import signal
import sys
import time
import tomllib
from pathlib import Path

import numpy as np
import pytest
from fuzz_keys import network_case, respell

from sim.cli import main
from sim.mc.config import flatten
from sim.studies import load_study

ROOT = Path(__file__).resolve().parent.parent
CASES = int(os.environ.get("FUZZ_CASES", "14"))
SEED = int(os.environ.get("FUZZ_SEED", "13"))
TIMEOUT = float(os.environ.get("FUZZ_TIMEOUT", "300"))

#: each study shrunk to a run of a few seconds (keys that the mutations then perturb)
SMALL = {
    "brown_dilution": {  # the jackknife intervals need 20 chunks
        "trials": 20,
        "chunk": 1,
        "dilution.grids": [3, 5],
        "region.points": 256,
        "region.rounds": 1,
    },
    "brown_table1": {"trials": 20, "chunk": 1, "region.points": 256, "region.rounds": 1},
    "brown_design": {
        "trials": 8,
        "chunk": 4,
        "design.positions": [4],
        "design.offsets_mm": [17.0],
        "design.grids": [5],
        "design.extents_mm": [90.0],
        "design.settings": [2],
        "design.setting_sigma_um": [1.7],
        "design.beta_mm": [1.0],
        "budget.max_trials": 40,
        "coverage.trials": 10,
        "coverage.sweep_trials": 10,
        "coverage.noise_um": [1.0],
        "coverage.grids": [3],
        "coverage.betas_mm": [1.0],
        "bayes.walkers": 16,
        "bayes.steps": 100,
        "region.points": 256,
        "region.rounds": 1,
        "region.plate_points": 256,
    },
    "gridplate_two_plates": {
        "trials": 8,
        "chunk": 4,
        "analysis.ratios": [1.0],
        "analysis.stated_sigmas_um": [0.7],
    },
    "salsig_encoders": {
        "trials": 8,
        "chunk": 4,
        "power.trials": 10,
        "power.marks": [3],
        "power.sigma_um": [5.0],
        "consistency.trials": 10,
        "consistency.relief_mm": [2.0],
        "consistency.sigma_z_um": [40.0],
        "consistency.control": [6],
        "consistency.b8_sigma_um": [25.0],
        "consistency.comparator_sigma_um": [3.0],
    },
    "wolf_polynomial": {
        "trials": 8,
        "chunk": 4,
        "trade.trials": 4,
        "trade.degrees": [2, 3],
        "trade.spacings_mm": [20.0],
        "trade.n_sets": [3],
        "trade.readings": [3],
        "trade.pointing_sigmas_um": [7.0],
        "trade.ages_weeks": [1.0],
        "trade.drift_fractions": [0.25],
        "unprinted.trials": 4,
        "unprinted.pointing_sigmas_um": [7.0],
        "unprinted.field_scales": [1.0],
        "unprinted.mono_sigmas_um": [0.0],
    },
    "agnard_block": {
        "trials": 8,
        "chunk": 4,
        "tradeoff.dpis": [600.0],
        "tradeoff.trials": 4,
        "tradeoff.block_strips": [2],
        "tradeoff.block_models": [8],
        "tradeoff.recentre_px": [0.5],
        "tradeoff.block_trials": 4,
        "sweep.trials": 4,
        "sweep.five_inset": [0.0, 0.17],
    },
}
NAMES = sorted(SMALL)

NAN, INF = math.nan, math.inf
SCALARS = [
    0,
    -1,
    1,
    2,
    3,
    7,
    10**6,
    10**9,
    2**63 - 1,
    -(2**63),
    0.0,
    -0.0,
    -1.0,
    0.5,
    1.5,
    1e-300,
    1e-12,
    1e-9,
    1e6,
    1e9,
    1e155,
    1e300,
    NAN,
    INF,
    -INF,
    True,
    False,
    "",
    "7",
    "1.0",
    "π☃ü",
    "../../../etc/passwd",
    "/dev/zero",
    "/",
    "/tmp",
    "studies",
    "x" * 5000,
]
LISTS = [
    [],
    [NAN],
    [INF],
    [-INF],
    [1e300],
    [1e-300],
    [0],
    [-1],
    [0.0],
    ["a"],
    [[1, 2]],
    [True],
    [3] * 20000,
    [1.0] * 3,
    list(range(1, 60)),
    [2, 3, 3],
    ["π"],
    [[0.0, 0.0]] * 10,
    [[NAN, 1.0]] * 4,
    [[1e300, 1e300], [0.0, 1.0], [1.0, 0.0]],
]


class Raw(str):
    """A TOML literal written as is (a date, ``0x10``, ``1_000``: values Python has no literal
    for that round-trips through ``toml_value``)."""


#: TYPE confusion: a number as a string, a bool, a date or time, a table or array for a scalar,
#: mixed, empty and nested arrays, a 64-bit-overflowing integer, -0, 0x/0o/0b and 1_000 literals
TYPED = [
    *map(Raw, ['"6"', '"0.5"', "true", "1979-05-27", "07:32:00", "1979-05-27T07:32:00Z"]),
    *map(Raw, ["1979-05-27 07:32:00.999999", "{a = 1}", "{}", '[1, "a"]', "[1, 2.0]", "[]"]),
    *map(Raw, ["[[1], [2]]", "[[]]", "99999999999999999999", "-0", "0x10", "0o17", "0b101"]),
    *map(Raw, ["1_000", "+inf", "-nan", "1e400", "[true, false]", "[1979-05-27]", "''"]),
]


def toml_value(v) -> str:
    if isinstance(v, Raw):
        return str(v)
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, int):
        return str(v)
    if isinstance(v, float):
        return (
            "nan" if math.isnan(v) else ("inf" if v > 0 else "-inf") if math.isinf(v) else repr(v)
        )
    if isinstance(v, str):
        return json.dumps(v, ensure_ascii=False)
    if isinstance(v, list):
        return "[" + ", ".join(toml_value(x) for x in v) + "]"
    if isinstance(v, dict):
        return "{" + ", ".join(f"{k} = {toml_value(x)}" for k, x in v.items()) + "}"
    raise TypeError(type(v))


def toml_doc(flat: dict, sweep: dict | None = None) -> str:
    lines = [f"{k} = {toml_value(v)}" for k, v in flat.items()]
    if sweep is not None:
        lines.append("[sweep]")
        lines += [f"{k} = {toml_value(v)}" for k, v in sweep.items()]
    return "\n".join(lines) + "\n"


def toml_tables(flat: dict, moved: dict | None = None) -> list[str]:
    """The document in table form (``[head]`` then ``leaf = value``), as an editor writes it;
    ``moved`` maps a key to the table it is written in instead (``""``: the top level)."""
    groups: dict[str, list[str]] = {}
    for k, v in flat.items():
        head, _, leaf = k.rpartition(".")
        head = (moved or {}).get(k, head)
        groups.setdefault(head, []).append(f"{leaf} = {toml_value(v)}")
    lines = groups.pop("", [])
    for head, body in groups.items():
        lines += [f"[{head}]", *body]
    return lines


def relocate(rng: random.Random, flat: dict, schema: list[str]) -> tuple[bytes, str]:
    """A well-formed key in the wrong place: moved into another table or to the top level,
    its table given as an array of tables or declared twice, the key itself a table array."""
    k = rng.choice([s for s in schema if "." in s and s in flat] or list(flat))
    head, _, leaf = k.rpartition(".")
    heads = sorted({s.rpartition(".")[0] for s in flat if "." in s} - {head})
    what = rng.choice(["moved", "top", "aot_table", "dup_table", "aot_key"])
    if what == "moved" and heads:
        to = rng.choice(heads)
        return "\n".join(toml_tables(flat, {k: to})).encode() + b"\n", f"{k} moved to [{to}]"
    if what in ("moved", "top"):
        return "\n".join(toml_tables(flat, {k: ""})).encode() + b"\n", f"{k} moved to the top"
    lines = toml_tables(flat)
    if what == "aot_key":
        lines = toml_tables({x: v for x, v in flat.items() if x != k})
        lines += [f"[[{k}]]", f"{leaf} = {toml_value(flat[k])}"]
    elif head and what == "aot_table":
        lines = [f"[[{head}]]" if ln == f"[{head}]" else ln for ln in lines]
    elif head:  # the table declared twice (malformed TOML)
        lines += [f"[{head}]", f"{leaf} = {toml_value(flat[k])}"]
    return "\n".join(lines).encode() + b"\n", f"{what} {k}"


def small(name: str) -> dict:
    """The tiny overrides the study's schema knows (study modules rename keys)."""
    schema = load_study(ROOT / "studies" / f"{name}.toml")[0].schema
    out = {}
    for k, v in SMALL[name].items():
        if k in schema:
            f = schema[k]
            short = isinstance(v, list) and len(v) < f.min_len and isinstance(f.default, list)
            out[k] = f.default[: f.min_len] if short else v
            if isinstance(v, (int, float)) and f.lo is not None and v < f.lo:
                out[k] = type(v)(f.lo)  # the schema's smallest size
    return out


def base(name: str) -> dict:
    doc = tomllib.loads((ROOT / "studies" / f"{name}.toml").read_text())
    flat = flatten({k: v for k, v in doc.items() if k != "sweep"})
    flat.update(small(name))
    return flat


def mutate_value(rng: random.Random, old):
    r = rng.random()
    if r < 0.35 and isinstance(old, (int, float)) and not isinstance(old, bool) and old:
        return (
            type(old)(old * 10.0 ** rng.choice([-300, -12, -6, -3, 3, 6, 12, 155, 300]))
            if isinstance(old, float)
            else old * rng.choice([0, -1, 10, 1000, 10**6, 10**9])
        )
    if r < 0.5 and isinstance(old, list) and old:
        i = rng.randrange(len(old))
        return old[:i] + [mutate_value(rng, old[i])] + old[i + 1 :]
    return rng.choice(LISTS if rng.random() < 0.4 else SCALARS)


def make_case(i: int):
    """``(name, flat config, sweep or None, extra argv, description, raw text or None)``."""
    rng = random.Random(SEED * 100_003 + i)
    name = NAMES[i % len(NAMES)]
    flat = base(name)
    schema = list(load_study(ROOT / "studies" / f"{name}.toml")[0].schema)
    extra: list[str] = []
    sweep = None
    raw = None
    kind = rng.choice(
        ["value"] * 5
        + ["two"] * 2
        + ["set", "structure", "sweep", "option", "relocate"]
        + ["type"] * int(os.environ.get("FUZZ_TYPE_WEIGHT", "2"))
        + ["key"] * int(os.environ.get("FUZZ_KEY_WEIGHT", "2"))
    )
    if kind in ("value", "two"):
        keys = rng.sample(schema, 2 if kind == "two" else 1)
        for k in keys:
            flat[k] = mutate_value(rng, flat.get(k, 1.0))
        desc = ", ".join(f"{k}={toml_value(flat[k])[:60]}" for k in keys)
    elif kind == "set":
        k = rng.choice(schema)
        text = rng.choice(
            [
                toml_value(mutate_value(rng, flat.get(k, 1.0))),
                "[1, 2",
                "{a = 1}",
                "nan",
                "",
                "'π'",
                "0x10",
                "1e999",
                "[[]]",
            ]
        )
        extra += ["--set", f"{k}={text}"]
        desc = f"--set {k}={text[:60]}"
    elif kind == "structure":
        what = rng.choice(
            [
                "unknown",
                "study",
                "nostudy",
                "garbage",
                "empty",
                "unicode_key",
                "table_for_value",
                "huge_list",
            ]
        )
        desc = what
        if what == "unknown":
            flat["bogus.key"] = 1
        elif what == "study":
            flat["study"] = rng.choice(["nope", 3, "", "brown_table1 ", "π"])
        elif what == "nostudy":
            flat.pop("study")
        elif what == "garbage":
            raw = bytes(rng.randrange(256) for _ in range(200))
        elif what == "empty":
            raw = b""
        elif what == "unicode_key":
            flat["plate.grïd"] = 5
        elif what == "table_for_value":
            flat[rng.choice(schema)] = {"a": 1}
        else:
            flat[rng.choice(schema)] = [1.0] * 100_000
    elif kind == "type":  # a value of the wrong TOML type, or a list with one such element
        k = rng.choice(schema)
        old, lit = flat.get(k), rng.choice(TYPED)
        if isinstance(old, list) and old and rng.random() < 0.5:
            i = rng.randrange(len(old))
            flat[k] = old[:i] + [lit] + old[i + 1 :]
        elif isinstance(old, (int, float)) and rng.random() < 0.3:
            flat[k] = Raw(json.dumps(str(old)))  # the right number as a string
        else:
            flat[k] = lit
        desc = f"{k}={toml_value(flat[k])[:60]}"
    elif kind == "relocate":
        raw, desc = relocate(rng, flat, schema)
    elif kind == "key":  # the last word of desc: the key the refusal must name
        text, desc, opts = respell(rng, flat, toml_value, toml_tables)
        raw, extra = text.encode(), extra + opts
    elif kind == "sweep":
        k = rng.choice(schema)
        rngv = rng.choice(
            [
                {"start": 1.0, "stop": NAN, "num": 2},
                {"start": "a", "stop": 2, "num": 2},
                {"start": 1.0, "stop": 2.0, "step": 1e-12},
                {"start": 1, "stop": 2, "num": 5_000_000},
                {"start": 1, "stop": 2, "num": 2},
                {"start": 0.5, "stop": 1.5, "step": 0.5},
                [flat.get(k, 1), mutate_value(rng, flat.get(k, 1))],
                [],
                {"start": 1},
            ]
        )
        sweep = {k: rngv}
        if rng.random() < 0.3:
            sweep["replicates"] = rng.choice([0, 2, 3_000_000, "x"])
        desc = f"[sweep] {k} = {toml_value(rngv)[:80]}"
    else:
        opt = rng.choice(
            [
                ["--trials", rng.choice(["0", "-1", "2.5", "abc", "1000000000", "1"])],
                ["--seed", rng.choice(["-1", str(2**70), "x", "0"])],
                ["--workers", rng.choice(["0", "-3", "1000000", "two"])],
                ["--scheduler", rng.choice(["foo", "tcp://", "tcp://h:99999", ""])],
                ["--max-memory-gb", rng.choice(["0", "nan", "-1", "1e-9"])],
                ["--out", rng.choice(["", "/", ".", "{file}", "π☃/ü", "x" * 300])],
            ]
        )
        extra += opt
        desc = " ".join(opt)[:80]
    return name, flat, sweep, extra, f"{name}: {kind}: {desc}", raw


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
        code = 99
        try:
            os.setsid()
            os.chdir(case_dir)
            import resource

            lim = 6 * 2**30
            resource.setrlimit(resource.RLIMIT_AS, (lim, lim))
            os.environ["SIM_MAX_MEMORY_GB"] = "2"
            # within TIMEOUT: a case asking for hours of work within the default limit
            # (agnard's region.trials = 150000, 2.7e8 adjustments) is a long run, not a hang;
            # under this limit it is refused in one line, as the fuzzer expects
            os.environ["SIM_MAX_ADJUSTMENTS"] = "1e7"
            fo, fe = os.open(so, os.O_WRONLY | os.O_CREAT), os.open(se, os.O_WRONLY | os.O_CREAT)
            os.dup2(fo, 1)
            os.dup2(fe, 2)
            sys.stdout = open(1, "w", closefd=False)
            sys.stderr = open(2, "w", closefd=False)
            code = main(argv)
        except SystemExit as e:
            code = e.code if isinstance(e.code, int) else 98
        except BaseException:  # noqa: BLE001 - a traceback: report it as a failure
            import traceback

            traceback.print_exc()
            code = 97
        finally:
            try:
                sys.stdout.flush()
                sys.stderr.flush()
            finally:
                os._exit(code if isinstance(code, int) else 96)
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


def test_fuzz_bases_run():
    """The tiny base of every study is valid (else the mutations test nothing) and takes
    the tiny sizes (else the fuzz cases run at full size)."""
    for name in NAMES:
        sizes = small(name)
        _, cfg = load_study(
            ROOT / "studies" / f"{name}.toml",
            [f"{k}={toml_value(v)}" for k, v in sizes.items()],
        )
        assert sizes and all(cfg[k] == v for k, v in sizes.items()), name
        if "chunk" in cfg:  # a run needs two chunks (and a jackknife 20: brown in SMALL)
            assert cfg["trials"] >= 2 * cfg["chunk"], name


def test_fuzz(tmp_path):
    failures = fuzz(CASES, tmp_path)
    assert not failures, f"{len(failures)} of {CASES} fuzz cases broke the contract:\n" + "\n".join(
        failures
    )


def test_fuzz_network_keys(tmp_path, capsys):
    """KEY spelling in a small network (tests/fuzz_keys.py): a table's name, a record's field
    or a constraint's point spelt as no key is; ``sim check`` must refuse each in one line
    naming the key as written (4 cases per fuzz case: each is a check, not a run)."""
    failures = []
    for i in range(4 * CASES):
        text, desc, needles = network_case(random.Random(SEED * 100_003 + 77_777 + i), toml_value)
        f = tmp_path / "study.toml"
        f.write_text(text)
        rc = main(["check", str(f)])
        err = capsys.readouterr().err.strip()
        if rc != 2 or "\n" in err or not any(n in err for n in needles):
            failures.append(f"case {i} ({desc}): exit {rc}: {err[-300:]}")
    assert not failures, f"{len(failures)} of {4 * CASES}:\n" + "\n".join(failures)


if __name__ == "__main__":  # pragma: no cover - the long run: make fuzz
    sys.exit(pytest.main([__file__, "-q", "-x", "-p", "no:cacheprovider"]))
