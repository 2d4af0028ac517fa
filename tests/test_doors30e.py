"""The classes of the sweep doors30e (brief D30e: the same results by every route), one case
each; each failed on the code before its fix. The harness that found them (brown_table1,
salsig_encoders and a small network at about 200 trials, each run by ``sim run`` on 1 and 2
workers, the Python API, ``python -m sim.batch``, interrupted by SIGINT, SIGTERM or SIGKILL
and resumed by each of the three, from another working directory, through a symbolic link,
from a clone and a copy of the project, under other ``PYTHONHASHSEED``, BLAS thread counts,
``TZ`` and locale, as a ``[sweep]`` against its ``--set`` runs, and from a study file with
its keys reordered, commented, spelled otherwise or written at their defaults; every file
compared byte for byte, then table by table and key by key of its metadata with pyarrow)
lives outside the project.

* ``sim.load(...).run(out=...)`` wrote no README.md: the results directory of the Python API
  lacked the file ``sim run`` and ``python -m sim.batch`` write into theirs (and that
  ``run.json`` lists), so the same run by two doors gave two directories; a run started by
  ``sim run``, interrupted and finished by the API ended without it too. ``run()`` now writes it
  as ``sim run`` does (:func:`sim.report.run_summary.write_run_readme`, into the sealed staging
  directory before the results are published).
* a network's record written with a field at its default (``role = "free"``, ``settings =
  1``, ``bias_mm = 0.0``, ``nearest = 0``, ``center_mm = [0, 0]``) or with an integer for a
  float (``sigma_arcsec = 2``, ``x_mm = 400``, a constraint's ``1``) was another config of the
  same network, with the same numbers: another config hash (another scratch directory, every
  file's provenance and chunk other bytes), refused as "results of a different config" naming
  a truncated ``network.points`` that showed no difference, or, the values comparing equal in
  Python, run over the other spelling's results. The flat keys were resolved by their fields
  already; the records are now written in one spelling once validated
  (:func:`sim.studies.network.canonical.canonical`).
* a ``[sweep]`` table with its reserved entries at their defaults (``seed_mode = "spawn"``,
  ``replicates = 1``) or an integer for a float key's values (``[35, 45]`` for ``[35.0,
  45.0]``) was another config hash of the same cells (recorded as written in ``run.json`` and
  every file's provenance); :func:`sim.mc.sweep.read_sweep` now gives the table in one spelling.

What held (every file byte-identical, the README's directory name aside): 1 and 2 workers,
the batch, every interruption resumed by any of the three doors, ``--chunk`` or ``--set
chunk=`` at the chunk ``--trials`` picks, another working directory, a symbolic link to the
study file or to ``studies/``, a ``git clone`` at another path (a copy without ``.git``:
``git_commit`` is ``unknown`` in the provenance, nothing else), ``PYTHONHASHSEED``,
``OMP_NUM_THREADS``/``OPENBLAS_NUM_THREADS`` = 1, ``TZ``, ``LANG``/``LC_ALL``, ``python -O``,
``umask 077``, ``SOURCE_DATE_EPOCH``; a ``[sweep]`` cell against the ``--set`` run of its
values (``seed_mode = "common"``: the study's seed; ``"spawn"``: ``--seed`` the cell's
recorded seed; the chunks' provenance names the sweep and cell); a study file reordered,
commented, written with inline tables, dotted keys, ``1_024``, ``4.5e1``, an integer for a
float key, or listed by ``sim check`` and saved: the same config and config hash; ``--executor
dask``; an interrupted sweep resumed by each door; figures drawn by the API in a process whose
``rcParams`` were changed. Named, not a class: another ``chunk`` for the same trials draws other
numbers (docs/cli.md now says so); a study file's ``trials`` (or a swept ``trials``) with a
``chunk`` too large for it is refused naming ``chunk``, where ``--trials`` picks one; a key a
configuration does not read, written at its default (``plate.n_random = 25`` on a grid), is
refused as set (docs/cli.md).
"""

import hashlib
import json
from pathlib import Path

import sim
from sim.cli import main
from sim.mc.storage import code_hash, config_hash

ROOT = Path(__file__).resolve().parent.parent
STUDY = ROOT / "studies" / "brown_table1.toml"
#: brown_table1 at a test's size: 200 trials in 20 chunks, the region at its smallest
SMALL = {"trials": 200, "chunk": 10, "region.points": 256, "region.rounds": 0}


def _files(d: Path) -> dict[str, bytes]:
    return {p.relative_to(d).as_posix(): p.read_bytes() for p in d.rglob("*") if p.is_file()}


def test_the_api_writes_the_directory_sim_run_writes(tmp_path):
    """The same run by ``sim run`` and by ``sim.load(...).run(out=...)``: the same files, each
    byte for byte (README.md and run.json included), each directory named ``bt``."""
    sets = [a for k, v in SMALL.items() for a in ("--set", f"{k}={v}")]
    cli = tmp_path / "cli" / "bt"
    argv = ["run", str(STUDY), "--out", str(cli), "--quiet", "--no-figures", *sets]
    assert main(argv) == 0
    api = tmp_path / "api" / "bt"
    sim.load(STUDY, **SMALL).run(out=api, figures=False)
    a, b = _files(cli), _files(api)
    assert sorted(a) == sorted(b), set(a) ^ set(b)
    # README.md names its directory's path for `sim show` (outside results/ and scratch/, doors39l)
    a["README.md"] = a["README.md"].replace(str(cli).encode(), b"DIR")
    b["README.md"] = b["README.md"].replace(str(api).encode(), b"DIR")
    assert b"sim show DIR" in a["README.md"]
    # run.json records README.md's sha256 (an edited README is the user's), which names the path
    for files, d in ((a, cli), (b, api)):
        rec = json.loads(files.pop("run.json"))
        assert (
            rec.pop("readme_sha256") == hashlib.sha256((d / "README.md").read_bytes()).hexdigest()
        )
        files["run.json"] = json.dumps(rec, sort_keys=True).encode()
    assert [f for f in a if a[f] != b[f]] == []


#: a small network of the README's kind, and the same network spelled otherwise
NETWORK = """
study = "network"
trials = 200
chunk = 10
[network]
points = [ { name = "A", x_mm = 0.0, y_mm = 0.0, role = "fixed" },
           { name = "B", x_mm = 400.0, y_mm = 0.0, role = "fixed" },
           { name = "C", x_mm = 400.0, y_mm = 300.0, role = "fixed" },
           { name = "P", x_mm = 150.0, y_mm = 120.0 } ]
generate = [ { kind = "distance", from = ["A", "B", "C"], to = "P", sigma_mm = 0.002 },
             { kind = "direction", from = "*", to = "*", sigma_arcsec = 2.0, nearest = 2 } ]
"""
SPELLED = {
    '{ name = "P", x_mm = 150.0, y_mm = 120.0 }': '{ name = "P", x_mm = 150, y_mm = 120.0, role = "free" }',
    "sigma_mm = 0.002 }": "sigma_mm = 0.002, settings = 1, bias_mm = 0.0 }",
    "sigma_arcsec = 2.0,": "sigma_arcsec = 2, settings = 1.0, bias_arcsec = 0,",
    "nearest = 2 }": "nearest = 2.0 }",
    "x_mm = 400.0, y_mm = 0.0": "x_mm = 400, y_mm = 0",
}


def test_a_network_spelled_otherwise_is_one_config(tmp_path):
    """The same network with its records' fields at their defaults and integers for floats:
    the same resolved config and config hash (as a flat key written ``0`` for ``0.0``)."""
    text = NETWORK
    for a, b in SPELLED.items():
        assert a in text
        text = text.replace(a, b)
    (tmp_path / "a.toml").write_text(NETWORK)
    (tmp_path / "b.toml").write_text(text)
    a, b = (sim.load(tmp_path / f"{n}.toml").config for n in "ab")
    code = code_hash("network")
    assert config_hash(dict(b), code) == config_hash(dict(a), code)
    assert "role" not in a["network.points"][3] and "settings" not in b["network.generate"][0]


def test_a_sweep_spelled_otherwise_is_one_config(tmp_path):
    """The same sweep with ``seed_mode`` and ``replicates`` at their defaults and integers for
    a float key: the same sweep table and config hash (as the ``--set`` runs of its cells)."""
    base = 'study = "brown_table1"\ntrials = 200\nchunk = 10\n[sweep]\n'
    (tmp_path / "a.toml").write_text(base + '"plate.spacing_mm" = [35.0, 45.0]\n')
    (tmp_path / "b.toml").write_text(
        base + '"plate.spacing_mm" = [35, 45]\nseed_mode = "spawn"\nreplicates = 1\n'
    )
    a, b = (sim.load(tmp_path / f"{n}.toml") for n in "ab")
    code = code_hash("brown_table1")
    assert b.sweep == {"plate.spacing_mm": [35.0, 45.0]}
    assert config_hash({**b.config, "sweep": b.sweep}, code) == config_hash(
        {**a.config, "sweep": a.sweep}, code
    )
