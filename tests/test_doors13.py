"""The classes of the twelfth sweep of bad inputs (issue 26, doors13), one case each; each
failed on the code before its fix.

* a network whose sigmas alone make the normals singular (weighted coordinates of 1 m
  beside coordinate differences of 2 um) was refused blaming "a rank defect of 0 ... that
  the datum does not cover"; now it names the weakest unknown and the condition number;
* a distance whose own ``bias_mm`` makes it read a negative length passed ``sim check``
  (``constant_mm`` doing the same was refused); an angle with a gross bias (200,000 arcsec)
  passed and its run's error blamed ``solver.max_iter``; now the error names the bias;
* a ``sim.load`` handle whose study file was edited (or deleted) afterwards: ``run()`` ran
  the config of load time, ``run(trials=...)`` and ``replace`` the edited file, so one
  handle gave two configs without a word; now refused naming ``study_file``;
* a GNU Gama d-m-s value with 60.00 seconds (gama-local reads it; its own test data
  ``zoltan-test_2d_dms.gkf`` holds "187-33-60.00") was refused as garbage;
* agnard with ``snoop.max_reject = 0`` (legal: no data snooping) decided "digital pugging
  removes no pass point" as holds, though no point could be removed; and with the fewest
  paired blocks (``table1.trials = 2``) the row's note stated a share of 780 %;
* the suite's own GNU Gama export of a free network (``adj="XY"``) read back was refused;
* a large (sparse-path) singular network named no point;
* ``make verify --study`` naming a sweep's results said there were none; results it could
  not re-run (no study file in studies/) printed "0 files; largest relative deviation 0";
* a ``sim.load`` handle was unhashable; NumPy scalars nested in table overrides refused;
* a defect between the distances' constant and scale blamed ``datum.kind``;
* a gama-local file of 3,000 points took three minutes to load (names matched by fnmatch).
"""

import json
import re
import shutil
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest
from oneline import one_line

import sim
import sim.studies.network.validate as validate
from sim.cli import main
from sim.mc.config import ConfigError
from sim.report.verify.cli import main as verify_main
from sim.studies import load_study
from sim.studies.agnard.decide import REJECTED, _zeros, without_snooping
from sim.studies.network.definition import build
from sim.studies.network.gama import merge_gama
from sim.studies.network.gama_read import read_gama
from sim.studies.network.linearity import biased
from sim.studies.network.validate import _match

ROOT = Path(__file__).resolve().parent.parent
PLATE = str(ROOT / "studies" / "network_plate.toml")
FIELD = ROOT / "studies" / "network_testfield.toml"


def test_a_network_singular_from_its_weights_names_the_unknown_not_a_rank_defect(capsys):
    grid = '[{prefix="G",nx=5,ny=5,spacing_mm=40.0,role="observed",sigma_mm=1e3}]'
    err = one_line(
        capsys, main(["check", PLATE, "--set", f"network.grids={grid}"]), "from its weights"
    )
    assert "point 'G" in err and "rank defect" not in err


def test_a_bias_that_makes_a_distance_negative_is_refused_at_check(capsys):
    obs = '[{kind="distance",from="N6",to="N7",sigma_mm=1.0,bias_mm=-30000}]'
    one_line(
        capsys,
        main(["check", str(FIELD), "--set", f"network.observations={obs}"]),
        "network.observations",
        "'N6' to 'N7'",
        "bias_mm",
    )


def test_a_gross_angle_bias_is_named_when_the_run_does_not_converge():
    obs = [{"kind": "angle", "at": "N6", "from": "N5", "to": "N7", "sigma_arcsec": 2.0}]
    _, cfg = load_study(FIELD, values={"network.observations": obs})
    assert biased(build(cfg), cfg, "w") is None  # no bias: the run's own message stands
    # lead32: the solver probe refuses it when the file is loaded (the run computed every
    # chunk first), naming the bias as the run's message did
    with pytest.raises(ConfigError) as e:
        load_study(FIELD, values={"network.observations": [{**obs[0], "bias_arcsec": 2e5}]})
    msg = str(e.value)
    assert msg.startswith("network.observations: none of 16 probe trials converged"), msg
    assert "200000 arcsec" in msg and "angle at 'N6' from 'N5' to 'N7'" in msg


@pytest.mark.parametrize("edit", ["change", "delete"])
def test_a_handle_refuses_its_study_file_edited_since_load(tmp_path, edit):
    f = tmp_path / "t.toml"
    f.write_text(FIELD.read_text())
    h = sim.load(f, trials=200)
    h.replace(seed=3)  # unchanged: fine
    if edit == "change":
        f.write_text(FIELD.read_text().replace("seed = 14", "seed = 15"))
    else:
        f.unlink()
    for call in (lambda: h.run(out=tmp_path / "o"), lambda: h.replace(seed=3)):
        with pytest.raises(ConfigError, match="study_file: .* since sim.load"):
            call()
    assert not (tmp_path / "o").exists()


def test_without_snooping_the_rejection_row_is_undecidable_not_holds():
    row = {"claim": REJECTED, "kind": "prediction", "outcome": "holds", "verdict": "holds"}
    row = {**row, "holds": True, "note": "n"}
    other = {**row, "claim": "agnard.other"}
    (r, o) = without_snooping({"snoop.max_reject": 0}, [row, other])
    assert (r["verdict"], r["outcome"], r["holds"]) == ("undecidable", "undecidable", None)
    assert "snoop.max_reject = 0" in r["note"] and o == other
    assert without_snooping({"snoop.max_reject": 25}, [row]) == [row]


def test_the_rejection_note_never_states_a_share_over_100_percent():
    ev = {"share_zero": np.array([1.0, 1.0]), "share_zero_high": np.array([1.0, 1.0])}
    note = _zeros(SimpleNamespace(outputs={REJECTED: ev}), REJECTED, 2)  # 2 pairs: the least
    shares = [float(x) for x in re.findall(r"([\d.e+]+) %", note)]
    assert shares and max(shares) <= 100, note


def test_a_dms_value_of_60_seconds_is_read_as_gama_local_reads_it(tmp_path, capsys):
    src = (ROOT / "tests" / "data" / "gama" / "user_dms.xml").read_text()
    m = re.search(r'val="(\d+)-(\d+)-([\d.]+)"', src)
    assert m, "the reference file has a d-m-s value"
    f = tmp_path / "n.xml"
    f.write_text(src.replace(m.group(0), f'val="{m.group(1)}-{m.group(2)}-60.00"', 1))
    study = tmp_path / "s.toml"
    study.write_text(f'study = "network"\ntrials = 40\nchunk = 2\n[network]\ngama_xml = "{f}"\n')
    assert main(["check", str(study)]) == 0, capsys.readouterr().err
    assert "d-m-s" not in read_gama(f)["note"]  # 60.00: a value rounded up, not named
    # (doors46x: 60.01 seconds, as gama-local reads them, the note naming the value)
    f.write_text(src.replace(m.group(0), f'val="{m.group(1)}-{m.group(2)}-60.01"', 1))
    assert main(["check", str(study)]) == 0, capsys.readouterr().err
    assert "60.01" in read_gama(f)["note"]


def test_a_free_gama_file_with_xy_points_is_read_in_their_inner_datum(tmp_path, capsys):
    """The suite's own export of a free network (``adj="XY"``, no fixed point) imported
    again, the study saying nothing of the datum: gama-local adjusts it in the inner datum
    over those points, and so does the study (it refused: "rank defect of 3")."""
    xml = ROOT / "tests" / "data" / "gama" / "directions_free.xml"
    study = tmp_path / "s.toml"
    study.write_text(f'study = "network"\ntrials = 40\nchunk = 2\n[network]\ngama_xml = "{xml}"\n')
    assert main(["check", str(study)]) == 0, capsys.readouterr().err
    _, cfg = load_study(study)
    full = merge_gama(cfg)
    assert full["datum.kind"] == "inner" and full["datum.points"] == ["P1", "P2", "P3"]


@pytest.mark.parametrize(
    "sets, words",
    [
        (  # two blocks of points, one of them tied to the fixed points by no observation
            [
                'network.grids=[{prefix="N",nx=15,ny=10,spacing_m=1.0,origin_m=[2.0,2.0]},'
                '{prefix="M",nx=15,ny=10,spacing_m=1.0,origin_m=[60.0,60.0]}]',
                'network.points=[{name="A",x_m=0.0,y_m=0.0,role="fixed"},'
                '{name="B",x_m=0.0,y_m=1.0,role="fixed"},{name="C",x_m=1.0,y_m=0.0,role="fixed"}]',
                'network.generate=[{kind="distance",from="*",to="*",nearest=4,sigma_mm=1.0},'
                '{kind="direction",from="*",to="*",nearest=3,sigma_arcsec=1.0}]',
            ],
            "points 'M1', 'M2', 'M3' and 147 more are tied to the datum by no observation",
        ),
        (  # a line of points seen by distances along it only: no y
            [
                'network.grids=[{prefix="N",nx=400,ny=1,spacing_m=1.0,origin_m=[2.0,0.0]}]',
                'network.generate=[{kind="distance",from="*",to="*",nearest=2,sigma_mm=1.0}]',
                'network.points=[{name="A",x_m=0.0,y_m=0.0,role="fixed"},'
                '{name="B",x_m=1.0,y_m=5.0,role="fixed"}]',
            ],
            "(y) is determined by no observation (399 such unknowns)",
        ),
    ],
)
def test_a_large_singular_network_names_its_loose_points(capsys, sets, words):
    """On the sparse path (400 unknowns and more) a singular network said only "the normal
    equations are singular": now it names the loose points."""
    base = ["network.observations=[]", "compare.fix=[]", "output.inner_over=[]"]
    args = ["check", str(FIELD)]
    for s in base + sets:
        args += ["--set", s]
    one_line(capsys, main(args), "datum.kind", words)


def _results_with(tmp_path, name: str) -> Path:
    res = tmp_path / "res"
    shutil.copytree(ROOT / "results" / "network_plate", res / name, ignore=_no_trials)
    return res


def _no_trials(d, names):
    return ["trials"] if "trials" in names else []


def test_verify_names_a_sweeps_results_as_a_sweep_not_as_missing(tmp_path, capsys):
    res = _results_with(tmp_path, "network_plate")
    (res / "sw").mkdir()
    (res / "sw" / "sweep.parquet").write_bytes(b"")
    rc = verify_main(["--results", str(res), "--study", "sw", "--no-record"])
    one_line(capsys, rc, "--study", "holds a sweep's results")


def test_verify_states_no_deviation_when_it_compared_nothing(tmp_path, capsys):
    """Results of a study file outside studies/ cannot be re-run: "FAILED; 0 files; largest
    relative deviation 0" read as a comparison made; now it says nothing was compared."""
    res = _results_with(tmp_path, "mine")
    rec = json.loads((res / "mine" / "run.json").read_text(encoding="utf-8"))
    rec["written_as"] = "mine"  # a run of a study file kept elsewhere, not a copy of another's
    rec["study_file"] = {"path": str(tmp_path / "mine.toml"), "sha256": "0" * 64}
    (res / "mine" / "run.json").write_text(json.dumps(rec), encoding="utf-8")
    rc = verify_main(["--results", str(res), "--study", "mine", "--no-record"])
    out = capsys.readouterr().out
    assert rc == 1 and "mine: FAILED; nothing compared" in out and "deviation" not in out
    assert "no study file" in out


def test_a_handle_is_hashable_and_numpy_values_nested_in_tables_are_plain():
    """``hash(handle)`` (a set of handles, a cache key) raised the dataclass's TypeError on
    its config dict; a NumPy scalar inside a list of tables was refused as "must be a finite
    number (got np.float32(1.0))"."""
    a, b, c = (sim.load(FIELD, trials=t) for t in (200, 200, 300))
    assert hash(a) == hash(b) and len({a, b, c}) == 2
    gen = sim.load(FIELD, trials=200).config["network.generate"]
    gen = [{**g, "sigma_mm": np.float32(g["sigma_mm"])} if "sigma_mm" in g else g for g in gen]
    h = sim.load(FIELD, trials=200, **{"network.generate": gen})
    assert h.config["network.generate"][0]["sigma_mm"] == 1.0


def test_a_defect_between_the_distance_constant_and_scale_names_their_keys(capsys):
    """Distances all of one length cannot separate an estimated additive constant from an
    estimated scale: the error blamed datum.kind and advised fixing points."""
    gen = (
        'network.generate=[{kind="distance",from="N*",to="N*",nearest=2,sigma_mm=1.0},'
        '{kind="direction",from=["A","B","C","D"],to="*",sigma_arcsec=1.0}]'
    )
    args = ["check", str(FIELD), "--set", gen, "--set", "network.estimate_scale=true"]
    args += ["--set", "network.estimate_constant=true"]
    err = one_line(capsys, main(args), "network.estimate_constant", "constant and the scale")
    assert "datum.kind" not in err


def test_plain_point_names_are_matched_without_a_pattern_scan(monkeypatch):
    """A gama-local file of 3,000 points and 42,000 listed observations took three minutes
    to load: every listed name was matched by fnmatch against every point (now 25 s, most
    of it the pre-analysis). 20,000 plain names among 2,000 points: the old scan made 4e7
    pattern matches, the lookup none; a pattern still matches as before (counted, not timed)."""
    names = [f"P{a}" for a in range(2000)]
    index = validate.name_index(names)
    calls = []
    real = validate.fnmatch.fnmatchcase
    monkeypatch.setattr(validate.fnmatch, "fnmatchcase", lambda a, b: calls.append(1) or real(a, b))
    hits = [_match("k", f"P{a % 2000}", names, index) for a in range(20000)]
    assert not calls and hits[1999] == [1999]
    assert _match("k", ["P1?", "P1"], names, index)[:2] == [10, 11]
    with pytest.raises(ConfigError, match="no point named 'Q1'"):
        _match("k", "Q1", names, index)
