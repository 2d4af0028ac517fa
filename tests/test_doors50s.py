"""The classes of the sweep doors50s (brief R51: a hostile reading of this session's first
merges), one case each; each failed on the code before its fix.

* A quoted pattern given as a study file (``sim check 'runs/*.toml'``) in a directory of more
  than 2,000 entries: R50's one-directory match read only its first 2,001 entries, and a study
  file listed after them was "a pattern that matched no file" (and more than 2,000 matches
  were "more than 2000 namess"). The directory is read up to 200,000 entries
  (:func:`sim.mc.study_file._matches`).
"""

from __future__ import annotations

import os

from sim.mc import study_file


class _Sorted:
    """``os.scandir`` in name order (the order of a real directory is its file system's)."""

    def __init__(self, scandir, path):
        self.entries = sorted(scandir(path), key=lambda e: e.name)

    def __enter__(self):
        return iter(self.entries)

    def __exit__(self, *_):
        return False


def test_a_pattern_matching_a_file_listed_after_2000_others_is_named_as_matching(
    tmp_path, monkeypatch
):
    """Bad input: a quoted pattern whose one study file is listed after 2,100 other files.
    Before: "no such study file (a pattern that matched no file ...)"."""
    for i in range(2100):
        (tmp_path / f"out{i:05}.txt").touch()
    (tmp_path / "zz.toml").write_text('study = "brown_table1"\n')
    real = os.scandir
    monkeypatch.setattr(os, "scandir", lambda p: _Sorted(real, p))
    said = study_file.study_file_problem(tmp_path / "*.toml")
    assert "it matches 1 file," in said and "matched no file" not in said
    said = study_file.study_file_problem(tmp_path / "*.txt")
    assert "it matches more than 2000 files," in said
