"""The classes of the sweep doors22d (a study author writing new study files from the docs: a
network of their own, variants of the paper studies, own directories, batches, verify), one
case each; each failed on the code before its fix.

* ``python -m sim.batch mine/brown_table1.toml`` (an author's variant named as a shipped
  study, run from the project's root with the default ``--results results``) replaced the
  committed ``results/brown_table1`` with the variant's results, exit 0: each run of a batch
  is ``--overwrite`` (:func:`sim.batch_checks._replaces_project_results`);
* ``sim run mine/my_net.toml`` without ``--out`` in the project's root wrote a new
  ``results/my_net/`` into the committed results (REPORT.md then listed it, ``make verify``
  failed on it), though the docs say only ``make reproduce``/``make rerun`` write there: it
  goes to ``scratch/<name>-<hash>/`` and says so (:func:`sim.places.default_out`);
* ``make verify`` over an author's own results directory re-ran the project's
  ``studies/<name>.toml`` (a variant named ``brown_table1`` was compared with the shipped
  study's full run, ``no study file studies/my_net.toml`` for a new one): ``--studies DIR``
  names where the study files are, and the messages say so (:mod:`sim.report.verify`);
* Wolf's ``table1.file`` relative path is read from the project root: an author's own edited
  copy at the same relative path in the working directory was silently passed over for the
  shipped table (``sim check`` and ``sim run`` exit 0 on the shipped numbers); a file there
  that differs from the root's is refused naming the key (:func:`sim.studies.wolf.checks.table_path`);
* ``include = "base.toml"`` (a key no study has, whose value is a file beside the study) was
  answered "base.toml not found in ... run from studies or give an absolute path", as if
  include were supported from another directory: it is ``include: unknown key``;
* an edited Wolf table left the config as it was (``--stale-only``: up to date): its sha256
  is part of the config (``table1.sha256``, ``table3.sha256``);
* a Wolf table beside the study file got ``network.gama_xml``'s hint "read from the working
  directory: run from studies", where it was still not read;
* ``scale.graduated_mm = 200`` in brown_design: "at most -32.8 mm fits": no offset fits;
* point layouts given only under ``[sweep]``: "a network needs at least two points", without
  saying that the file's own values are checked first, the swept key at its default.
"""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest
from oneline import SIM_ERROR, one_line

from sim import batch, cli
from sim.batch_checks import _replaces_project_results
from sim.mc.config import ConfigError
from sim.report.verify import main as verify_main
from sim.studies import load_study

ROOT = Path(__file__).resolve().parents[1]

NET = """study = "network"
trials = 40
chunk = 2
seed = 5
[network]
name = "mine"
points = [ { name = "A", x_mm = 0.0, y_mm = 0.0, role = "fixed" },
           { name = "B", x_mm = 400.0, y_mm = 0.0, role = "fixed" },
           { name = "C", x_mm = 400.0, y_mm = 300.0, role = "fixed" },
           { name = "P", x_mm = 150.0, y_mm = 120.0 } ]
generate = [ { kind = "distance", from = ["A", "B", "C"], to = "P", sigma_mm = 0.002 } ]
"""


def _project(tmp_path: Path, monkeypatch) -> Path:
    """A project root in ``tmp_path`` as the working directory: ``studies/net_a.toml`` and its
    committed results ``results/net_a``; returns an author's directory ``mine/``."""
    (tmp_path / "studies").mkdir()
    (tmp_path / "studies" / "net_a.toml").write_text(NET)
    monkeypatch.chdir(tmp_path)
    argv = ["run", "studies/net_a.toml", "--out", "results/net_a", "--quiet", "--no-figures"]
    assert cli.main(argv) == 0
    (tmp_path / "mine").mkdir()
    return tmp_path / "mine"


def test_a_batch_of_an_authors_file_named_as_a_shipped_study_leaves_its_results(
    tmp_path, monkeypatch, capsys
):
    mine = _project(tmp_path, monkeypatch)
    record = (tmp_path / "results" / "net_a" / "run.json").read_text()
    f = mine / "net_a.toml"
    f.write_text(NET.replace("seed = 5", "seed = 6"))  # the author's variant
    capsys.readouterr()
    line = one_line(
        capsys, batch.main([str(f)]), "results/net_a", "--results", prefix="sim.batch: "
    )
    assert "studies/net_a.toml" in line
    assert (tmp_path / "results" / "net_a" / "run.json").read_text() == record
    assert _replaces_project_results(f, Path("elsewhere")) is None  # its own results: fine
    assert _replaces_project_results(Path("studies/net_a.toml"), Path("results")) is None


def test_a_run_of_an_authors_file_without_out_stays_out_of_the_committed_results(
    tmp_path, monkeypatch, capsys
):
    mine = _project(tmp_path, monkeypatch)
    (mine / "my_net.toml").write_text(NET)
    assert cli.main(["run", "mine/my_net.toml", "--quiet", "--no-figures"]) == 0
    assert "not the project's studies/my_net.toml" in capsys.readouterr().err
    assert not (tmp_path / "results" / "my_net").exists()
    assert [p.name[:7] for p in (tmp_path / "scratch").iterdir()] == ["my_net-"]


def test_verify_re_runs_an_authors_results_from_their_study_files(tmp_path, monkeypatch, capsys):
    mine = _project(tmp_path, monkeypatch)
    (mine / "my_net.toml").write_text(NET)
    res = tmp_path / "myres"
    assert cli.main(["run", "mine/my_net.toml", "--out", str(res / "my_net"), "--quiet"]) == 0
    capsys.readouterr()
    argv = ["--results", str(res), "--scratch", str(tmp_path / "s"), "--no-record"]
    assert verify_main(argv) == 1  # the project's studies/ has no my_net.toml
    assert "--studies" in capsys.readouterr().out
    assert verify_main([*argv, "--studies", str(mine)]) == 0
    assert "my_net: ok" in capsys.readouterr().out
    one_line(capsys, verify_main([*argv, "--studies", str(tmp_path / "nosuch")]), "--studies")


def test_wolfs_table_of_the_working_directory_is_not_passed_over_for_the_projects(
    tmp_path, monkeypatch, capsys
):
    data = tmp_path / "studies" / "data"
    data.mkdir(parents=True)
    for t in ("wolf_table1.csv", "wolf_table3.csv"):  # the same bytes: read the same
        shutil.copy(ROOT / "studies" / "data" / t, data)
    monkeypatch.chdir(tmp_path)
    wolf = str(ROOT / "studies" / "wolf_polynomial.toml")
    assert cli.main(["check", wolf]) == 0
    capsys.readouterr()
    edited = (data / "wolf_table1.csv").read_text().replace("59.080", "59.090")
    (data / "wolf_table1.csv").write_text(edited)  # the author's own numbers
    line = one_line(capsys, cli.main(["check", wolf]), "table1.file", prefix=SIM_ERROR)
    assert "absolute path" in line and str(tmp_path) in line
    own = f"table1.file={str(data / 'wolf_table1.csv')!r}"
    assert cli.main(["check", wolf, "--set", own]) == 0  # named absolutely: read


@pytest.mark.parametrize("key", ["include", "extends"])
def test_an_include_of_another_study_file_is_an_unknown_key(tmp_path, monkeypatch, key):
    (tmp_path / "studies").mkdir()
    (tmp_path / "studies" / "base.toml").write_text(NET)
    f = tmp_path / "studies" / "mine.toml"
    f.write_text(f'{key} = "base.toml"\n{NET}')
    monkeypatch.chdir(tmp_path)
    with pytest.raises(ConfigError, match=rf"^{key}: unknown key"):
        load_study(f)


def test_wolfs_tables_contents_are_part_of_its_config(tmp_path):
    """An edited Table 1 (the author's own coordinates) left the config, and so
    ``--stale-only``, ``make verify`` and a resume, as they were: the results stayed
    "up to date". The sha256 of each table is recorded in the config on load."""
    own = tmp_path / "t1.csv"
    shutil.copy(ROOT / "studies" / "data" / "wolf_table1.csv", own)
    wolf = ROOT / "studies" / "wolf_polynomial.toml"
    _, before = load_study(wolf, values={"table1.file": str(own)})
    own.write_text(own.read_text().replace("59.080", "59.090"))
    _, after = load_study(wolf, values={"table1.file": str(own)})
    differ = sorted(k for k in before if before[k] != after[k])
    assert differ == ["table1.sha256"]
    with pytest.raises(ConfigError, match=r"^table1.sha256: .* has changed"):
        load_study(wolf, values={"table1.file": str(own), "table1.sha256": before["table1.sha256"]})


def test_a_scale_too_short_for_any_offset_says_so_not_a_negative_bound():
    """``scale.graduated_mm = 200`` (an author's shorter comparator) was refused with "at most
    -32.8 mm fits a +-90 mm grid": no offset fits, and the line now says that and what to
    change."""
    design = ROOT / "studies" / "brown_design.toml"
    with pytest.raises(
        ConfigError, match=r"^paper.offset_mm: .*\(no offset fits a \+-90 mm grid: "
    ) as e:
        load_study(design, values={"scale.graduated_mm": 200.0})
    assert "-3" not in str(e.value) and "scale.graduated_mm" in str(e.value)
    with pytest.raises(ConfigError, match=r"\(at most 33.6 mm fits a \+-90 mm grid\)$"):
        load_study(design, values={"paper.offset_mm": 80.0})


def test_wolfs_table_beside_the_study_is_not_said_to_be_read_from_the_working_directory(
    tmp_path, monkeypatch, capsys
):
    """A ``table1.file`` beside the study file was answered "not found in <cwd> (a relative
    path is read from the working directory) ...: run from studies": the hint of
    ``network.gama_xml``; run from there, the table was still not read (the project root is
    where it is read from). The line names the file under the root it looked for."""
    (tmp_path / "studies").mkdir()
    shutil.copy(ROOT / "studies" / "data" / "wolf_table1.csv", tmp_path / "studies" / "t1.csv")
    f = tmp_path / "studies" / "wolf.toml"
    f.write_text('study = "wolf_polynomial"\n[table1]\nfile = "t1.csv"\n')
    monkeypatch.chdir(tmp_path)
    line = one_line(capsys, cli.main(["check", str(f)]), "table1.file", prefix=SIM_ERROR)
    assert (
        str(ROOT / "t1.csv") in line and "working directory" not in line and "run from" not in line
    )


def test_a_key_given_only_in_the_sweep_is_named_when_the_files_own_values_fail(tmp_path):
    """Two point layouts of an author's network given only under ``[sweep]`` were refused
    "network.points: a network needs at least two points": the file's own values are checked
    first as a study of their own, where the swept key takes its default. The line says so."""
    layout = NET[NET.index("points = ") : NET.index("generate = ")].removeprefix("points = ")
    body = NET.replace(f"points = {layout}", "")
    other = layout.strip().replace("x_mm = 150.0", "x_mm = 350.0")  # P moved
    f = tmp_path / "layouts.toml"
    f.write_text(f'{body}[sweep]\n"network.points" = [{layout.strip()}, {other}]\n')
    with pytest.raises(ConfigError, match=r"^network.points: a network needs at least two") as e:
        load_study(f)
    assert "network.points is swept but not given there" in str(e.value)
    g = tmp_path / "given.toml"  # given outside [sweep] too: it loads
    g.write_text(f'{NET}[sweep]\n"network.points" = [{layout.strip()}, {other}]\n')
    assert cli.main(["check", str(g)]) == 0
    assert load_study(g)[1]["network.points"][3]["name"] == "P"
