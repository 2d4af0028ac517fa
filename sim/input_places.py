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
before any work too, naming it, and so is a file of the user's (one the earlier run did not
write) where a network run writes its export (``network.xml``, a sweep's
``cells/<label>/network.xml``): it was refused only when the run published, after every
chunk was computed."""

from __future__ import annotations

import os
from pathlib import Path

from sim.mc.config import ConfigError
from sim.mc.export_edits import refuse_changed_export
from sim.mc.storage import read_record
from sim.mc.sweep import cell_label, expand

__all__ = ["check_inputs_outside"]


def _file_keys(cfg: dict) -> list[str]:
    """The config keys that name a file the study reads."""
    return [k for k in cfg if k == "network.gama_xml" or k.endswith(".file")]


def check_inputs_outside(out: Path, shown: str, cfg: dict, sweep: dict | None = None) -> None:
    """Refuse a run into ``out`` (absolute) when a file its config ``cfg`` reads is one of the
    files that the earlier run in ``out`` wrote (its ``run.json`` lists them; one of a record
    without the list counts as written), which the run replaces at its end; or when a file
    the run writes (a network run's export; ``sweep``: its ``[sweep]`` table) is there as the
    user's, or as an export edited by hand."""
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
    _refuse_foreign_export(out, shown, cfg, sweep, files)


def _exports(cfg: dict, sweep: dict | None) -> list[str]:
    """The GNU Gama exports a run of ``cfg`` (and ``sweep``) writes, relative to its ``--out``
    (a network run writes one unless its network has no ``gama-local`` form: a bias, a scale
    unknown, ...; such a run is refused all the same: the name is the export's)."""
    if cfg.get("study") != "network":
        return []
    if not sweep:
        return ["network.xml"]
    try:
        _, cells, reps, _ = expand(sweep)
    except ConfigError:  # (refused where the sweep is read)
        return []
    return [f"cells/{cell_label(i, r)}/network.xml" for i in range(len(cells)) for r in range(reps)]


def _refuse_foreign_export(out: Path, shown: str, cfg: dict, sweep, files) -> None:
    """Refuse the run when a file of the user's (one the earlier run in ``out`` did not write:
    ``files``, its record's list) stands where the run writes its export."""
    if not isinstance(files, list):  # a record of before the list: every file the suite's
        return
    for name in _exports(cfg, sweep):
        if name not in files and os.path.lexists(out / name):
            raise ConfigError(
                "--out",
                f"{Path(shown) / name} was not written by sim, and this network run writes its "
                "GNU Gama export of that name: move it away (or copy it out of the results "
                "directory) and run again",
            )


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
