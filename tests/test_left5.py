"""What the last session left under issue 26 (notes/note10.md, "Left, with the reasons"), one
case each; each failed on the code before its fix.

* ``network.xml`` was written in place: a symbolic link placed by hand under that name in a
  run's staging directory was written through (a file outside the output replaced by the
  export); it is now written as every other output, a temporary renamed over the name
  (:func:`sim.studies.network.gama.write_gama`).
"""

from __future__ import annotations

import importlib
from pathlib import Path

from sim.cli import main

network_run = importlib.import_module("sim.studies.network.run")

ROOT = Path(__file__).resolve().parent.parent
PLATE = str(ROOT / "studies" / "network_plate.toml")
SMALL = ["--trials", "40", "--chunk", "2", "--no-figures", "--quiet"]


def test_a_link_named_network_xml_in_the_staging_directory_is_not_written_through(
    tmp_path, monkeypatch
):
    """A run cut short after its trials leaves its staging directory; a link placed there by
    hand under the export's name was followed by the resumed run, which replaced the file it
    points to (outside the output) by the export."""
    notes = tmp_path / "notes.txt"
    notes.write_text("my notes\n")
    cmd = ["run", PLATE, *SMALL, "--out", str(tmp_path / "o")]

    def cut_short(*args, **kwargs):
        raise KeyboardInterrupt

    with monkeypatch.context() as m:
        m.setattr(network_run, "write_points", cut_short)
        assert main(cmd) == 130
    stage = tmp_path / ".o.partial"
    (stage / "network.xml").symlink_to(notes)
    assert main(cmd) == 0
    assert notes.read_text() == "my notes\n"
    xml = tmp_path / "o" / "network.xml"
    assert not xml.is_symlink() and xml.read_text().startswith("<?xml")
