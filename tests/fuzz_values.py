"""The study files the fuzzer (tests/test_fuzz.py) starts from and the values it puts in:
each study shrunk to a run of a few seconds (``SMALL``), the scalars and lists a VALUE mutation
draws (``SCALARS``, ``LISTS``), the TOML literals of a TYPE mutation (``TYPED``), and the
writing of a flat config as TOML (dotted keys, or in table form as an editor writes it)."""

from __future__ import annotations

import json
import math
import random
import tomllib
from pathlib import Path

from sim.mc.config import flatten
from sim.studies import load_study

ROOT = Path(__file__).resolve().parent.parent

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
        "region.trials": 2,  # the regions' blocks: 2,400 and 1,536 of them, 50 s of CPU a run
        "region.points": 2,
        "table1.points": 2,
        "table1.trials": 2,
    },
    # two network study files (the network kind: points, grids, generated and single
    # observations, a datum by constraints, a second parameterisation)
    "network_brown": {"trials": 40, "chunk": 2},
    "network_testfield": {"trials": 40, "chunk": 2},
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
        return "{" + ", ".join(f"{toml_key(k)} = {toml_value(x)}" for k, x in v.items()) + "}"
    raise TypeError(type(v))


def toml_key(k: str) -> str:
    """``k`` as one TOML key: bare when it can be, else quoted (a network's ``"S1.x"``)."""
    return k if k and all(c.isascii() and (c.isalnum() or c in "_-") for c in k) else json.dumps(k)


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
