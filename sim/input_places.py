"""A run never replaces a file its own study reads.

A study reads files named by its config (``network.gama_xml``, Wolf's ``table1.file``): a
GNU Gama file may well be a results directory's own ``network.xml`` (the export, edited by
hand with the field's values, say). Publishing a run replaces every file of ``--out`` that the
earlier run there wrote (:mod:`sim.mc.publish`): a run with ``--out`` that directory read the
file, then replaced it with its own export, and the user's edited file was gone (and the
results recorded the sha256 of a file that no longer existed). Such a run is refused before
any work, naming the key and the file; a file of the user's in ``--out`` (one the earlier run
did not write) is carried into the new results, and may be read. So is an export edited in
place that no key reads (:mod:`sim.mc.export_edits`): a run that would replace it is refused
before any work too, naming it."""

from __future__ import annotations

import os
from pathlib import Path

from sim.mc.config import ConfigError
from sim.mc.export_edits import refuse_changed_export
from sim.mc.storage import read_record

__all__ = ["check_inputs_outside"]


def _file_keys(cfg: dict) -> list[str]:
    """The config keys that name a file the study reads."""
    return [k for k in cfg if k == "network.gama_xml" or k.endswith(".file")]


def check_inputs_outside(out: Path, shown: str, cfg: dict) -> None:
    """Refuse a run into ``out`` (absolute) when a file its config ``cfg`` reads is one of the
    files that the earlier run in ``out`` wrote (its ``run.json`` lists them; one of a record
    without the list counts as written), which the run replaces at its end."""
    try:
        rec = read_record(out) if out.is_dir() else None
        o = Path(os.path.realpath(out))
    except (OSError, ValueError):
        return  # (what cannot be read is named where it is read)
    if rec is None:
        return
    files = rec.get("files")
    for key in _file_keys(cfg):  # (named first: the key that reads it)
        _refuse_read(o, shown, cfg, key, files)
    refuse_changed_export(
        out, shown, rec, cfg.get("study")
    )  # an export edited in place: the user's, kept


def _refuse_read(o: Path, shown: str, cfg: dict, key: str, files) -> None:
    """Refuse the run when the file ``cfg[key]`` is one the earlier run in ``o`` wrote."""
    v = cfg[key]
    if not isinstance(v, str) or not v:
        return
    try:
        p = Path(os.path.realpath(v))
    except (OSError, ValueError):
        return
    if not p.is_relative_to(o) or p == o:
        return
    rel = p.relative_to(o).as_posix()
    if isinstance(files, list) and rel not in files:
        return  # the user's own: carried into the new results
    raise ConfigError(
        key,
        f"{v} is {rel} of --out {shown}, which this run replaces with its own at its end "
        f"(the file it reads would be lost): copy it out of {shown} and read the copy",
    )
