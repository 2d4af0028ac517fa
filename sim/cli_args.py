"""The arguments of the command line ``sim`` (:mod:`sim.cli`): the parser of every command
and its options, with one-line errors (exit 2 through :func:`sim.cli.main`)."""

from __future__ import annotations

import argparse
import ast
import re
from pathlib import Path

import sim
from sim.mc.argv import OnceParser, integer, most_workers
from sim.mc.chunk_count import MIN_CHUNKS
from sim.mc.config import ConfigError
from sim.mc.numtext import UnheldError, float_text
from sim.option_words import Meant

__all__ = ["module_doc", "parser"]


class _Parser(Meant, OnceParser):
    """argparse with one-line errors (exit 2 through :func:`main`, no usage dump); a word of
    another tool is answered by its meaning here (:class:`sim.option_words.Meant`)."""

    def refuse(self, message: str):
        if message.startswith("the following arguments are required"):
            # `sim --verison`, `sim check --hlep`: the mistyped option, not the missing
            # argument it left behind, is what the user must fix
            known = self._option_string_actions
            bad = [
                a
                for a in getattr(self, "given", [])
                if a.startswith("-") and a != "-" and a.split("=")[0] not in known
            ]
            if bad:
                message = self.explain(f"unrecognized arguments: {bad[0]}")
        extra = re.match(r"unrecognized arguments: (\S+\.toml)\b", message)
        if extra:  # `sim run a.toml b.toml`: one study a command
            message += " (one study file a command: python -m sim.batch runs many)"
        # the command's own parser names itself ("sim run: argument --trials: ..."); the top
        # one reports what no command takes: its line already starts "sim: error:" (it said
        # "sim: error: sim: unrecognized arguments"), and the help to see is the command's
        head, helps = f"{self.prog}: ", self.prog
        if " " in self.prog:  # a command's own parser (`sim show --trials`: DIR not given)
            cmd = self.prog.split(" ")[-1]
            commands = getattr(self, "commands", {})
            if other := _of_another(message, commands, cmd, getattr(self, "given", [])):
                head, message = "", other
        if " " not in self.prog:
            head = ""
            cmds = next((a.choices for a in self._actions if a.dest == "cmd"), {}) or {}
            cmd = next((a for a in getattr(self, "given", []) if a in cmds), None)
            helps = f"{self.prog} {cmd}" if cmd else self.prog
            message = _of_another(message, cmds, cmd, getattr(self, "given", [])) or message
        raise ConfigError(None, f"{head}{message} (see {helps} --help)")


class _Version(argparse._VersionAction):
    """``--version``: the version, printed when the option is the command line's only word;
    ``sim --version extra`` (or ``--version check x.toml``) printed it and exited 0, the rest
    of the line ignored without a word."""

    def __call__(self, parser, namespace, values, option_string=None):
        rest = list(getattr(parser, "given", []))
        if option_string in rest:
            rest.remove(option_string)
        if rest:
            parser.error(f"{option_string} takes no other words: give it alone (got {rest[0]!r})")
        super().__call__(parser, namespace, values, option_string)


def _of_another(message: str, cmds: dict, cmd: str | None, given: list[str]) -> str | None:
    """``--trials: an option of sim run, not of sim show`` for an option the command ``cmd``
    lacks and another command has: ``sim show --trials 4 results/x`` was "unrecognized
    arguments: --trials results/x" (the 4 taken for DIR), ``sim check x.toml --out d``
    "(did you mean --set?)"; None when the message is no such option's. The value of
    ``sim check``'s ``--set`` advice is the one ``given`` after the option (the command
    line), else ``N``: taken from argparse's leftovers it was the study file (``sim check
    --trials 5 x.toml``: argparse read 5 as the file, "--set trials=x.toml"), the next option
    (``--trials --seed``) or the hint's own words (``--seed=``: "--set seed=(did")."""
    m = re.match(r"unrecognized arguments: (.*)", message)
    if m is None or cmd not in cmds:
        return None
    bad = next((w for w in m.group(1).split(" ") if w.startswith("-") and w != "-"), "")
    word = bad.split("=")[0]
    if not any(word in p._option_string_actions for p in cmds.values()):
        word = word.lower()  # sim check --Trials 40: no guess (sim run's --trials meant)
    has = [c for c, p in cmds.items() if c != cmd and word in p._option_string_actions]
    if not has or word in cmds[cmd]._option_string_actions:
        return None
    line = f"{word}: an option of {' and '.join(f'sim {c}' for c in has)}, not of sim {cmd}"
    if cmd == "check" and word in ("--trials", "--seed", "--chunk"):  # as sim run's (d46)
        at = given.index(bad) if bad in given else len(given)
        value = bad.partition("=")[2] or "".join(given[at + 1 : at + 2])
        if not value or value.startswith("-") or value.endswith(".toml"):
            value = "N"  # (no value given, or the next option or the study file)
        line += f": sim check --set {word[2:]}={value} checks what sim run {word} {value} runs"
    return line


def module_doc(doc: str | None, path: str) -> str:
    """A module's docstring ``doc``, or, under ``python -OO`` (which strips docstrings, so
    ``doc`` is None and ``sim`` ended in an AttributeError), the same text read from the
    module's source ``path``; "" when neither can be had."""
    if doc is not None:
        return doc
    try:
        tree = ast.parse(Path(path).read_text(encoding="utf-8"))
    except (OSError, SyntaxError, ValueError):
        return ""
    return ast.get_docstring(tree, clean=False) or ""


def _limit_value(text: str) -> float:
    """A limit's number as argparse's ``float`` reads it, but digits no double holds named as
    written (``--max-adjustments 1e-400`` was "must be a positive number (got 0.0)")."""
    try:
        return float_text(text)
    except UnheldError as e:
        raise argparse.ArgumentTypeError(str(e)) from None
    except ValueError:  # argparse's own words for type=float
        raise argparse.ArgumentTypeError(f"invalid float value: {text!r}") from None


def _run_parser(sub) -> None:
    """The options of ``sim run``."""
    r = sub.add_parser(
        "run",
        help="run a study, print its verdicts, write its results directory",
        description="Run a study file and write its results directory (Parquet tables, "
        "figures, README.md); print the verdict counts and the headline claims at the end.",
    )
    r.add_argument("study", help="study file, e.g. studies/brown_dilution.toml")
    r.add_argument(
        "--out",
        help="output directory (default: results/<name>, <name> the study file's name "
        "without .toml (of a copy of a project's study file, kept under another name outside "
        "studies/: the study's), for a study file run as written (in the project: one of its studies/) "
        "whose results there are of its config and code, or none yet; else "
        "scratch/<name>-<config hash>; see docs/cli.md)",
    )
    r.add_argument(
        "--trials",
        type=integer("trials"),
        help=f"number of Monte-Carlo trials; also picks a chunk size giving at least "
        f"{MIN_CHUNKS} chunks unless --chunk or chunk= is given",
    )
    r.add_argument(
        "--chunk", type=integer("chunk"), help="trials per chunk (the intervals are over chunks)"
    )
    r.add_argument("--seed", type=integer("seed"), help="override the root seed")
    r.add_argument(
        "--set",
        action="append",
        default=[],
        metavar="KEY=VALUE",
        help="override any config key by its dotted name, value read as TOML (repeatable); "
        "sim check STUDY.toml lists the keys",
    )
    r.add_argument("--quiet", action="store_true", help="no progress bar and no closing summary")
    r.add_argument(
        "--no-figures",
        action="store_true",
        help="draw no figure (PNG): the same tables, README.md and run.json in less time; "
        "make verify re-runs this way (it compares tables). make reproduce re-runs such "
        "results to draw them",
    )
    r.add_argument(
        "--executor",
        choices=("local", "dask"),
        default="local",
        help="local (in-process, or a process pool with --workers) or dask",
    )
    r.add_argument(
        "--workers",
        type=integer("workers", 1, most_workers()),
        default=1,
        help="worker processes (default 1)",
    )
    r.add_argument(
        "--scheduler",
        help="dask scheduler address tcp://HOST:PORT (default: a LocalCluster started for the run)",
    )
    r.add_argument(
        "--overwrite",
        action="store_true",
        help="replace results of a different config or code version (only results "
        "directories the suite wrote are ever replaced)",
    )
    _limit_options(r)


def _limit_options(p) -> None:
    """The limits of ``sim run``, which ``sim check`` applies too (its refusal over a limit
    named ``--max-memory-gb``, an option it did not take)."""
    p.add_argument(
        "--max-memory-gb",
        type=_limit_value,
        default=None,
        help="refuse a run whose estimated memory exceeds this (env SIM_MAX_MEMORY_GB)",
    )
    p.add_argument(
        "--max-adjustments",
        type=_limit_value,
        default=None,
        help="refuse a run with more least-squares adjustments than this (env SIM_MAX_ADJUSTMENTS)",
    )


def parser(doc: str) -> argparse.ArgumentParser:
    """The parser of ``sim``; ``doc``: the command line's module docstring (its first paragraph
    the description, its second the epilog)."""
    p = _Parser(
        prog="sim",
        description=doc.split("\n\n")[0],
        epilog="\n\n".join(doc.split("\n\n")[1:2]) + "\n\nsim COMMAND --help: its options.",
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    p.add_argument("--version", action=_Version, version=f"sim {sim.__version__}")
    sub = p.add_subparsers(dest="cmd", required=True, metavar="COMMAND")
    _run_parser(sub)
    sh = sub.add_parser(
        "show",
        help="print one results directory: its claims and verdicts",
        description="Print the claims of one results directory (a table; --markdown: its "
        "README.md). DIR may also be a directory name under results/ or scratch/ (where a "
        "run without --out writes), as its README.md names it.",
    )
    sh.add_argument("dir", metavar="DIR", help="a results directory, e.g. results/brown_table1")
    sh.add_argument("--markdown", action="store_true", help="print the directory's README.md")
    c = sub.add_parser(
        "check",
        help="validate a study file; print each key with its meaning, unit, bounds and the work",
        description="Validate a study file (and overrides) and print every key with its "
        "resolved value, meaning, unit and bounds, then the work the run would do.",
    )
    c.add_argument("study", help="study file, e.g. studies/brown_dilution.toml")
    c.add_argument(
        "--set",
        action="append",
        default=[],
        metavar="KEY=VALUE",
        help="override a config key as sim run --set does (repeatable); --set trials=N shows "
        "the chunk sim run --trials N would pick",
    )
    _limit_options(c)
    rep = sub.add_parser(
        "report",
        help="rebuild results/REPORT.md and each results/<study>/README.md from the Parquet files",
        description="Rebuild REPORT.md and each results directory's README.md from the "
        "Parquet files alone (nothing is run).",
    )
    rep.add_argument(
        "--results", help="the results directory (default results, the project's from inside it)"
    )
    for q in sub.choices.values():  # an option of another command is named as one
        q.commands = sub.choices
    return p
