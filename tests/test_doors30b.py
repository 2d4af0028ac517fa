"""The classes of the sweep doors30b (brief D30b: every filesystem step fails in turn, on the
paths doors29e did not enumerate: a resumed run, the Python API, the network kind with a
``gama_xml`` file, and a run stopped between publishing's two steps), one case each; each
failed on the code before its fix.

* A run stopped (killed, Ctrl-C) right after its results were swapped into place, before the
  old results (now in the staging directory ``.X.partial``) were moved aside, left them there;
  the next run of the same command without ``--overwrite`` refused them as "an unfinished run
  of a different config" and advised to "run again with its values to finish it", which would
  have brought the replaced results back over the new ones. A publish now records the run
  record it replaces by its sha256 (``run.json`` ``replaced``); the next run removes those
  results, or refuses in one line when a file of the user's in them is not in
  the new results.
* ``Results.table(name)`` (``claims()``) whose table's provenance could not be read (EIO,
  EACCES while reading its schema) called it "not a table sim wrote ...; run the study again"
  (a re-run would not help); a table that cannot be read said only the error's kind
  ("cannot be read (OSError)"). Both now name the file and the reason ("Input/output error").
* A study file that could not be read when a handle checked it (EACCES after a chmod, EIO) was
  said to have "changed since sim.load()" (``run()``, ``replace()``) or to have "changed while
  it was loaded" (``sim.load``), and a handle whose first read failed checked nothing later.
  It is now one ``ConfigError`` naming ``study_file``, the file and the reason.
* A staging directory's ``run.json`` that could not be read when the sealed run was published
  (EIO on its read: the 111th filesystem step of a network run through the API) ended in an
  AttributeError, exit 3 "internal error" (a traceback from the API). It is now one line
  naming the file, exit 2, the finished chunks kept: the same command again resumes.
"""

from __future__ import annotations

import errno
import json
import os

import pytest

import sim
from sim.cli import main
from sim.mc import publish as publish_mod
from sim.mc.outputs import stage_dir
from sim.mc.storage import LOCK
from tests.oneline import SIM_ERROR, one_line

RUN = ["run", "studies/brown_table1.toml", "--trials", "40", "--chunk", "2", "--quiet"]
RUN += ["--set", "region.points=256", "--set", "region.rounds=0", "--no-figures"]


def _stopped_after_the_swap(monkeypatch, out, argv):
    """``argv`` interrupted right after the swap, as a kill there leaves it: the old results in
    the staging directory (the lock file, in a kill's place, in the published results)."""
    real = os.replace

    def stop(a, b, *k, **kw):
        if str(a) == str(stage_dir(out)) and ".old." in str(b):
            raise KeyboardInterrupt
        return real(a, b, *k, **kw)

    monkeypatch.setattr(os, "replace", stop)
    try:
        main(argv)
    except KeyboardInterrupt:
        pass
    monkeypatch.undo()


def test_replaced_results_left_by_a_stop_after_the_swap_are_not_an_unfinished_run(
    tmp_path, monkeypatch, capsys
):
    out = tmp_path / "X"
    assert main([*RUN, "--seed", "7", "--out", str(out)]) == 0
    (out / "notes.txt").write_text("mine\n")
    _stopped_after_the_swap(monkeypatch, out, [*RUN, "--out", str(out), "--overwrite"])
    assert read(stage_dir(out))["config"]["seed"] == 7  # the state a kill leaves
    assert read(out)["config"]["seed"] != 7
    capsys.readouterr()
    assert main([*RUN, "--out", str(out)]) == 0  # before: "an unfinished run of a different config"
    err = capsys.readouterr().err
    assert "resuming" not in err and "note" not in err  # nothing of the old results kept
    assert read(out)["config"]["seed"] != 7 and (out / "notes.txt").read_text() == "mine\n"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["X"] and not (out / LOCK).exists()


def test_replaced_results_with_a_users_file_not_in_the_new_ones_are_named(
    tmp_path, monkeypatch, capsys
):
    out = tmp_path / "X"
    assert main([*RUN, "--seed", "7", "--out", str(out)]) == 0
    (out / "notes.txt").write_text("mine\n")
    _stopped_after_the_swap(monkeypatch, out, [*RUN, "--out", str(out), "--overwrite"])
    (out / "notes.txt").unlink()  # the copy in the new results (the old one is kept)
    capsys.readouterr()
    rc = main([*RUN, "--out", str(out), "--overwrite"])
    one_line(capsys, rc, "replaced", "notes.txt", "which is not in", prefix=SIM_ERROR)
    assert (stage_dir(out) / "notes.txt").read_text() == "mine\n"


def read(d):
    return json.loads((d / "run.json").read_text())


def test_a_table_whose_provenance_cannot_be_read_is_named_with_the_reason(
    tmp_path, monkeypatch, capsys
):
    out = tmp_path / "X"
    assert main([*RUN, "--out", str(out)]) == 0
    res = sim.Results(out, "brown_table1")

    def eio(p):
        raise OSError(errno.EIO, "Input/output error", str(p))

    monkeypatch.setattr("sim.api_tables.read_provenance", eio)
    with pytest.raises(sim.ConfigError, match=r"claims.parquet cannot be read \(Input/output"):
        res.claims()  # before: "is not a table sim wrote, not of 'brown_table1'; run ... again"
    monkeypatch.setattr("sim.api.pq.read_table", eio)
    with pytest.raises(sim.ConfigError, match=r"points.parquet cannot be read \(Input/output"):
        res.table("points")  # before: "cannot be read (OSError)"


def test_a_study_file_that_cannot_be_read_is_not_called_changed(tmp_path, monkeypatch):
    study = tmp_path / "b.toml"
    study.write_bytes(open("studies/brown_table1.toml", "rb").read())
    h = sim.load(study, trials=40, chunk=2)
    real = type(study).read_bytes

    def denied(self):
        if self == study:
            raise PermissionError(errno.EACCES, "Permission denied", str(self))
        return real(self)

    monkeypatch.setattr(type(study), "read_bytes", denied)
    for call in (lambda: h.run(out=tmp_path / "X"), lambda: h.replace(seed=3)):
        with pytest.raises(sim.ConfigError, match=r"study_file: .*b.toml cannot be read \(Perm"):
            call()  # before: "b.toml has changed since sim.load(): load the study again"
    assert not (tmp_path / "X").exists()


def test_a_run_record_unreadable_when_publishing_is_one_line(tmp_path, monkeypatch, capsys):
    out, state = tmp_path / "X", {"publishing": False}
    real_publish, real_read = publish_mod.publish, publish_mod.read_record

    def publishing(stage, dest):
        state["publishing"] = True
        real_publish(stage, dest)

    def read(d):  # the staging directory's record, read as it is published, fails (EIO)
        return None if state["publishing"] and d == stage_dir(out) else real_read(d)

    monkeypatch.setattr("sim.execute.publish", publishing)
    monkeypatch.setattr(publish_mod, "read_record", read)
    rc = main([*RUN, "--out", str(out)])
    one_line(capsys, rc, str(stage_dir(out) / "run.json"), "cannot be read", prefix=SIM_ERROR)
    monkeypatch.undo()
    assert not out.exists() and main([*RUN, "--out", str(out)]) == 0
    assert "resuming brown_table1: 20 finished chunks" in capsys.readouterr().err
