"""The paper's printed tables, transcribed (``studies/data/``), parsed and recomputed.

Wolf & Pearsall 1976 (seed ``000_668e60e68f004f98.txt``). Table 1: PUG-mark coordinates (mm)
of P-30 plates 003 and 005 read with the PG-2 on two dates; Table 2: the same points read with
the H. Dell Foster monocomparator; Table 3: natural images on two Hasselblad photos (501, 505)
read with the DBA comparator and the PG-2, with the printed differences (mm).
A file that is not the table (binary, other columns, non-numbers) is a :class:`ConfigError`
naming the config key, raised when the study is loaded.
"""

from __future__ import annotations

import csv
import math
from pathlib import Path

import numpy as np

from sim.mc.config import ConfigError
from sim.mc.paths import link_problem

STATS = ("max", "rms", "mean")
T1_NUM = ("x_set1_mm", "x_set2_mm", "y_set1_mm", "y_set2_mm", "x_foster_mm", "y_foster_mm")
T3_NUM = ("x_dba_mm", "y_dba_mm", "x_pg2_mm", "y_pg2_mm", "dx_printed_mm", "dy_printed_mm")


def _read_csv(path, key: str, numeric, groups: str, need: tuple[str, ...]) -> dict:
    p = Path(path)
    if not str(p).isprintable():  # a line break would split the one-line message
        raise ConfigError(key, f"is not a file name: it holds a control character ({str(p)!r})")
    try:
        is_file = p.is_file()
    except OSError as e:  # a name too long: pathlib raises what it does not take for "absent"
        raise ConfigError(key, f"cannot read {str(p)[:80]}...: {e.strerror}") from None
    if not is_file:
        if why := link_problem(p):
            raise ConfigError(key, f"{p} {why}")
        if p.exists():  # a directory, a FIFO, a device: never opened (a FIFO would block)
            raise ConfigError(key, f"{p} is not a regular file: expected the CSV transcription")
        raise ConfigError(key, f"no such file: {p}")
    try:
        with open(p, newline="", encoding="utf-8-sig") as fh:  # Excel's "CSV UTF-8" signature
            text = fh.read(2_000_000)
    except UnicodeDecodeError:
        raise ConfigError(
            key, f"{p} is not a text file (not UTF-8): expected the CSV transcription"
        ) from None
    except OSError as e:
        raise ConfigError(key, f"cannot read {p}: {e.strerror}") from None
    if "\x00" in text:
        raise ConfigError(key, f"{p} is a binary file, not the CSV transcription")
    lines = [ln for ln in text.splitlines() if ln.strip() and not ln.startswith("#")]
    try:
        rows = list(csv.DictReader(lines))
    except csv.Error as e:
        raise ConfigError(key, f"{p}: not a CSV table ({e})") from None
    cols = (groups, "point", *numeric, "note")
    header = set(rows[0]) if rows else set()
    missing = [c for c in cols if c not in header]
    if missing:
        raise ConfigError(
            key,
            f"{p} is not the expected table: missing column(s) "
            f"{', '.join(missing)} (needs {', '.join(cols)})",
        )
    out: dict[str, list] = {c: [] for c in cols}
    for i, r in enumerate(rows, start=1):
        if None in r:  # more cells than the header: every value after a decimal comma moved
            raise ConfigError(
                key,
                f"{p}: data row {i} has {len(r) - 1 + len(r[None])} cells for the header's "
                f"{len(r) - 1} (a decimal comma? numbers take a point: 33.221)",
            )
        try:
            out[groups].append(str(r[groups]).strip())
            out["point"].append(int(r["point"]))
            for c in numeric:
                v = float(r[c])
                if not math.isfinite(v) or abs(v) > 1000.0:
                    raise ValueError(c)
                out[c].append(v)
        except (TypeError, ValueError) as e:
            raise ConfigError(
                key, f"{p}: data row {i} has a bad value ({e}): numbers in mm expected"
            ) from None
        out["note"].append(r["note"] or "")
    res = {k: np.array(v) for k, v in out.items()}
    for g in need:
        if np.sum(res[groups] == g) < 3:
            raise ConfigError(key, f"{p}: {groups} {g} needs at least 3 points")
    return res


def load_table1(path, key: str = "table1.file") -> dict[str, np.ndarray]:
    """Tables 1 and 2 (CSV, ``#`` comments): ``plate, point, x_set1_mm, ..., note``."""
    return _read_csv(path, key, T1_NUM, "plate", ("003", "005"))


def load_table3(path, key: str = "table3.file") -> dict[str, np.ndarray]:
    """Table 3 (CSV, ``#`` comments): ``photo, point, x_dba_mm, ..., dy_printed_mm, note``."""
    return _read_csv(path, key, T3_NUM, "photo", ("501", "505"))


def _um(a):
    return np.round(np.asarray(a) * 1000.0).astype(int)


def table1_discrepancies(t: dict) -> dict[str, np.ndarray]:
    """Per point: Set 1 - Set 2 and Set - Foster in um (whole um: the coordinates are printed
    to 1 um)."""
    return {
        "plate": t["plate"],
        "point": t["point"],
        "dx_sets_um": _um(t["x_set1_mm"] - t["x_set2_mm"]),
        "dy_sets_um": _um(t["y_set1_mm"] - t["y_set2_mm"]),
        "dx_set1_foster_um": _um(t["x_set1_mm"] - t["x_foster_mm"]),
        "dx_set2_foster_um": _um(t["x_set2_mm"] - t["x_foster_mm"]),
        "dy_set1_foster_um": _um(t["y_set1_mm"] - t["y_foster_mm"]),
        "dy_set2_foster_um": _um(t["y_set2_mm"] - t["y_foster_mm"]),
        "x_set1_mm": t["x_set1_mm"],
        "y_set1_mm": t["y_set1_mm"],
        "note": t["note"],
    }


def table3_discrepancies(t: dict) -> dict[str, np.ndarray]:
    """Per point: the printed differences and PG-2 - DBA from the coordinates, in um."""
    return {
        "photo": t["photo"],
        "point": t["point"],
        "dx_printed_um": _um(np.abs(t["dx_printed_mm"])),
        "dy_printed_um": _um(np.abs(t["dy_printed_mm"])),
        "dx_coord_um": _um(t["x_pg2_mm"] - t["x_dba_mm"]),
        "dy_coord_um": _um(t["y_pg2_mm"] - t["y_dba_mm"]),
        "x_dba_mm": t["x_dba_mm"],
        "y_dba_mm": t["y_dba_mm"],
        "note": t["note"],
    }


def summary(v) -> dict[str, float]:
    """The paper's summary line of discrepancies ``v`` (um): max, rms and mean of ``|v|``."""
    a = np.abs(np.asarray(v, float))
    return {"max": float(a.max()), "rms": float(np.sqrt(np.mean(a**2))), "mean": float(a.mean())}


def recomputation(v, stat: str) -> str:
    """The arithmetic behind a recomputed summary number, for a claim's note."""
    a = np.abs(np.asarray(v, int))
    lst = ", ".join(str(x) for x in a)
    if stat == "max":
        return f"|d| = {lst} um: max {a.max()}"
    if stat == "mean":
        return f"|d| = {lst} um: sum {a.sum()} / {a.size} = {a.sum() / a.size:.2f}"
    s2 = int(np.sum(a**2))
    return f"|d| = {lst} um: sum of squares {s2} / {a.size}, rms {math.sqrt(s2 / a.size):.2f}"
