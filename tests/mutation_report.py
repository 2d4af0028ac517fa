"""Write docs/mutation.md from a finished ``mutmut run`` (``make mutation``).

Reads ``mutmut results --all true`` (one ``name: status`` line a mutant) and, for each mutant
that was not killed, its diff (``mutmut show``). The score is killed / (all mutants), where a
mutant that makes the tests run past mutmut's time limit ("timeout": e.g. a refinement step that
no longer shrinks) counts as killed (the tests did not pass) and is listed apart; a mutant that
no selected test reaches ("no tests") counts as surviving. Lines marked
``# pragma: no mutate`` in the mutated modules are listed with the reason written beside them
(equivalent mutants: a change no test can see because the behaviour is the same).
"""

from __future__ import annotations

import subprocess
import sys
import tomllib
from collections import Counter
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
MUTMUT = [sys.executable, "-m", "mutmut"]

#: survivors checked by hand, with the reason they survive
NOTES = {
    "sim.claims.intervals.x_bootstrap_ci__mutmut_1": (
        "a default argument: mutmut's trampoline calls the mutant with the original default, "
        "so no test can see it. Applied by hand (n_boot = 401) the mutant fails "
        "tests/test_intervals.py::test_bootstrap_ci_is_the_2_5_and_97_5_percentiles_of_the_"
        "resamples: killed."
    ),
    **{
        f"sim.claims.intervals.x_spread_rows__mutmut_{k}": (
            "equivalent: np.asarray(x) without the float dtype; np.nanpercentile computes in "
            "floating point for any numeric input (integers give the same quantiles), and the "
            "two differ only for an object array such as a list holding None, which no caller "
            "passes (the callers pass simulated float arrays)."
        )
        for k in (13, 15)
    },
}


def _mutmut(*args: str) -> str:
    return subprocess.run(
        [*MUTMUT, *args], cwd=ROOT, capture_output=True, text=True, check=True
    ).stdout


def main(out: Path = ROOT / "docs" / "mutation.md") -> int:
    status = {}
    for line in _mutmut("results", "--all", "true").splitlines():
        name, _, st = line.strip().rpartition(": ")
        if name:
            status[name] = st
    if not status:
        print("mutation_report: no mutmut results (run `make mutation`)", file=sys.stderr)
        return 2
    modules = tomllib.loads((ROOT / "pyproject.toml").read_text())["tool"]["mutmut"]
    by_module: dict[str, Counter] = {}
    for name, st in status.items():
        by_module.setdefault(name.split(".x")[0], Counter())[st] += 1
    killed = sum(c["killed"] + c["timeout"] for c in by_module.values())
    total = len(status)
    lines = [
        "# Mutation testing of the verdict rules and intervals",
        "",
        "Written by `make mutation` (mutmut on "
        + ", ".join(f"`{m}`" for m in modules["only_mutate"])
        + "; tests: "
        + ", ".join(f"`{t}`" for t in modules["pytest_add_cli_args_test_selection"])
        + "). A mutant is a small change to the code (an operator, a constant, a comparison, "
        "a string); it is *killed* when a test fails. See [verdict rules](verdict-rules.md).",
        "",
        f"**Score: {killed} of {total} mutants killed ({100 * killed / total:.1f} %).**",
        "",
        "| module | mutants | killed | timeout | score | survived | no tests | other |",
        "| --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: |",
    ]
    for mod, c in sorted(by_module.items()):
        n = sum(c.values())
        k = c["killed"] + c["timeout"]
        other = n - k - c["survived"] - c["no tests"]
        lines.append(
            f"| `{mod}` | {n} | {c['killed']} | {c['timeout']} | {100 * k / n:.1f} % | "
            f"{c['survived']} | {c['no tests']} | {other} |"
        )
    left = [n for n, st in status.items() if st not in ("killed", "timeout")]
    lines += ["", f"## Mutants not killed ({len(left)})", ""]
    if not left:
        lines.append("None.")
    for n in left:
        diff = [
            ln
            for ln in _mutmut("show", n).splitlines()
            if ln[:1] in "+-" and not ln.startswith(("+++", "---"))
        ]
        lines += [f"- `{n}` ({status[n]})", "", "  ```diff", *("  " + d for d in diff), "  ```"]
        if n in NOTES:
            lines += ["", f"  {NOTES[n]}"]
    lines += ["", "## Lines not mutated, with the reason (equivalent mutants)", ""]
    marked = []
    for mod in modules["only_mutate"]:
        for i, ln in enumerate((ROOT / mod).read_text().splitlines(), 1):
            if "pragma: no mutate" in ln:
                marked.append(
                    f"- `{mod}:{i}`: `{ln.split('#')[0].strip()}` -- {ln.split('#', 1)[1]}"
                )
    lines += marked or ["None."]
    out.write_text("\n".join(lines) + "\n")
    print(f"mutation: {killed} of {total} killed ({100 * killed / total:.1f} %); see {out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
