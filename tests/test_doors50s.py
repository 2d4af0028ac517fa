"""The classes of the sweep doors50s (brief R51: a hostile reading of this session's first
merges), one case each; each failed on the code before its fix.

* A quoted pattern given as a study file (``sim check 'runs/*.toml'``) in a directory of more
  than 2,000 entries: R50's one-directory match read only its first 2,001 entries, and a study
  file listed after them was "a pattern that matched no file" (and more than 2,000 matches
  were "more than 2000 namess"). The directory is read up to 200,000 entries
  (:func:`sim.mc.study_file._matches`).
* A study file's name mistyped in a directory whose own name holds ``[`` (``run[1]/stdy.toml``,
  a directory of that very name): R50 took every path with ``[`` in its folders for a pattern
  of folders, "a pattern, not a study file", where it is a file that is not there (and
  ``'run[1]/*.toml'`` was not counted). An existing directory is read as itself: "no such
  study file (did you mean run[1]/study.toml?)".
* A study file at its size limit (16 MiB) with a literal string left open at its end: R50's
  hint for the line that opened it walked the file character by character in Python, 10 s
  of CPU, three times tomllib's own parse of the file, before the one line. Its comments and
  strings are matched by one regular expression now (:func:`sim.mc.toml_slips._left_open`,
  the same line for every case: 300,000 random texts compared).
"""

from __future__ import annotations

import os
import time
import tomllib

from sim.mc import study_file
from sim.mc.toml_slips import slip_hint


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


def test_a_mistyped_name_in_a_directory_named_with_brackets_is_no_pattern(tmp_path):
    """Bad input: ``run[1]/stdy.toml`` for ``run[1]/study.toml``. Before: "a pattern, not a
    study file (which the shell did not expand ...)", without the near name."""
    d = tmp_path / "run[1]"
    d.mkdir()
    (d / "study.toml").write_text('study = "brown_table1"\n')
    said = study_file.study_file_problem(d / "stdy.toml")
    assert "no such study file" in said and "study.toml?" in said and "pattern" not in said
    assert "it matches 1 file," in study_file.study_file_problem(d / "*.toml")


def test_the_hint_for_a_string_left_open_costs_less_than_the_parse_itself():
    """Bad input: 2 MiB of keys with double-quoted texts, then ``q = 'abc`` left open. Before:
    the hint's scan took about three times tomllib's parse of the same text (here: under
    it); the line it names is the one that opened the text."""
    lines = ['study = "brown_table1"', 'name = "Brown\'s plate"']
    lines += [f'a{i} = "{"x" * 60}"  # it\'s {i}' for i in range(24000)] + ["q = 'abc"]
    text = "\n".join(lines) + "\n"
    t0 = time.process_time()
    try:
        tomllib.loads(text)
    except tomllib.TOMLDecodeError as e:
        message = str(e).split(" (at ")[0]
    t1 = time.process_time()
    said = slip_hint(text, message, 0, 0)
    t2 = time.process_time()
    assert said == f" (the text opened at line {len(lines)} is not closed by ')"
    assert t2 - t1 < t1 - t0, (t2 - t1, t1 - t0)
