"""The classes of the sweep "numbers of every type through every door" (doors29a), one case
each; each failed on the code before its fix.

* the Python API refused a ``Decimal`` or a ``Fraction`` as "must be a number (got
  Decimal('0.1'))", and ``np.longdouble`` alike; now each is the number it is
  (``Decimal("0.1")`` the double TOML reads for ``0.1``, ``Fraction(400, 1)`` the int 400),
  and one beyond a double's range is refused naming the key (not "must be finite (got inf)");
* an ``int`` subclass (an ``IntEnum`` member) was kept in the resolved config as itself;
  ``np.float32(0.1)`` was ``0.10000000149011612``: the config (and its hash) of the same
  numbers differed by type; now every type gives the config of the plain value, and a NumPy
  float is the decimal number it prints;
* a tuple was a list at the top of an override but refused inside one (``plate.points`` as
  a tuple of pairs, a network's ``from`` as a tuple of names);
* ``run(trials=400.0)`` was refused while ``sim.load(trials=400.0)`` took it (and
  ``Decimal``/``IntEnum`` trials): ``run()`` now validates them as the config keys;
* a -0.0 (a point at ``y_mm = -0.0``, a gama-local ``y="-0"``) gave a network other results
  than 0.0 (atan2 of -0.0) and the config another hash: the sign of a zero is dropped;
* a float of a study file, a ``--set``, a sweep or a GNU Gama file (an attribute, a
  ``<cov-mat>`` variance, a ``distance-stdev`` word) whose digits no double holds was read as
  something else: ``bias_um = 1e-400`` as 0 without a word (a network coordinate too), and
  ``1e400`` "must be finite (got inf)"; now each is refused naming the key and the digits;
* a sweep range's ``num = 3.0`` was refused ("num must be an integer") where ``trials = 3.0``
  is the count 3: now it is the count;
* ``--set comparator.beta_mm=.5`` (or ``5.``, ``07``, ``0x1p3``, a quoted ``"400"``) said
  "must be a number (got '.5')" of what reads as a number: now it says how to write it.
"""

import enum
import math
from decimal import Decimal
from fractions import Fraction
from pathlib import Path

import numpy as np
import pytest
from oneline import one_line

import sim
import sim.api
from sim.cli import main
from sim.mc.config import ConfigError
from sim.mc.storage import config_hash
from sim.studies import load_study
from sim.studies.network.gama import merge_gama

ROOT = Path(__file__).resolve().parent.parent
BROWN = str(ROOT / "studies" / "brown_table1.toml")
FIELD = str(ROOT / "studies" / "network_testfield.toml")


class Count(enum.IntEnum):
    FORTY = 40


class Real(float):
    pass


def _config(**overrides) -> dict:
    return sim.load(BROWN, **overrides).config


def test_decimal_fraction_and_longdouble_are_the_numbers_they_are():
    plain = _config(trials=400, comparator__beta_mm=0.1)
    for trials, beta in [
        (Decimal("400"), Decimal("0.1")),
        (Fraction(400, 1), Fraction(1, 10)),
        (np.int64(400), np.longdouble("0.1")),
    ]:
        cfg = _config(trials=trials, comparator__beta_mm=beta)
        assert (
            cfg == plain and type(cfg["trials"]) is int and type(cfg["comparator.beta_mm"]) is float
        )
    with pytest.raises(ConfigError, match=r"^comparator.beta_mm: Decimal\('1E\+999'\) is beyond"):
        _config(comparator__beta_mm=Decimal("1e999"))
    with pytest.raises(ConfigError, match=r"^trials: must be an integer \(got 400.5\)"):
        _config(trials=Decimal("400.5"))  # not truncated to 400


def test_every_type_of_one_number_gives_one_config_and_one_hash():
    base = _config(trials=40, chunk=2, comparator__beta_mm=0.1)
    want = config_hash(base, "code")
    for trials, beta in [
        (Count.FORTY, np.float32(0.1)),
        (np.uint8(40), np.float16(0.1)),
        (np.array(40), Real(0.1)),
        (40.0, np.array(np.float32(0.1))),
    ]:
        cfg = _config(trials=trials, chunk=2, comparator__beta_mm=beta)
        assert cfg == base and config_hash(cfg, "code") == want
        assert type(cfg["trials"]) is int and type(cfg["comparator.beta_mm"]) is float
    with pytest.raises(ConfigError, match=r"^trials: must be an integer \(got True\)"):
        _config(trials=np.bool_(True))  # a bool is not the count 1


def test_tuples_are_lists_at_any_depth():
    pts = [[0.0, 0.0], [90.0, 0.0], [0.0, 90.0], [90.0, 90.0], [45.0, 45.0], [20.0, 70.0]]
    want = _config(plate__pattern="list", plate__points=pts)["plate.points"]
    for given in (tuple(tuple(p) for p in pts), [tuple(p) for p in pts], np.float32(pts)):
        assert _config(plate__pattern="list", plate__points=given)["plate.points"] == want
    gen = sim.load(FIELD).config["network.generate"]
    as_tuple = [{**g, "from": tuple(g["from"])} if isinstance(g["from"], list) else g for g in gen]
    assert sim.load(FIELD, **{"network.generate": as_tuple}).config["network.generate"] == gen


def test_run_takes_the_trials_and_seed_load_takes(tmp_path, monkeypatch):
    seen = []
    monkeypatch.setattr(sim.api, "execute", lambda study, cfg, *a, **k: seen.append(cfg))
    h = sim.load(BROWN, chunk=2)
    for trials, seed in [(40.0, Decimal("7")), (Count.FORTY, np.int64(7))]:
        h.run(out=tmp_path / "out", trials=trials, seed=seed)
        assert (seen[-1]["trials"], seen[-1]["seed"]) == (40, 7)
    with pytest.raises(ConfigError, match=r"^trials: must be an integer \(got 40.5\)"):
        h.run(out=tmp_path / "out", trials=40.5)


def _unsigned(v: float) -> bool:
    return math.copysign(1.0, v) == 1.0


def test_a_negative_zero_is_zero_in_the_config_and_a_gama_file(tmp_path):
    points = sim.load(FIELD).config["network.points"]
    y = "y_m" if "y_m" in points[0] else "y_mm"
    _, a = load_study(FIELD, values={"network.points": [{**points[0], y: -0.0}, *points[1:]]})
    _, b = load_study(FIELD, values={"network.points": [{**points[0], y: 0.0}, *points[1:]]})
    assert _unsigned(a["network.points"][0][y])
    assert config_hash(a, "code") == config_hash(b, "code")
    _, c = load_study(BROWN, ["errors.bias_um=-0.0"])
    assert _unsigned(c["errors.bias_um"])
    gama = (ROOT / "tests" / "data" / "gama" / "one_fixed.xml").read_text()
    assert 'id="A" x="0.0" y="0.0"' in gama
    (tmp_path / "net.xml").write_text(gama.replace('x="0.0" y="0.0"', 'x="-0" y="-0.0"'))
    study = tmp_path / "net.toml"
    study.write_text(
        f'study = "network"\ntrials = 40\nchunk = 2\n[network]\ngama_xml = "{tmp_path}/net.xml"\n'
    )
    _, cfg = load_study(study)
    a = merge_gama(cfg)["network.points"][0]
    assert a["name"] == "A" and all(_unsigned(a[k]) for k in a if k[0] in "xy")


@pytest.mark.parametrize(
    ("value", "write"),
    [(".5", "write 0.5"), ("5.", "write 5.0"), ("0x1p3", "write 8.0"), ('"0.5"', "write 0.5")],
)
def test_a_set_value_that_spells_a_number_says_how_to_write_it(capsys, value, write):
    args = ["check", BROWN, "--set", f"comparator.beta_mm={value}"]
    one_line(capsys, main(args), "comparator.beta_mm: must be a number (got the text", write)


@pytest.mark.parametrize(
    ("where", "text", "key", "words"),
    [
        ("file", "bias_um = 1e-400", "errors.bias_um", "1e-400 is too small for a 64-bit float"),
        ("set", "errors.bias_um=-1e400", "errors.bias_um", "-1e400 is beyond a 64-bit float"),
        ("sweep", "errors.bias_um = [1e-400, 1.0]", "sweep.errors.bias_um", "1e-400 is too"),
        ("network", "x_mm = 1e-4_00", "network.points", "1e-4_00 is too small"),
    ],
)
def test_digits_no_double_holds_are_refused_not_read_as_zero(
    tmp_path, capsys, where, text, key, words
):
    study = tmp_path / "study.toml"
    args = ["check", str(study)]
    if where == "network":
        study.write_text(
            'study = "network"\ntrials = 40\nchunk = 2\n[network]\npoints = [\n'
            + "".join(
                f'{{ name = "{n}", {x}, y_mm = {y}, role = "fixed" }},\n'
                for n, x, y in [
                    ("A", "x_mm = 0.0", 0),
                    ("B", "x_mm = 400.0", 0),
                    ("C", "x_mm = 0", 300),
                ]
            )
            + f'{{ name = "P", {text}, y_mm = 120.0 }} ]\n'
            + 'generate = [ { kind = "distance", from = ["A", "B", "C"], to = "P", sigma_mm = 0.002 } ]\n'
        )
    else:
        body = Path(BROWN).read_text().replace("trials = 4000", "trials = 40")
        body = body.replace("chunk = 200", "chunk = 2")
        if where == "file":
            assert "bias_um = 0.0" in body
            body = body.replace("bias_um = 0.0", text)
        if where == "sweep":
            body += f"\n[sweep]\n{text}\n"
        if where == "set":
            args += ["--set", text]
        study.write_text(body)
    one_line(capsys, main(args), f"{key}: {words}")


def test_a_gama_value_no_double_holds_is_refused_naming_the_attribute(tmp_path, capsys):
    gama = (ROOT / "tests" / "data" / "gama" / "one_fixed.xml").read_text()
    assert 'id="B" x="250.0"' in gama
    (tmp_path / "net.xml").write_text(gama.replace('id="B" x="250.0"', 'id="B" x="1e-400"'))
    study = tmp_path / "net.toml"
    study.write_text(f'study = "network"\n[network]\ngama_xml = "{tmp_path}/net.xml"\n')
    line = one_line(capsys, main(["check", str(study)]), "network.gama_xml", "attribute 'x'")
    assert "1e-400 is too small for a 64-bit float" in line


def test_a_sweep_range_num_written_as_a_float_is_the_count(tmp_path, capsys):
    body = Path(BROWN).read_text().replace("trials = 4000", "trials = 40")
    study = tmp_path / "brown_table1.toml"
    cells = []
    for num in ("3", "3.0"):
        study.write_text(
            body.replace("chunk = 200", "chunk = 2")
            + f"\n[sweep]\nerrors.settings = {{start = 1, stop = 3, num = {num}}}\n"
        )
        assert main(["check", str(study)]) == 0, capsys.readouterr().err
        cells += [ln for ln in capsys.readouterr().out.splitlines() if "sweep cells" in ln]
    assert len(cells) == 2 and cells[0] == cells[1] and "in 3 sweep cells" in cells[0]


@pytest.mark.parametrize(
    ("file", "old", "new", "words"),
    [
        (
            "user_dms.xml",
            '<cov-mat dim="4" band="0">9.0',
            '<cov-mat dim="4" band="0">1e-400',
            "<cov-mat>",
        ),
        (
            "user_defaults.xml",
            'distance-stdev="2 3 1"',
            'distance-stdev="1e-400 3 1"',
            "distance-stdev",
        ),
    ],
)
def test_gama_variances_and_stdev_words_no_double_holds_are_named(
    tmp_path, capsys, file, old, new, words
):
    gama = (ROOT / "tests" / "data" / "gama" / file).read_text()
    assert old in gama
    (tmp_path / "net.xml").write_text(gama.replace(old, new))
    study = tmp_path / "net.toml"
    study.write_text(f'study = "network"\n[network]\ngama_xml = "{tmp_path}/net.xml"\n')
    line = one_line(capsys, main(["check", str(study)]), "network.gama_xml", words)
    assert "1e-400 is too small for a 64-bit float" in line
