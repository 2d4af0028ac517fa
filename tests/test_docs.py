"""Every command in the README and in docs/ runs (issue 25), at a tiny size, into scratch
directories; the README stays short and its links resolve.

Per page, in a fresh working directory (``studies/`` linked, ``results/`` mirrored with its
files linked, so nothing in the repository is written): the page's ``toml`` blocks are
written to the file their first comment names, then its ``sh`` lines run in order and its
``python`` blocks run as scripts (but a block whose first line is ``# excerpt ...``, a part of
a module shown to be read). ``sim ...`` runs as ``python -m sim ...`` does, through
:func:`sim.cli.main` in the test's process; ``sim run`` gets its study's tiny configuration
(``tests/data/tiny/``) in place of ``--trials`` and runs with ``--no-figures`` (each study's
figures are drawn and layout-checked by its shared tiny run), and every ``/tmp/...`` path
becomes a path in the scratch directory; a Python block's temporary directories go there too. ``make TARGET`` lines are
checked to name a real target of the Makefile, not run. ``python -m MODULE ...`` of another
module is checked with ``--help``. Anything else is reported as unchecked (a warning).

``sim run studies/<file>.toml [OPTIONS] [--out DIR]`` is, at the tiny size, the session's
shared run of that file with those options (``tiny_run`` in conftest.py: the same command
with ``--quiet``, which leaves out the progress lines, and ``--workers 1``, the default):
its output is copied to DIR, and a run another test shares is not made twice.
"""

import contextlib
import io
import os
import re
import shlex
import shutil
import subprocess
import sys
import warnings
from pathlib import Path

import pytest
from conftest import ROOT, long_params, study_of, tiny_overrides

from sim.cli import main

PAGES = [ROOT / "README.md", *sorted((ROOT / "docs").rglob("*.md"))]
BLOCK = re.compile(r"^```(\w*)\n(.*?)^```", re.M | re.S)
TIMEOUT = 900


def blocks(page: Path) -> list[tuple[str, str]]:
    return [(m.group(1), m.group(2)) for m in BLOCK.finditer(page.read_text())]


def make_targets() -> set[str]:
    text = (ROOT / "Makefile").read_text()
    return set(re.findall(r"^([A-Za-z][\w.-]*):", text, re.M))


def mirror_results(dest: Path) -> None:
    """``dest`` holds the tree of ``results/`` with real directories and linked files (no
    per-trial datasets): a report written there replaces links, never the committed files."""
    src = ROOT / "results"
    for d, dirs, files in os.walk(src):
        dirs[:] = [x for x in dirs if x not in ("trials", "cells") and not x.startswith(".")]
        rel = Path(d).relative_to(src)
        (dest / rel).mkdir(parents=True, exist_ok=True)
        for f in files:
            if f.endswith(".md"):  # reports are rewritten, and a link is never replaced
                shutil.copy2(Path(d) / f, dest / rel / f)
            else:
                (dest / rel / f).symlink_to(Path(d) / f)


class Page:
    """Runs the commands of one page in ``work``; ``/tmp/X`` becomes ``work/tmp/X``."""

    def __init__(self, work: Path, shared=None):
        self.work = work
        self.shared = shared  # tiny_run: the session's tiny run of a study file
        self.unchecked: list[str] = []

    def path(self, arg: str) -> str:
        if arg.startswith("/tmp/"):
            return str(self.work / "tmp" / arg[len("/tmp/") :])
        return arg

    def sim(self, args: list[str]) -> list[str]:
        args = [self.path(a) for a in args]
        if args and args[0] == "run":
            study_file = self.work / args[1]
            out = []
            skip = False
            for a in args:
                if skip:
                    skip = False
                    continue
                if a == "--trials":  # the tiny configuration sets the size
                    skip = True
                    continue
                out.append(a)
            if self.reuse(out):
                return None
            # the figures of every study are drawn and layout-checked by its shared tiny
            # run (tiny_run in conftest.py); a page's own run is checked for its tables
            extra = [] if "--no-figures" in out else ["--no-figures"]
            args = out + extra + tiny_overrides(study_of(study_file))
        return [sys.executable, "-m", "sim", *args]

    def reuse(self, args: list[str]) -> bool:
        """``run studies/<file>.toml [OPTIONS] [--out DIR]``: the shared tiny run with those
        options, copied to DIR (with no --out, to no directory: the run goes to scratch/,
        which no page reads)."""
        if self.shared is None or len(args) < 2:
            return False
        f, options = Path(args[1]), args[2:]
        if f.parent != Path("studies") or not (ROOT / f).is_file():
            return False
        out = None
        if "--out" in options:
            k = options.index("--out")
            out, options = options[k + 1], options[:k] + options[k + 2 :]
        done = self.shared(f.stem, *options)
        if out is not None:
            shutil.copytree(done, self.work / out)
        return True

    def command(self, line: str) -> list[str] | None:
        words = shlex.split(line, comments=True)
        if not words:
            return None
        if words[0] == "make":
            target = next((w for w in words[1:] if "=" not in w and not w.startswith("-")), "")
            assert target in make_targets(), f"{line!r}: no make target {target!r}"
            return None
        if words[0] in (".venv/bin/sim", "sim"):
            return self.sim(words[1:])
        py = words[0] in (".venv/bin/python", "python", "python3")
        if py and words[1:3] == ["-m", "sim"]:
            return self.sim(words[3:])
        if py and len(words) > 2 and words[1] == "-m":
            return [sys.executable, "-m", words[2], "--help"]
        self.unchecked.append(line)
        return None

    def run(self, cmd: list[str], what: str) -> None:
        (self.work / "tmp").mkdir(exist_ok=True)
        if cmd[1:3] == ["-m", "sim"]:  # in this process: a second start of Python saves nothing
            return self.run_sim(cmd[3:], what)
        # TMPDIR: a run of the Python API without ``out`` writes to a temporary directory of
        # its own, which it leaves for the user to read; here it is the test's scratch
        env = dict(os.environ, TMPDIR=str(self.work / "tmp"))
        r = subprocess.run(
            cmd, cwd=self.work, capture_output=True, text=True, timeout=TIMEOUT, env=env
        )
        assert r.returncode == 0, f"{what}: exit {r.returncode}\n{r.stderr[-2000:]}"
        assert "Traceback" not in r.stderr, f"{what}:\n{r.stderr[-2000:]}"

    def run_sim(self, args: list[str], what: str) -> None:
        """``sim ARGS`` as :func:`sim.cli.main` in ``work`` (the console script and ``python
        -m sim`` are that function: test_cli.py); an exception fails the test with its
        traceback."""
        here, err = os.getcwd(), io.StringIO()
        os.chdir(self.work)
        try:
            with contextlib.redirect_stdout(io.StringIO()), contextlib.redirect_stderr(err):
                try:
                    code = main(args)
                except SystemExit as e:  # --version, --help
                    code = e.code
        finally:
            os.chdir(here)
        assert code in (0, None), f"{what}: exit {code}\n{err.getvalue()[-2000:]}"


# docs/sparse.md's commands (networks of thousands of points, 15 s of CPU) in make fuzz: the
# other pages' commands guard the class in make test, test_sparse the sparse path
@pytest.mark.parametrize(
    "page",
    long_params(PAGES, {ROOT / "docs" / "sparse.md"}),
    ids=[str(p.relative_to(ROOT)) for p in PAGES],
)
def test_every_command_of_the_page_runs(page, tmp_path, tiny_run):
    (tmp_path / "studies").symlink_to(ROOT / "studies")
    mirror_results(tmp_path / "results")
    runner = Page(tmp_path, tiny_run)
    ran = 0
    for i, (lang, text) in enumerate(blocks(page)):
        if lang == "toml":
            first = text.splitlines()[0]
            m = re.match(r"#\s*([\w.-]+\.toml)", first)
            if m:  # a study file a later command runs; other toml blocks are excerpts
                (tmp_path / m.group(1)).write_text(text)
        elif lang in ("sh", "bash", "console"):
            for line in text.splitlines():
                cmd = runner.command(line)
                if cmd is not None:
                    runner.run(cmd, f"{page.name}: {line.strip()}")
                    ran += 1
        elif lang == "python" and text.startswith("# excerpt"):
            continue  # a part of a module, shown to be read (its first line says from where)
        elif lang == "python":
            script = tmp_path / f"block_{i}.py"
            script.write_text(text)
            runner.run([sys.executable, str(script)], f"{page.name}: python block {i}")
            ran += 1
    if runner.unchecked:
        warnings.warn(f"{page.name}: commands not checked: {runner.unchecked}")


def exists(p: Path) -> bool:
    """A link target exists, or is a results directory's README.md, which ``sim report``
    (in ``make reproduce``) writes from the directory's ``claims.parquet``."""
    p = p.resolve()
    if p.name == "README.md" and p.parent.parent == ROOT / "results":
        return (p.parent / "claims.parquet").is_file() or p.exists()
    return p.exists()


def test_the_readme_is_short_and_its_links_resolve():
    text = (ROOT / "README.md").read_text()
    lines = text.splitlines()
    assert len(lines) <= 150
    assert max(len(ln) for ln in lines) <= 140
    assert "../shared" not in text and "seeds/" not in text
    for target in re.findall(r"\]\(([^)#\s]+)", text):
        if not target.startswith("http") and Path(target).name not in OTHER_PAGES:
            assert exists(ROOT / target), f"README links to a missing {target}"
    # the papers are named by authors and year, never by their OCR file names
    assert not re.search(r"00\d_[0-9a-f]{16}", text)


def test_the_docs_name_papers_by_authors_and_links_resolve():
    for page in PAGES[1:]:
        text = page.read_text()
        assert not re.search(r"00\d_[0-9a-f]{16}", text), page
        for target in re.findall(r"\]\(([^)#\s]+)", text):
            if target.startswith("http"):
                continue
            linked = (page.parent / target).resolve()
            other = linked.parent == ROOT / "docs" and linked.name in OTHER_PAGES
            if not other:  # pages of other parts may land later (docs/index.md lists them)
                assert exists(linked), f"{page.name} links to a missing {target}"


#: pages written by other parts of the suite, linked from docs/index.md
OTHER_PAGES = {
    "verdict-rules.md",
    "reproducibility.md",
    "gama.md",
    "sparse.md",
    "mutation.md",
    "benchmark.md",
    "inference.md",
}
