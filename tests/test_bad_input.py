"""Every file of the bad-input corpus gives one clear line, exit code 2, and no result.

Each file in ``tests/data/bad/`` starts with ``# expect: <text>``: the text the error line
must contain (files without it, e.g. binary garbage, only need the clean failure).
"""

from pathlib import Path

import pytest

from sim.cli import main

BAD = sorted((Path(__file__).parent / "data" / "bad").glob("*.toml"))


def test_corpus_is_large_enough():
    assert len(BAD) >= 30


def _expect(p: Path) -> str | None:
    try:
        first = p.read_text().splitlines()[0]
    except (UnicodeDecodeError, IndexError):
        return None
    return first.split("# expect:", 1)[1].strip() if first.startswith("# expect:") else None


@pytest.mark.parametrize("path", BAD, ids=[p.stem for p in BAD])
def test_bad_study_file(path, tmp_path, capsys):
    out = tmp_path / "res"
    code = main(["run", str(path), "--out", str(out), "--quiet"])
    err = capsys.readouterr().err.strip().splitlines()
    assert code == 2
    assert len(err) == 1 and err[0].startswith("sim: error:"), err
    assert "Traceback" not in err[0]
    want = _expect(path)
    if want:
        assert want in err[0], err[0]
    assert not out.exists() and not (tmp_path / ".res.partial").exists()
