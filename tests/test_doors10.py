"""The failure classes of the tenth sweep of bad inputs (issue 26), one case per class; each
failed on the code before its fix.

* a handle of the Python API kept its study file's path as given: after ``os.chdir``,
  ``handle.replace(...)`` and ``handle.run(trials=...)`` (which load the file again) read
  another file of that relative name, or none;
* ``handle.run(out="o")`` in a working directory that was deleted ended in pathlib's
  ``FileNotFoundError`` with a traceback;
* a handle run after its ``network.gama_xml`` file was edited simulated the edited network
  and recorded the sha256 of the file as loaded (results that are not what their run record
  says);
* ``SIM_FIGURE_CHECK`` naming a directory or a path that cannot be written ended the run
  with "sim: error: Is a directory: DIR", not naming the variable;
* number keys of Wolf and Agnard at the smallest positive double (5e-324, inside their open
  bound 0: ``reduce.ab_mm``, ``reading.count_um``, ``field.drift_tau_weeks``,
  ``measure.parallax_px``, ``weights.pass``) passed ``sim check`` and then failed at run time
  naming an internal function (ZeroDivisionError, NonFiniteError), or ran with NumPy's
  overflow warnings: each is now at least 1e-6 of the paper's value; Brown's range sigma
  (``errors.setting_sigma_um = 5e-324`` without a comparator error, brown_dilution) is at
  least 1e-6 um (its claims were NaN);
* ``make verify`` compared committed results made with other options (or stale against the
  study file) with a re-run of the study file and reported the differing numbers as failures
  to reproduce; it now names the config keys that differ;
* a GNU Gama ``<angle>`` giving a sight twice (``bs`` and its alias ``to``, ``fs`` and
  ``rs``) kept one without a word, and its sight was not read as a point name (``bs=" B "``
  was "from=' B ': no such <point>", naming the suite's field, not the attribute).
"""

import os
from pathlib import Path

import matplotlib.pyplot as plt
import pytest

import sim
from sim.mc.config import ConfigError
from sim.report.plotting import save
from sim.report.verify.rerun import verify
from sim.studies import load_study
from sim.studies.network.gama_read import read_gama

ROOT = Path(__file__).resolve().parent.parent
GAMA = ROOT / "tests" / "data" / "gama" / "one_fixed.xml"


def test_a_handle_reloads_its_own_file_after_a_chdir(tmp_path, monkeypatch):
    monkeypatch.chdir(ROOT)
    h = sim.load("studies/network_brown.toml", trials=40)
    (tmp_path / "studies").mkdir()  # another study file of the same relative name
    (tmp_path / "studies" / "network_brown.toml").write_text('study = "salsig_encoders"\n')
    monkeypatch.chdir(tmp_path)
    assert h.path == ROOT / "studies" / "network_brown.toml"
    assert h.replace(seed=3).name == "network"


def test_a_relative_out_in_a_deleted_working_directory_is_named(tmp_path, monkeypatch):
    h = sim.load(ROOT / "studies" / "network_brown.toml", trials=40)
    gone = tmp_path / "gone"
    gone.mkdir()
    monkeypatch.chdir(gone)
    gone.rmdir()
    with pytest.raises(ConfigError, match=r"^out: o is relative, but the working directory"):
        h.run(out="o", figures=False)


def test_a_run_refuses_a_gama_file_edited_since_the_study_was_loaded(tmp_path):
    xml = tmp_path / "net.xml"
    xml.write_text(GAMA.read_text())
    study = tmp_path / "s.toml"
    study.write_text(
        f'study = "network"\ntrials = 40\nchunk = 2\n[network]\ngama_xml = "{xml}"\n'
        '[datum]\nkind = "inner"\n'
    )
    h = sim.load(study)
    xml.write_text(GAMA.read_text().replace('stdev="2.0"', 'stdev="4.0"'))
    with pytest.raises(ConfigError, match=r"^network.gama_sha256: .* has changed since"):
        h.run(out=tmp_path / "o", figures=False)
    assert sorted(os.listdir(tmp_path)) == ["net.xml", "s.toml"]  # nothing written


@pytest.mark.parametrize(
    "angle, words",
    [
        ('bs="B" to="A" fs="D"', "attribute 'to' (to='A'): 'bs' and 'to' both name this sight"),
        ('bs="B" fs="D" rs="A"', "attribute 'rs': 'fs' and 'rs' both name this sight"),
        ('bs="B\u202e" fs="D"', "attribute 'bs': 'B\\u202e': a point name is printable"),
    ],
)
def test_an_angles_sights_are_read_once_as_point_names(tmp_path, angle, words):
    old = '<distance to="D" val="256.7586415293553" stdev="2.0" />'
    p = tmp_path / "a.xml"
    # val="10.0" is no angle of these points: a tol-abs under which gama-local keeps it
    text = GAMA.read_text().replace('sigma-act="apriori"', 'sigma-act="apriori" tol-abs="1e9"')
    p.write_text(text.replace(old, f'<angle {angle} val="10.0" stdev="5" />'))
    with pytest.raises(ConfigError) as e:
        read_gama(p)
    assert words in str(e.value) and "\n" not in str(e.value), str(e.value)
    p.write_text(text.replace(old, '<angle bs=" B " fs="D" val="10.0" stdev="5" />'))
    (got,) = [o for o in read_gama(p)["network.observations"] if o["kind"] == "angle"]
    assert got == {
        "kind": "angle",
        "at": "C",
        "from": "B",
        "to": "D",
        "sigma_arcsec": pytest.approx(5 * 0.324),
    }


def test_a_users_link_fifo_and_empty_directory_survive_a_rerun(tmp_path):
    # an --overwrite re-run kept a user's regular files only: a symbolic link (to data
    # elsewhere), a FIFO and an empty directory in the results directory were deleted
    h = sim.load(ROOT / "studies" / "network_brown.toml", trials=40)
    out = tmp_path / "out"
    h.run(out=out, figures=False)
    (tmp_path / "data").mkdir()
    (out / "data").symlink_to(tmp_path / "data")
    (out / "dangling").symlink_to(tmp_path / "nowhere")
    os.mkfifo(out / "pipe")
    (out / "empty" / "deeper").mkdir(parents=True)
    h.run(out=out, trials=60, figures=False, overwrite=True)
    assert os.readlink(out / "data") == str(tmp_path / "data")
    assert os.readlink(out / "dangling") == str(tmp_path / "nowhere")
    assert (out / "pipe").is_fifo() and (out / "empty" / "deeper").is_dir()
    assert sim.Results(out, "network").table("trials").num_rows == 60


def test_a_figure_check_file_that_cannot_be_written_names_the_variable(tmp_path, monkeypatch):
    monkeypatch.setenv("SIM_FIGURE_CHECK", str(tmp_path))
    fig = plt.figure(figsize=(1, 1))
    with pytest.raises(ConfigError, match=r"^SIM_FIGURE_CHECK: cannot append to .*: Is a dir"):
        save(fig, tmp_path / "f.png")
    plt.close(fig)


@pytest.mark.parametrize(
    "study, key, lo",
    [
        ("wolf_polynomial", "reduce.ab_mm", 1e-4),
        ("wolf_polynomial", "reading.count_um", 4e-6),
        ("wolf_polynomial", "field.drift_tau_weeks", 52e-6),
        ("agnard_block", "measure.parallax_px", 5e-7),
        ("agnard_block", "weights.pass", 1e-7),
    ],
)
def test_a_positive_key_at_the_smallest_double_is_refused_on_load(study, key, lo):
    # (the runs at each bound itself end with exit 0 and no warning: checked by the sweep)
    with pytest.raises(ConfigError, match=rf"^{key}: must be >= {lo:g} \(got 5e-324\)$"):
        load_study(ROOT / "studies" / f"{study}.toml", values={key: 5e-324})


def test_a_brown_range_sigma_the_model_cannot_divide_by_is_refused_on_load():
    study = ROOT / "studies" / "brown_dilution.toml"
    with pytest.raises(ConfigError, match=r"^errors.setting_sigma_um: the range sigma .* is 0 um"):
        load_study(study, values={"errors.setting_sigma_um": 5e-324})
    assert load_study(study, values={"errors.setting_sigma_um": 1e-6})[1]["trials"] > 0


def test_verify_names_committed_results_of_another_config_as_stale(tmp_path):
    # results made with other options (trials 40) against a re-run of the study file (60):
    # verify reported their numbers as failures to reproduce ("0.950185 committed, 0.950296
    # re-run"), as if the suite were not reproducible
    h = sim.load(ROOT / "studies" / "network_brown.toml", trials=40)
    h.run(out=tmp_path / "results" / "network_brown", figures=False)
    h.run(out=tmp_path / "scratch" / "network_brown", trials=60, figures=False)
    (c,) = verify(tmp_path / "results", tmp_path / "scratch", rerun=False)
    assert not c.ok and c.failures == [
        "the committed results are of another config than the re-run (keys chunk, trials): "
        "they are stale or were made with other options; run make reproduce, then verify"
    ]
