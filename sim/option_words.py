"""What a newcomer's option from another tool means here: the words of other command lines
(``-o``, ``-j``, ``--force``, ``--threads``, ``--verbose``, ``--dry-run``, ``sim help run``)
named with the option or command that does it, for the one-line refusal of ``sim``,
``python -m sim.batch`` and ``make verify`` (``python -m sim.report.verify``).

The spelling guess of :func:`sim.mc.argv._guess` goes by letters alone, so such a word got a
guess of another meaning (``--threads 2``: "did you mean --trials?", which would run two
trials; ``--force``: ``--workers``; ``--verbose`` and ``--iterations``: ``--version``;
``--config``: ``--no-figures``; ``--resume``: ``--set``) or none (``-o``, ``-j``, ``-q``,
``-f``). A word listed here is answered by its meaning first; the others keep the spelling
guess."""

from __future__ import annotations

import re

__all__ = ["Meant", "meant", "set_split", "command_word", "two_sets"]

#: an option, and the words of other tools that mean it
SYNONYMS: dict[str, tuple[str, ...]] = {
    "--out": ("-o", "--output", "--output-dir", "--outdir", "--out-dir", "--output_dir", "-O"),
    "--trials": (
        "-N",
        "--samples",
        "--nsamples",
        "--n-samples",
        "--num-samples",
        "--iterations",
        "--iters",
        "--runs",
        "--draws",
        "--reps",
        "--replications",
        "--simulations",
        "--num-trials",
        "--n_trials",
    ),
    "--workers": (
        "-j",
        "-p",
        "--jobs",
        "--threads",
        "--processes",
        "--procs",
        "--nproc",
        "--cores",
        "--cpus",
        "--ncpu",
        "--parallel",
        "--num-workers",
        "--np",
    ),
    "--set": (
        "-s",
        "-D",
        "--define",
        "--param",
        "--params",
        "--parameter",
        "--override",
        "--option",
        "--var",
    ),
    "--overwrite": ("-f", "--force", "--clobber", "--replace"),
    "--quiet": ("-q", "--silent", "--no-progress", "--no-bar"),
    "--no-figures": (
        "--no-plots",
        "--no-plot",
        "--noplot",
        "--noplots",
        "--nofigures",
        "--no-figs",
        "--no-png",
        "--no-images",
        "--no-graphics",
        "--skip-figures",
    ),
    "--chunk": ("--chunksize", "--chunk-size", "--chunk_size", "--batch-size", "--batch"),
    "--seed": ("--random-seed", "--rng-seed", "--random_seed", "--rseed"),
    "--version": ("-V",),
    "--markdown": ("--md", "--markdown-output"),
}

#: ``python -m sim.batch``: its own words for its options (its runs' are after ``--``)
BATCH_SYNONYMS: dict[str, tuple[str, ...]] = {
    "--jobs": ("-j", "-p", "--threads", "--processes", "--procs", "--parallel", "--cores"),
    "--results": ("-o", "--out", "--output", "--output-dir", "--outdir", "--out-dir"),
    "--stale-only": ("--only-stale", "--changed", "--outdated"),
}

#: ``make verify``: where its re-runs go
VERIFY_SYNONYMS: dict[str, tuple[str, ...]] = {
    "--scratch": ("-o", "--out", "--output", "--output-dir", "--outdir", "--tmp", "--tmpdir"),
}

#: words that mean no option of ``sim``: what does their work instead
NO_SUCH: dict[tuple[str, ...], str] = {
    ("-v", "-vv", "--verbose", "--debug"): (
        "no such option: sim prints its progress and summary unless --quiet; SIM_DEBUG=1 "
        "shows a bug's traceback"
    ),
    ("--dry-run", "--dryrun", "--check", "--validate"): (
        "no such option: sim check STUDY.toml validates the file and prints the work "
        "without running it"
    ),
    ("--resume", "--continue", "--restart"): (
        "no such option: the same command again resumes a stopped run; --overwrite starts it over"
    ),
    ("-c", "-i", "--config", "--study", "--file", "--study-file", "--input"): (
        "no such option: the study file is the command's argument: sim run STUDY.toml"
    ),
}

#: words that mean no option of any ``sim`` command: what does their work instead
NO_SUCH_ANY: dict[tuple[str, ...], str] = {
    ("--json", "--csv", "--table", "--format"): (
        "no such option: a run's tables are the Parquet files of its results directory "
        "(pyarrow reads them; in Python sim.Results(DIR, STUDY).table(NAME))"
    ),
    ("--list", "--keys", "--list-keys", "--show-keys"): (
        "no such option: sim check STUDY.toml lists every key with its meaning, unit and bounds"
    ),
}

#: sim.batch: sim run's options, which a batch takes after ``--``
RUN_OPTIONS = (
    "--trials",
    "--chunk",
    "--seed",
    "--set",
    "--workers",
    "--executor",
    "--scheduler",
    "--quiet",
    "--no-figures",
    "--overwrite",
    "--max-memory-gb",
    "--max-adjustments",
)


def _of(word: str, table: dict[str, tuple[str, ...]], options) -> str | None:
    return next((o for o, words in table.items() if word in words and o in options), None)


def meant(
    word: str, options, batch: bool = False, run: bool = False, verify=False, sim=False
) -> str:
    """`` (did you mean OPTION? ...)`` for an option ``word`` (``=value`` cut off) of another
    tool whose meaning is an option among ``options`` (a command line's), or, with ``run``
    (``sim run``'s command line) or ``sim`` (any of ``sim``'s), for a word no option of
    ``sim`` means, what does its work;
    "" for any other word. ``batch``: the words of ``python -m sim.batch``, where ``sim
    run``'s options go after ``--``; ``verify``: those of ``make verify`` first."""
    if verify and (o := _of(word, VERIFY_SYNONYMS, options)) is not None:
        return f" (did you mean {o}?)"
    if batch:
        if (o := _of(word, BATCH_SYNONYMS, options)) is not None:
            return f" (did you mean {o}?)"
        opt = word if word in RUN_OPTIONS else _of(word, SYNONYMS, RUN_OPTIONS)
        if opt is not None:
            return (
                f" (an option of sim run: give it after --, python -m sim.batch FILES -- {opt} ...)"
            )
        return ""
    if (o := _of(word, SYNONYMS, options)) is not None:
        return f" (did you mean {o}?)"
    why = next((w for words, w in NO_SUCH_ANY.items() if word in words), None)
    if (sim or run) and why is not None:
        return f" ({why})"
    if run:  # sim run's words (sim check, sim show, make verify: the spelling guess)
        if word == "-n":  # pytest's -n is workers, most Monte-Carlo tools' the trials
            return " (did you mean --trials, the number of trials, or --workers?)"
        if word == "-t":
            return " (did you mean --trials?)"
        why = next((w for words, w in NO_SUCH.items() if word in words), None)
        if why is not None:
            return f" ({why})"
    return ""


def set_split(given: list[str], unrecognized: str) -> str:
    """`` (--set takes KEY=VALUE as one word: --set trials=40)`` when the ``unrecognized``
    words of a command line are the value of a ``--set`` given apart from its key
    (``--set trials 40``, ``--set trials = 40``, ``--set trials= 40``: argparse said
    "unrecognized arguments: 40" alone); "" otherwise."""
    rest = unrecognized.split(" ")
    for k in range(len(given) - 2):
        if given[k] != "--set" or given[k + 2 : k + 2 + len(rest)] != rest:
            continue
        key, words = given[k + 1], [w for w in rest if w != "="]
        if not words or key.startswith("-"):
            continue
        joined = key.rstrip("=").strip() + "=" + words[0].lstrip("=")
        return f" (--set takes KEY=VALUE as one word: --set {joined})"
    return ""


def command_word(word: str, given: list[str], prog: str, commands) -> str:
    """`` (did you mean sim run --help?)`` for ``help`` or ``version`` typed as a command
    (``sim help``, ``sim help run``, ``sim version``: "invalid choice" with the commands, as
    git and cargo take them); "" for another word."""
    w = word.lower().lstrip("-")
    if w == "version":
        return f" (did you mean {prog} --version?)"
    if w != "help":
        return ""
    cmd = next((a for a in given if a in commands), None)
    if cmd is not None:
        return f" (did you mean {prog} {cmd} --help?)"
    return f" (did you mean {prog} --help? {prog} COMMAND --help gives a command's options)"


class Meant:
    """A mixin of an argparse parser (before :class:`sim.mc.argv.OnceParser`) whose
    ``explain`` says what a word of another tool means here before the spelling guess:
    :attr:`words` is ``"sim"`` (:func:`meant` of ``sim run``'s words too), ``"batch"`` or
    ``"verify"``. Also a ``--set`` whose value came apart from its key (:func:`set_split`),
    ``help`` or ``version`` typed as a command (:func:`command_word`) and a switch given a
    value (``--overwrite=true``: argparse's "ignored explicit argument 'true'" alone)."""

    words = "sim"

    def explain(self, message: str) -> str:
        text, cmds = self._explained(message), _commands(self)
        cmd = next((a for a in getattr(self, "given", []) if a in cmds), None)
        if cmd is None:
            return text
        own = set(self._option_string_actions) - set(cmds[cmd]._option_string_actions)
        return re.sub(  # sim's own option guessed after a command (--verison, -V): the guess
            r"\(did you mean (--?[\w-]+)\?",  # refused again when typed there, as sim's
            lambda g: f"(did you mean {self.prog} {g[1]}?" if g[1] in own else g[0],
            text,
        )

    def _explained(self, message: str) -> str:
        given = getattr(self, "given", [])
        m = re.match(r"unrecognized arguments: (.*)", message)
        if m:
            if split := set_split(given, m.group(1)):
                return message + split
            bad = next((w for w in m.group(1).split(" ") if w.startswith("-") and w != "-"), "")
            opts = self.options()
            run = self.words == "sim" and "--trials" in opts  # sim run's line
            kind = {w: self.words == w for w in ("batch", "verify", "sim")}
            if bad and _after_dashes(given, bad):
                return (
                    message + " (-- ends the options: the words after it are no options; drop it)"
                )
            cmds = getattr(self, "commands", None) or _commands(self)
            cmd = next((a for a in given if a in cmds), None)
            if bad and cmd and (word := bad.split("=")[0]) in self._option_string_actions:
                return message + (  # sim's own (--version) after the command: "did you mean
                    f" ({word} is an option of {self.prog} itself, not of {self.prog} {cmd}: "
                    f"{self.prog} {word})"  # --version?" before, the spelling guess
                )
            if bad and (hint := meant(bad.split("=")[0], opts, run=run, **kind)):
                return message + hint
            if not bad and self.words == "sim" and cmd == "report":
                return message + (
                    " (sim report takes --results DIR, the directory that holds the results "
                    "directories; sim show DIR prints one)"
                )
        m = re.match(r"argument COMMAND: invalid choice: '?(.*?)'? \(choose from", message)
        if m and (hint := command_word(m.group(1), given, self.prog, _commands(self))):
            return message + hint
        m = re.match(r"(?:.*: )?argument (--[\w-]+): ignored explicit argument", message)
        if m:
            return f"{message} ({m.group(1)} takes no value: give {m.group(1)} alone)"
        return super().explain(message)


def _commands(parser) -> dict:
    """The commands of a parser with subcommands (``sim``'s ``run``, ``show``, ...); {} else."""
    return next((a.choices for a in parser._actions if a.dest == "cmd"), None) or {}


def _after_dashes(given: list[str], word: str) -> bool:
    """True when ``word`` is given only after a ``--`` (``sim run x.toml -- --trials 40``:
    the option read as a file)."""
    return "--" in given and word in given and given.index(word) > given.index("--")


#: a second ``KEY=`` in a ``--set`` value, after a comma, a semicolon or white space
_SECOND = re.compile(r"\s*[,;]\s*(?=[A-Za-z_][\w.]*\s*=)|\s+(?=[A-Za-z_][\w.]*\s*=)")


def two_sets(overrides: list[str], key: str | None) -> str:
    """`` (one KEY=VALUE a --set: --set trials=40 --set seed=3)`` when the refused value of
    ``key`` holds a second override (``--set trials=40,seed=3``, ``--set "trials=40
    seed=3"``: "trials: must be an integer (got '40,seed=3')" alone); "" otherwise."""
    for text in overrides:
        k, eq, value = text.partition("=")
        if not eq or k.strip() != key or not _SECOND.search(value):
            continue
        parts = [f"{k.strip()}={p}" if i == 0 else p for i, p in enumerate(_SECOND.split(value))]
        return f" (one KEY=VALUE a --set: {' '.join(f'--set {p}' for p in parts)})"
    return ""
