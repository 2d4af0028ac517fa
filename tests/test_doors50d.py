"""Helper d50: every statement of the docs, true on a fresh clone; one case per class found,
each failing on the code (or the page) before its fix. Read as a new user in a fresh clone:
README.md and docs/*.md, their commands run as written, their quoted messages, options,
defaults and counts held against the code, and the help texts of ``sim``, ``python -m
sim.batch``, ``python -m sim.report.verify`` and ``python -m benchmarks`` against the pages.
What did not hold:

* docs/reproducibility.md said ``tests/test_verify.py`` checks *every* study kind on another
  numerical path inside ``make test``; since the ``long`` marker, agnard_block's and
  brown_design's cases run in ``make fuzz`` only (``make test`` skips them).
* ``python -m sim.batch --help`` printed a usage line without ``--report`` (a usage written
  by hand, older than the option), though the option is listed below it and ``make
  reproduce`` passes it.
* A new user could not learn from the README or docs/index.md that ``agnard_block_104`` and
  ``network_gridplate_2500`` are study files of the project: the README's table of the papers'
  studies and docs/network.md's list of the example networks each left one out.
* ``python -m sim.report.verify --help`` did not give ``--workers``' default (1; ``make
  verify`` passes 2) nor ``--trials``' floor (400), which it refuses below.
"""

from __future__ import annotations

import contextlib
import io
import re
from pathlib import Path

import pytest

from sim import batch
from sim.cli import main
from sim.report.verify import cli as verify_cli

ROOT = Path(__file__).resolve().parents[1]


def _help(fn, argv) -> str:
    out = io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(io.StringIO()):
        try:
            code = fn(argv)
        except SystemExit as e:  # python -m benchmarks --help: argparse's own exit
            code = e.code
    assert code in (0, None)
    return out.getvalue()


def _benchmarks(argv):
    from benchmarks.cli import main as bench_main

    return bench_main(argv)


@pytest.mark.parametrize(
    ("fn", "argv"),
    [
        (batch.main, ["--help"]),
        (verify_cli.main, ["--help"]),
        (main, ["run", "--help"]),
        (main, ["check", "--help"]),
        (_benchmarks, ["--help"]),
    ],
    ids=["sim.batch", "verify", "sim run", "sim check", "benchmarks"],
)
def test_a_usage_line_names_every_option_the_help_lists(fn, argv):
    """A help text whose usage line leaves out an option it lists below (``python -m
    sim.batch``'s usage, written by hand, lacked ``--report``, the option ``make reproduce``
    passes)."""
    text = _help(fn, argv)
    usage, _, rest = text.partition("\n\n")
    listed = set(re.findall(r"^\s{2}(--[\w-]+)", rest.partition("options:")[2], re.M))
    assert listed, text
    missing = sorted(o for o in listed if o not in usage)
    assert not missing, f"usage line lacks {missing}:\n{usage}"


def test_verify_help_gives_the_workers_default_and_the_trials_floor():
    """``python -m sim.report.verify --help`` said neither ``--workers``' default nor that
    ``--trials`` below 400 is refused (docs/reproducibility.md states both)."""
    text = " ".join(_help(verify_cli.main, ["--help"]).split())
    assert "default 1" in text and f"at least {verify_cli.MIN_TRIALS}" in text, text
    page = (ROOT / "docs" / "reproducibility.md").read_text()
    assert f"at least {verify_cli.MIN_TRIALS}" in " ".join(page.split())


def test_the_reproducibility_page_names_the_kinds_make_test_leaves_to_make_fuzz():
    """docs/reproducibility.md said ``tests/test_verify.py`` checks every study kind on another
    numerical path inside ``make test``; the kinds marked ``long`` run in ``make fuzz`` only:
    the page names each of them."""
    import test_verify

    fn = test_verify.test_another_numerical_path_agrees_by_the_same_rules
    (mark,) = [m for m in fn.pytestmark if m.name == "parametrize"]
    long = [
        test_verify.FILES.get(p.values[0], p.values[0])
        for p in mark.args[1]
        if hasattr(p, "marks") and any(m.name == "long" for m in p.marks)
    ]
    text = " ".join((ROOT / "docs" / "reproducibility.md").read_text().split())
    bullet = text.partition("* every study kind at its tiny size")[2].partition("* ")[0]
    assert bullet, "the page no longer has its bullet on every study kind"
    if long:
        assert "make fuzz" in bullet, bullet
    for study in long:
        assert f"`{study}`" in bullet, f"{study}'s case runs in make fuzz only: {bullet}"


def test_every_study_file_of_the_project_is_named_for_a_new_user():
    """A study file the README and docs/index.md never named (``agnard_block_104``; and
    ``network_gridplate_2500`` left out of docs/network.md's examples): every paper study is in
    the README, the network examples are counted there and each is named in network.md."""
    readme = " ".join((ROOT / "README.md").read_text().split())
    network_page = (ROOT / "docs" / "network.md").read_text()
    stems = sorted(p.stem for p in (ROOT / "studies").glob("*.toml"))
    networks = [s for s in stems if s.startswith("network_")]
    words = ["no", "one", "two", "three", "four", "five", "six", "seven", "eight", "nine"]
    count = words[len(networks)] if len(networks) < len(words) else str(len(networks))
    assert f"{count} `network_*` studies" in readme, f"the README counts {len(networks)}?"
    for s in stems:
        if s in networks:
            assert f"studies/{s}.toml" in network_page, f"docs/network.md: {s}"
        else:
            assert f"`{s}`" in readme, f"README.md names no study {s}"


def test_a_point_named_in_a_large_grid_counts_once_in_the_estimate():
    """A network of more than ``NAME_SAMPLE`` points whose observations start at one point
    named (``from = "G1"``, docs/sparse.md's grid plate): the name was matched against the
    evenly spaced sample of names, each standing for k / 20,000 points, so G1 counted as 4.5
    points of a 300 x 300 plate; its rows (990,000 for 360,000), memory (1.98 GiB where
    docs/sparse.md stated 0.50 and the run takes 0.49) and work were over by as much, and a
    run that fits was refused under a limit it met. Counted from the declaration alone."""
    from sim.mc.network_size import NAME_SAMPLE, network_counts

    side = 300
    assert side * side > NAME_SAMPLE
    grid = {"prefix": "G", "nx": side, "ny": side, "spacing_mm": 1.0}
    gen = [{"kind": k, "from": "G1", "to": "G*", "sigma_mm": 0.002} for k in ("dx", "dy")]
    cfg = {
        "network.grids": [{**grid, "role": "observed", "sigma_mm": 0.0012}],
        "network.generate": gen,
    }
    assert network_counts(cfg).rows == 4 * side * side  # two coordinates, dx and dy a point
    # a listed name and one that no set declares (G0, G090001, a prefix's leading zero)
    cfg["network.generate"] = [{"kind": "dx", "from": ["G1", "G0", "G01", "G90001"], "to": "G*"}]
    assert network_counts(cfg).rows == 2 * side * side + side * side


def test_the_sparse_page_states_the_estimates_of_its_grid_plates():
    """docs/sparse.md gave the 150 x 150 and 300 x 300 grid plates' estimates as 0.22 and
    0.50 GiB, while ``sim check`` showed 0.217 and 1.98 (the point named in a large grid
    counted as 4.5): the page's numbers are the estimate's, from the declaration alone."""
    from sim.mc.config import validate
    from sim.mc.estimate import estimate
    from sim.studies import get_study

    got = []
    for side in (150, 300):
        flat = {
            "trials": 40,
            "chunk": 2,
            "network.grids": [
                {"prefix": "G", "nx": side, "ny": side, "spacing_mm": 1.0, "role": "observed"}
                | {"sigma_mm": 0.0012}
            ],
            "network.generate": [
                {"kind": k, "from": "G1", "to": "G*", "sigma_mm": 0.002} for k in ("dx", "dy")
            ],
        }
        cfg = dict(validate(flat, get_study("network").schema, None), study="network")
        got.append(f"{estimate(cfg).bytes / 2**30:.2f}")
    page = " ".join((ROOT / "docs" / "sparse.md").read_text().split())
    assert f"(estimated {got[0]} and {got[1]}" in page, got


def test_the_python_page_names_every_keyword_of_run():
    """docs/python.md named neither ``figures`` (``--no-figures`` of the API) nor
    ``scheduler`` among ``run()``'s keywords: each one is named on the page."""
    import inspect

    import sim

    page = (ROOT / "docs" / "python.md").read_text()
    params = inspect.signature(sim.StudyHandle.run).parameters
    missing = [p for p in params if p != "self" and f"`{p}`" not in page and f"{p}=" not in page]
    assert not missing, missing


def test_the_mutation_page_names_the_commit_and_the_modules_changed_since():
    """docs/mutation.md gave its score and survivors as the suite's, though four of the mutated
    modules changed after the commit it was made at (six survivors quote lines no longer in
    the code): the page names its commit, and each module whose quoted lines are gone is named
    as changed since."""
    page = (ROOT / "docs" / "mutation.md").read_text()
    assert re.search(r"Written by `make mutation` at commit `[0-9a-f]{7,40}`", page)
    items = re.findall(
        r"- `(sim\.claims\.\w+)\.[^`]*` \(\w[\w ]*\)\n\n  ```diff\n(.*?)```", page, re.S
    )
    assert items
    gone = set()
    for module, diff in items:
        src = (ROOT / (module.replace(".", "/") + ".py")).read_text()
        removed = [ln.strip()[1:].strip() for ln in diff.splitlines() if ln.strip()[:1] == "-"]
        if any(code not in src for code in removed):
            gone.add(module.rpartition(".")[2] + ".py")
    flat = " ".join(page.split())
    said = flat.partition(" changed since")[0].rpartition("**")[2] if gone else ""
    assert all(f"{m}`" in said for m in gone), (sorted(gone), said)
