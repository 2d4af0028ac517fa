"""FILE SYSTEM, a mutation kind of the fuzzer (tests/test_fuzz.py): the disk and the process's
limits under a run of one small study (the SEQUENCE kind's network, ``net.toml`` and
``net.xml``, 40 trials in chunks of 2, into ``res/net``).

A seeded case draws one of: a file-size limit (``ulimit -f``, ``RLIMIT_FSIZE``: a write past
it fails with EFBIG, as on a full disk) of 1 KB to 40 KB hit mid-run; too few file descriptors
(``RLIMIT_NOFILE``: those the process holds plus 0-24), with one or two workers; or a file
where a directory is expected, or a directory where a file is (holding a file of the user's),
at a level of the output tree: the parent of ``--out``, ``--out`` itself, its staging
directory ``.net.partial``, in the staging directory of a run interrupted at a marker (its
``trials``, ``part-0``, a chunk, ``run.json``), in finished results (``trials``, ``part-0``,
a chunk, a table, ``run.json``, ``README.md``), run again with or without ``--overwrite``.

Each run must exit 0, or 2 with one line (no traceback, no hang) that names the file the
limit cut short or the thing in the way; nothing outside ``res/net`` and its staging
directory changes (a file of the user's beside them, the thing in the way of the user's in
finished results); then the user's remedy (the limit lifted; the thing in the way moved
away, or ``--overwrite`` where the line says so) runs with exit 0, and the results are then a
complete run whose tables and chunks are a clean run's (a resume after the failure gives the
clean run's results). ``FUZZ_CASES`` sets the number of cases (one a seven, at least 2),
``FUZZ_FS_SECONDS`` the time after which no new one starts."""

from __future__ import annotations

import math
import os
import random
import re
import shutil
import signal
from pathlib import Path

from fuzz_sequence import XMLS, study_text
from fuzz_sequence_run import References, against_reference, budgeted, lines, sha256, spawn

MODEL = {"trials": 40, "seed": 0, "alpha": 0, "sweep": False}
ARGV = ["run", "net.toml", "--quiet", "--no-figures", "--out", "res/net"]
#: where a thing is put in the way: (level, a directory where a file goes?) relative to the
#: case's directory; a level under ``.net.partial`` is in an interrupted run's staging directory
STAGE = [("res/.net.partial/" + p, d) for p, d in [("trials", False), ("trials/part-0", False)]]
STAGE += [
    ("res/.net.partial/trials/part-0/chunk-000000.parquet", True),
    ("res/.net.partial/run.json", True),
]
DONE = [("res/net/" + p, d) for p, d in [("trials", False), ("trials/part-0", False)]]
DONE += [
    ("res/net/trials/part-0/chunk-000003.parquet", True),
    ("res/net/claims.parquet", True),
    ("res/net/run.json", True),
    ("res/net/README.md", True),
]
LEVELS = [("res", False), ("res/net", False), ("res/.net.partial", False), *STAGE, *DONE]


class Case:
    """One case's directory, its study, the clean run it is held to and the user's files."""

    def __init__(self, d: Path, refs: References):
        self.d, self.refs = d, refs
        self.out = d / "res" / "net"
        self.state = (study_text(MODEL), XMLS[0], ())
        self.asked = [self.state]
        d.mkdir(parents=True)
        (d / "net.toml").write_text(study_text(MODEL))
        (d / "net.xml").write_bytes(XMLS[0])
        (d / "notes.txt").write_text("the user's notes\n")
        self.n = 0

    def run(self, extra=(), limit=None):
        """``sim run`` of the study (``extra`` options; ``limit``: ``(resource, soft)`` set in
        the child first): ``(code, stderr's lines that are not notes, description)``."""

        def target():
            import resource

            from sim.cli import main

            if limit is not None:
                what, soft = limit
                if what == resource.RLIMIT_NOFILE:
                    soft += len(os.listdir("/proc/self/fd"))  # those it holds, plus `soft`
                resource.setrlimit(what, (soft, resource.getrlimit(what)[1]))
            return main([*ARGV, *extra])

        self.n += 1
        code, _, err = spawn(self.d, target, self.d / f"step{self.n}")
        return code, lines(err)

    def interrupted(self, k: int):
        """A run interrupted (SIGINT) at its ``k``-th rename: its staging directory."""

        def target():
            from sim.cli import main

            return main(ARGV)

        self.n += 1
        return spawn(self.d, target, self.d / f"step{self.n}", marker=(k, signal.SIGINT))[0]

    def outside(self) -> dict[str, str]:
        """The files of the case's directory outside the results and their staging directory."""
        keep = {self.out, self.out.with_name(".net.partial")}
        return {
            str(p.relative_to(self.d)): sha256(p)
            for p in self.d.rglob("*")
            if p.is_file()
            and not any(q in p.parents for q in keep)
            and not p.name.startswith("step")
        }


def _one_line(code, err: list[str], needle: tuple[str, ...] | None) -> str | None:
    """Exit 0, or 2 with one line (naming one of ``needle`` when given): the violation, or
    None."""
    if code == 0:
        return None
    if code != 2:
        return f"exit {code}: {' | '.join(err[-3:])[:400]}"
    if len(err) != 1 or "Traceback" in err[0]:
        return f"exit 2 but not one line: {' | '.join(err[-4:])[:400]}"
    if needle is not None and not any(n in err[0] for n in needle):
        return f"exit 2 but the line does not name {needle}: {err[0][:400]}"
    return None


def _plant(p: Path, is_dir: bool) -> dict[str, bytes]:
    """Put the user's thing in the way at ``p`` (a directory holding a file, or a file):
    the user's files it holds, by path."""
    if p.is_dir() and not p.is_symlink():
        shutil.rmtree(p)
    elif p.exists():
        p.unlink()
    p.parent.mkdir(parents=True, exist_ok=True)
    if is_dir:
        p.mkdir()
        (p / "mine.txt").write_bytes(b"the user's file\n")
        return {str(p / "mine.txt"): b"the user's file\n"}
    p.write_bytes(b"the user's file in the way\n")
    return {str(p): b"the user's file in the way\n"}


def _clean(c: Case) -> str | None:
    """Why ``res/net`` is not a complete run equal to the clean run, or None."""
    from fuzz_sequence_run import record

    rec = record(c.out)
    if rec is None:
        return "exit 0 but res/net holds no run record"
    ref, _, ref_dir = c.refs.get(c.state)
    if rec.get("config") != (ref or {}).get("config"):
        return "res/net holds another config"
    for f, h in (rec.get("chunk_sha256") or {}).items():  # git was out of reach (see _same)
        if h != ref["chunk_sha256"].get(f) and _same(c.out / f, ref_dir / f):
            rec["chunk_sha256"][f] = ref["chunk_sha256"][f]
    return against_reference(c, rec, set(), "no case asked for")


def _same(a: Path, b: Path) -> bool:
    """Whether two chunk files hold the same trials and identity, their provenance but its
    ``git_commit`` the same: a run short of file descriptors cannot start ``git`` and records
    the commit as "unknown" (as a run where git is missing does), its numbers unchanged."""
    import json

    import pyarrow.parquet as pq

    ta, tb = pq.read_table(a), pq.read_table(b)
    ma, mb = dict(ta.schema.metadata or {}), dict(tb.schema.metadata or {})
    pa_, pb = (json.loads(m.pop(b"sim.provenance", b"{}")) for m in (ma, mb))
    pa_.pop("git_commit", None), pb.pop("git_commit", None)
    data = ta.replace_schema_metadata(None).equals(tb.replace_schema_metadata(None))
    return data and ma == mb and pa_ == pb


def _limit(rng: random.Random, c: Case) -> tuple[str, str | None]:
    import resource

    workers = rng.choice([[], [], ["--workers", "2"]])
    if rng.random() < 0.6:
        size = int(math.exp(rng.uniform(math.log(1024), math.log(40_000))))
        desc = f"ulimit -f of {size} bytes {' '.join(workers)}"
        code, err = c.run(workers, (resource.RLIMIT_FSIZE, size))
        bad, first = _one_line(code, err, None), code
        if not bad and code == 2 and "res/" not in err[0]:
            bad = f"exit 2 but the line names no file of the results: {err[0][:400]}"
    else:
        extra = rng.randint(0, 24)
        desc = f"ulimit -n of the files held plus {extra} {' '.join(workers)}"
        code, err = c.run(workers, (resource.RLIMIT_NOFILE, extra))
        bad, first = _one_line(code, err, None), code
    if bad:
        return desc, bad
    code, err = c.run(workers)  # the limit lifted: the same command resumes or runs
    return desc + f" -> {first}; again -> {code}", _one_line(code, err, None) or (
        f"exit {code}" if code != 0 else _clean(c)
    )


def _in_the_way(rng: random.Random, c: Case) -> tuple[str, str | None]:
    level, is_dir = rng.choice(LEVELS)
    p = c.d / level
    desc = f"a {'directory' if is_dir else 'file'} at {level}"
    if level.startswith("res/.net.partial/"):  # an interrupted run's staging directory
        k = rng.randint(2, 22)
        desc += f" (a run interrupted at rename {k}: {c.interrupted(k)})"
        if not p.parent.is_dir():  # interrupted before it was there: nothing to put it in
            return desc, None
    elif level.startswith("res/net/"):
        if (code := c.run()[0]) != 0:
            return desc, f"the clean run first: exit {code}"
    users = _plant(p, is_dir)
    users_kept = not level.startswith("res/.net.partial/")  # (the staging is the suite's)
    before = c.outside()
    overwrite = rng.random() < 0.4
    code, err = c.run(["--overwrite"] * overwrite)
    desc += f" {'--overwrite ' * overwrite}-> {code}"
    named = p.parent if p.name == "run.json" else p  # (as a path, or as --out res/net spells it)
    needle = (str(named), str(named.relative_to(c.d)))
    if (bad := _one_line(code, err, needle)) is not None:
        return desc, bad
    if c.outside() != before:
        return desc, "a file outside res/net was changed or removed"
    if users_kept and any(
        not Path(f).is_file() or Path(f).read_bytes() != b for f, b in users.items()
    ):
        return desc, "the user's file in the way was deleted or changed"
    if code == 0:
        return desc, _clean(c)
    # the user's remedy: the line's (--overwrite), or the thing moved away (the results
    # themselves when their run record is: a directory without one is never sim's to replace)
    gone = c.out if named == c.out else p
    if gone.is_dir() and not gone.is_symlink():
        shutil.rmtree(gone)
    elif gone.exists():
        gone.unlink()
    again = ["--overwrite"] if re.search(r"(with|use) --overwrite to", err[0]) else []
    code, err = c.run(again)
    desc += f"; moved away, again {' '.join(again)} -> {code}"
    return desc, _one_line(code, err, None) or (f"exit {code}" if code else _clean(c))


def run_case(i: int, seed: int, tmp: Path, refs: References) -> str | None:
    rng = random.Random(seed * 100_003 + 46_046 + i)
    c = Case(tmp / f"fs{i:03d}", refs)
    desc, bad = (_limit if rng.random() < 0.45 else _in_the_way)(rng, c)
    if bad is None and c.outside().get("notes.txt") != sha256_text("the user's notes\n"):
        bad = "the user's notes beside the results were changed"
    if bad:
        return f"file-system case {i} (seed {seed}): {desc}: {bad}"
    shutil.rmtree(c.d, ignore_errors=True)
    return None


def sha256_text(s: str) -> str:
    import hashlib

    return hashlib.sha256(s.encode()).hexdigest()


def cases(n: int, seed: int, tmp: Path) -> list[str]:
    """Run ``n`` cases (fewer when ``FUZZ_FS_SECONDS`` run out): their failures."""
    return budgeted(run_case, n, seed, tmp, "FUZZ_FS_SECONDS")
