"""Review of the session ending 77d4b1b3 (brief R32: the diff c26b6107..77d4b1b3 read for
defects); one case each, each failed on the code before its fix.

* A study file that is no TOML and begins with ``{`` nested deeper than Python's recursion
  limit (``{"a": [[[[...``) made ``sim.load`` raise RecursionError (no ConfigError) and
  ``sim check`` say "RecursionError: maximum recursion depth exceeded while decoding a JSON
  array", naming no file: the hint that names a JSON file (:func:`sim.mc.not_toml.kind_hint`)
  parsed it with ``json.loads``, which raised inside the "malformed TOML" handler. It is now
  the file's "malformed TOML ... (it is JSON, ...)" line.
"""

from __future__ import annotations

import subprocess
import sys

import pytest

import sim


def test_deeply_nested_json_as_study_file_is_one_line(tmp_path):
    f = tmp_path / "deep.toml"
    f.write_text('{"a": ' + "[" * 100_000 + "\n")
    p = subprocess.run(
        [sys.executable, "-m", "sim", "check", str(f)], capture_output=True, text=True
    )
    assert p.returncode == 2, p.stderr
    assert "Traceback" not in p.stderr
    lines = p.stderr.strip().splitlines()
    assert len(lines) == 1 and "malformed TOML" in lines[0] and "JSON" in lines[0], p.stderr


def test_deeply_nested_json_as_study_file_api(tmp_path):
    f = tmp_path / "deep.toml"
    f.write_text('{"a": ' + "[" * 100_000 + "\n")
    with pytest.raises(sim.ConfigError, match="malformed TOML.*JSON"):
        sim.load(f)
