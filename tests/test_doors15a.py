"""The small items issue 26's last sweep left (doors15a), one regression test each; each
failed on the code before its fix.

* a number of hundreds of digits (1e300 on an integer key is the integer 10**300) was printed
  whole in its one-line message; now it is shortened (1e+300) in every config message;
"""

import re
from pathlib import Path

import pytest
from oneline import one_line

from sim.cli import main
from sim.mc.config import ConfigError, shown
from sim.studies import load_study

ROOT = Path(__file__).resolve().parent.parent
STUDIES = sorted((ROOT / "studies").glob("*.toml"))
FIELD = ROOT / "studies" / "network_testfield.toml"
LONG = re.compile(r"\d{20,}")


def test_shown_shortens_only_numbers_longer_than_64_bits():
    assert shown(2**63 - 1) == "9223372036854775807"  # a legal seed stays whole
    assert shown(10**300) == "1e+300" and shown(-(10**30)) == "-1e+30"
    assert shown(10**400) == "a 401-digit number" and shown(1.5) == "1.5"
    msg = str(ConfigError("k", f"{10**40} at /tmp/{10**25}/x and 0.{10**30}"))
    assert msg.startswith("k: 1e+40 at /tmp/1") and f"0.{10**30}" in msg  # paths, decimals kept


@pytest.mark.parametrize("path", STUDIES, ids=lambda p: p.stem)
def test_a_huge_number_on_any_integer_key_gets_a_short_message(path):
    study, _ = load_study(path)
    ints = [k for k, f in study.schema.items() if f.kind in ("int", "list[int]")]
    assert ints, path
    for key in ints:
        kind = study.schema[key].kind
        for big in (1e300, -1e30, 1e30):
            value = [big] if kind == "list[int]" else big
            with pytest.raises(ConfigError) as err:
                load_study(path, values={key: value})
            msg = str(err.value)
            assert not LONG.search(msg) and len(msg) < 300, (key, msg)


@pytest.mark.parametrize(
    "setting, needle",
    [
        ("trials=1e300", "trials: must be <= 1e+07 (got 1e+300)"),
        ("seed=-1e30", "seed: must be >= 0 (got -1e+30)"),
        ("chunk=1e400", "chunk: must be finite (got inf)"),
        ("trials=" + "1" * 401, "trials: an integer of 401 digits"),
        ('network.grids=[{prefix="N",nx=1e300,ny=3,spacing_m=25.0}]', "nx: 1e+300 x 3 points"),
        ('network.random=[{prefix="R",n=1e30,half_extent_mm=5.0}]', "network.random[0].n"),
    ],
)
def test_a_huge_set_override_gets_a_short_message(capsys, setting, needle):
    err = one_line(capsys, main(["check", str(FIELD), "--set", setting]), needle)
    assert not LONG.search(err) and len(err) < 300, err
