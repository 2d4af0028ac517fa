"""doors30a: every number an output prints is the run's (the studies doors29f did not reach).

Small variants of gridplate_two_plates, wolf_polynomial, salsig_encoders, agnard_block,
brown_design and the network kind, their README, claims notes and figure texts read against
the run's config: a number that is the paper's default where the run changed it is silent
nonsense. Each test builds the text from a config with the keys changed (no run), so the
file stays fast; the figures are drawn with ``save`` replaced and their texts read."""

from importlib import import_module
from pathlib import Path

import numpy as np

GP_CFG = {
    "comparator.coord_sigma_um": 1.6,
    "readings.count": 3,
    "readings.sigma_um": 2.0,
    "analysis.iter_tol_um": 0.001,
    "plate.count": 3,
}


def _titles(fig) -> list[str]:
    """Every title, label, legend entry and suptitle of ``fig``."""
    out = [fig._suptitle.get_text()] if fig._suptitle is not None else []
    for ax in fig.axes:
        out += [ax.get_title(), ax.get_xlabel(), ax.get_ylabel()]
        if ax.get_legend() is not None:
            out += [t.get_text() for t in ax.get_legend().get_texts()]
    return out


def _drawn(monkeypatch, module) -> list:
    figs = []
    monkeypatch.setattr(module, "save", lambda fig, path: figs.append(fig))
    return figs


def test_gridplate_per_point_error_makes_up_the_runs_comparator_sigma():
    """The mean_of_L note said the per-point comparator error (computed from the run's
    1.6 um, 2 um readings, L = 3) made up 'the 1.2' (the paper's): it names the run's."""
    import sim.studies.gridplate.claims as C

    res = {"gn_iterations": np.full(64, 2.0), "comp_sigma_um": np.full(64, 1.6)}
    note = C._comparator(C.load_book(), GP_CFG, res)["twoplate.comparator_sigma.mean_of_L"].note
    assert "1.11 um to make up its comparator sigma 1.6 um" in note
    assert "make up the 1.2" not in note


def _two_sets_of_zero_vectors(monkeypatch, F):
    """wolf's vectors table read by its figures: two calibration sets of two zero vectors."""
    g = np.zeros(4)
    vec = {"set": np.repeat([1, 2], 2), "x_mm": np.tile([0.0, 20.0], 2), "y_mm": g}
    vec.update({k: g for k in ("dx_before_um", "dy_before_um", "dx_after_um", "dy_after_um")})

    class _T:
        def to_pydict(self):
            return vec

    monkeypatch.setattr(F, "read_table", lambda path: _T())


def test_wolf_names_the_runs_polynomial_not_the_cubic(monkeypatch):
    """calib.degree = 2: the model text, the after-rows' note and the vectors figure said
    'the cubic' / 'ten-term cubic'; they name the run's six-term quadratic."""
    import sim.studies.wolf.claims as C
    import sim.studies.wolf.figures as F

    R = import_module("sim.studies.wolf.report")
    from sim.studies.wolf.schema import SCHEMA

    cfg = {k: f.default for k, f in SCHEMA.items() if hasattr(f, "default")}
    cfg.update({"calib.degree": 2, "calib.n_sets": 2, "seed": 1})
    assert "six-term quadratic (degree 2) is fitted" in R._model_text(cfg, 10)
    assert "residuals of the six-term quadratic" in C._simulated_notes(cfg)["wolf.after."]
    figs = _drawn(monkeypatch, F)
    _two_sets_of_zero_vectors(monkeypatch, F)
    F.vectors_figure(cfg, Path("."))
    texts = _titles(figs[0])
    assert any("after the quadratic" in t for t in texts)
    assert not any("cubic" in t for t in texts)


def test_wolf_counts_the_runs_calibration_sets(monkeypatch):
    """calib.n_sets = 2: the vectors figure's title said 'three dates' and the stability
    table 'calibration on the paper's sets'; both count the run's."""
    import sim.studies.wolf.figures as F

    R = import_module("sim.studies.wolf.report")

    figs = _drawn(monkeypatch, F)
    _two_sets_of_zero_vectors(monkeypatch, F)
    F.vectors_figure({"calib.degree": 3}, Path("."))
    assert "2 dates" in figs[0]._suptitle.get_text()
    monkeypatch.setattr(R, "figure", lambda *a: "")
    monkeypatch.setattr(R, "md_table", lambda *a: "")
    text = R._stability_table(
        None,
        {k: [] for k in ("drift_fraction", "age_weeks")}
        | {"before_rms_um": [], "after_rms_um": [], "share_after_better": []},
        {"calib.n_sets": 2, "calib.degree": 3},
    )[0]
    assert "calibration on the run's 2 sets (cubic)" in text


SA_CFG = {
    "b8.sx_mm_per_digit": 12.700082809,
    "b8.sy_mm_per_digit": 12.71,
    "b8.e_arcsec": -30.0,
    "analysis.alpha": 0.01,
    "zscale.s_mm_per_digit": 12.4,
}


def test_salsig_power_figure_states_the_runs_effects_and_level(monkeypatch):
    """The power figure's titles said E = -59.2" and SY - SX 0.016 %, its axis and the
    report's table 'the 95 % level', whatever b8.* and analysis.alpha: they are the run's."""
    import sim.studies.salsig.figures as F

    figs = _drawn(monkeypatch, F)
    sw = {"sigma_um": [2.0, 2.0], "n_marks": [9, 16], "power_E": [0.5, 0.6]}
    sw["power_scale"] = [0.4, 0.5]
    F.fig_power(sw, SA_CFG, None)
    texts = _titles(figs[0])
    assert 'power to detect non-perpendicularity E = -30"' in texts
    assert "power to detect scale difference SY - SX (0.0781 %)" in texts
    assert "detection rate at the 99 % level" in texts


def test_salsig_vertical_correction_is_the_runs_factor():
    """zscale.s_mm_per_digit = 12.4: the chain text and the rms_ratio note said z was
    multiplied by 12.500/12.700 (the paper's); the simulation multiplies by the run's."""
    R = import_module("sim.studies.salsig.report")
    from sim.studies.salsig.wording import correction

    cfg = {**SA_CFG, "marks.grid": 5, "marks.extent_mm": 200.0, "marks.placement_sd_mm": 1.2}
    cfg.update({"b8.sigma_um": 25.0, "grid.points": 5, "comparator.sigma_um": 3.0})
    text = R._chain(cfg)
    assert "before and after the 12.400/12.700 correction" in text
    assert "as printed in FIG. 3" not in text  # SY and E are the run's
    assert correction(cfg) == "12.400/12.700"


def _agnard_layout(monkeypatch, R, many: int, few: int) -> None:
    """``layout.parquet`` of a block whose many-point pass has ``many`` control points."""
    kinds = ["control_both"] * few + ["control_many"] * (many - few) + ["check"] * 7
    monkeypatch.setattr(R, "table", lambda out, name: {"kind": kinds})


def test_agnard_counts_the_runs_many_point_control(monkeypatch):
    """A 2 x 6 block over 120 points: the 'full' layout has 15 control points, but the
    scanner trade-off's figure title and table heading, the layout figure's legend and the
    gain rows' notes said 21 (the paper's); they count the run's (the committed
    agnard_block_104's 4 x 26 block has 105, its README said '(21 control')."""
    import sim.studies.agnard.figures as F

    R = import_module("sim.studies.agnard.report")

    _agnard_layout(monkeypatch, R, 15, 5)
    monkeypatch.setattr(R, "rows", lambda out, name: [])
    assert R._scanner_table(None)[0].startswith(
        "**Trade-off: scan resolution and calibration** (15 control"
    )
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots()
    scan = {"dpi": [300.0, 300.0], "calibration": ["raw", "corrected"]}
    for q in ("check_xy_m", "check_z_m"):
        scan |= {q: [0.1, 0.1], q + "_se": [0.01, 0.01]}
    F._scan_panel(ax, scan, 15)
    assert ax.get_title() == "scanner resolution and calibration (15 control)"
    plt.close(fig)
    from sim.studies.agnard.claims import scanner_rows

    scan = {"dpi": [600.0], "calibration": ["corrected"], "gain_xy_pct": [5.0]}
    scan |= {"gain_xy_pct_se": [1.0], "trials": [4]}
    note = scanner_rows(scan, 15)["agnard.scanner.gain_600dpi_pct"].note
    assert "at 600 DPI (15 control; mean over 4 blocks" in note


def test_agnard_layout_tradeoff_and_weights_are_the_runs(monkeypatch):
    """scan.dpi = 400, weights.pass = 0.2: the layout trade-off's heading said '600 DPI
    calibrated' and the model choices 'Weights as in the paper'; they say the run's."""
    R = import_module("sim.studies.agnard.report")
    from sim.studies.agnard.schema import SCHEMA

    monkeypatch.setattr(R, "rows", lambda out, name: [])
    cfg = {k: f.default for k, f in SCHEMA.items() if hasattr(f, "default")}
    cfg.update({"scan.dpi": 400.0, "weights.pass": 0.2})
    assert "(400 DPI calibrated" in R._layout_table(None, cfg)[0]
    assert R._as_in_paper(cfg) == ""
    assert R._as_in_paper({**cfg, "weights.pass": 0.1}) == " as in the paper"


def test_network_mdb_of_a_direction_is_in_arcsec():
    """observations.parquet holds NaN (not null) in the other unit's column: a direction's
    MDB printed ' mm' with no number (committed network_testfield too); it prints arcsec."""
    R = import_module("sim.studies.network.report")

    nan = float("nan")
    o = {"mdb_mm": [nan, 2.5, nan], "mdb_arcsec": [16.9, nan, nan]}
    assert [R._mdb(o, a) for a in range(3)] == ["16.9 arcsec", "2.50 mm", "uncontrolled"]


def test_design_measuring_time_is_the_runs():
    """time.images = 20: the trade-off said 'the paper's 60 and 90 minutes for 30 images' and
    the time rows' notes 'the time model at 30 images' (the model runs at the run's 20)."""
    from sim.studies.design.claims import _operation

    R = import_module("sim.studies.design.report")
    cfg = {"time.single_min": 60.0, "time.double_min": 90.0, "time.images": 20}
    cfg |= {"paper.positions": 4, "calibration.accuracy_um": 1.0, "operation.gap_um": 75.0}
    rows = _operation(cfg, {"external": {"axis_tilt_deg": 0.76}, "time": (40.0, 60.0)})
    assert rows["brown.operation.single_settings_min"].note.startswith(
        "the time model at 20 images"
    )
    assert "operation.gap_um = 75 um" in rows["brown.calibration.axis_tilt_deg"].note
    assert R._time_words(cfg) == (
        "60 and 90 minutes for 20 images (the paper's: 60 and 90 minutes for 30 images)"
    )
    assert R._time_words({**cfg, "time.images": 30}).startswith("the paper's 60 and 90")


def test_design_region_scale_is_said_to_be_the_papers():
    """scale.graduated_mm = 300: the region's hardware statement reads the built comparator's
    261 + 1 mm scale (by design); the lead said 'its 261 + 1 mm scale' as if the run's."""
    R = import_module("sim.studies.design.report")

    words = R._scale_words({"scale.graduated_mm": 300.0, "scale.micrometer_mm": 1.0})
    assert words.startswith("the paper's 261 + 1 mm scale (the built comparator's")
    assert "this run's 300 + 1 mm bounds the design trade-off only" in words
    assert R._scale_words({"scale.graduated_mm": 261.0, "scale.micrometer_mm": 1.0}) == (
        "its 261 + 1 mm scale"
    )


def test_a_region_row_without_values_prints_no_empty_interval():
    """gridplate with plate.count = 3 and every sigma changed: no input is consistent, the
    iterations row has no value, and its interval printed '[, ]' (README, sim show) and its
    note 'counts over the region ;'; now '—' and 'none (no point of the region)'."""
    from types import SimpleNamespace

    from sim.report.claimtext import interval_text
    from sim.studies.gridplate import region as G

    row = {"interval": "region", "ci_low": None, "ci_high": None, "p_plate": None}
    assert interval_text(row) == "—"
    empty = SimpleNamespace(outputs={G.IT: {"counts": np.array([2.0])}}, accepted=np.array([False]))
    cfg = {**GP_CFG, "region.iter_calibrations": 1}
    note = G.iteration_note(cfg, empty, np.array([2.0, 2.0]))
    assert "counts over the region none (no point of the region); at the configured" in note


def test_design_region_notes_are_the_runs_zeiss_grid_and_accuracy():
    """zeiss.points = 25, zeiss.grid_sigma_um = 0.5, calibration.accuracy_um = 2: the region
    rows' notes said '33-point stand-in layout', 'the grid's 0.8 um' and 'the accuracy
    (1 um)' while the region computed with the run's (external.zeiss_points, plate_rms)."""
    from sim.studies.design import region as DR

    cfg = {"zeiss.points": 25, "zeiss.grid_sigma_um": 0.5, "calibration.accuracy_um": 2.0}
    notes = " ".join(DR._notes(cfg).values())
    assert "25-point stand-in layout" in notes and "the grid's 0.5 um" in notes
    assert "= the accuracy (2 um)" in notes
    assert "33" not in notes and "0.8" not in notes


def test_wolf_repeatability_photograph_is_the_runs_format():
    """repeat.format_mm = [120, 90]: the repeatability rows' note said 'a simulated P-30
    photograph' (the paper's 150 x 100 mm); it names the run's format."""
    import sim.studies.wolf.claims as C
    from sim.studies.wolf.schema import SCHEMA

    cfg = {k: f.default for k, f in SCHEMA.items() if hasattr(f, "default")}
    note = C._simulated_notes({**cfg, "repeat.format_mm": [120.0, 90.0]})["wolf.repeatability."]
    assert "points of a simulated 120 x 90 mm photograph" in note
    assert "simulated P-30 photograph" in C._simulated_notes(cfg)["wolf.repeatability."]


def test_wolf_before_rows_do_not_claim_the_runs_amplitudes_were_fitted():
    """field.stress_um = 20: the 'before' rows' note said the field amplitudes 'were chosen
    so these look like the paper's' (true of the defaults only); it names the changed keys."""
    import sim.studies.wolf.claims as C
    from sim.studies.wolf.schema import SCHEMA

    cfg = {k: f.default for k, f in SCHEMA.items() if hasattr(f, "default")}
    note = C._simulated_notes({**cfg, "field.stress_um": 20.0})["wolf.before."]
    assert "This run's field amplitudes differ from the defaults" in note
    assert "(field.stress_um)" in note
    assert "were chosen so these look" in C._simulated_notes(cfg)["wolf.before."]


def test_agnard_scanner_peaks_are_the_runs():
    """scan.max_y_um = 30: every simulated scanner field peaks at the run's +-20 / +-30 um
    (simulate.py), but the scanner region's lead and the Table 1 line said 'the printed
    +-20 / +-40 um peaks' / 'peaking at the paper's +-20 / +-40 um'."""
    from sim.studies.agnard.leads import peaks

    R = import_module("sim.studies.agnard.report")
    cfg = {"scan.max_x_um": 20.0, "scan.max_y_um": 30.0}
    assert peaks(cfg) == "this run's +-20 / +-30 um peaks (printed: +-20 / +-40 um)"
    assert "scaled to this run's +-20 / +-30 um peaks" in R._table1_line({}, cfg)
    assert peaks({**cfg, "scan.max_y_um": 40.0}) == "the printed +-20 / +-40 um peaks"


def test_design_datum_geometry_is_named_the_runs():
    """datum.grid = 4: the datum rows and the scale-length note computed on the run's
    +-67.5 mm grid but called it brown_dilution's (a 5 x 5 grid at +-90 mm)."""
    from sim.studies.design.run import _scale_length
    from sim.studies.design.schema import SCHEMA, datum_geometry

    cfg = {k: f.default for k, f in SCHEMA.items() if hasattr(f, "default")}
    assert datum_geometry(cfg) == "brown_dilution's"
    cfg["datum.grid"] = 4
    note = _scale_length(cfg)["brown.design.max_offset_dilution_grid_mm"][1]
    assert note.startswith("the same for the run's datum.* +-67.5 mm grid")


def test_salsig_recovery_notes_name_the_runs_truth_and_sigmas():
    """b8.e_arcsec = -30, b8.sigma_um = 20: the recovery rows said the truth is 'the printed
    FIG. 3 value' and b8.sigma_um / comparator.sigma_um are 'set to reproduce' the .002 /
    .003, whatever the run set; they name the run's truth and values."""
    import sim.studies.salsig.claims as C

    rng = np.random.default_rng(1)
    rec = {k: rng.normal(size=50) for k in ("SX", "SY", "E_arcsec", "s0_fig3_digits")}
    rec |= {k: rng.normal(size=50) for k in ("s0_fig2_mm", "scale_diff_ppm")}
    rec |= {"sd_E_arcsec": np.ones(50), "sd_scale_diff_ppm": np.ones(50)}
    rec |= {"detect_E": np.ones(50, bool), "detect_scale": np.ones(50, bool)}
    cfg = {**SA_CFG, "marks.grid": 5, "b8.sigma_um": 20.0, "comparator.sigma_um": 3.0}
    rows = C._recovery(cfg, rec)
    assert "the truth is the run's b8.* value" in rows["salsig.recovery.SX"].note
    note3 = rows["salsig.recovery.s0_fig3_digits"].note
    assert "b8.sigma_um is not printed: this run's 20 um (the default 25 reproduces" in note3
    assert "set to reproduce the .003" in rows["salsig.recovery.s0_fig2_mm"].note


def test_agnard_recentring_is_not_said_to_match_when_the_run_changed_it(monkeypatch):
    """pugging.recentre_px = 0.7: the mechanical rejection row and the report said the
    unprinted re-centring error 'is set so the share matches' the paper's; the run's is not."""
    from sim.studies.agnard.schema import SCHEMA, recentre_words

    cfg = {"pugging.recentre_px": 0.7, "snoop.max_reject": 25}  # snooping (doors35p)
    assert recentre_words(cfg).startswith("unprinted: this run's 0.7 px, the default 0.5 px")
    default = {"pugging.recentre_px": SCHEMA["pugging.recentre_px"].default}
    assert recentre_words(default) == "unprinted, set so the share matches the paper: an input"
    R = import_module("sim.studies.agnard.report")
    monkeypatch.setattr(
        R, "table", lambda out, name: {"recentre_px": [0.7], "mean_share_pct": [20.0]}
    )
    row = {"value": 1.0, "value_high": None, "verdict": "finding"}
    c = {"agnard.pass_rejections.digital": row, "agnard.pass_rejections.mechanical_pct": row}
    line = R._rejection_line(c, Path("/nonexistent"), cfg)
    assert "(the re-centring error unprinted: this run's 0.7 px" in line
