"""The classes of the sweep doors21a (issue 26: the advice at the end of a refusal, followed
literally), one case each; each failed on the code before its fix.

* a network whose normals are singular because an unknown is determined by no observation, or
  a part of it is tied to the datum by none, was refused "...: fix points or change the
  datum"; changing the datum cannot hold either (``datum.kind = inner`` gave the same refusal
  again, explicit constraints are refused as more than the datum defect): the advice now names
  what does, fixing points or adding observations;
* a network with fixed points whose rank defect is more than the datum defect (a part of it
  held by one fixed point of its own, free to turn about it) was told "... or use datum.kind =
  inner"; the inner datum covers only the network's own defect and was refused in turn ("add
  observations ..., or fix points"): the advice no longer names the inner datum there;
* ``run()`` refused by a work limit named ``--max-adjustments``/``--max-memory-gb``, options it
  does not take: it names the environment variable;
* too few trials for the chunks asked for were told "give at least 20 trials (one per chunk)";
  followed with the chunk kept (``--chunk 2``, or ``chunk = 2`` in the file), 20 trials in
  chunks of 2 were refused again ("make chunk at most 1"): the advice gives both numbers;
* too many chunk files were told "make chunk larger": a chunk of 2 for 10,000,000 trials was
  refused again; the advice names the smallest chunk accepted.
"""

from pathlib import Path

from sim.cli import main
from tests.oneline import SIM_ERROR, one_line

ROOT = Path(__file__).resolve().parents[1]
HEAD = 'study = "network"\ntrials = 40\nchunk = 2\nseed = 1\n[network]\nname = "n"\n'


def _pt(name, x, y, fixed):
    role = ', role = "fixed"' if fixed else ""
    return f'{{ name = "{name}", x_mm = {x}, y_mm = {y}{role} }}'


def _study(tmp_path, fixed: str, obs: str, gen: str = "", kind: str = "fixed"):
    xy = {"A": (0.0, 0.0), "B": (100.0, 0.0), "C": (50.0, 80.0)}
    xy |= {"D": (500.0, 500.0), "E": (600.0, 500.0), "F": (550.0, 600.0)}
    pts = ", ".join(_pt(n, *p, n in fixed) for n, p in xy.items() if n in obs + gen + fixed)
    p = tmp_path / f"net_{fixed}_{kind}.toml"
    text = HEAD + f"points = [ {pts} ]\nobservations = [ {obs} ]\n"
    text += f"generate = [ {gen} ]\n" if gen else ""
    p.write_text(text + f'[datum]\nkind = "{kind}"\n')
    return str(p)


def _d(a, b):
    return f'{{ kind = "distance", from = "{a}", to = "{b}", sigma_mm = 0.01 }}'


def test_unobserved_unknown_is_not_told_to_change_the_datum(tmp_path, capsys):
    obs = ", ".join([_d("A", "C"), _d("B", "C"), _d("D", "E")])  # D.y, E.y: no observation
    line = one_line(capsys, main(["check", _study(tmp_path, "AB", obs)]), prefix=SIM_ERROR)
    assert "determined by no observation" in line and line.endswith(
        "fix points or add observations"
    )
    # the datum it used to advise gives the same refusal: the advice no longer names it
    again = one_line(capsys, main(["check", _study(tmp_path, "AB", obs, kind="inner")]))
    assert "determined by no observation" in again and "change the datum" not in again
    # the advice followed: the points fixed, the check passes
    assert main(["check", _study(tmp_path, "ABDE", obs)]) == 0


def test_a_part_turning_about_its_own_fixed_point_is_not_told_to_use_the_inner_datum(
    tmp_path, capsys
):
    obs = ", ".join([_d("A", "C"), _d("B", "C")])
    tri = '["D", "E", "F"]'
    gen = f'{{ kind = "distance", from = {tri}, to = {tri}, sigma_mm = 0.01 }}'
    line = one_line(capsys, main(["check", _study(tmp_path, "ABD", obs, gen)]), "rank defect")
    assert "datum.kind = inner" not in line and line.endswith("or fix points"), line
    inner = one_line(capsys, main(["check", _study(tmp_path, "ABD", obs, gen, kind="inner")]))
    assert "rank defect" in inner  # the inner datum does not hold it: the advice was wrong
    assert main(["check", _study(tmp_path, "ABDE", obs, gen)]) == 0
    capsys.readouterr()


def test_api_limit_refusal_names_what_run_takes(tmp_path, monkeypatch):
    """``run()`` refused by a work limit said "(--max-adjustments or SIM_MAX_ADJUSTMENTS)", an
    option it does not take; it names the environment variable, and setting it lets the run
    through."""
    import pytest

    import sim
    from sim.mc.config import ConfigError

    h = sim.load("studies/network_plate.toml").replace(trials=40, chunk=2)
    for var, small, option in (
        ("SIM_MAX_ADJUSTMENTS", "10", "--max-adjustments"),
        ("SIM_MAX_MEMORY_GB", "1e-9", "--max-memory-gb"),
    ):
        monkeypatch.setenv(var, small)
        with pytest.raises(ConfigError) as e:
            h.run(out=tmp_path / "a", figures=False)
        assert option not in str(e.value) and f"the environment variable {var}" in str(e.value)
        assert "\n" not in str(e.value) and not (tmp_path / "a").exists()
        monkeypatch.delenv(var)
    monkeypatch.setenv("SIM_MAX_ADJUSTMENTS", "1e6")  # the advice followed
    assert (h.run(out=tmp_path / "a", figures=False).path / "run.json").is_file()


def test_too_few_trials_advice_followed_with_either_chunk(capsys):
    p = "studies/network_plate.toml"
    line = one_line(capsys, main(["check", p, "--set", "trials=10", "--set", "chunk=2"]))
    assert line.endswith("give at least 20 trials in chunks of 1, or 40 in chunks of 2"), line
    for trials, chunk in (("20", "1"), ("40", "2")):  # each half of the advice, literally
        assert main(["check", p, "--set", f"trials={trials}", "--set", f"chunk={chunk}"]) == 0
    capsys.readouterr()


def test_too_many_chunks_advice_names_the_smallest_chunk(capsys):
    p, trials = "studies/network_plate.toml", "trials=9999999"
    line = one_line(capsys, main(["check", p, "--set", trials, "--set", "chunk=2"]), "chunk files")
    assert line.endswith("make chunk at least 100"), line
    assert main(["check", p, "--set", trials, "--set", "chunk=100"]) == 0  # followed literally
    assert main(["check", p, "--set", trials, "--set", "chunk=99"]) == 2  # and it is the least
    capsys.readouterr()


def test_an_unfinished_run_of_another_config_names_the_values_to_finish_it(tmp_path, capsys):
    """ "holds an unfinished run of a different config; run that command again to finish it"
    named neither the command nor what differs: the keys, the unfinished run's values and
    this run's are named now, so the run can be finished (or replaced with --overwrite)."""
    study = tmp_path / "s.toml"
    study.write_text((ROOT / "studies" / "network_plate.toml").read_text())
    out = tmp_path / "o"
    assert main(["run", str(study), "--out", str(out), "--trials", "40", "--chunk", "2",
                 "--no-figures"]) == 0  # fmt: skip
    capsys.readouterr()
    (out / "run.json").replace(tmp_path / "record.json")
    out.rename(tmp_path / ".o.partial")  # as a run stopped before it published
    (tmp_path / "record.json").replace(tmp_path / ".o.partial" / "run.json")
    rc = main(["run", str(study), "--out", str(out), "--trials", "60", "--chunk", "2"])
    one_line(capsys, rc, "unfinished run of a different config: trials = 40 (this run 60)",
             "run again with its values", "--overwrite", prefix=SIM_ERROR)  # fmt: skip
