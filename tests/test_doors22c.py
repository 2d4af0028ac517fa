"""The documentation followed literally (sweep doors22c): what README.md and docs/ name in
their prose exists, as a new user on a fresh clone reads it.

Each class was found false in the docs and fixed there; each test fails on the pages before
the fix:

* a file of the repository named by its path (``sim/instruments/block/similarity_jit.py`` in
  docs/architecture.md, deleted with the kernel; ``results/brown_table1/trials``, which the
  committed results do not hold);
* an output file a page says a study writes (``consistent_set.parquet``, ``sweep.parquet``,
  ``sweep_values.parquet`` on the Brown, Salsig and Wolf pages and in docs/outputs.md, from
  before the consistent region) that no committed results directory holds;
* a config key a page names (``consistency.offset_min_mm`` in the Brown page's key table) that
  no study's schema has, and a default that table states against the study file's value;
* an option a page names that no parser of the suite has;
* docs/architecture.md opening a paragraph in mid-sentence ("whose Jacobian is mostly zero
  ..."): its *A new instrument* heading and first sentences were lost when the README was split.

``make`` targets, the commands of the code blocks and the links are test_docs.py's; the values,
counts and behaviour the pages state are test_doors22c_values.py's.
"""

from __future__ import annotations

import fnmatch
import re
import subprocess
import sys
from functools import lru_cache
from pathlib import Path

import pyarrow.parquet as pq
import pytest
from conftest import ROOT
from oneline import one_line_of

import sim

PAGES = [ROOT / "README.md", *sorted((ROOT / "docs").rglob("*.md"))]
#: written by ``make mutation``: it names mutants, not files or keys
GENERATED = {"mutation.md"}
TICKS = re.compile(r"`([^`\n]+)`")


def ticks(page: Path):
    """``(line, text)`` of every inline code span of the page (code blocks left out)."""
    text = re.sub(
        r"^```.*?^```", lambda m: "\n" * m.group(0).count("\n"), page.read_text(), flags=re.M | re.S
    )
    for m in TICKS.finditer(text):
        yield text[: m.start()].count("\n") + 1, m.group(1)


def prose_pages():
    return [p for p in PAGES if p.name not in GENERATED]


# ---------------------------------------------------------------- repository paths

#: paths a page names as gone, each with the words that say so beside it
NAMED_AS_DELETED = {("benchmark.md", "sim/mc/heap.py"): "Deleted because no row justified them"}
PATH = re.compile(r"(?<![\w./-])((?:sim|tests|studies|benchmarks|docs|results|\.ci)/[\w./-]*)")


def test_every_repository_path_the_docs_name_exists():
    missing = []
    for page in prose_pages():
        text = page.read_text()
        for line, span in ticks(page):
            if span.startswith("cd "):  # a shell step into a directory of the user's choosing
                continue
            for path in PATH.findall(span):
                path = path.rstrip(".")
                why = NAMED_AS_DELETED.get((page.name, path))
                if why is not None:
                    assert why in text, f"{page.name}: {path} is no longer said to be deleted"
                    continue
                if not (ROOT / path).exists():
                    missing.append(f"{page.relative_to(ROOT)}:{line}: {path}")
    assert not missing, "the docs name paths that do not exist:\n" + "\n".join(missing)


# ---------------------------------------------------------------- output files

#: the studies of each paper page (its output lists are about these)
PAPER_STUDIES = {
    "brown-1968.md": ["brown_dilution", "brown_table1", "brown_design"],
    "ohio-state-two-plates.md": ["gridplate_two_plates"],
    "wolf-pearsall-1976.md": ["wolf_polynomial"],
    "salsig-1985.md": ["salsig_encoders"],
    "agnard-nolette-gagnon.md": ["agnard_block", "agnard_block_104"],
}
#: files a [sweep] run writes (docs/sweeps.md) and `make bench`'s directory: no study run's
SWEEP_FILES = {"sweep.parquet", "sweep.png"}
OUTPUT = re.compile(r"(?<![\w/.-])([\w*]+\.(?:parquet|png))\b")


def written(studies) -> set[str]:
    out = set()
    for s in studies:
        d = ROOT / "results" / s
        if d.is_dir():
            out |= {p.name for p in d.iterdir()}
    return out


def test_every_output_file_a_page_names_is_written():
    every = written(p.name for p in (ROOT / "results").iterdir()) | SWEEP_FILES
    wrong = []
    for page in prose_pages():
        have = written(PAPER_STUDIES[page.name]) if page.name in PAPER_STUDIES else every
        for line, span in ticks(page):
            if "/" in span and not span.startswith("results/bench/"):
                continue  # a path (test_every_repository_path_the_docs_name_exists)
            for name in OUTPUT.findall(span):
                if not any(fnmatch.fnmatchcase(h, name) for h in have):
                    wrong.append(f"{page.relative_to(ROOT)}:{line}: {name}")
    assert not wrong, "files no committed run of the page's studies writes:\n" + "\n".join(wrong)


def test_the_paper_pages_map_to_their_results():
    assert set(PAPER_STUDIES) == {p.name for p in (ROOT / "docs" / "papers").glob("*.md")}
    for studies in PAPER_STUDIES.values():
        for s in studies:
            assert (ROOT / "results" / s / "claims.parquet").is_file(), s


# ---------------------------------------------------------------- config keys


@lru_cache(maxsize=None)
def configs() -> dict[str, dict]:
    """The resolved config of every study file (its name -> config)."""
    return {f.stem: sim.load(f).config for f in sorted((ROOT / "studies").glob("*.toml"))}


@lru_cache(maxsize=None)
def claim_ids() -> frozenset[str]:
    ids = set()
    for f in (ROOT / "results").glob("*/claims.parquet"):
        ids |= set(pq.read_table(f, columns=["claim"]).column("claim").to_pylist())
    return frozenset(ids)


@lru_cache(maxsize=None)
def source() -> str:
    return "".join(f.read_text() for f in (ROOT / "sim").rglob("*.py"))


def module_names() -> set[str]:
    """Every module, package and top-level name of the suite, as a page may name it
    (``compile.compiled``, ``book_region.sample_evidence``)."""
    names = set()
    for f in (ROOT / "sim").rglob("*.py"):
        names.add(f.stem)
        names.add(f.parent.name)
    return names


#: first parts of dotted names that are not the suite's: libraries, pyproject tables, tests
FOREIGN = {
    "np",
    "numpy",
    "scipy",
    "linalg",
    "chi2",
    "time",
    "os",
    "sys",
    "monkeypatch",
    "tool",
    "t",
}
#: keys a page names as refused (docs/cli.md: the guess for a mistyped key)
# names the docs give as refused or as a slip the API answers (python.md: res.trials)
REFUSED_KEYS = {"comparator.beta", "plate.spacing_um", "res.claims.num_rows", "res.trials"}
DOTTED = re.compile(r"(?<![\w./-])([a-z_][a-z0-9_]*(?:\.[a-z0-9_*{},]+)+)(?![\w(])")


def _claim_like(tok: str) -> bool:
    """A claim id, or a part of one as the pages abbreviate it (``control_5.check_z_cm``,
    ``agnard.control_21.*``, ``control_{5,21}.{ctrl,check}_xy_cm``, ``control_21_``)."""
    alts = [tok]
    while any("{" in a for a in alts):
        nxt = []
        for a in alts:
            m = re.search(r"\{([^}]*)\}", a)
            if m is None:
                nxt.append(a)
                continue
            nxt += [a[: m.start()] + x + a[m.end() :] for x in m.group(1).split(",")]
        alts = nxt
    for a in alts:
        pat = a + "*" if a.endswith("_") else a
        ok = any(
            fnmatch.fnmatchcase(i, pat)
            or fnmatch.fnmatchcase(i, "*." + pat)
            or fnmatch.fnmatchcase(i, pat + ".*")
            or fnmatch.fnmatchcase(i, "*." + pat + ".*")
            or fnmatch.fnmatchcase(i, "*." + pat + "_*")  # without its unit: `after.max_y`
            for i in claim_ids()
        )
        if not ok:
            return False
    return True


def _key_like(tok: str, keys: set[str]) -> bool:
    t = tok[len("sweep.") :] if tok.startswith("sweep.") and tok != "sweep.trials" else tok
    if t in keys or tok == "sweep.trials":  # sweeps.md: the refused `sweep.trials`, by name
        return True
    if t.endswith(".*"):
        return any(k.startswith(t[:-1]) for k in keys)
    return False


def test_every_dotted_name_the_docs_give_is_a_key_a_claim_or_a_module():
    keys = {k for c in configs().values() for k in c}
    sections = {k.split(".")[0] for k in keys if "." in k}
    modules = module_names()
    unknown = []
    for page in prose_pages():
        for line, span in ticks(page):
            if (
                re.search(r"\.(py|md|toml|parquet|png|json|xml|txt|csv|gkf)\b", span)
                and "=" not in span
            ):
                continue  # a file name
            for tok in DOTTED.findall(span):
                tok = tok.rstrip(".,")
                first = tok.split(".")[0]
                if first in FOREIGN or first == "sim" or "*" in first or tok in REFUSED_KEYS:
                    continue
                if re.search(r"\.(xml|toml|py|md|parquet|png|json|csv)$", tok):
                    continue  # a file name
                if f'"{tok}"' in source():
                    continue  # a name the suite's code declares (a region statement's id)
                if first in sections and _key_like(tok, keys):
                    continue
                if tok.startswith("sweep.") and _key_like(tok, keys):
                    continue
                if _claim_like(tok):
                    continue
                if first in modules and first not in sections:
                    continue  # module.attribute
                unknown.append(f"{page.relative_to(ROOT)}:{line}: {tok}")
    assert not unknown, "dotted names that are no key, claim or module:\n" + "\n".join(unknown)


def _value(text: str):
    """A default as the Brown page's key table writes it: a number, a list or a word."""
    text = text.strip().strip("`")
    if text.startswith("["):
        return [float(x) for x in text.strip("[]").split(",") if x.strip()]
    try:
        return float(text)
    except ValueError:
        return text


def test_the_brown_key_table_gives_the_study_files_values():
    """docs/papers/brown-1968.md's *Config keys* table: every key is one of the two studies',
    and its default (``dilution / table1`` where they differ) is the study file's value."""
    text = (ROOT / "docs" / "papers" / "brown-1968.md").read_text()
    table = text.split("| key | default (dilution / table1) | meaning |")[1].split("\n\n")[0]
    cfg = {"dilution": configs()["brown_dilution"], "table1": configs()["brown_table1"]}
    rows = [r for r in table.splitlines() if r.startswith("| `")]
    assert len(rows) >= 15
    for row in rows:
        cells = [c.strip() for c in row.strip("|").split("|")]
        keys = re.findall(r"`([^`]+)`", cells[0])
        only = re.search(r"\((dilution|table1)\)", cells[0])
        studies = [only.group(1)] if only else ["dilution", "table1"]
        # "4000, 1968 / 1967, 200": one value a key, a " / " inside one of them; "1.0, 1 /
        # 1.7, 2": the whole cell per study; "[3, 4, ...]": one key's list
        parts = [cells[1]] if len(keys) == 1 else cells[1].split(", ")
        if len(parts) == len(keys):
            per = {
                s: [v.split(" / ")[i] if " / " in v else v for v in parts]
                for i, s in enumerate(["dilution", "table1"])
            }
        else:
            both = cells[1].split(" / ")
            assert len(both) == 2, row
            per = {s: v.split(", ") for s, v in zip(["dilution", "table1"], both)}
        for s in studies:
            values = per[s]
            assert len(values) == len(keys), row
            for k, v in zip(keys, values):
                assert k in cfg[s], f"{row}: {k} is not a key of brown_{s}"
                want, got = _value(v), cfg[s][k]
                if isinstance(want, float):
                    assert float(got) == pytest.approx(want), f"{k} (brown_{s}): {got}, not {v}"
                elif isinstance(want, list):
                    assert [float(x) for x in got] == want, f"{k} (brown_{s}): {got}, not {v}"
                else:
                    assert str(got) == want, f"{k} (brown_{s}): {got!r}, not {v}"


# ---------------------------------------------------------------- options


@lru_cache(maxsize=None)
def help_texts() -> str:
    cmds = [
        ["-m", "sim", "-h"],
        *(["-m", "sim", c, "-h"] for c in ("run", "show", "check", "report")),
        ["-m", "sim.batch", "-h"],
        ["-m", "sim.report.verify", "-h"],
        ["-m", "benchmarks", "-h"],
    ]
    out = ""
    for c in cmds:
        r = subprocess.run([sys.executable, *c], capture_output=True, text=True, cwd=ROOT)
        assert r.returncode == 0, (c, r.stderr)
        out += r.stdout
    return out


#: options of other programs that the pages name (cmake, gama-local)
OTHER_PROGRAMS = {"--build", "--target", "--algorithm", "--xml", "--cov-band"}
# docs/cli.md's examples of prefixes every parser refuses (tests/test_doors29b.py asserts each is
# refused naming the option it abbreviates): named in the docs as what not to write
REFUSED_PREFIXES = {"--tri", "--no-fig", "--stale", "--o"}


def test_every_option_the_docs_name_is_an_option_of_the_suite():
    opts = set(re.findall(r"(--[a-z][\w-]*)", help_texts()))
    wrong = []
    for page in PAGES:
        for line, span in ticks(page):
            for o in re.findall(r"(?<![\w-])(--[a-z][\w-]*)", span):
                if o not in opts and o not in OTHER_PROGRAMS | REFUSED_PREFIXES:
                    wrong.append(f"{page.relative_to(ROOT)}:{line}: {o}")
    assert not wrong, "options no parser of the suite has:\n" + "\n".join(wrong)


def test_help_texts_point_to_pages_that_exist():
    """``python -m benchmarks -h`` said "(see README, Benchmark)": the README has no such
    section; the page is docs/benchmark.md."""
    text = help_texts()
    for ref in re.findall(r"see ([\w./-]+\.md)", text):
        assert (ROOT / ref).is_file(), ref
    assert "see README, Benchmark" not in text


# ---------------------------------------------------------------- paragraphs


def test_no_doc_paragraph_opens_in_mid_sentence():
    """A paragraph of prose starts with a capital, a mark-up character or a number, never with
    a lower-case word that continues a lost sentence (docs/architecture.md: "whose Jacobian is
    mostly zero ...")."""
    bad = []
    for page in prose_pages():
        text = re.sub(r"^```.*?^```", "", page.read_text(), flags=re.M | re.S)
        for para in re.split(r"\n\s*\n", text):
            first = para.lstrip("\n").split("\n")[0]
            if re.match(r"[a-z]", first) and not re.match(r"[a-z_]+[\w.]*\(|[a-z]+://", first):
                bad.append(f"{page.relative_to(ROOT)}: {first[:70]!r}")
    assert not bad, "paragraphs that open in mid-sentence:\n" + "\n".join(bad)


def test_the_mistyped_key_of_cli_md_is_refused_with_its_guess():
    """docs/cli.md: ``--set comparator.beta=0`` answers ``unknown key (did you mean
    comparator.beta_mm?)``."""
    text = (ROOT / "docs" / "cli.md").read_text()
    assert (
        "`--set comparator.beta=0` answers `unknown key (did you mean comparator.beta_mm?)`" in text
    )
    f = ROOT / "studies" / "brown_table1.toml"
    r = subprocess.run(
        [sys.executable, "-m", "sim", "check", str(f), "--set", "comparator.beta=0"],
        capture_output=True,
        text=True,
        cwd=ROOT,
    )
    line = one_line_of(r)
    assert line == "sim: error: comparator.beta: unknown key (did you mean comparator.beta_mm?)"
