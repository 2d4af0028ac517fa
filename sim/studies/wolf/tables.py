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
import re
from pathlib import Path

import numpy as np

from sim.mc.config import ConfigError
from sim.mc.message_text import key_text
from sim.mc.paths import link_problem
from sim.mc.text_bytes import NotText, utf8_text

STATS = ("max", "rms", "mean")
T1_NUM = ("x_set1_mm", "x_set2_mm", "y_set1_mm", "y_set2_mm", "x_foster_mm", "y_foster_mm")
T3_NUM = ("x_dba_mm", "y_dba_mm", "x_pg2_mm", "y_pg2_mm", "dx_printed_mm", "dy_printed_mm")


#: a transcription is a few kB; more is not the table (it was read cut at 2,000,000 characters)
MAX_BYTES = 2_000_000
#: the line ends of a CSV file: str.splitlines also split at a form feed, a vertical tab,
#: NEL (U+0085) and U+2028, so such a character in a comment made the comment's rest the
#: header ("missing column(s)" of every column) and one in a row split the row
_LINE_END = re.compile(r"\r\n|\r|\n")


def _text(p: Path, key: str) -> str:
    """The file's UTF-8 text (a leading signature skipped, as Excel's "CSV UTF-8" writes)."""
    try:
        with open(p, "rb") as fh:
            data = fh.read(MAX_BYTES + 1)
    except OSError as e:
        raise ConfigError(key, f"cannot read {p}: {e.strerror}") from None
    if len(data) > MAX_BYTES:
        raise ConfigError(key, f"{p} has over {MAX_BYTES:,} bytes: not the CSV transcription")
    try:
        return utf8_text(data)
    except NotText as e:  # the byte and its line, UTF-16 named (sim.mc.text_bytes)
        raise ConfigError(key, f"{p}: {e}: expected the CSV transcription") from None


def _rows(p: Path, key: str, text: str) -> tuple[list[str], list[tuple[int, list[str]]]]:
    """The header and the data rows with their line numbers (comments and blank lines out)."""
    kept = [
        (n, ln)
        for n, ln in enumerate(_LINE_END.split(text), start=1)
        if ln.strip() and not ln.startswith("#")
    ]
    reader = csv.reader((ln for _, ln in kept), strict=True)
    try:
        table = list(reader)
    except csv.Error as e:  # a quoted cell never closed: the file cut short in a note
        n = kept[min(reader.line_num, len(kept)) - 1][0]
        cut = " (a quoted cell is not closed: is the file cut short?)" * ("end of data" in str(e))
        raise ConfigError(key, f"{p}: not a CSV table at line {n} ({e}){cut}") from None
    header = table[0] if table else []
    while header and not header[-1].strip():  # Excel pads every line to the widest with commas
        header = header[:-1]
    rows = [(kept[i][0], _unpadded(r, len(header))) for i, r in enumerate(table) if i]
    return header, rows


def _unpadded(cells: list[str], width: int) -> list[str]:
    """``cells`` without the empty cells after the header's ``width`` (Excel's trailing commas:
    a line padded to the file's widest, a comment's, as Excel writes a CSV it opened)."""
    while len(cells) > width and not cells[-1].strip():
        cells = cells[:-1]
    return cells


def _split_number(header: list[str], cells: list[str], numeric) -> str | None:
    """A decimal comma in the number before the note (``32,270``, the note ``270``: the same
    count of cells as the header when the note was left empty or out, or Excel's trailing
    comma was its place): named, not read as 32 mm and a note."""
    at = header.index("note")
    if 0 < at < len(cells) and header[at - 1] in numeric and "." not in cells[at - 1]:
        if re.fullmatch(r"\d+", cells[at].strip()):
            return (
                f"{header[at - 1]} {cells[at - 1].strip()!r} and the note {cells[at].strip()!r}: "
                "a decimal comma? numbers take a point: 33.221"
            )
    return None


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
    header, rows = _rows(p, key, _text(p, key))
    cols = (groups, "point", *numeric, "note")
    missing = [c for c in cols if c not in header]
    if missing:
        raise ConfigError(
            key,
            f"{p} is not the expected table: missing column(s) "
            f"{', '.join(missing)} (needs {', '.join(cols)})",
        )
    out: dict[str, list] = {c: [] for c in cols}
    for i, (line, cells) in enumerate(rows, start=1):
        if len(cells) > len(header):  # every value after a decimal comma moved
            raise ConfigError(
                key,
                f"{p}: data row {i} has {len(cells)} cells for the header's {len(header)} "
                f"(line {line}: {cells[len(header)].strip()[:20]!r} after its last column, "
                f"{header[-1]}: a decimal comma? numbers take a point: 33.221)",
            )
        r = dict(zip(header, cells))
        if gone := [c for c in cols[:-1] if c not in r]:  # the note may be left out
            raise ConfigError(  # it was "float() argument must be ... not 'NoneType'"
                key,
                f"{p}: data row {i} (line {line}) has {len(cells)} cells for the header's "
                f"{len(header)}: no {gone[0]} (is the file cut short?)",
            )
        if why := _split_number(header, cells, numeric):  # the last number's decimals a note
            raise ConfigError(key, f"{p}: data row {i} (line {line}): {why}")
        g = r[groups].strip()
        if g not in need:  # a row of another plate was left out of every claim without a word
            raise ConfigError(  # (a zero-width space in "003" too)
                key,
                f"{p}: data row {i} (line {line}): {groups} {key_text(g)} is not "
                f"{' or '.join(need)}, the {groups}s of the paper's table",
            )
        try:
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
        out[groups].append(g)
        out["note"].append(r.get("note") or "")
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
