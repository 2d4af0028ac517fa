"""Fuzz: mutated study files, overrides and options for the seven paper studies and two
network study files (``network_brown``, ``network_testfield``).

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
the key as written), a number at an EDGE (on its key's bound, one ulp inside or beyond it,
``-0.0``, a subnormal, ``2**53 + 1``, ``1e2`` for an integer key, a network record's number:
tests/fuzz_edges.py; ``FUZZ_EDGE_WEIGHT`` sets its share: a value beyond the bounds must be
refused naming its key), its SHAPE (a table written inline, records as an array of tables:
the same document, which must run; a table given twice, by dotted keys and a header or inline
and then more, the study's name as a table: refused naming it; tests/fuzz_shapes.py;
``FUZZ_SHAPE_WEIGHT``), its BYTES (a UTF-8 signature, CRLF or lone CR ends, a NUL, UTF-16, a
Latin-1 byte, an invisible or look-alike character in a key or a number, a form feed for a
space, the file cut short: tests/fuzz_bytes.py; ``FUZZ_BYTES_WEIGHT``: a signature, CRLF or
no last line end is the same document, which must run), a SPLICE of two valid files (a table,
a ``[sweep]`` or a record's field of another study or list pasted in, a list of records
written as one inline table, a table as an array of tables: tests/fuzz_splice.py;
``FUZZ_SPLICE_WEIGHT``: refused naming the key brought in) or the command line (``--trials``, ``--seed``, ``--workers``, ``--out``,
``--scheduler``). Every case runs ``sim run`` in a forked child
(its own session, an address-space limit, a time bound) and must give exit 0 with finite
results, or exit 2 with exactly one line on standard error and no traceback, and leave
nothing outside the output directory but, after a failed run, its staging directory.

``make test`` runs a few cases per study; ``make fuzz`` runs ``FUZZ_CASES`` (default 300).
``FUZZ_SEED`` picks the generator's seed, ``FUZZ_TIMEOUT`` the bound per case in seconds,
``FUZZ_SAVE`` a directory that keeps the study file of every failing case (the failure
message prints the command that reproduces it). The cases are made in tests/fuzz_cases.py
from the values of tests/fuzz_values.py and run by tests/fuzz_run.py. The BYTES of a GNU Gama
XML file and of Wolf's reading tables are fuzzed by ``sim check`` of the study that reads
them (``test_fuzz_bytes_of_data_files``), the SPLICE of study files and of GNU Gama XML files
by ``sim check`` too (``test_fuzz_splice``: many cases in little time). A SEQUENCE of
operations on one small study and one output directory (runs, interrupts at a marker, resumes,
edits of the study and its Gama file, overrides, ``sim show``, ``sim report``, verify, a sweep,
``--stale-only``, hand edits, the API: tests/fuzz_sequence.py) is checked after each step
(``test_fuzz_sequences``: one sequence a ten cases, at least two; ``FUZZ_SEQ_SECONDS``). A
CONCURRENT pair of operations on that study and directory (two runs, a run and ``--overwrite``,
``sim show``, ``sim report``, verify, ``--stale-only``, the API, a sweep and a run of its cell,
an edit of the study or Gama file), started at once or the second while the first waits at a
rename, is checked when both end (tests/fuzz_concurrent.py; ``test_fuzz_concurrent``: one pair
a seven cases, at least two; ``FUZZ_PAIR_SECONDS``). The FILE SYSTEM under a run of that study
(a file-size limit hit mid-run, too few file descriptors, a file where a directory is expected
and the reverse at every level of the output tree: tests/fuzz_fs.py; ``test_fuzz_file_system``:
one case a seven, at least two; ``FUZZ_FS_SECONDS``) must give exit 0 or one line naming the
file or the thing in the way, change nothing beside the results, and then, the limit lifted or
the thing moved away, the clean run's results. The LEVELS of a small ``[sweep]`` table (a level
of the wrong type, none, one twice, a key that is no key, a list's item by its index, more
cells than the bound or the work limit allows: tests/fuzz_sweep.py; ``test_fuzz_sweep_levels``:
one case a five, at least two, by ``sim check``; in ``make fuzz`` a valid one also run). A
finished RESULTS directory changed by hand (its bytes, a file's kind, a table rewritten, the
run record, the trials: tests/fuzz_results.py; ``test_fuzz_results_directory``: one case a
three, at least three) read by ``sim show``, ``sim report``, the API and verify: exit 0 with what the
clean run gives, or one line; the directory unchanged. The API's arguments in odd TYPES
(``np.int64``, a 0-d array, ``Fraction``, ``np.str_``, a ``str`` subclass, bytes paths, an
``os.PathLike`` or a container that raises: tests/fuzz_api_types.py; ``test_fuzz_api_types``:
three calls a case) give what the plain value gives, or one ``ConfigError`` line naming the
argument."""

from __future__ import annotations

import os
import random
import sys
from pathlib import Path

import pytest
from conftest import TRIANGLE_NETWORK
from fuzz_api_types import case as api_case
from fuzz_api_types import check as api_check
from fuzz_bytes import csv_sites, gama_sites, mutate_bytes
from fuzz_cases import SEED
from fuzz_concurrent import pairs
from fuzz_fs import cases as fs_cases
from fuzz_gama_values import gama_value
from fuzz_keys import network_case
from fuzz_results import cases as results_cases
from fuzz_run import check_case, fuzz, run_case
from fuzz_sequence import sequences
from fuzz_splice import gama_splice, splice_case
from fuzz_sweep import sweep_case
from fuzz_values import NAMES, ROOT, base, small, toml_doc, toml_value

import sim
from sim.cli import main
from sim.studies import load_study
from sim.studies.network.gama_read import read_gama
from sim.studies.wolf import tables

CASES = int(os.environ.get("FUZZ_CASES", "8"))


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


def test_fuzz_bases_load_as_written(tmp_path):
    """Every base written as the fuzzer writes it is a valid study file (a network's
    constraint key ``"S1.x"`` written bare was a table ``S1``: every network case refused)."""
    assert any(name.startswith("network") for name in NAMES)
    for name in NAMES:
        f = tmp_path / f"{name}.toml"
        f.write_text(toml_doc(base(name)))
        want = "network" if name.startswith("network") else name
        assert load_study(f)[1]["study"] == want, name


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


def _read(which: str, path, rows: int | None = None):
    """What the study reads of the file: Gama's network, or a table without its notes (its
    first ``rows`` rows)."""
    if which == "gama":
        return repr({k: v for k, v in read_gama(path).items() if k != "note"})
    t = getattr(tables, f"load_{which}")(path)
    return repr({k: v[:rows].tolist() for k, v in t.items() if k != "note"})


def _shorter(which: str, f, src) -> bool:
    """A table cut at the end of a row (or in the last number of a row without its note) is a
    valid shorter table, which no reader can tell from one written so: its rows but the last
    are the first rows of the table."""
    if which == "gama":
        return False
    n = getattr(tables, f"load_{which}")(f)["point"].size
    return _read(which, f, n - 1) == _read(which, src, n - 1)


def test_fuzz_bytes_of_data_files(tmp_path, capsys):
    """BYTES of a GNU Gama XML file and of Wolf's two reading tables (tests/fuzz_bytes.py):
    ``sim check`` of the study that reads the file must read it as the same input (exit 0) or
    refuse it in one line naming the file (exit 2); a table cut at the end of a row is a
    shorter table, whose rows must be the table's first rows."""
    srcs = {
        "gama": ROOT / "tests" / "data" / "gama" / "one_fixed.xml",
        "table1": ROOT / "studies" / "data" / "wolf_table1.csv",
        "table3": ROOT / "studies" / "data" / "wolf_table3.csv",
    }
    wolf = str(ROOT / "studies" / "wolf_polynomial.toml")
    failures = []
    for i in range(3 * CASES):
        which = sorted(srcs)[i % 3]
        text = srcs[which].read_text(encoding="utf-8")
        sites = gama_sites(text) if which == "gama" else csv_sites(text)
        data, desc = mutate_bytes(random.Random(SEED * 100_003 + 55_555 + i), text, sites)
        f = tmp_path / f"{which}-{i}.{'xml' if which == 'gama' else 'csv'}"
        f.write_bytes(data)
        if which == "gama":
            study = tmp_path / "gama.toml"
            study.write_text(
                f'study = "network"\ntrials = 40\nchunk = 2\n[network]\ngama_xml = "{f}"\n'
            )
            rc = main(["check", str(study)])
        else:
            rc = main(["check", wolf, "--set", f'{which}.file="{f}"'])
        err = capsys.readouterr().err.strip()
        if desc == "cut" and rc == 0 and _shorter(which, f, srcs[which]):
            continue
        if rc == 0 and _read(which, f) != _read(which, srcs[which]):
            failures.append(f"case {i} ({which}: {desc}): exit 0 but read as another input")
        elif rc not in (0, 2) or (rc == 2 and ("\n" in err or str(f) not in err)):
            failures.append(f"case {i} ({which}: {desc}): exit {rc}: {err[-300:]}")
    assert not failures, f"{len(failures)} of {3 * CASES}:\n" + "\n".join(failures)


def test_fuzz_splice(tmp_path, capsys):
    """SPLICE (tests/fuzz_splice.py) by ``sim check``: a study file crossed with another
    study's must be refused naming the key it brought in, or be a valid file (exit 0); a GNU
    Gama file with an element or attribute moved must be refused in one line naming the file
    and the element or attribute, or, moved as ``gama-local`` reads the same, read as it is."""
    gamas = [ROOT / "tests" / "data" / "gama" / f"{n}.xml" for n in ("one_fixed", "two_sets")]
    gamas += [ROOT / "tests" / "data" / "gama" / f"{n}.xml" for n in ("user_dms", "plate")]
    schemas = {n: load_study(ROOT / "studies" / f"{n}.toml")[0].schema for n in NAMES}
    failures = []
    for i in range(2 * CASES):
        rng, name = random.Random(SEED * 100_003 + 33_333 + i), NAMES[i % len(NAMES)]
        text, desc = splice_case(rng, name, base(name), schemas[name])
        (f := tmp_path / "study.toml").write_text(text)
        rc, err = main(["check", str(f)]), capsys.readouterr().err.strip()
        named = desc.split(": must name ")[-1].removeprefix("one of ").split()
        if rc not in (0, 2) or (rc == 2 and "\n" in err) or "Traceback" in err:
            failures.append(f"case {i} ({name}: {desc}): exit {rc}: {err[-300:]}")
        elif ": must name " in desc and (rc != 2 or not any(n in err for n in named)):
            failures.append(f"case {i} ({name}: {desc}): not refused naming it: {err[-300:]}")
    for i in range(2 * CASES):
        src = gamas[i % len(gamas)]
        rng = random.Random(SEED * 100_003 + 44_444 + i)
        text, desc, needle = gama_splice(rng, src.read_text(encoding="utf-8"))
        (x := tmp_path / f"splice-{i}.xml").write_text(text, encoding="utf-8")
        study = _gama_study(tmp_path, x)
        rc, err = main(["check", str(study)]), capsys.readouterr().err.strip()
        if needle is None and (rc != 0 or _read("gama", x) != _read("gama", src)):
            failures.append(f"case {i} ({src.name}: {desc}): exit {rc} or read as another input")
        elif needle and (rc != 2 or "\n" in err or str(x) not in err or needle not in err):
            failures.append(f"case {i} ({src.name}: {desc}): exit {rc}: {err[-300:]}")
    assert not failures, f"{len(failures)} of {4 * CASES}:\n" + "\n".join(failures)


def _gama_study(tmp_path: Path, x: Path) -> Path:
    """A small network study (40 trials in chunks of 2) reading the Gama file ``x``."""
    study = tmp_path / "gama.toml"
    study.write_text(f'study = "network"\ntrials = 40\nchunk = 2\n[network]\ngama_xml = "{x}"\n')
    return study


def test_fuzz_gama_values(tmp_path, capsys):
    """VALUES of a GNU Gama file (tests/fuzz_gama_values.py) by ``sim check``: one attribute
    given another value (no number, an edge, a padded number, another point's name) is read
    (exit 0) or refused in one line naming the file; no finite number where a number stood
    is refused."""
    srcs = ("one_fixed", "two_sets", "user_dms", "plate", "directions_free", "brown")
    failures = []
    for i in range(CASES):
        src = ROOT / "tests" / "data" / "gama" / f"{srcs[i % len(srcs)]}.xml"
        rng = random.Random(SEED * 100_003 + 49_049 + i)
        text, desc, refuse = gama_value(rng, src.read_text(encoding="utf-8"))
        (x := tmp_path / f"value-{i}.xml").write_text(text, encoding="utf-8")
        study = _gama_study(tmp_path, x)
        rc, err = main(["check", str(study)]), capsys.readouterr().err.strip()
        if rc not in (0, 2) or (rc == 2 and ("\n" in err or str(x) not in err)):
            failures.append(f"case {i} ({src.name}: {desc}): exit {rc}: {err[-300:]}")
        elif refuse and rc != 2:
            failures.append(f"case {i} ({src.name}: {desc}): no number, read as one")
    assert not failures, f"{len(failures)} of {CASES}:\n" + "\n".join(failures)


def test_fuzz_sweep_levels(tmp_path, capsys, monkeypatch):
    """SWEEP LEVELS (tests/fuzz_sweep.py) by ``sim check``: a small ``[sweep]`` table of each
    study with a level mutated must be refused in one line naming the key as written (a
    level of the wrong type may be read as one instead: ``0x10``); in ``make fuzz`` a work
    limit against thousands of cells too, and a third of the files that pass run by
    ``sim run`` (tests/fuzz_run.py)."""
    n, long = max(2, CASES // 5), CASES > 14
    failures = []
    for i in range(n):
        rng, name = random.Random(SEED * 100_003 + 66_666 + i), NAMES[i % len(NAMES)]
        schema = load_study(ROOT / "studies" / f"{name}.toml")[0].schema
        kind = None if long else ("empty", "duplicate")[i % 2]  # make test: the classes fixed
        lines, desc, needle, env, key = sweep_case(rng, flat := base(name), schema, long, kind)
        (d := tmp_path / f"case{i}").mkdir()
        (f := d / "study.toml").write_text(toml_doc(flat) + "\n".join(lines) + "\n")
        with monkeypatch.context() as m:
            for k, v in env.items():
                m.setenv(k, v)
            rc = main(["check", str(f)])
        err = capsys.readouterr().err.strip()
        said = [ln for ln in err.splitlines() if ln.strip()]
        # two keys swept, every cell refused: named by the key its reasons name, or "sweep"
        every = needle is None and err.startswith("sim: error: sweep") and "nothing to run" in err
        if rc not in (0, 2) or (rc == 2 and len(said) != 1) or "Traceback" in err:
            failures.append(f"case {i} ({name}: {desc}): exit {rc}: {err[-300:]}")
        elif (needle and rc != 2) or (rc == 2 and (needle or key) not in err and not every):
            failures.append(
                f"case {i} ({name}: {desc}): not refused naming {needle or key}: {err[-300:]}"
            )
        elif rc == 0 and long and rng.random() < 1 / 3:
            code, _, err, secs, argv = run_case(
                d, f, [], float(os.environ.get("FUZZ_TIMEOUT", "300"))
            )
            if bad := check_case(d, code, err, []):
                failures.append(f"case {i} ({name}: {desc}; {secs:.0f} s): sim {argv}: {bad}")
    assert not failures, f"{len(failures)} of {n}:\n" + "\n".join(failures)


def test_fuzz_sequences(tmp_path):
    """SEQUENCE (tests/fuzz_sequence.py): seeded orders of runs, interrupts, resumes, edits,
    overrides, ``sim show``, ``sim report``, verify, sweeps, ``--stale-only``, hand edits and
    the API on one output directory; after each step the results there are one whole run of
    a config a step asked for, equal to its clean run, or the step was refused in one line."""
    n = max(2, CASES // 10)
    failures = sequences(n, SEED, tmp_path)
    assert not failures, f"{len(failures)} of {n} sequences:\n" + "\n".join(failures)


def test_fuzz_concurrent(tmp_path):
    """CONCURRENT (tests/fuzz_concurrent.py): seeded pairs of operations on one output
    directory at once; after both, each exited 0 or was refused in one line (a run naming the
    other), and the results are one whole run of a config one of them (or the results before)
    stood for, equal to its clean run, and the next run of the study file runs."""
    n = max(2, CASES // 7)
    failures = pairs(n, SEED, tmp_path)
    assert not failures, f"{len(failures)} of {n} pairs:\n" + "\n".join(failures)


def test_fuzz_file_system(tmp_path):
    """FILE SYSTEM (tests/fuzz_fs.py): seeded limits (``ulimit -f``, ``ulimit -n``) and things
    in the way at each level of the output tree under a run; each run exits 0 or refuses in
    one line naming the file or thing, changes nothing beside the results, and the user's
    remedy then gives the clean run's results."""
    n = max(2, CASES // 7)
    failures = fs_cases(n, SEED, tmp_path)
    assert not failures, f"{len(failures)} of {n} file-system cases:\n" + "\n".join(failures)


def test_fuzz_results_directory(tiny_run, tmp_path):
    """RESULTS (tests/fuzz_results.py): seeded changes of a finished run's files (bytes, kind,
    a table rewritten with its metadata, the run record, the trials) read by show, report,
    the API and verify: exit 0 giving what the clean run gives, or one line; nothing changed."""
    n = max(3, CASES // 3)
    failures = results_cases(n, SEED, tmp_path, tiny_run("network_plate"))
    assert not failures, f"{len(failures)} of {n} results cases:\n" + "\n".join(failures)


def test_fuzz_api_types(tmp_path):
    """API TYPES (tests/fuzz_api_types.py): seeded calls of ``sim.load``, ``replace``,
    ``run`` (into a finished run's directory: no new run), ``sim.Results`` and ``table`` with
    one argument of an odd type: what the plain value gives, or one ConfigError line that
    starts with the argument's name; never the caller's object's own exception."""
    (study := tmp_path / "tri.toml").write_text(TRIANGLE_NETWORK)
    res = sim.load(study).run(out=(out := tmp_path / "out"), figures=False)
    failures = []
    for i in range(3 * CASES):
        c = api_case(random.Random(SEED * 100_003 + 58_585 + i), study, out, res)
        if (why := api_check(c)) is not None:
            failures.append(f"case {i} ({c.desc}): {why}")
    assert not failures, f"{len(failures)} of {3 * CASES}:\n" + "\n".join(failures)


if __name__ == "__main__":  # pragma: no cover - the long run: make fuzz
    sys.exit(pytest.main([__file__, "-q", "-x", "-p", "no:cacheprovider"]))
