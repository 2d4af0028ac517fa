"""The classes of the sweep doors51r (brief R52: a hostile reading of session 51's second wave),
one case each; each failed on the code before its fix.

* A sweep range reckoned in halves (its span overflows a double) with the smallest step
  (``{start = -1e308, stop = 1e308, step = 5e-324}``): half the step is 0.0, and the count of
  values divided by it: ``ZeroDivisionError`` from ``sim.load`` (a traceback of the API),
  "sim: error: ZeroDivisionError: float division by zero" from ``sim check``, no key named;
  now "more than 10000 values", naming the key.
* A ``run.json`` of this code's run forged by keeping its integrity fields and emptying them
  (``table_sha256 = {}``, ``table_shape = {}``): J50's check refused them made null or
  removed, but empty ones passed and a claim's value edited beside them was printed as the
  run's (``sim show`` exit 0, ``sim.Results``); now refused in one line naming the table.
"""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import pytest
from conftest import TRIANGLE_NETWORK

import sim
from sim.cli import main


@pytest.fixture(scope="module")
def tri_run(tmp_path_factory) -> Path:
    """A finished run of conftest's triangle network (no figures), made once: READ ONLY."""
    base = tmp_path_factory.mktemp("tri")
    (base / "tri.toml").write_text(TRIANGLE_NETWORK, encoding="utf-8")
    args = ["run", str(base / "tri.toml"), "--out", str(base / "tri"), "--no-figures", "--quiet"]
    assert main(args) == 0
    return base / "tri"


def _in(cwd: Path, args: list[str], capsys, monkeypatch) -> tuple[int, str]:
    monkeypatch.chdir(cwd)
    rc = main(args)
    return rc, capsys.readouterr().err


def test_sweep_range_in_halves_with_a_denormal_step(tmp_path: Path, capsys, monkeypatch) -> None:
    """Bad input: a sweep's step of 5e-324 over a range whose span overflows (reckoned in
    halves). Before: ZeroDivisionError (the API's traceback, the command's bare "float
    division by zero"); now one ConfigError naming the sweep's key."""
    f = tmp_path / "s.toml"
    f.write_text(
        TRIANGLE_NETWORK + "[sweep]\ntrials = { start = -1e308, stop = 1e308, step = 5e-324 }\n",
        encoding="utf-8",
    )
    with pytest.raises(sim.ConfigError, match=r"^sweep\.trials: step 5e-324 gives more than"):
        sim.load(f)
    rc, err = _in(tmp_path, ["check", "s.toml"], capsys, monkeypatch)
    assert rc == 2 and "sweep.trials" in err and "ZeroDivision" not in err, err


def test_forged_record_with_emptied_integrity_fields(
    tri_run: Path, tmp_path: Path, capsys, monkeypatch
) -> None:
    """Bad input: a run record of this code whose ``table_sha256`` and ``table_shape`` are kept
    but emptied (``{}``), or whose claims' entries are removed, or emptied with every table
    taken off ``files`` too, beside a claim's value edited by hand. Before: ``sim show``
    printed the edited value, exit 0, ``sim.Results`` read it, and ``sim.batch --stale-only``
    called the results up to date; now the readers refuse in one line naming a table, the
    batch calls them out of date, and the unforged record still finds the edit."""
    from hand_edits import edit_first_value

    from sim.batch_checks import why_stale

    d = tmp_path / "tri"
    shutil.copytree(tri_run, d)
    rec = json.loads((d / "run.json").read_text(encoding="utf-8"))
    edit_first_value(d)
    keys = ("table_sha256", "table_shape")
    one = {k: {n: v for n, v in rec[k].items() if n != "claims.parquet"} for k in keys}
    emptied = {**rec, "table_sha256": {}, "table_shape": {}}
    listed = [f for f in rec["files"] if f.startswith("trials/") or not f.endswith(".parquet")]
    words = "neither a sha256 nor a shape of claims.parquet"
    for forged, said in (
        (emptied, words),
        ({**rec, **one}, words),
        ({**emptied, "files": listed}, "lists no claims.parquet among the files"),
    ):
        (d / "run.json").write_text(json.dumps(forged), encoding="utf-8")
        rc, err = _in(tmp_path, ["show", "tri", "--markdown"], capsys, monkeypatch)
        assert rc == 2, err
        assert len(err.strip().splitlines()) == 1 and "Traceback" not in err, err
        assert said in err or "(removed by hand?)" in err, err
        with pytest.raises(sim.ConfigError, match=r"claims\.parquet is not .*table its run"):
            sim.Results(d, "network").claims()
        why = why_stale(tri_run.parent / "tri.toml", d, ["--no-figures"])
        assert why is not None and "by hand?" in why, why
    (d / "run.json").write_text(json.dumps(rec), encoding="utf-8")
    rc, err = _in(tmp_path, ["show", "tri"], capsys, monkeypatch)
    assert rc == 2 and "is not the claims table its run wrote" in err, err  # the edit is seen


def test_joiners_of_a_legit_name_are_not_escaped(tmp_path: Path, capsys, monkeypatch) -> None:
    """Legit non-ASCII names: a Persian directory name with its zero-width non-joiner
    ("نقشه‌برداری", surveying) and an emoji sequence joined by ZWJ. Before: L51's escaping of
    every format character wrote them as ``\\u200c``/``\\u200d`` in every refusal naming them
    (noise, a path no longer copyable); now kept between two non-ASCII characters, while a
    joiner hidden between Latin letters and a bidi override are still escaped."""
    from sim.mc.message_text import printable

    persian, emoji = "نقشه\u200cبرداری", "fam\U0001f468\u200d\U0001f469\u200d\U0001f467"
    for name in (persian, emoji):
        rc, err = _in(tmp_path, ["check", f"{name}/nosuch.toml"], capsys, monkeypatch)
        assert rc == 2 and f"{name}/nosuch.toml: no such study file" in err, err
    assert printable("r\u200dm \u200cx \u202e\u200c") == "r\\u200dm \\u200cx \\u202e\\u200c"


def test_paths_too_long_for_the_system_at_the_other_doors(
    tmp_path: Path, capsys, monkeypatch
) -> None:
    """Paths too long for the system (a name of 300 bytes; 30 names of 200): T50 checked
    ``sim run STUDY`` and the API's ``out``, not the neighbouring doors. Before:
    ``python -m sim.batch --timings`` of one ended in pathlib's "OSError: File name too long"
    (a traceback, exit 1), ``sim run --out`` of one printed the system's words and the whole
    path (6 kB, no option named), ``sim report --results`` said it "does not exist", and
    ``python -m sim.report.verify --scratch`` (``--results``, ``--studies``, ``--study``)
    "File name too long: " and the whole path; now one line each naming the option, exit 2,
    nothing made."""
    import sim.batch
    from sim.report.verify.cli import main as verify

    (tmp_path / "tri.toml").write_text(TRIANGLE_NETWORK, encoding="utf-8")
    deep, wide = "/".join(["b" * 200] * 30), "c" * 300
    for path in (deep, wide):
        monkeypatch.chdir(tmp_path)
        assert sim.batch.main(["--timings", path, "tri.toml"]) == 2
        err = capsys.readouterr().err
        assert err.startswith("sim.batch: --timings: ") and "too long a path" in err, err
        for args in (["run", "tri.toml", "--out", path], ["report", "--results", path]):
            rc, err = _in(tmp_path, args, capsys, monkeypatch)
            assert rc == 2 and f"{args[-2]}: " in err and "too long a path" in err, err
            assert len(err) < 400, err
        for opt in ("--scratch", "--study"):
            assert verify([opt, path]) == 2
            err = capsys.readouterr().err
            assert f"error: {opt}: " in err and "too long a path" in err and len(err) < 400, err
    assert sorted(p.name for p in tmp_path.iterdir()) == ["tri.toml"]


def test_a_kept_readme_of_the_users_is_not_called_the_report(tri_run: Path, tmp_path: Path) -> None:
    """A README.md of the user's kept in a results directory (carried by a run of another
    study with ``--overwrite``: the earlier run's README, edited, or notes of the user's).
    Before: the run's closing lines said "report: DIR/README.md", sending the user to a file
    that is not the run's report (another study's, or their own notes); now they say none
    was written, that one is theirs, and how to print the run's."""
    from sim.report.run_summary import terminal_summary
    from sim.studies import get_study

    d = tmp_path / "tri"
    shutil.copytree(tri_run, d)
    assert terminal_summary(d, shown="r", get_study=get_study).endswith("report: r/README.md")
    (d / "README.md").write_text("# my notes\n", encoding="utf-8")
    last = terminal_summary(d, shown="r", get_study=get_study).splitlines()[-1]
    assert last.startswith("report: not written (r/README.md is yours, kept"), last
    assert "sim show --markdown r" in last


def test_verify_of_a_study_whose_gama_file_is_no_file(tmp_path: Path, capsys, monkeypatch) -> None:
    """A study's ``network.gama_xml`` replaced by a directory, or by a link to nothing, since
    its run; then ``make verify``. Before: B51 told a file moved away (ENOENT) from a failed
    reproduction, but these re-runs' refusals were recorded as "FAILED; nothing compared: the
    re-run exited with 2" (exit 1); now one line naming the file, nothing recorded. (The
    re-run's own line is taken from ``sim check`` of the same study here.)"""
    from sim.report.verify.child import refusal
    from sim.report.verify.rules import VerifyError

    sf = tmp_path / "net.toml"
    sf.write_text('study = "network"\n[network]\ngama_xml = "net.xml"\n', encoding="utf-8")
    (tmp_path / "net.xml").mkdir()
    (tmp_path / "gone.xml").symlink_to(tmp_path / "nowhere")
    for xml in ("net.xml", "gone.xml"):
        sf.write_text(f'study = "network"\n[network]\ngama_xml = "{xml}"\n', encoding="utf-8")
        rc, err = _in(tmp_path, ["check", "net.toml"], capsys, monkeypatch)
        assert rc == 2, err
        line = err.strip()
        with pytest.raises(VerifyError, match=rf"^net: a file its study file .* {xml}"):
            refusal("net", sf, line, tmp_path / "S" / "net", [], [])
