"""What ``python -m sim.batch`` checks before it starts any run, and whether a study's results
are current (``--stale-only``, ``make verify``'s staleness rule).

:func:`why_stale` reads the run record against the config ``sim run STUDY RUN_OPTIONS``
resolves and the study's current code hash; the ``_..._problem`` checks run once before any
study starts (a clash of two runs on one results directory, run options that every run would
refuse, ``--set`` keys no study has, a timings file that is not the batch's).
"""

from __future__ import annotations

import contextlib
import copy
import io
import json
import os
from pathlib import Path

from sim.api_paths import arrow_name, too_long
from sim.cli import DOC as cli_doc
from sim.cli_args import parser as run_parser
from sim.cli_errors import cwd_exists
from sim.cli_load import load_run
from sim.cli_run import check_run_args
from sim.ends import unshown
from sim.execute import sweep_limits
from sim.input_places import check_inputs_outside
from sim.mc.codehash import study_code_hash
from sim.mc.config import ConfigError, StudyError, check_chunks, parse_override, read_toml
from sim.mc.export_edits import changed_exports
from sim.mc.message_text import key_text, printable
from sim.mc.outputs import check_out
from sim.mc.overrides import command_values, listed, recorded
from sim.mc.paths import absolute
from sim.mc.publish import changed_figure
from sim.mc.storage import read_record, regular_text
from sim.mc.study_source import other_source, recorded_source
from sim.mc.sweep import read_sweep, reordered, swept_order
from sim.mc.table_edits import edited_tables
from sim.mc.table_shape import recorded_shape, sum_problem
from sim.mc.unknown_key import unknown_key_hint
from sim.places import base
from sim.report.read import mixed_table
from sim.studies import get_study

__all__ = ["is_current", "why_stale"]


def is_current(study_file: str | Path, results: str | Path, run_args=()) -> bool:
    """True when ``results/run.json`` records the config ``sim run STUDY_FILE RUN_ARGS``
    resolves (the study file with the run options' ``--set``, ``--trials``, ``--seed``,
    ``--chunk``) and the study's current code hash, and the run drew its figures (not
    ``--no-figures``) unless ``run_args`` ask for none (:func:`why_stale` says None)."""
    return why_stale(study_file, results, run_args) is None


def why_stale(
    study_file: str | Path, results: str | Path, run_args=(), loaded: tuple | None = None
) -> str | None:
    """Why ``results`` are not current for ``sim run STUDY_FILE RUN_ARGS`` (no results, a
    config key that differs, the code changed since, no figures or one replaced by hand), in
    a few words, a network export edited by hand among them (the user's now: a run is
    refused while it is there); None when they are (:func:`is_current`). ``--stale-only`` printed nothing
    for a study it re-ran, so results made by older code or copied from elsewhere were re-run
    without a word. ``loaded``: the file's ``(args, study, cfg, sweep)`` as the batch resolved
    them before any run (:func:`_configs_problems`), not resolved again."""
    try:
        text = regular_text(Path(results) / "run.json")
    except OSError:
        return "no results yet" if not Path(results).exists() else "no run record (run.json)"
    except UnicodeDecodeError:  # bytes of another tool: a traceback of make reproduce
        return "its run record is not one (run.json is not UTF-8 text)"
    try:
        record = json.loads(text.removeprefix("\ufeff"))  # an editor's signature: the record
        if loaded is not None:  # the batch resolved it already (_configs_problems)
            args, study, cfg, sweep = loaded
        else:
            args = _parsed(run_args, study_file)
            study, cfg = load_run(args)
            sweep = read_sweep(study_file, study.schema)  # recorded with the config (execute):
    except (OSError, ValueError, RecursionError, ConfigError, StudyError, SystemExit):
        return "its run record or study file does not load"  # RecursionError: nested too deep
    if not isinstance(record, dict):  # run.json edited into another JSON shape: not current
        return "its run record is not one"
    if record.get("figures") is False and not args.no_figures:  # sim run --no-figures
        return "made without figures"
    if other_source(results, Path(study_file).stem, record):  # B/alpha copied over B/beta
        written, path = recorded_source(record)
        return printable(  # a forged record's escape sequences shown, not obeyed
            f"its run.json records a run written as {written}/" + (f" from {path}" if path else "")
        )
    # the record holds the [sweep] table beside the config, as the run wrote it: without it
    # a swept study was "made with another config: sweep" at once, and re-run every time
    want = json.loads(json.dumps({**cfg, "sweep": sweep} if sweep else cfg))
    have = record.get("config")
    if have != want:
        have = have if isinstance(have, dict) else {}
        keys = sorted(k for k in {*want, *have} if want.get(k) != have.get(k))
        more = f" and {len(keys) - 3} more" if len(keys) > 3 else ""
        return f"made with another config: {', '.join(map(key_text, keys[:3]))}{more}"
    if order := reordered(record, swept_order(sweep)):  # the cells of another order
        return f"made with another config: {order}"
    if record.get("code_hash") != study_code_hash(cfg["study"]):
        return "made by other code: the code the study imports changed since"
    # a table copied in from another run (two results directories merged by hand, or one
    # rewritten by a tool that drops its provenance) beside this run's record: not current
    mixed = mixed_table(Path(results), missing_ok=False)
    if mixed is not None:
        return f"{mixed[0].name} is not of the run of run.json: {mixed[1]}"
    if edited := edited_tables(Path(results)):  # a table edited by hand: made again, as a
        return f"{edited[0]} changed after its run (sha256 not run.json's: edited by hand?)"
    if unsealed := _unsealed(Path(results)):  # a record emptied by hand: the readers refuse
        return unsealed  # its tables ("up to date", where sim show and the API refuse them)
    for name, what in sorted(changed_exports(Path(results)).items())[:1]:  # the user's now:
        # the results were called up to date, and a run of them is refused while it is there
        kind = f"was {what}" if what.startswith("changed") else f"is {what}, not its run's export"
        return f"{name} {kind}: a run into {results} is refused until it is moved away"
    return changed_figure(Path(results))  # figure replaced by hand is drawn again


def _clashes(files: list[Path], run_args: list[str], results: str = "results") -> list[str]:
    """Why these runs cannot share one batch, one line each (every clash, not only the
    first: a batch of many files was refused one clash at a time): two of them would write
    one results directory (the same file twice, two files of one name), one file would run
    twice under two names (a symbolic or hard link beside it: each wrote <results>/<its name>,
    the same study run twice), or a file's name is ``.toml`` or ``...toml`` (its results would
    be <results> itself or its parent), or standard output's encoding cannot show its name."""
    seen: dict[str, Path] = {}
    out, named = [], {}  # named: the files by their inode, so a link's second name is seen
    try:  # a locale whose file names are not UTF-8: Arrow's would be other files
        arrow_name("--results", results)
    except ConfigError as e:
        return [str(e)]
    for f in files:
        try:
            st = f.stat()
            other = named.setdefault((st.st_dev, st.st_ino), f)
        except OSError:  # (said by the file's own check)
            other = f
        if other.stem != f.stem:  # two names of one file (a link): the same study run twice
            out.append(
                f"{other} and {f} are one file (a link): its study would run twice, into "
                f"{Path(results) / other.stem} and {Path(results) / f.stem}; list it once"
            )
        elif f.stem in ("", ".", ".."):
            out.append(f"{f}: a study file named like this would write <results>/{f.stem}")
        elif f.stem in seen:
            same = f.resolve() == seen[f.stem].resolve()
            out.append(
                f"{f} is listed twice"
                if same
                else f"{seen[f.stem]} and {f} would both write {Path(results) / f.stem}"
            )
        elif why := unshown(f.name) or unshown(str(Path(results) / f.stem / "README.md")):
            out.append(f"{f}: {why}")  # its lines name it: a traceback after every run
        else:
            seen[f.stem] = f
    return out


def _unsealed(results: Path) -> str | None:
    """``NAME its run record holds neither ...`` for the first table of ``results`` (a
    sweep's cells' too) that its record neither sums nor shapes, as the readers refuse it
    (:func:`sim.mc.table_shape.sum_problem`), else None."""
    files = (read_record(results) or {}).get("files")
    for p in sorted([*results.glob("*.parquet"), *results.glob("cells/*/*.parquet")]):
        name = p.relative_to(results).as_posix()
        if isinstance(files, list) and name not in files and p.name not in _RUNS_OWN:
            continue  # a table of the user's put beside (the readers name it): no re-run
        if p.is_file() and recorded_shape(p) is None and (why := sum_problem(p)) is not None:
            return f"{name}: {why}"
    return None


#: the tables every run (or sweep) writes: one its record does not list was taken off by hand
_RUNS_OWN = ("claims.parquet", "sweep.parquet")


def _configs_problems(
    files: list[Path],
    run_args: list[str],
    results: Path,
    stale_only: bool = False,
    needs: dict | None = None,
) -> tuple[list[str], dict]:
    """``(lines, loaded)``: one line for each study file whose run would refuse its config
    (``sim run FILE RUN_ARGS`` resolves it here, before any run starts: a study file ported
    from another study, a bad key or value, a bad ``[sweep]``, a run over the memory or work
    limits, a ``<results>/<file name>`` its run refuses to replace: a file, a foreign
    directory, a link; one whose network export was edited by hand, or where a file of the
    user's stands in its export's place; with ``stale_only``, not for results that are current:
    no run replaces them), every such file named, and
    ``{file: (args, study, cfg, sweep)}`` of the others (``--stale-only`` reads them). One
    broken file among many ran the others first, for hours in ``make reproduce``, and was
    named only when its turn came. A ``--set`` key a study has not is left out of its check
    (:func:`_unknown_sets` says it once; that run refuses it). A working directory that was
    deleted is one line for all (as ``sim run`` says it). ``needs`` gets ``{file: bytes}``, each
    run's estimated memory with its workers (:mod:`sim.batch_memory`)."""
    if not cwd_exists():  # each run resolves its --out against it, and would refuse
        return ["No such file or directory: the working directory (it was deleted)"], {}
    base = _parsed(run_args)
    lines, loaded = [], {}
    for f in files:
        args = copy.copy(base)
        args.study, args.quiet = str(f), True
        try:
            schema = get_study(read_toml(f).get("study")).schema
            args.set = [t for t in base.set or [] if parse_override(t)[0] in schema]
            study, cfg = load_run(args)  # with its --max-memory-gb (a large network's check)
            check_chunks(cfg)
            sweep = read_sweep(f, study.schema)
            lim = args.max_memory_gb, args.max_adjustments, args.workers
            est = sweep_limits(study, cfg, sweep, *lim)  # its run's limits (sim check's too)
            if needs is not None:
                needs[f] = est.bytes * max(args.workers or 1, 1)
            out = results / f.stem  # each run is --overwrite: the record is not compared
            record = {"config": cfg, "code_hash": study_code_hash(cfg["study"])}
            try:  # (as sim run: check_run_args)
                check_out(absolute(out), str(out), record, True)
            except ConfigError:  # results on a read-only share: --stale-only runs none that
                if not stale_only or why_stale(f, out, run_args, (args, study, cfg, sweep)):
                    raise  # is current, and was refused ("cannot be replaced") for each
            check_inputs_outside(absolute(out), str(out), cfg, sweep)  # an edited export
        except (ConfigError, StudyError) as e:  # a line that names the file already: as it is
            text = str(_out_in_batch_words(e) if isinstance(e, ConfigError) else e)
            lines.append(text if text.startswith(f"{f}: ") else f"{f}: {text}")
            continue
        except RecursionError:  # nested too deeply for the parser: its run says so
            lines.append(f"{f}: malformed TOML: nested too deeply")
            continue
        if args.set == (base.set or []):  # the run's own config (not one without a --set)
            loaded[f] = (args, study, cfg, sweep)
    return lines, loaded


def _in_batch_words(text: str | None) -> str | None:
    """A run's refusal of its ``--out`` in the words of the batch's command line: the user
    gave ``--results`` (each study writes ``<results>/<file name>``), not ``--out``."""
    if not text:
        return text
    text = text.replace("sim: error: --out: ", "sim: error: --results: ")
    return text.replace("choose another --out", "choose another --results")


def _out_in_batch_words(e: ConfigError) -> ConfigError:
    """``e``, a refusal of a run's ``--out`` found before the run, in the batch's words
    (:func:`_in_batch_words`, as the batch says its runs' own refusals)."""
    if e.key != "--out":
        return e
    return ConfigError("--results", _in_batch_words(str(e).removeprefix("--out: ")))


def _replaces_project_results(f: Path, results: Path) -> str | None:
    """Why the run of ``f`` would replace the results of the project's own study file of its
    name (``results/<stem>``, made from ``studies/<stem>.toml`` of the working directory) with
    the results of another file of that name (a study author's own ``brown_table1.toml``):
    each run is ``--overwrite``, and the committed results were silently replaced. A file of
    another name (``mine/my_net.toml``) made a new ``results/my_net`` among the project's
    (in its REPORT.md, not checked by ``make verify``), which ``sim run`` never makes."""
    at = base()  # the project's from a directory inside it
    own = at / "studies" / f"{f.stem}.toml"
    try:
        target = (results / f.stem).resolve()
        if target != (at / "results" / f.stem).resolve() or not (at / "studies").is_dir():
            return None
        if f.resolve() == own.resolve():
            return None
    except (OSError, RuntimeError):  # a loop: the run names it
        return None
    if not own.is_file():
        return (
            f"{f} is not a study file of the project's {at / 'studies'}: it would make a new "
            f"{results / f.stem} among the project's results: give your own --results DIR"
        )
    return (
        f"{f} would replace {results / f.stem}, the results of the project's {own} "
        "(another file of that name): give your own --results DIR"
    )


def _default_results_problem(files: list[Path], run_args: list[str]) -> str | None:
    """Why a batch given no ``--results`` may not write the default ``results/``, which holds
    what ``make reproduce`` makes of the project's study files as written: run options that
    make the runs other than the files (a key set, ``--no-figures``: ``make rerun`` writes the
    committed results with them when asked, by ``RUN_FLAGS``, whose Makefile line names
    ``--results results``). ``sim run`` of each of these without ``--out`` goes to
    ``scratch/`` (:func:`sim.places.default_out`); a study file that is no
    ``studies/<name>.toml`` is refused by :func:`_replaces_project_results`. None when it
    may."""
    args = _parsed(run_args)
    sets = recorded(command_values(args.set, trials=args.trials, seed=args.seed, chunk=args.chunk))
    off = [f"the overrides {listed(sets)}"] if sets else []
    off += ["--no-figures"] if args.no_figures else []
    if off:
        return (
            f"run options: a run with {' and '.join(off)} is not its study file as written, "
            "whose results the default results/ holds: give --results DIR (--results results "
            "to replace them)"
        )
    return None


def _parsed(run_args, study: str | Path = "STUDY.toml"):
    """``sim run STUDY RUN_ARGS`` as its parser reads it, its messages kept quiet: the batch
    checked the options first (:func:`_run_options_problem` says what is wrong with them)."""
    with contextlib.redirect_stderr(io.StringIO()):
        return run_parser(cli_doc).parse_args(["run", str(study), *run_args])


def _run_options_problem(run_args: list[str]) -> str | None:
    """Why the run options cannot go to every run, checked once before any starts (as
    ``sim run`` reads them, abbreviations included): a bad option or value, an ``--out``
    (each study writes <results>/<file name>), or ``--help`` (each run would print its help
    and exit 0 without running)."""
    why = _sim_run_problem(run_args)
    own = [o for a in run_args if (o := _batch_option(a.partition("=")[0]))]
    if why is not None and own:  # "unrecognized arguments: --jobs 2 (did you mean --workers?)"
        return f"{own[0]} is an option of sim.batch, not of sim run: give it before --"
    return why


#: the batch's own options, which a hurried user puts among sim run's after ``--``
BATCH_OPTIONS = ("-j", "--jobs", "--results", "--stale-only", "--report", "--timings")


def _batch_option(name: str) -> str | None:
    """The batch's option that ``name`` (an argument after ``--``) gives: itself, ``-j2``'s
    ``-j``, or the one it begins (``--stale``, ``--job``: no option of sim run begins so), or
    None. (``--job 2`` there got sim run's guess "a batch's output: give --results".)"""
    if name in BATCH_OPTIONS or (name[:2] == "-j" and name[2:].isdigit()):
        return name[:2] if name[:2] == "-j" else name
    begun = [o for o in BATCH_OPTIONS if len(name) >= 4 and o.startswith(name)]
    return f"{name} ({begun[0]}?)" if len(begun) == 1 else None


def _sim_run_problem(run_args: list[str]) -> str | None:
    """Why ``sim run STUDY.toml RUN_ARGS`` refuses its options (:func:`_run_options_problem`)."""
    text = io.StringIO()
    try:
        with contextlib.redirect_stdout(text), contextlib.redirect_stderr(text):
            args = run_parser(cli_doc).parse_args(["run", "STUDY.toml", *run_args])
        if args.out is not None:
            return (
                "--out cannot be a run option: each study writes <results>/<file name> "
                "(give --results DIR before --)"
            )
        check_run_args(args)
    except SystemExit:
        return f"{' '.join(run_args)!r} would print the help of sim run and run nothing"
    except ConfigError as e:  # -o after --: sim run's --out, which a batch refuses (d46)
        why = str(e).removeprefix("sim: ")
        return why.replace(
            "(did you mean --out?)", "(a batch's output: give --results DIR before --)"
        )
    return None


def _unknown_sets(files: list[Path], run_args: list[str]) -> tuple[str | None, str | None]:
    """``(problem, note)`` of the run options' ``--set`` keys against the studies of the batch
    (each file's ``study``, its schema): a key no study has is a problem (exit 2 before any
    run: each run would refuse it, one line per study); a key only some lack is a note said
    once before the runs start (those runs refuse it). A file whose study cannot be read is
    left to its run's own line."""
    sets = _parsed(run_args).set or []
    keys = []
    for text in sets:
        try:
            key = parse_override(text)[0]
        except ConfigError as e:  # "--set needs key=value (got 'bad')"
            return str(e), None
        keys.append(key)
    schemas: dict[Path, tuple[str, set]] = {}
    for f in files:
        try:
            name = read_toml(f).get("study")
            schemas[f] = (name, get_study(name).schema)
        except (ConfigError, OSError, ValueError, RecursionError):
            continue
    notes = []
    for key in dict.fromkeys(keys):
        lack = [f for f, (_, schema) in schemas.items() if key not in schema]
        if not lack:
            continue
        if len(lack) == len(schemas):
            if len({name for name, _ in schemas.values()}) == 1:  # sim run's own words
                hint = unknown_key_hint(key, next(iter(schemas.values()))[1])
                return (
                    f"--set {key_text(key)}: unknown key{hint or ' (the study has no such key)'}",
                    None,
                )
            return f"--set {key_text(key)}: unknown key (no study of the batch has it)", None
        studies = ", ".join(f"{f.name} ({schemas[f][0]})" for f in lack)
        notes.append(
            f"--set {key_text(key)}: unknown to {studies}, whose run{'s' * (len(lack) > 1)} will refuse it"
        )
    return None, "; ".join(notes) or None


#: the most bytes an earlier ``--timings`` file is read (one short list a study: a batch of
#: every study writes under 2 kB); a larger file is not one, and is not read
TIMINGS_BYTES = 1 << 20


def _timings_problem(path: str) -> str | None:
    """Why the timings cannot be written to ``path`` (checked before anything runs): its
    directory must be writable, and an existing file must be an earlier timings file (a
    JSON object of lists), never a file of the user's."""
    if path == "-":  # read as standard output by many programs: here it named a file "-"
        return "'-' is not standard output here: name a file (./- for a file named '-')"
    if why := too_long(path):  # pathlib's is_dir raised it: "OSError: File name too long"
        return why
    p = Path(path)
    try:
        parent = p.resolve().parent
    except (OSError, RuntimeError) as e:  # a symlink loop
        return f"{p} cannot be resolved: {e}"
    if not parent.is_dir() or not os.access(parent, os.W_OK):
        return f"cannot write into {parent}"
    if p.is_symlink() or (p.exists() and not p.is_file()):
        return f"{p} exists and is not a regular file"
    if p.exists():
        try:
            if p.stat().st_size > TIMINGS_BYTES:  # never read whole: a disk image named by
                raise ValueError  # mistake was read into memory (MemoryError, a traceback)
            old = json.loads(p.read_bytes())  # as JSON reads: a signature (Notepad's) skipped
            ours = isinstance(old, dict) and all(isinstance(v, list) for v in old.values())
        except (OSError, ValueError):
            ours = False
        if not ours:
            return f"{p} exists and is not a timings file of sim.batch; sim never replaces it"
    return None


def _files_after(message: str, run_args: list[str]) -> str:
    """``; study files come before --, not after it (a.toml)`` when argparse's ``message``
    says no study file was given and one is among sim run's options after ``--`` (a word of
    its own, not an option's ``KEY=VALUE``); "" otherwise (a ``--set x=a.toml`` after a bad
    ``--jobs`` is not a study file put in the wrong place)."""
    if not message.startswith("the following arguments are required"):
        return ""
    after = [a for a in run_args if a.endswith(".toml") and not a.startswith("-") and "=" not in a]
    return f"; study files come before --, not after it ({after[0]})" if after else ""
