"""The lead's own sweep of the session of 2026-11-28/29, 23:52 UTC (issue 26): fresh bad input
tried as a new user, door by door, here the network kind at real size. Each test failed on
the code before its fix."""

from __future__ import annotations

from pathlib import Path

import pytest

from sim.cli import main

STUDIES = Path(__file__).resolve().parents[1] / "studies"


def _refused(capsys, args) -> str:
    assert main(args) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1, err
    return err


def _trilateration(tmp_path: Path, half_extent_mm: float) -> Path:
    """300 random points (600 unknowns: the sparse path), 8 nearest distances of 1 mm and
    directions: a half extent of 1 m puts the closest pair 6 mm apart."""
    p = tmp_path / "tri.toml"
    p.write_text(
        'study = "network"\ntrials = 40\nchunk = 2\nseed = 5\n[network]\n'
        f'random = [ {{ prefix = "P", n = 300, half_extent_mm = {half_extent_mm} }} ]\n'
        'generate = [ { kind = "distance", from = "P*", to = "P*", nearest = 8, sigma_mm = 1.0 },'
        ' { kind = "direction", from = "P1*", to = "P*", nearest = 4, sigma_arcsec = 2.0 } ]\n'
        '[datum]\nkind = "inner"\n',
        encoding="utf-8",
    )
    return p


def test_a_network_too_far_from_linear_is_refused_at_check_naming_its_weakest_sight(
    tmp_path, capsys
):
    # before: `sim check` passed; `sim run` computed every chunk (52 s at 40,000 points),
    # then refused naming solver.max_iter, which no limit helps (200 did not)
    err = _refused(capsys, ["check", str(_trilateration(tmp_path, 1000.0))])
    assert err.startswith("sim: error: network.generate: none of 16 probe trials converged"), err
    assert "the distance from 'P152' to 'P204', is 6.437 mm long" in err, err
    assert "place the points further apart" in err and "raise solver.max_iter" not in err


def test_a_network_run_says_how_many_trials_did_not_converge(tmp_path, capsys):
    # before: 29 of 40 trials left out of the estimates was said only in the README's
    # summary sentence and the claims' notes; `sim run`'s closing lines and `sim show` said
    # nothing (docs/cli.md: "how many trials had an adjustment that did not converge")
    out = tmp_path / "out"
    args = ["run", str(_trilateration(tmp_path, 8000.0)), "--out", str(out), "--no-figures"]
    assert main(args) == 0
    line = "not converged: 29 of 40 trials (the claims' notes say how each Monte-Carlo"
    assert line in capsys.readouterr().out
    assert main(["show", str(out)]) == 0
    assert line in capsys.readouterr().out
    # a network of which every trial converges says nothing of it
    plate = tmp_path / "plate"
    assert (
        main(
            [
                "run",
                str(STUDIES / "network_plate.toml"),
                "--trials",
                "40",
                "--out",
                str(plate),
                "--no-figures",
                "--quiet",
            ]
        )
        == 0
    )
    assert main(["show", str(plate)]) == 0
    assert "not converged" not in capsys.readouterr().out


def _plate(tmp_path: Path, side: int) -> Path:
    """A side x side grid plate: observed coordinates and dx, dy from one point (4 slots)."""
    p = tmp_path / "plate.toml"
    grid = f'{{ prefix = "G", nx = {side}, ny = {side}, spacing_mm = 1.0, role = "observed", '
    p.write_text(
        f'study = "network"\ntrials = 40\nchunk = 2\n[network]\ngrids = [ {grid}'
        'sigma_mm = 0.0012 } ]\ngenerate = [ { kind = "dx", from = "G1", to = "G*", '
        'sigma_mm = 0.002 }, { kind = "dy", from = "G1", to = "G*", sigma_mm = 0.002 } ]\n'
        '[datum]\nkind = "fixed"\n',
        encoding="utf-8",
    )
    return p


def test_a_network_whose_estimate_fits_the_memory_limit_is_not_refused_for_memory(
    tmp_path, monkeypatch, capsys
):
    # before: a 300 x 300 plate, shown by `sim check` as "about 0.222 GiB of memory" (it took
    # 0.49), was refused under SIM_MAX_MEMORY_GB=0.5 for "1 x 90000 observations need about
    # 0.515 GiB", while `sim run --max-memory-gb 0.5` ran it: two models of one network. The
    # early check of the declaration and the estimate now count one state, so a limit just
    # over the estimate is met, and one under it refused, by the option and the variable alike
    import sim

    f = _plate(tmp_path, 60)
    gib = sim.load(f).estimate().bytes / 2**30
    monkeypatch.setenv("SIM_MAX_MEMORY_GB", f"{gib * 1.01:.6g}")
    assert main(["check", str(f)]) == 0
    capsys.readouterr()
    monkeypatch.setenv("SIM_MAX_MEMORY_GB", f"{gib * 0.99:.6g}")
    assert "over the" in _refused(capsys, ["check", str(f)])
    monkeypatch.delenv("SIM_MAX_MEMORY_GB")
    args = ["run", str(f), "--out", str(tmp_path / "o"), "--max-memory-gb", f"{gib * 0.99:.6g}"]
    assert "over the" in _refused(capsys, args)


def test_a_networks_shares_are_not_decided_on_the_trials_that_converged_alone(tmp_path, capsys):
    # before: 1,830 of 2,000 trials did not converge and the coverage and false-alarm
    # self-checks held on the 170 that did (0.952 in [0.945, 0.958]); over every trial the
    # share is anywhere between the converged ones' all missing and all counted
    import pyarrow.parquet as pq

    out = tmp_path / "out"
    f = str(_trilateration(tmp_path, 8000.0))
    assert main(["run", f, "--out", str(out), "--no-figures", "--quiet"]) == 0
    rows = {r["claim"]: r for r in pq.read_table(out / "claims.parquet").to_pylist()}
    for claim in ("network.coverage95.mean", "network.global_test.false_alarm"):
        r = rows[claim]
        assert r["ci_low"] <= 11 / 40 and r["ci_high"] >= 29 / 40, r  # either outcome
        assert r["verdict"] == "self-check" and r["outcome"] == "inconclusive", r
        assert "29 trials that did not converge" in r["note"], r["note"]


def _points_of(xml: Path) -> list[str]:
    return [ln.strip() for ln in xml.read_text(encoding="utf-8").splitlines() if "<point " in ln]


def test_a_random_networks_layout_is_one_network_across_seeds_and_sweep_cells(tmp_path, capsys):
    # before: the layout was drawn from `seed`, so each cell of a sweep (its own seed, after
    # the cells were validated at the study's) and each `--seed` drew another network: a sweep
    # over a sigma compared networks of other geometries. network.layout_seed draws it now
    f = tmp_path / "rsw.toml"
    f.write_text(
        'study = "network"\ntrials = 40\nchunk = 2\nseed = 5\n[network]\n'
        'random = [ { prefix = "P", n = 30, half_extent_mm = 5000.0 } ]\n'
        'generate = [ { kind = "distance", from = "P*", to = "P*", nearest = 6, '
        'sigma_mm = 1.0 } ]\n[datum]\nkind = "inner"\n[sweep]\n'
        '"network.generate" = [[{ kind = "distance", from = "P*", to = "P*", nearest = 6, '
        'sigma_mm = 1.0 }], [{ kind = "distance", from = "P*", to = "P*", nearest = 6, '
        "sigma_mm = 2.0 }]]\n",
        encoding="utf-8",
    )
    out = tmp_path / "sweep"
    assert main(["run", str(f), "--out", str(out), "--no-figures", "--quiet"]) == 0
    a, b = (_points_of(out / "cells" / c / "network.xml") for c in ("cell0000_r0", "cell0001_r0"))
    assert a == b and len(a) == 30
    one = tmp_path / "one.toml"
    one.write_text(f.read_text(encoding="utf-8").split("[sweep]")[0], encoding="utf-8")
    runs = {}
    for name, extra in (
        ("s5", []),
        ("s6", ["--seed", "6"]),
        ("l2", ["--set", "network.layout_seed=2"]),
    ):
        o = tmp_path / name
        assert main(["run", str(one), "--out", str(o), "--no-figures", "--quiet", *extra]) == 0
        runs[name] = _points_of(o / "network.xml")
    assert runs["s5"] == runs["s6"] == a  # another seed: other noise, the same network
    assert runs["l2"] != a  # another layout seed: another network
    capsys.readouterr()


def test_brown_s_random_plate_is_one_plate_across_seeds():
    # the same class in Brown's studies: the random pattern was drawn from `seed`, so a sweep's
    # cells and `--seed` measured other plates; plate.layout_seed draws it now
    import numpy as np

    import sim
    from sim.studies.brown.schema import points_of

    over = {"plate.pattern": "random", "plate.random_half_extent_mm": 100.0}
    f = STUDIES / "brown_table1.toml"
    a, b = (points_of(sim.load(f, seed=s, **over).config) for s in (5, 6))
    c = points_of(sim.load(f, seed=5, plate__layout_seed=2, **over).config)
    assert np.array_equal(a, b) and not np.array_equal(a, c)


def test_a_drivers_variable_left_set_in_a_shell_is_named_not_a_silent_exit():
    # before: SIM_STOP_WITH_PARENT (set by sim.batch and make verify for their runs) left set
    # in a shell ended every `sim` command with status 130 and not a word
    import os
    import subprocess
    import sys

    env = {**os.environ, "SIM_STOP_WITH_PARENT": "2"}
    p = subprocess.run(
        [sys.executable, "-m", "sim", "check", str(STUDIES / "wolf_polynomial.toml")],
        env=env,
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert p.returncode == 130 and p.stdout == ""
    assert p.stderr.startswith("sim: stopped: SIM_STOP_WITH_PARENT=2 names the program"), p.stderr
    assert len(p.stderr.splitlines()) == 1


@pytest.mark.long
def test_a_sweep_whose_first_key_is_text_and_has_a_second_key_draws_its_figure(tmp_path, capsys):
    # before: the figure's second panel read the first panel's tick labels as the legend's
    # texts: "the run failed in sim.execute.run_sweep: TypeError: string indices must be
    # integers", exit 3, no results at all (swept: datum.kind = ["fixed", "inner"] until
    # doors37s refused an inner datum the testfield's fixed pillars already hold)
    f = tmp_path / "sw.toml"
    f.write_text(
        (STUDIES / "network_testfield.toml").read_text(encoding="utf-8")
        + '\n[sweep]\n"network.name" = ["one", "two"]\n"reliability.alpha0" = [0.001, 0.01]\n',
        encoding="utf-8",
    )
    out = tmp_path / "out"
    assert main(["run", str(f), "--trials", "40", "--out", str(out), "--quiet"]) == 0
    assert (out / "sweep.png").is_file() and len(list((out / "cells").iterdir())) == 4


def test_the_sweep_figure_labels_tiny_values_and_integer_keys_readably(tmp_path, monkeypatch):
    # before: a claim zero but for rounding (Brown's bias invariance, 3e-13 mm) had every y
    # label "0.000000000000000"; a swept integer (errors.settings, a layout seed) had ticks
    # at 1.25 and 1.5 of it
    import pyarrow as pa
    import pyarrow.parquet as pq

    from sim.report import sweep as sweep_fig

    t = pa.table(
        {
            "errors.settings": [1, 2, 3],
            "replicate": [0, 0, 0],
            "feasible": [True, True, True],
            "a.tiny_mm": [2e-13, 5e-13, 3e-13],
            "a.tiny_mm:lo": [2e-13, 5e-13, 3e-13],
            "a.tiny_mm:hi": [2e-13, 5e-13, 3e-13],
        }
    )
    meta = {b"sim.provenance": b'{"sweep_keys": ["errors.settings"]}'}
    pq.write_table(t.replace_schema_metadata(meta), tmp_path / "sweep.parquet")
    drawn = []
    monkeypatch.setattr(sweep_fig, "save", lambda fig, png: drawn.append(fig) or png)
    assert sweep_fig.fig_sweep(tmp_path / "sweep.parquet", tmp_path / "sweep.png") is not None
    ax = drawn[0].axes[0]
    drawn[0].canvas.draw()
    ys = [x.get_text() for x in ax.get_yticklabels() if x.get_text()]
    assert len(set(ys)) == len(ys) > 1 and any("×10" in y for y in ys), ys
    xs = [x.get_text() for x in ax.get_xticklabels() if x.get_text()]
    assert xs and all(x.lstrip("−-").isdigit() for x in xs), xs


def test_readings_whose_average_is_too_precise_are_named_as_such(capsys):
    # before: "1,000,000 readings of sigma 1e-09 mm: over 1,000,000 or an averaged sigma under
    # 1e-09 mm", of a count that is not over 1,000,000
    obs = '[{kind="distance",from="N6",to="N7",sigma_mm=1e-9,settings=1000000}]'
    f = str(STUDIES / "network_testfield.toml")
    err = _refused(capsys, ["check", f, "--set", f"network.observations={obs}"])
    assert "average to sigma 1e-12 mm, under 1e-09 mm" in err and "over 1,000,000" not in err


def test_a_value_equal_as_shown_is_not_named_a_change_by_any_of_the_three_rules():
    # before: the Configuration line compared with `!=`: a swept 1.1 + 0.6 was named changed
    # from 1.7 while the inputs table and the claims' off-setup note read it as 1.7
    from sim.mc.numtext import shows_differently
    from sim.report.config_diff import changed_keys

    assert (
        changed_keys({"a": 1.1 + 0.6, "b": 4, "c": [0.1 + 0.2]}, {"a": 1.7, "b": 4.0, "c": [0.3]})
        == []
    )
    assert changed_keys({"a": 1.7001, "t": True}, {"a": 1.7, "t": 1}) == ["a", "t"]
    assert not shows_differently({"x": 0.1 + 0.2}, {"x": 0.3}) and shows_differently("1", 1)
    assert not shows_differently([{"a": 1, "b": 2.0}], [{"b": 2, "a": 1}])  # keys in any order


def test_the_committed_results_are_of_their_study_files_configurations():
    # the project's results are made from studies/<name>.toml as written: their READMEs carry
    # no Configuration line (a rule comparing records by their keys' order named every
    # network's records changed)
    results = STUDIES.parent / "results"
    named = [d for d in sorted(results.iterdir()) if (STUDIES / f"{d.name}.toml").is_file()]
    assert len(named) >= 12
    for d in named:
        assert "**Configuration.**" not in (d / "README.md").read_text(encoding="utf-8"), d.name


def test_a_small_bias_is_not_blamed_for_a_network_too_far_from_linear(tmp_path, capsys):
    # before: any bias was named "a gross error the adjustment cannot absorb" when no probe
    # trial converged, here 0.01 mm on distances of a network whose sights are 6 mm long
    p = _trilateration(tmp_path, 1000.0)
    text = p.read_text(encoding="utf-8").replace(
        "sigma_mm = 1.0 },", "sigma_mm = 1.0, bias_mm = 0.01 },"
    )
    p.write_text(text, encoding="utf-8")
    err = _refused(capsys, ["check", str(p)])
    assert "weakest sight" in err and "bias" not in err, err


def test_another_studys_results_under_a_name_are_said_to_be_so_by_verify(tmp_path, capsys):
    # before: network_plate's results copied as brown_table1 were "of another config than the
    # re-run (keys ...)", about 70 keys with `study` among them
    from sim.report.verify import main as verify_main

    R, S = tmp_path / "R" / "brown_table1", tmp_path / "S" / "brown_table1"
    quiet = ["--quiet", "--no-figures", "--trials", "40"]
    assert main(["run", str(STUDIES / "network_plate.toml"), "--out", str(R), *quiet]) == 0
    assert main(["run", str(STUDIES / "brown_table1.toml"), "--out", str(S), *quiet]) == 0
    capsys.readouterr()
    argv = ["--results", str(R.parent), "--scratch", str(S.parent), "--no-rerun", "--no-record"]
    assert verify_main(argv) == 1
    text = " ".join(capsys.readouterr().out.split())
    assert "are of the study 'network', not of 'brown_table1'" in text, text
