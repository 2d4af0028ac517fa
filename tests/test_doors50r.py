"""Issue 26, helper R50: a hostile reading of session 48's second-wave merges (the copy check
of run.json's ``written_as``, the export and input checks, the chunk digests, the TOML slips).
Each test names the class of bad input and what was wrong before its fix."""

from __future__ import annotations

import glob
import os
import signal
import warnings
from pathlib import Path

import pytest
from conftest import TRIANGLE_NETWORK
from oneline import one_line

import sim
from sim.cli import main
from sim.mc.config import ConfigError, read_toml
from sim.mc.study_source import other_source

RUN = ["--quiet", "--no-figures"]


@pytest.fixture(scope="module")
def done(tmp_path_factory) -> Path:
    """``sim run tri.toml --out r1``: a network run into a directory named by the user."""
    top = tmp_path_factory.mktemp("r50")
    (top / "tri.toml").write_text(TRIANGLE_NETWORK)
    assert main(["run", str(top / "tri.toml"), "--out", str(top / "r1"), *RUN]) == 0
    return top


def _not_named_another_studys(capsys, d) -> None:
    """``sim show`` and ``sim.Results`` of ``d`` say nothing of another study's results."""
    capsys.readouterr()
    assert main(["show", str(d)]) == 0
    assert "holds the results of a run" not in capsys.readouterr().err
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        sim.Results(d, "network").claims()


def test_results_renamed_as_a_whole_are_not_called_another_studys(done, tmp_path, capsys):
    """Unclear message on a legitimate use (J48's copy check): results written with ``--out
    r1`` and then moved or renamed as a whole (``mv r1 2026-11-30``) were noted by ``sim show``
    as "not 2026-11-30's (copied or renamed by hand?): run 2026-11-30's own study file to
    replace them" (no such file ever was) and ``sim.Results`` raised a StaleResultsWarning.
    A name of the user's says no study: no note now. A batch's, or make verify's, name still
    says one (the copy ``cp -r B/alpha B/beta``: tests/test_doors48j.py)."""
    moved = tmp_path / "2026-11-30"
    (done / "r1").rename(moved)
    try:
        _not_named_another_studys(capsys, moved)
        # where the name is taken as a study file's (a batch's B/<stem>), it is still named
        assert "written as r1/" in other_source(moved, "beta")
        assert other_source(moved, "tri") is None
    finally:
        moved.rename(done / "r1")


def test_the_api_takes_every_path_the_command_line_wrote(done, tmp_path):
    """Refused legitimate input (the API's path check against the command line's): results
    that ``sim run --out`` wrote under a name with a no-break space (or a zero-width one: a
    name pasted from a web page) were shown by ``sim show`` but ``sim.Results`` refused them,
    "must be a path (a str or os.PathLike of a str)", of a str; so was a name ``os.listdir``
    gave of a non-UTF-8 directory, whose words are ``sim run``'s now."""
    there = tmp_path / "no\u00a0break\u200b"
    (done / "r1").rename(there)
    try:
        assert sim.Results(there, "network").claims().num_rows == 9
        assert sim.Results(str(there), "network").claims().num_rows == 9
    finally:
        there.rename(done / "r1")
    with pytest.raises(ConfigError, match=r"^path: contains bytes that are not UTF-8 text"):
        sim.Results(str(tmp_path) + "/r\udcff", "network")
    with pytest.raises(ConfigError, match=r"^out: contains a control character or a line br"):
        sim.load(done / "tri.toml").run(out=str(tmp_path / "a\nb"))


@pytest.mark.parametrize(
    "lines, meant",
    [  # the line the slip is on, not the one with an apostrophe in double quotes before it
        (
            ["[network]", 'name = "Brown\'s plate"', "gama_xml = 'net.xml"],
            "(the text opened at line 4 is not closed by ')",
        ),  # a sign: the same thousands separator as without one, not a decimal comma
        (["trials = -4,000"], "no thousands separator: trials = -4000, or trials = -4_000)"),
    ],
)
def test_a_toml_slips_hint_names_the_slip_the_user_made(tmp_path, lines, meant):
    """Unclear message (K48's TOML slips): an unclosed 'text' after a line holding an
    apostrophe inside double quotes (``name = "Brown's plate"``) was said to be opened on
    that earlier line, and ``trials = -4,000`` got "a TOML number has a decimal point, not a
    comma: trials = -4.000" where ``4,000`` gets the thousands separator."""
    f = tmp_path / "slip.toml"
    f.write_text("\n".join(['study = "network"', *lines]) + "\n", encoding="utf-8")
    with pytest.raises(ConfigError) as e:
        read_toml(f)
    assert str(e.value).endswith(meant), str(e.value)


def test_a_handles_study_file_replaced_by_a_fifo_is_named_not_read(done, tmp_path):
    """Hang: ``sim.load(f)``, then ``f`` replaced by a FIFO (or a link to ``/dev/zero``, a
    disk image) before ``run()``: the check that the file is the one loaded read it whole,
    and ``run()`` blocked for ever (``/dev/zero``: until memory ran out). It is named now,
    unread. (Before the fix this test ended on its alarm, not by hanging.)"""
    f = tmp_path / "tri.toml"
    f.write_text(TRIANGLE_NETWORK)
    h = sim.load(f)
    f.unlink()
    os.mkfifo(f)
    old = signal.signal(signal.SIGALRM, lambda *a: pytest.fail("run() read the FIFO"))
    signal.alarm(20)
    try:
        with pytest.raises(ConfigError, match="is no longer a regular file .* since sim.load"):
            h.run(out=tmp_path / "r", figures=False)
        f.unlink()
        f.symlink_to("/dev/zero")
        with pytest.raises(ConfigError, match="is no longer a regular file"):
            h.replace(trials=40)
    finally:
        signal.alarm(0)
        signal.signal(signal.SIGALRM, old)
    assert not (tmp_path / "r").exists()


def test_a_link_to_a_studys_results_is_not_called_a_copy(tmp_path, capsys):
    """Unclear message on a legitimate use (J48's copy check): a symbolic link to a batch's
    results (``latest -> B/alpha``, written under its study file's name) was noted by ``sim
    show latest`` as "not latest's (copied or renamed by hand?)", and ``sim.Results`` warned.
    A link is named by the directory it leads to now; a copy under another name still is
    noted (tests/test_doors48j.py)."""
    (tmp_path / "alpha.toml").write_text(TRIANGLE_NETWORK)
    out = tmp_path / "B" / "alpha"
    assert main(["run", str(tmp_path / "alpha.toml"), "--out", str(out), *RUN]) == 0
    (latest := tmp_path / "latest").symlink_to(out)
    _not_named_another_studys(capsys, latest)
    assert "written as alpha/" in other_source(latest, "beta")  # a batch's beta: still named


def test_a_quoted_pattern_of_folders_is_not_walked(tmp_path, monkeypatch, capsys):
    """Hang: a study file given as a quoted pattern was counted with ``glob``: ``sim check
    '/*/*/*/*/*/*/*/*/*.toml'`` walked the whole disk (/proc too) for minutes before its one
    line. A pattern is matched in its own directory only now (at most 2,000 names); one in
    its folders is named as a pattern unwalked (here ``glob`` would raise)."""
    (tmp_path / "a").mkdir()
    (tmp_path / "a" / "x.toml").write_text(TRIANGLE_NETWORK)
    (tmp_path / "a" / "y.toml").write_text(TRIANGLE_NETWORK)

    def walked(*a, **k):
        raise AssertionError("the pattern was walked with glob")

    monkeypatch.setattr(glob, "glob", walked)
    monkeypatch.setattr(glob, "iglob", walked)
    capsys.readouterr()
    rc = main(["check", f"{tmp_path}/*/*.toml"])
    one_line(capsys, rc, "a pattern, not a study file (which the shell did not expand")
    rc = main(["check", f"{tmp_path}/a/*.toml"])
    one_line(capsys, rc, "a pattern, not a study file (it matches 2 files,")
