"""What a file given as a study file is when it is not TOML at all: a new user's likely
mistakes, named in the "malformed TOML" refusal (:func:`sim.mc.config.read_toml`) instead of
tomllib's "Invalid statement (at line 1, column 1)" alone. A GNU Gama XML file is read by a
network study (``network.gama_xml``); a ``run.json`` is a results directory's record, whose
study file is the one its run read."""

from __future__ import annotations

import json

__all__ = ["kind_hint"]


def kind_hint(text: str) -> str:
    """`` (it is ...: ...)`` for ``text`` that is XML or a run record, else ``""``."""
    head = text.lstrip()
    if head.startswith("<"):
        what = "a GNU Gama file" if "gama-local" in head[:2000] else "XML"
        return (
            f" (it is {what}, not a study file: a network study reads it, "
            'study = "network" and [network] gama_xml = "<the file>")'
        )
    if head.startswith("{"):
        try:
            doc = json.loads(text)
        except (ValueError, RecursionError):  # (RecursionError: nested too deeply for json)
            return " (it is JSON, not a study file: study files are TOML)"
        if isinstance(doc, dict) and "config" in doc and "code_hash" in doc:
            return (
                " (it is a results directory's run.json, not a study file: run the study file "
                "that made it, or sim show the directory)"
            )
        return " (it is JSON, not a study file: study files are TOML)"
    return ""
