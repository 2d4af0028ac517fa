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

``make`` targets, the commands of the code blocks and the links are test_docs.py's.
"""

from __future__ import annotations

import fnmatch
import math
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
REFUSED_KEYS = {"comparator.beta"}
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
OTHER_PROGRAMS = {"--build", "--target", "--algorithm", "--xml"}


def test_every_option_the_docs_name_is_an_option_of_the_suite():
    opts = set(re.findall(r"(--[a-z][\w-]*)", help_texts()))
    wrong = []
    for page in PAGES:
        for line, span in ticks(page):
            for o in re.findall(r"(?<![\w-])(--[a-z][\w-]*)", span):
                if o not in opts and o not in OTHER_PROGRAMS:
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


STATED = re.compile(
    r"`([a-z_0-9]+(?:\.[a-z_0-9]+)+)` = (-?[\d.]+(?:e-?\d+)?)|`([a-z_0-9]+(?:\.[a-z_0-9]+)+) = (-?[\d.]+(?:e-?\d+)?)`"
)


def test_every_value_the_docs_state_for_a_key_is_a_study_files():
    """``the same `table1.trials` = 48 blocks``, ``(`table1.rounds = 0`: ...)``: a value a page
    states for a key is the value of that key in a study file (the agnard page said the
    scanner's vectors were 16 where `table1.points` had been raised to 32)."""
    wrong = []
    stated = 0
    for page in prose_pages():
        text = page.read_text()
        for m in STATED.finditer(text):
            key, value = (m.group(1), m.group(2)) if m.group(1) else (m.group(3), m.group(4))
            have = [c[key] for c in configs().values() if key in c]
            if not have:
                continue  # not a key (test_every_dotted_name_...)
            stated += 1
            if not any(float(v) == float(value) for v in have if isinstance(v, (int, float))):
                line = text[: m.start()].count("\n") + 1
                wrong.append(f"{page.relative_to(ROOT)}:{line}: {key} = {value}, files: {have}")
    assert stated >= 4
    assert not wrong, "values the docs state that no study file has:\n" + "\n".join(wrong)


def test_the_agnard_page_counts_the_scanner_vectors_the_run_explores():
    """The scanner region and the joint design: `table1.points` vectors (scanner_region.parquet
    rows), two joint points per vector (joint_region.parquet rows)."""
    n = configs()["agnard_block"]["table1.points"]
    res = ROOT / "results" / "agnard_block"
    assert pq.read_metadata(res / "scanner_region.parquet").num_rows == n
    assert pq.read_metadata(res / "joint_region.parquet").num_rows == 2 * n
    text = (ROOT / "docs" / "papers" / "agnard-nolette-gagnon.md").read_text()
    assert f"every explored vector (`table1.points` = {n}" in text
    assert f"{2 * n} joint points, {n} with\nthe centres" in text


def _cells(table_head: str, text: str) -> list[list[str]]:
    block = text.split(table_head)[1].split("\n\n")[0]
    return [[c.strip() for c in r.strip("|").split("|")] for r in block.splitlines()[2:]]


def _num(cell: str) -> float:
    return float(cell.replace(",", ""))


def test_the_sparse_page_measures_are_the_committed_bench_rows():
    """docs/sparse.md's *Measured* tables are the rows of the committed
    results/bench/scaling.parquet, to the digits printed (the page gave a run on a loaded
    machine, 10.5 s for the 10,000-point analytic row and "target missed", where the record
    says 2.5 s)."""
    text = (ROOT / "docs" / "sparse.md").read_text().split("## Measured\n")[1]
    rows = pq.read_table(ROOT / "results" / "bench" / "scaling.parquet").to_pylist()

    def close(cell: str, value: float) -> bool:
        return math.isclose(_num(cell), value, rel_tol=0.05, abs_tol=5e-5)

    net = [r for r in rows if r["kind"] in ("trilateration", "triangulation")]
    cells = _cells("| network | points |", text)
    assert len(cells) == len(net)
    for c, r in zip(cells, net):
        assert c[0] == r["kind"] and _num(c[1]) == r["points"] and _num(c[2]) == r["unknowns"]
        for cell, col in zip(
            c[3:7], ("factor_nonzeros", "analytic_s", "mc_s_per_trial", "peak_mib")
        ):
            assert close(cell, r[col]), (c, col, r[col])
        if not c[7].startswith("--"):
            assert close(c[7], r["gama_s"]), (c, r["gama_s"])
    grid = [r for r in rows if r["kind"] == "gridplate"]
    cells = _cells("| grid plate | points |", text)
    assert len(cells) == len(grid)
    for c, r in zip(cells, grid):
        assert _num(c[1]) == r["points"] and _num(c[2]) == r["unknowns"]
        for cell, col in zip(c[3:6], ("analytic_s", "mc_s_per_trial", "peak_mib")):
            assert close(cell, r[col]), (c, col, r[col])
    block = [r for r in rows if r["kind"] == "block"]
    cells = _cells("| block | models |", text)
    assert len(cells) == len(block)
    for c, r in zip(cells, block):
        assert _num(c[2]) == r["points"] and _num(c[3]) == r["unknowns"]
        for cell, col in zip(c[6:9], ("analytic_s", "mc_s_per_trial", "peak_mib")):
            assert close(cell, r[col]), (c, col, r[col])


def test_the_batch_help_states_the_run_options_cli_md_documents():
    """docs/cli.md: in ``python -m sim.batch`` "the run options after ``--`` are read once, as
    ``sim run`` reads them"; its --help showed ``files [files ...]`` and no such part (and RST
    quotes, ``make reproduce``); ``sim check --help`` gave no meaning for ``--set``."""
    assert "run options after `--`" in " ".join((ROOT / "docs" / "cli.md").read_text().split())
    r = subprocess.run(
        [sys.executable, "-m", "sim.batch", "-h"], capture_output=True, text=True, cwd=ROOT
    )
    words = " ".join(r.stdout.split())
    assert "[-- RUN_OPTIONS]" in words and "so --out is refused" in words, r.stdout
    assert "``" not in r.stdout
    r = subprocess.run(
        [sys.executable, "-m", "sim", "check", "-h"], capture_output=True, text=True, cwd=ROOT
    )
    assert re.search(r"--set KEY=VALUE\s+override a config key", r.stdout), r.stdout


def test_every_make_variable_a_user_may_set_is_named_by_make_help():
    """The Makefile's ``VAR ?= default`` knobs (RUN_JOBS, RUN_FLAGS, MUTATION_WORKERS,
    BENCH_OUT, PYTHON) were named by no page and not by ``make help``."""
    text = (ROOT / "Makefile").read_text()
    knobs = re.findall(r"^([A-Z][A-Z_]*) *\?=", text, re.M)
    assert len(knobs) >= 6
    helps = " ".join(re.findall(r"^[\w.-]+:.*## (.*)$", text, re.M))
    missing = [k for k in knobs if k not in helps]
    assert not missing, f"make help names no {missing}"


def test_what_the_docs_say_of_the_gama_local_export(tmp_path):
    """README.md said every run exports its network as ``network.xml``, and docs/network.md
    that the export refuses the additive constant, the offset, the scale and ``dx``/``dy``:
    a network with biases is not exported (the summary says why), while a known constant and
    offset (network_brown) and ``dx``/``dy`` pairs (network_plate) are."""
    res = ROOT / "results"
    brown = configs()["network_brown"]
    assert brown["network.constant_mm"] != 0 and brown["network.offset_mm"] != 0
    assert (res / "network_brown" / "network.xml").is_file()
    assert "<vec " in (res / "network_plate" / "network.xml").read_text()
    words = " ".join((ROOT / "docs" / "network.md").read_text().split())
    assert "refuses biases, the additive constant, the offset" not in words
    assert "every run exports its network" not in " ".join((ROOT / "README.md").read_text().split())

    readme = (ROOT / "README.md").read_text()
    toml = re.search(r"```toml\n(# my_network\.toml.*?)```", readme, re.S).group(1)
    biased = toml.replace("sigma_mm = 0.002 }", "sigma_mm = 0.002, bias_mm = 0.001 }")
    assert biased != toml
    f = tmp_path / "my_network.toml"
    f.write_text(biased)
    out = sim.load(f, trials=40, chunk=2).run(out=tmp_path / "out", figures=False).path
    assert not (out / "network.xml").exists()
    why = pq.read_table(out / "summary.parquet").column("gama_xml").to_pylist()[0]
    assert why.startswith("not exported") and "bias" in why, why


@pytest.mark.parametrize(
    "override, key",
    [
        (
            {
                "network.generate": [
                    {"kind": "distance", "from": ["A", "B"], "to": "N*", "sigma_mm": 1.0},
                    {
                        "kind": "distance",
                        "from": ["C"],
                        "to": "N*",
                        "sigma_mm": 1.0,
                        "bias_mm": -2e5,
                    },
                ]
            },
            "network.generate[1].bias_mm",
        ),
        (
            {
                "network.observations": [
                    {"kind": "distance", "from": "A", "to": "N1", "sigma_mm": 1.0},
                    {"kind": "distance", "from": "A", "to": "N2", "sigma_mm": 1.0, "bias_mm": -2e5},
                ]
            },
            "network.observations[1].bias_mm",
        ),
    ],
)
def test_a_bias_that_reads_a_negative_length_names_its_key(override, key):
    """docs/network.md: "A bad network ... gives one line naming the key", and "a distance
    whose `bias_mm` would make it read a negative length is refused by `sim check`": it was
    refused naming ``network.observations`` also for a bias of ``network.generate[1]``."""
    with pytest.raises(sim.ConfigError) as e:
        sim.load(ROOT / "studies" / "network_testfield.toml", **override)
    assert str(e.value).startswith(f"{key}: the distance from"), str(e.value)


def test_the_settings_bound_network_md_states():
    """docs/network.md: "at most 1,000,000 settings": 1,000,000 is accepted, 1,000,001 refused,
    and the line says the number (it read "1e+06 readings ...: over 1e+06", a bound broken
    by an equal number)."""
    f = ROOT / "studies" / "network_testfield.toml"
    assert "at most 1,000,000 settings" in " ".join(
        (ROOT / "docs" / "network.md").read_text().split()
    )

    def angle(n):
        o = {"kind": "angle", "at": "N6", "from": "N5", "to": "N7", "sigma_arcsec": 1.0}
        return {"network.observations": [{**o, "settings": n}]}

    sim.load(f, **angle(1_000_000))
    with pytest.raises(sim.ConfigError) as e:
        sim.load(f, **angle(1_000_001))
    assert "1,000,001 readings of sigma 1 arcsec: over 1,000,000" in str(e.value), str(e.value)


def test_the_studies_study_code_md_names_as_users_of_the_run_steps():
    """docs/study-code.md names the studies that use ``run_part`` and ``over_region`` (it
    named brown_design for both, which uses only ``run_part``, and left out agnard_block)."""
    text = " ".join((ROOT / "docs" / "study-code.md").read_text().split())
    pkg = {"gridplate_two_plates": "gridplate", "salsig_encoders": "salsig"}
    pkg |= {"wolf_polynomial": "wolf", "brown_design": "design", "agnard_block": "agnard"}
    for helper in ("run_part", "over_region"):
        said = re.search(rf"`{helper}` (?:is used )?by ((?:`\w+`(?:, | and )?)+)", text).group(1)
        named = set(re.findall(r"`(\w+)`", said))
        users = set()
        for study, d in pkg.items():
            src = "".join(f.read_text() for f in (ROOT / "sim" / "studies" / d).glob("*.py"))
            if re.search(rf"from sim\.studies\.run_steps import [^\n]*\b{helper}\b", src):
                users.add(study)
        assert named == users, (helper, named, users)


def _sets_of(path: Path) -> dict[str, set[str]]:
    """The literal string sets assigned by name in a module (``_p = {"name", ...}``)."""
    import ast

    out = {}
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.Assign) and isinstance(node.value, ast.Set):
            vals = {e.value for e in node.value.elts if isinstance(e, ast.Constant)}
            for t in node.targets:
                if isinstance(t, ast.Name):
                    out[t.id] = vals
    return out


def test_sim_check_names_every_field_a_network_record_accepts():
    """``sim check`` "prints every key with its meaning": a network record's description
    listed ``{name, x_mm, y_mm, role, sigma_mm}`` while the metre forms (``x_m``) and a
    direction's ``set`` are accepted too."""
    net = ROOT / "sim" / "studies" / "network"
    sets = _sets_of(net / "definition.py") | _sets_of(net / "validate.py")
    obs = sets["_OBS"]
    accepted = {
        "network.points": sets["_p"],
        "network.grids": sets["_g"] | {"sigma_mm"},
        "network.random": sets["_r"] | {"sigma_mm"},
        "network.observations": obs - {"nearest"},
        "network.generate": obs - {"at", "set"},
    }
    from sim.studies.network.schema import SCHEMA

    for key, fields in accepted.items():
        doc = SCHEMA[key].doc
        listed = set(re.findall(r"[a-z_]+\*?", doc.split("{")[1].split("}")[0]))
        for f in fields:
            ok = f in listed or any(x.endswith("*") and f.startswith(x[:-1]) for x in listed)
            assert ok, f"{key}: the validator accepts {f!r}, sim check's meaning lists {listed}"


def test_every_sim_load_of_a_docstring_example_loads(monkeypatch):
    """sim/api.py's example loaded brown_table1 with ``trials=400, chunk=100``: 4 chunks,
    which the study refuses (its jackknife intervals need 20). Every ``>>>`` line of the
    package that calls ``sim.load`` runs as written, from the repository's root."""
    monkeypatch.chdir(ROOT)
    lines = []
    for f in sorted((ROOT / "sim").rglob("*.py")):
        for line in f.read_text().splitlines():
            s = line.strip()
            if s.startswith(">>> ") and "sim.load(" in s:
                lines.append((f.relative_to(ROOT), s[4:].split("  #")[0]))
    assert lines
    for where, code in lines:
        try:
            exec(code, {"sim": sim})
        except sim.ConfigError as e:
            raise AssertionError(f"{where}: {code}: {e}") from None


def test_outputs_md_names_every_key_of_a_run_record():
    """docs/outputs.md's ``run.json`` entry names each key a run records (it gave the config
    and the code hash, with a stray "run.," and no ``versions``)."""
    import json

    text = (ROOT / "docs" / "outputs.md").read_text()
    entry = text.split("- `run.json`:")[1].split("\n- ")[0]
    for d in (ROOT / "results").iterdir():
        if (d / "run.json").is_file():
            for k in json.loads((d / "run.json").read_text()):
                assert f"`{k}`" in entry, (d.name, k)
    assert "`figures`" in entry or '"figures": false' in entry


def test_every_paper_page_names_its_studies_config_sections():
    """docs/index.md: "One page per paper, with its studies, their models, keys and outputs":
    the Ohio State, Wolf, Salsig and Agnard pages named almost none of their studies' keys
    (``comparator.*``, ``field.*``, ``b8.*``, ``block.*``, ...)."""
    assert "their models, keys and outputs" in (ROOT / "docs" / "index.md").read_text()
    for page, studies in PAPER_STUDIES.items():
        text = (ROOT / "docs" / "papers" / page).read_text()
        sections = {
            k.split(".")[0] for s in studies if s in configs() for k in configs()[s] if "." in k
        }
        missing = sorted(s for s in sections if f"`{s}." not in text)
        assert not missing, f"{page} names no key of {missing}"
