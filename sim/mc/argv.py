"""The argparse base of every command line (``sim``, ``python -m sim.batch``, ``make verify``,
``python -m benchmarks``): a bound on the options one command line may hold, options never
abbreviated, an option that decides a result given once, and a guess at a mistyped option
or command.

argparse's time grows with the square of the options given (it looks for the next option
among all of them, once per option): 50,000 ``--set`` ran for over three minutes before
"unknown key", and 50,000 ``--study`` kept ``make verify`` busy as long. A study has a few
hundred keys at most, and a study file holds any number of them.

argparse takes any unambiguous prefix of an option (``--tri 40`` for ``--trials``, ``--stale``
for ``--stale-only``, ``sim --vers``) without a word: such a command line, in a script or a
Makefile, breaks the day an option of the same prefix is added (``--o`` already matches both
``--out`` and ``--overwrite``). Options are read by their whole name;
a prefix is refused naming the option it abbreviates.
"""

from __future__ import annotations

import argparse
import difflib
import errno
import os
import re
import sys

from sim.ends import stdout_unwritten
from sim.mc.config import COMMON, ConfigError, Field, parse_override, validate
from sim.mc.lookalike import char_name, looks

__all__ = ["MAX_OPTIONS", "ONCE", "BoundedParser", "OnceParser", "integer", "most_workers"]

#: options (arguments starting with "-") one command line may hold
MAX_OPTIONS = 2000

#: the options that decide what is computed, read or written: given twice, one value would be
#: dropped. The others (``--workers``, ``--executor``, ``--jobs``, the limits) change no
#: number; a later one wins, as in argparse, so a default put first can be overridden
#: (tests/conftest.py's ``--workers 1 ... --workers 2``, the Makefile's ``VERIFY_FLAGS``)
ONCE = frozenset(
    {"--out", "--trials", "--chunk", "--seed", "--results", "--timings", "--scratch", "--studies"}
)


def most_workers() -> int:
    """The most worker processes a run takes (``--workers``, ``workers=``): four per core,
    at least 8."""
    return max(4 * (os.cpu_count() or 1), 8)


def integer(key: str, lo: int | None = None, hi: int | None = None):
    """argparse's ``type`` of an option that sets the integer key ``key`` (``--trials``,
    ``--chunk``, ``--seed``; ``make verify``'s ``--trials``): the value read as ``--set
    KEY=VALUE`` reads it (TOML), so a float without a fraction is that integer (``1e3``,
    ``1000.0``: 1000), and anything else is refused in ``--set``'s words (``must be an
    integer (got 1000.5)``). ``--trials 1e3`` was refused ("invalid int value") while ``--set
    trials=1e3`` and ``sim.load(..., trials=1e3)`` ran 1000 trials; above the key's bound it
    is refused as ``--set`` refuses it (``--trials 1e30`` said "an integer of 31 digits is
    outside TOML's 64-bit range", ``--set trials=1e30`` "must be <= 1e+08"). The key's lower
    bound is left to the command (``make verify --trials`` asks for more).

    An integer option that is no config key (``--workers``, ``--jobs``) is read the same way
    within ``lo`` and ``hi`` and refused in the same words (``must be <= 16 (got 17)``):
    ``--workers 1e1`` was "invalid int value" while ``--trials 1e1`` ran 10 trials."""
    if key in COMMON:
        lo, hi = None, COMMON[key].hi
    field = Field(0, "int", "", lo=lo, hi=hi)

    def read(text: str) -> int:
        try:
            return validate({"v": parse_override(f"v={text}")[1]}, {"v": field})["v"]
        except ConfigError as e:
            raise argparse.ArgumentTypeError(str(e).removeprefix("v: ")) from None

    read.__name__ = key  # argparse's "invalid trials value" should it ever say one
    return read


#: dashes a word processor or a web page puts where ``--`` or ``-`` was typed (``—trials``)
_DASHES = {"\u2014": "--", "\u2013": "--", "\u2015": "--", "\u2212": "-", "\u2010": "-"}
_DASHES |= {"\u2011": "-", "\u2012": "-", "\ufe63": "-", "\uff0d": "-"}


def _guess(word: str, names) -> str:
    """`` (did you mean NAME?)`` for a mistyped ``word`` among ``names``: the name it is with
    its dashes typed as hyphens (``—trials``, an em dash, was "unrecognized" without a guess)
    or that looks the same (``--TRIALS=40``, no guess either) first, then the names it is a
    prefix of (an abbreviation), else the closest one; "" when none is close."""
    names = sorted(set(names))
    lead = len(word) - len(word.lstrip("-" + "".join(_DASHES)))
    typed = "".join(_DASHES.get(c, c) for c in word[:lead]) + word[lead:]
    # a dash beside a hyphen (``—-trials``: "---trials") is one or two hyphens too
    tries = {looks(typed)} | ({looks(h + word[lead:]) for h in ("-", "--")} if lead > 1 else set())
    same = [n for n in names if looks(n) in tries and n != word]
    if same and typed != word:
        dash = next(c for c in word if c in _DASHES)
        return f" (did you mean {same[0]}? {char_name(dash)} is no hyphen: type -)"
    if same:
        return f" (did you mean {same[0]}?)"
    longer = [n for n in names if n.startswith(word) and n != word]
    if longer:
        said = " or ".join(longer[:3])
        return f" (did you mean {said}? options are not abbreviated)"
    close = difflib.get_close_matches(word, names, n=1, cutoff=0.6)
    return f" (did you mean {close[0]}?)" if close else ""


class BoundedParser(argparse.ArgumentParser):
    """argparse that reads at most :data:`MAX_OPTIONS` options, takes no abbreviation of an
    option, and adds a guess to a mistyped option or choice; its one-line refusal is
    :meth:`refuse` (argparse's own ``error`` by default)."""

    def __init__(self, *args, **kwargs):
        kwargs.setdefault("allow_abbrev", False)  # the commands' parsers too (add_parser)
        super().__init__(*args, **kwargs)

    def parse_known_args(self, args=None, namespace=None):
        given = sys.argv[1:] if args is None else args
        self.given = [str(a) for a in given]
        n = sum(1 for a in self.given if a.startswith("-"))
        if n > MAX_OPTIONS:
            self.error(
                f"{n:,} options: at most {MAX_OPTIONS:,} (write the keys into a study file, "
                "or pass them to the Python API)"
            )
        out = super().parse_known_args(args, namespace)
        self._dashed(out[1])
        return out

    def _dashed(self, extras: list) -> None:
        """Refuse a word typed with a word processor's dash that spells an option of this
        parser and that argparse took for a value (``sim run —trials 40 x.toml``: the study
        file; ``python -m sim.batch —jobs 2 x.toml``: two study files). It said
        "unrecognized arguments: 40 x.toml", or "—jobs: no such study file" and "2: no such
        study file", the dash unnamed: lead33 named it only in a word left ``extras``
        (unrecognized), where :meth:`explain` still does."""
        acts = self._acts()
        for before, word in zip(["", *self.given], self.given):
            if word == "--":  # the rest are values (sim.batch's run options: checked there)
                return
            takes = before in acts and acts[before].nargs != 0  # --set —x=1: its key's problem
            if word[:1] not in _DASHES or word in extras or takes:
                continue
            if "is no hyphen" in (guess := _guess(word.split("=")[0], self.options())):
                self.error(f"{word}: not an option{guess}")

    def options(self) -> set[str]:
        """Every option string of this parser and of the command named in the arguments
        being read (``sim run ... --tri``: the options of ``run``)."""
        return set(self._acts())

    def _acts(self) -> dict:
        """The actions of :meth:`options`, by option string."""
        known = dict(self._option_string_actions)
        for a in self._actions:
            if isinstance(a, argparse._SubParsersAction):
                cmd = next((w for w in getattr(self, "given", []) if w in a.choices), None)
                if cmd is not None:
                    known.update(a.choices[cmd]._option_string_actions)
        return known

    def explain(self, message: str) -> str:
        """argparse's ``message`` with a guess at what was meant: an abbreviated or mistyped
        option (``--tri``: ``--trials``), a mistyped command or choice (``sim rn``: ``run``)."""
        m = re.match(r"unrecognized arguments: (.*)", message)
        if m:
            dash = ("-", *_DASHES)  # —trials too
            bad = next((w for w in m.group(1).split(" ") if w.startswith(dash) and w != "-"), None)
            if bad is not None:
                return message + _guess(bad.split("=")[0], self.options())
        m = re.search(r"invalid choice: '(.*?)' \(choose from (.*)\)$", message)
        if m:
            # quoted ('run', 'check') up to Python 3.12.7, bare (run, check) since
            choices = [c.strip().strip("'") for c in m.group(2).split(",")]
            close = difflib.get_close_matches(m.group(1), choices, 1)
            word = m.group(1)
            if "run" in choices and (word.lower().endswith(".toml") or os.path.isfile(word)):
                # `sim studies/x.toml`, the command left out: a file is no command (D45)
                return f"{message} (a study file: did you mean {self.prog} run {word}?)"
            if close:
                return f"{message} (did you mean {close[0]}?)"
        return message

    def error(self, message: str):
        self.refuse(self.explain(message))

    def refuse(self, message: str):
        """One line naming the problem (a subclass raises its own error)."""
        super().error(message)

    def _print_message(self, message, file=None):
        """argparse's, which dropped a failed write (``--help > /dev/full`` with unbuffered
        output: exit 0 and no word); one to standard output is kept for the program's end
        (:func:`sim.ends.flush_stdout`: one line naming it, exit 2)."""
        if not message:
            return
        if file is None and sys.stdout is None:  # --help, --version >&-: it went to standard
            stdout_unwritten(OSError(errno.EBADF, "closed"))  # error, exit 0: now one line, 2
            return
        file = file or sys.stderr
        try:
            file.write(message)
        except (AttributeError, OSError) as e:  # a closed or gone stream: as argparse did
            if isinstance(e, OSError) and file is sys.stdout:
                stdout_unwritten(e)


class _Once(argparse.Action):
    """Store an option's value and refuse a second one: ``--trials 40 --trials 60`` (or
    ``--out A --out B``, ``--results A --results B``) ran with the last and dropped the first
    without a word, as ``--set seed=3 --set seed=4`` did before the eighth sweep."""

    def __call__(self, parser, namespace, values, option_string=None):
        given = parser.__dict__.setdefault("given_once", set())
        if self.dest in given:
            parser.error(f"argument {'/'.join(self.option_strings)}: given twice: give one value")
        given.add(self.dest)
        setattr(namespace, self.dest, values)


class OnceParser(BoundedParser):
    """:class:`BoundedParser` where an option of :attr:`once` (:data:`ONCE` unless a
    subclass names more) may be given once."""

    once: frozenset = ONCE

    def add_argument(self, *args, **kwargs):
        if args and args[0] in self.once and "action" not in kwargs:
            kwargs["action"] = _Once
        return super().add_argument(*args, **kwargs)

    def parse_known_args(self, args=None, namespace=None):
        self.given_once = set()  # each parse starts afresh (a parser may be used again)
        return super().parse_known_args(args, namespace)
