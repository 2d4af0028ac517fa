"""The two classes of the eighth sweep of bad inputs still open (issue 26), one case each;
each failed on the code before its fix.

* brown_design at allowed values of its keys failed at run time in an internal function
  (``comparator.alpha_mm = 50`` or ``-50``: "zero-size array" in ``cells.within_front``;
  ``datum.beta_mm = 50``: the arm's offset beyond the nearest point; ``coverage.sigma_um =
  1e5`` or ``datum.spacing_mm = 0.01``: ZeroDivisionError in ``claims._coverage``, no trial
  converged; ``zeiss.points = 3``: LinAlgError in ``external.plate_rms``). Each is refused
  on load with the instrument's reason: beta at most half the 29 mm scale's width, alpha
  below the shortest distance the scale reads, the nominal coverage's noise at most 1 % of
  the datum plate's spacing and shortest station distance, the Zeiss sample redundant in
  the pivot model (:mod:`sim.studies.design.checks`);
* ``sim check`` accepted a ``[sweep]`` in which every cell is refused (the run then stopped
  with "every cell failed"); it is refused up front naming the swept key and its values, and
  the refused cells of a sweep that has others are named once (recorded, not run).
"""

from pathlib import Path

from oneline import one_line

from sim.cli import main

ROOT = Path(__file__).resolve().parent.parent
DESIGN = ROOT / "studies" / "brown_design.toml"


def test_brown_design_at_its_allowed_edges_is_refused_on_load_naming_the_key(capsys):
    cases = [
        ("comparator.alpha_mm=50", "comparator.alpha_mm: alpha = 50 mm", "negative range"),
        ("comparator.alpha_mm=-50", "comparator.alpha_mm: the longest range", "296.5 mm"),
        ("datum.beta_mm=50", "datum.beta_mm: beta = 50 mm", "29 mm width of the scale"),
        ("coverage.sigma_um=1e5", "coverage.sigma_um: 100000 um", "at most 450 um"),
        ("datum.spacing_mm=0.01", "coverage.sigma_um: 1 um", "0.01 mm spacing"),
        ("zeiss.points=3", "zeiss.points: 3 points in 4 positions", "at least 4 points"),
    ]
    for setting, *needles in cases:
        one_line(capsys, main(["check", str(DESIGN), "--set", setting]), *needles)
    # just inside: alpha below the region's 29.64 mm shortest reading, the noise at 1 % of 45 mm
    for setting in ("comparator.alpha_mm=29.6", "coverage.sigma_um=450"):
        assert main(["check", str(DESIGN), "--set", setting]) == 0, setting


def test_a_sweep_of_only_refused_cells_is_refused_by_check_and_run(tmp_path, capsys):
    f = tmp_path / "s.toml"
    f.write_text(DESIGN.read_text() + '\n[sweep]\n"comparator.alpha_mm" = [49.5, 50.0]\n')
    err = one_line(capsys, main(["check", str(f)]), "sweep.comparator.alpha_mm: every cell")
    assert "(2 of 2)" in err and "[49.5, 50.0]" in err and "negative range" in err
    out = tmp_path / "o"
    one_line(capsys, main(["run", str(f), "--out", str(out)]), "sweep.comparator.alpha_mm")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["s.toml"]  # nothing was started
    # one refused cell of two: named once, the check passes (the run records it, not runs it)
    f.write_text(DESIGN.read_text() + '\n[sweep]\n"comparator.alpha_mm" = [0.5, 50.0]\n')
    assert main(["check", str(f)]) == 0
    err = capsys.readouterr().err.strip()
    assert err.startswith("sim: sweep: 1 of 2 cells are infeasible") and "\n" not in err, err
    assert "cell0001" in err and "cell0000" not in err


def test_the_check_of_a_sweeps_cells_is_bounded_in_time(tmp_path):
    # a cell of a 2,500-point network takes 0.7 s to validate: sim check of a large sweep
    # must not take hours; the cells beyond the budget are validated when they run
    from sim.mc.sweep import refused_cells, refused_note
    from sim.studies import load_study

    study, cfg = load_study(DESIGN)
    table = {"comparator.alpha_mm": [49.5, 50.0, 40.0]}
    bad, checked = refused_cells(study, cfg, table, budget_s=0.0)
    assert checked == 1 and list(bad) == [0]  # not all checked: not refused as a whole
    note = refused_note(table, bad, checked)
    assert "1 of 3 cells are infeasible" in note and "first 1 of 3 cells checked" in note
