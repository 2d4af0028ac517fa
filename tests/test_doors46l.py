"""Doors sweep 46l: the items session 45 left (stop 55), each a class of bad input with a test
that failed on the code before its fix.

* R45: ``--out`` naming a directory with files but no run record (a home directory, ``/usr``)
  was walked in full, every entry of every subdirectory, before its refusal (1-4 s on ``/usr``,
  minutes on a home directory of millions of files), looking for a running run's lock to name.
  It now looks at no more than :data:`sim.mc.swap.LOOK_AT` entries, breadth first, and the
  refusal names one of the entries it holds (a directory holding only ``.DS_Store`` looked
  empty to ``ls`` and was refused for holding "files").
"""

from __future__ import annotations

import os

import sim.mc.swap as swap_mod
from sim.cli import main
from sim.mc.storage import StageLock
from tests.oneline import SIM_ERROR, one_line

STUDY = "studies/brown_table1.toml"
ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def _tree(root, dirs: int, files: int) -> None:
    for i in range(dirs):
        d = root / f"d{i:03d}"
        d.mkdir(parents=True)
        for j in range(files):
            (d / f"f{j}").touch()


def test_a_full_out_without_a_record_is_refused_after_a_bounded_look(tmp_path, capsys, monkeypatch):
    """A non-empty ``--out`` with no run record: before, every entry under it was looked at
    (here 2,040; a home directory's millions took minutes) before the one-line refusal."""
    out = tmp_path / "home"
    _tree(out, 40, 50)
    monkeypatch.setattr(swap_mod, "LOOK_AT", 200, raising=False)
    seen, scandir = [], os.scandir

    class Counted:
        def __init__(self, path):
            self.it = scandir(path)

        def __enter__(self):
            return self

        def __exit__(self, *a):
            self.it.close()

        def __iter__(self):
            for e in self.it:
                seen.append(e.path)
                yield e

        def __next__(self):
            e = next(self.it)
            seen.append(e.path)
            return e

        def close(self):
            self.it.close()

    monkeypatch.setattr(os, "scandir", Counted)
    argv = ["run", os.path.join(ROOT, STUDY), "--quiet", "--no-figures", "--out", str(out)]
    line = one_line(capsys, main(argv), "holds files but no sim run record", prefix=SIM_ERROR)
    assert len([p for p in seen if p.startswith(str(out))]) <= 250, len(seen)  # before: 2,040
    assert "it holds 'd000' and more" in line


def test_a_directory_holding_only_a_hidden_file_names_it(tmp_path, capsys):
    """``ls`` shows it empty: the refusal said "holds files" and named none."""
    out = tmp_path / "res"
    out.mkdir()
    (out / ".DS_Store").write_bytes(b"\0")
    argv = ["run", os.path.join(ROOT, STUDY), "--quiet", "--no-figures", "--out", str(out)]
    line = one_line(capsys, main(argv), "no sim run record", prefix=SIM_ERROR)
    assert line.endswith("(it holds '.DS_Store')")


def test_a_running_run_near_the_top_is_still_named(tmp_path, capsys):
    """The bounded look still finds a running run's lock one level down (held: as before)."""
    out = tmp_path / "home"
    _tree(out, 3, 5)
    lock = StageLock(out / "res" / ".net.partial").acquire()
    try:
        argv = ["run", os.path.join(ROOT, STUDY), "--quiet", "--no-figures", "--out", str(out)]
        line = one_line(capsys, main(argv), "is being written by a running sim", prefix=SIM_ERROR)
    finally:
        lock.release()
    assert "holds res/.net.partial, which" in line
