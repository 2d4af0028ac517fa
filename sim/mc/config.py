"""Study configuration: TOML files validated against a typed schema.

A study file is TOML with a top-level ``study = "<name>"`` that selects the schema
(see :mod:`sim.studies`). Every key of the schema has a type, a default, a range and
a one-line description; unknown keys, wrong types, NaN/inf and out-of-range values
raise :class:`ConfigError`, whose message names the dotted key. Command-line
overrides (``--set plate.grid=6``) are parsed as TOML values and validated the same
way. The resolved configuration is a flat ``{dotted.key: value}`` dict, stored in the
provenance of every result file.

Keys marked ``input=True`` are simulation inputs set to match a paper (for example an
error amplitude); the report lists them so nobody mistakes them for predictions.
"""

from __future__ import annotations

import math
import re
import tomllib
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Callable, Mapping

from sim.mc.lookalike import note, toml_char_hint
from sim.mc.message_text import cut_text, key_text, shorten, shown, unit_hint
from sim.mc.not_toml import kind_hint
from sim.mc.numtext import UnheldError, number_text, toml_float, unsigned_zeros
from sim.mc.pickled_error import remade
from sim.mc.study_file import study_file_problem
from sim.mc.text_bytes import NotText, utf8_text
from sim.mc.toml_dates import as_written
from sim.mc.toml_slips import quote_hint, slip_hint
from sim.mc.toml_twice import twice_text
from sim.mc.unknown_key import did_you_mean, unknown_key_hint

__all__ = [
    "ConfigError",
    "config_changes",
    "StudyError",
    "Field",
    "parse_override",
    "validate",
    "check_chunks",
    "did_you_mean",
    "shown",
]


class ConfigError(ValueError):
    """A bad study configuration. ``str(err)`` is one line naming the key; a character that looks
    like an ASCII one but is not (a Cyrillic letter, a full-width digit) is named too."""

    def __init__(self, key: str | None, message: str):
        self.key = key  # a number of hundreds of digits is shortened in any message
        head = f"{key_text(key)}: " if key is not None else ""  # the key as the user wrote it
        super().__init__(head + shorten(message + note(head + message)))  # (points[1e+23])

    @property
    def detail(self) -> str:
        """The message without the key it names (to be said again of another key or door)."""
        return str(self).removeprefix(f"{key_text(self.key)}: " if self.key is not None else "")

    def __reduce__(self):  # its args are the whole line, not (key, message): sim.mc.pickled_error
        return (remade, (type(self), self.args, self.__dict__))


class StudyError(RuntimeError):
    """The input passed validation but the study cannot produce results from it (e.g. a
    singular reduced normal matrix in every trial). One line, like :class:`ConfigError`."""


#: the first classes, kept by ``importlib.reload(sim.mc.config)``: the suite's modules hold
#: them, and a caller's ``except sim.ConfigError`` (the new class) let their errors through
ConfigError, StudyError = globals().get("_ERRORS", (ConfigError, StudyError))
_ERRORS = (ConfigError, StudyError)


@dataclass(frozen=True)
class Field:
    """One configuration key.

    kind : "int", "float", "str", "bool", "list[float]", "list[int]",
        "list[str]", "points" (a list of [x, y] pairs in mm) or "records" (a list of tables,
        e.g. a network's observations; their fields are checked by the study's ``check``).
    lo, hi : inclusive bounds for numbers (and for every element of a list).
    lo_open : if True, ``lo`` itself is excluded (``> lo``).
    choices : allowed values for strings (and elements of string lists).
    min_len : minimum length of lists.
    input : the value was set to match a paper (reported as *input*).
    printed : the default is a value the paper prints for its own setup (its design: the
        plate, the grid, counts, printed error levels); a run with another value is off the
        paper's setup and its predictions are findings (:func:`sim.claims.rules.off_paper`;
        written with :func:`sim.mc.schema_helpers.printed`).
    sweep : the key may be swept (``[sweep]``); None, or the reason it may not.
    read_when : None (always read), or when the study reads the key (a
        :class:`sim.mc.read_when.When`): a key set where it is not read is refused.
    compared : the list is a set of settings compared (a row and a point of a trade-off
        each): a value given twice is refused, and numbers are read in increasing order.
    """

    default: Any
    kind: str
    doc: str
    lo: float | None = None
    hi: float | None = None
    lo_open: bool = False
    choices: tuple | None = None
    min_len: int = 0
    input: bool = False
    unit: str = ""
    sweep: str | None = None
    read_when: Any = None
    printed: bool = False
    compared: bool = False


#: TOML's integers are 64-bit ("an integer that cannot be represented losslessly is an
#: error"); Python's tomllib and the API take any size, which overflowed float() and NumPy
INT64 = 2**63
#: below it every integer is a double: a float for an integer key from it on may be another
#: integer than the one written (9007199254740993.0 reads 9007199254740992.0, 2**53)
EXACT_INT = 2**53


def refuse_big_ints(key: str, v: Any) -> None:
    """Refuse (naming ``key``) an integer outside TOML's 64-bit range anywhere in ``v`` (a
    value, or nested lists and tables), walked without recursion."""
    todo = [(key, v)]
    while todo:
        k, x = todo.pop()
        if isinstance(x, int) and not isinstance(x, bool) and not -INT64 <= x < INT64:
            digits = len(str(abs(x))) if abs(x) < 10**4000 else "over 4000"  # str(): < 4300
            raise ConfigError(k, f"an integer of {digits} digits is outside TOML's 64-bit range")
        if isinstance(x, Mapping):
            todo += [(f"{k}.{n}" if k else str(n), y) for n, y in x.items()]
        elif isinstance(x, (list, tuple)):
            todo += [(k, y) for y in x]


def _num(key: str, v: Any, want_int: bool) -> float | int:
    if isinstance(v, bool) or not isinstance(v, (int, float)):
        what = "an integer" if want_int else "a number"
        n = number_text(v) if isinstance(v, str) else ""  # --set x=.5: TOML read a string
        if n and (not want_int or float(n).is_integer()):  # (no "write 0.5" for an integer)
            raise ConfigError(key, f"must be {what} (got the text {v[:60]!r}: write {n})")
        said = cut_text(shown(v), len(v) if isinstance(v, str) else None)  # (its length)
        hint = unit_hint(key, v) if isinstance(v, str) else ""  # "45mm": the key's _mm
        raise ConfigError(key, f"must be {what} (got {said}{hint})")
    refuse_big_ints(key, v)
    if not math.isfinite(v):
        raise ConfigError(key, f"must be finite (got {v!r})")
    if want_int and not isinstance(v, int):
        if float(v).is_integer():
            v = int(v)
        else:
            raise ConfigError(key, f"must be an integer (got {v!r})")
    return v if want_int else float(v)


def _exact(key: str, given: Any) -> None:
    """Refuse a float ``given`` for an integer key from 2**53 on, within the key's bounds
    (beyond them, the bounds are the words): ``seed = 9007199254740993.0`` was the seed
    9007199254740992, silently."""
    if isinstance(given, float) and abs(given) >= EXACT_INT:
        raise ConfigError(
            key,
            f"must be an integer (got {given!r}, a float: from 2**53 = {EXACT_INT} on, a float "
            "is not exact to the unit; write the integer without a point or an exponent)",
        )


def _bounds(key: str, f: Field, v: float) -> None:
    if f.lo is not None:
        if f.lo_open and not v > f.lo:
            raise ConfigError(key, f"must be > {f.lo:g} (got {shown(v)})")
        if not f.lo_open and not v >= f.lo:
            raise ConfigError(key, f"must be >= {f.lo:g} (got {shown(v)})")
    if f.hi is not None and not v <= f.hi:
        raise ConfigError(key, f"must be <= {f.hi:g} (got {shown(v)})")


def check_value(key: str, f: Field, v: Any) -> Any:
    """Validate and normalise one value against its field; return the clean value."""
    k = f.kind
    if k in ("int", "float"):
        given, v = v, _num(key, v, k == "int")
        _bounds(key, f, v)
        refuse_big_ints(key, v)  # 1e300 for an unbounded integer key: 10**300, not TOML's
        if k == "int":
            _exact(key, given)
        return v
    if k == "bool":
        if not isinstance(v, bool):
            raise ConfigError(key, f"must be true or false (got {v!r})")
        return v
    if k == "str":
        if not isinstance(v, str):
            raise ConfigError(key, f"must be a string (got {v!r})")
        if f.choices and v not in f.choices:
            raise ConfigError(key, f"must be one of {', '.join(map(str, f.choices))} (got {v!r})")
        return v
    if k == "records":
        if not isinstance(v, list) or not all(isinstance(e, dict) for e in v):
            raise ConfigError(key, f"must be a list of tables {{key = value, ...}} (got {v!r:.60})")
        if len(v) < f.min_len:
            raise ConfigError(key, f"needs at least {f.min_len} entries (got {len(v)})")
        return v
    if k.startswith("list[") or k == "points":
        if not isinstance(v, list):
            raise ConfigError(key, f"must be a list (got {v!r})")
        if len(v) < f.min_len:
            raise ConfigError(key, f"needs at least {f.min_len} entries (got {len(v)})")
        if k == "points":
            out = []
            for i, p in enumerate(v):
                if not (isinstance(p, list) and len(p) == 2):
                    raise ConfigError(key, f"entry {i} must be a pair [x, y] (got {p!r})")
                out.append([_num(f"{key}[{i}]", c, False) for c in p])
            return out
        inner = k[5:-1]
        sub = Field(None, inner, f.doc, f.lo, f.hi, f.lo_open, f.choices)
        vals = [check_value(f"{key}[{i}]", sub, e) for i, e in enumerate(v)]
        if f.compared:  # [3, 3, 5] gave two rows of one setting, [7, 3, 5] a zigzag line
            if twice := [x for i, x in enumerate(vals) if x in vals[:i]]:
                raise ConfigError(key, f"{shown(twice[0])} is given twice: give each setting once")
            return vals if inner == "str" else sorted(vals)
        return vals
    raise AssertionError(f"unknown field kind {k}")  # programming error


class _EmptyTable(dict):
    """An empty TOML table of a study file, kept by :func:`flatten`: an empty section is
    dropped by :func:`validate`, a value written as ``{}`` is refused there."""


def flatten(d: Mapping, prefix: str = "") -> dict[str, Any]:
    out: dict[str, Any] = {}
    for k, v in d.items():
        key = f"{prefix}{k}"
        if key in out:  # "a.b" = 1 and [a] b = 2: the same key twice, the later would win
            raise ConfigError(key, "is given twice (as a quoted dotted key and in a table)")
        if isinstance(v, dict) and v:
            inner = flatten(v, key + ".")
            twice = [k2 for k2 in inner if k2 in out]
            if twice:
                raise ConfigError(
                    twice[0], "is given twice (as a quoted dotted key and in a table)"
                )
            out.update(inner)
        elif isinstance(v, dict):  # an empty table: a section, or a value given as {} (validate)
            out[key] = _EmptyTable()
        else:
            out[key] = v
    return out


#: the white space TOML reads around a key and a value (a no-break space is none: a character)
TOML_SPACE = " \t"


class Resolved(dict):
    """The dict :func:`validate` gives ``check``: ``given`` holds the keys the file, an option
    or a sweep cell set, as against those left at their defaults (a study whose default
    resolves by the input, as the network's ``datum.kind`` by an imported file, refuses an
    explicit value that cannot hold instead of replacing it). A copy is a plain dict."""

    given: frozenset = frozenset()


def given(cfg: Mapping[str, Any], key: str) -> bool:
    """Whether ``key`` was set (not its default) in ``cfg`` as :func:`validate` resolved it;
    False for a plain dict (a configuration resolved before, whose check has run)."""
    return key in getattr(cfg, "given", ())


def validate(
    raw: Mapping[str, Any],
    schema: Mapping[str, Field],
    check: Callable[[dict], None] | None = None,
    set_keys: frozenset | None = None,
) -> dict[str, Any]:
    """Resolve a flat ``{dotted: value}`` mapping against ``schema``.

    Unknown keys are errors; missing keys take their defaults. ``check`` receives the
    resolved dict (a :class:`Resolved` whose ``given`` is ``set_keys``, by default the keys of
    ``raw``) for cross-key rules and raises :class:`ConfigError` itself.
    """
    raw = {
        k: v
        for k, v in raw.items()
        if not (
            isinstance(v, _EmptyTable)
            and k not in schema
            and any(s.startswith(k + ".") for s in schema)
        )
    }  # an empty section of the file ([compare] with nothing in it) says nothing
    for key in raw:
        refuse_big_ints(key, raw[key])  # an API value, or a --set one
    for key in raw:  # -0.0 is 0.0
        try:
            raw[key] = unsigned_zeros(raw[key])
        except RecursionError:
            raise ConfigError(key, "is nested too deeply") from None
        except UnheldError as e:  # 1e-400: not 0, silently
            raise ConfigError(key, str(e)) from None
    for key in raw:
        if key not in schema:  # what was meant (sim.mc.unknown_key: the batch's words too)
            raise ConfigError(key, f"unknown key{unknown_key_hint(key, schema)}")
    cfg = Resolved()
    cfg.given = frozenset(raw if set_keys is None else set_keys)
    for key, f in schema.items():
        v = raw.get(key, f.default)
        if v is None:
            raise ConfigError(key, "is required")
        cfg[key] = check_value(key, f, v)
    if check is not None:
        check(cfg)
    return cfg


def parse_override(text: str) -> tuple[str, Any]:
    """Parse ``key=value`` where value is a TOML value (bare words are strings)."""
    if "=" not in text:
        raise ConfigError(None, f"--set needs key=value (got {text!r})")
    key, val = text.split("=", 1)
    key, val = key.strip(TOML_SPACE), val.strip(TOML_SPACE)  # as TOML reads white space: a
    # no-break space is part of the key ("trials\u00a0" was read as trials) or the value
    if not key:
        raise ConfigError(None, f"--set needs key=value (got {text!r})")
    if any(c in val for c in "\n\r\0"):  # one value: a line break would smuggle in more keys
        raise ConfigError(key, f"--set value must be one line (got {val!r})")
    if any("\udc80" <= c <= "\udcff" for c in text):  # bytes the locale could not decode
        raise ConfigError(  # (LC_ALL=C without UTF-8 mode: "é" was "must be printable")
            key or None, "--set holds bytes that are not UTF-8 text (a non-UTF-8 locale or value)"
        )
    try:
        doc = tomllib.loads(f"v = {val}", parse_float=toml_float)
    except tomllib.TOMLDecodeError:
        return key, val
    except RecursionError:
        raise ConfigError(key, "--set value is nested too deeply") from None
    except ValueError:  # Python's int-from-text limit ("Exceeds the limit", naming no key)
        raise ConfigError(key, "--set value holds an integer of over 4300 digits") from None
    if list(doc) != ["v"]:
        raise ConfigError(key, f"--set value must be one TOML value (got {val!r})")
    return key, as_written(doc["v"])  # a date quoted as TOML wrote it


def read_toml(path: str | Path) -> dict[str, Any]:
    """Read a TOML study file; a missing, oversized or malformed file is a ConfigError."""
    p = Path(path)
    if why := study_file_problem(p):  # the one check (the batch's too, before any run)
        raise ConfigError(None, why)
    try:
        # a UTF-8 signature skipped (refused as malformed at 1:1), UTF-16 and Latin-1 named
        doc = tomllib.loads(text := utf8_text(p.read_bytes()), parse_float=toml_float)
        refuse_big_ints("", doc)
        return as_written(doc)  # a date or time quoted in a message as TOML wrote it
    except ConfigError:  # a ValueError: not to be read as "malformed TOML: <path>: ..." again
        raise
    except tomllib.TOMLDecodeError as e:
        at = re.search(r"at line (\d+), column (\d+)", str(e))  # before 3.14: in the text only
        n, col = (int(at.group(1)), int(at.group(2))) if at else (0, 0)
        line = "".join(text.split("\n")[n - 1 : n] if n else [])  # as tomllib
        hint = quote_hint(line) or kind_hint(text) or toml_char_hint(line, col)
        hint = hint or slip_hint(text, str(e), n, col)  # what was meant (sim.mc.toml_slips)
        twice = twice_text(text, str(e))  # the key given twice, named (tomllib names none)
        raise ConfigError(None, f"{p}: malformed TOML: {twice or e}{hint}") from None
    except RecursionError:
        raise ConfigError(None, f"{p}: malformed TOML: nested too deeply") from None
    except NotText as e:  # where, and the likely encoding (it was "not UTF-8 text" alone)
        raise ConfigError(None, f"{p}: {e}") from None
    except ValueError as e:  # an integer of over 4300 digits (Python's int-from-text limit)
        raise ConfigError(None, f"{p}: malformed TOML: {str(e).split(';')[0]}") from None
    except OSError as e:  # another user's file (mode 0600): the API raised PermissionError
        raise ConfigError(None, f"{p}: cannot read the study file ({e.strerror or e})") from None


def config_changes(old: Mapping[str, Any], new: Mapping[str, Any], shown: int = 3) -> str:
    """The keys whose values differ between a recorded config ``old`` and this run's ``new``
    (sorted), the first ``shown`` as ``key = OLD (this run NEW)`` and `` ...`` after them. A
    key one side lacks says so: a key an older version read and retired since was
    ``key = 40 (this run None)``, as if this run had set it to None."""
    keys = sorted(k for k in {*old, *new} if k not in old or k not in new or old[k] != new[k])

    def cut(v) -> str:  # at most 40 characters, its closing quote kept ('d6ede3...' was
        r = repr(v)  # 'd6ede3 (this run ..., a sha256 cut at 40)
        end = r[-1] if len(r) > 40 and r[-1] in "'\"]})" else ""
        return r if len(r) <= 40 else r[: 37 - len(end)] + "..." + end

    def one(k: str) -> str:  # a key with a character that does not print named with its
        n = key_text(k)  # escape (a zero-width space in run.json's key was shown raw: unseen)
        if k not in new:
            return f"{n} = {cut(old[k])} (no such key in this run's config)"
        if k not in old:
            return f"{n}: not in that config (this run {cut(new[k])})"
        return f"{n} = {cut(old[k])} (this run {cut(new[k])})"

    return ", ".join(map(one, keys[:shown])) + (" ..." if len(keys) > shown else "")


#: most chunks of one run (each is a file of the trials dataset, read back by every resume)
MAX_CHUNKS = 100_000


def check_chunks(cfg: Mapping[str, Any]) -> None:
    """A run needs at least 2 chunks: the Monte-Carlo intervals are delete-one-chunk jackknife
    intervals, undefined for one chunk. Checked by ``sim run`` (and its sweep cells and the
    Python API) for every study that has ``trials`` and ``chunk``."""
    if "trials" in cfg and "chunk" in cfg and cfg["chunk"] >= cfg["trials"]:
        raise ConfigError(
            "chunk",
            f"{cfg['chunk']} >= trials ({cfg['trials']}) gives one chunk; the jackknife "
            "intervals need at least 2 chunks (make chunk smaller than trials)",
        )
    if "trials" in cfg and "chunk" in cfg and -(-cfg["trials"] // cfg["chunk"]) > MAX_CHUNKS:
        raise ConfigError(
            "chunk",
            f"{cfg['trials']:,} trials in chunks of {cfg['chunk']:,} make "
            f"{-(-cfg['trials'] // cfg['chunk']):,} chunk files (at most {MAX_CHUNKS:,}): "
            f"make chunk at least {-(-cfg['trials'] // MAX_CHUNKS):,}",  # "larger": 2 was refused
        )


COMMON = {
    "trials": Field(1000, "int", "Monte-Carlo trials", lo=2, hi=100_000_000),
    "seed": Field(20261122, "int", "root seed of numpy.random.SeedSequence", lo=0, hi=2**63 - 1),
    "chunk": Field(
        1000, "int", "trials per chunk (each chunk has its own spawned stream)", lo=1, hi=1_000_000
    ),
}
