"""How the texts of ``wolf_polynomial`` name the run's correction polynomial (``calib.degree``:
the paper's ten-term cubic at degree 3, the run's own otherwise, a six-term quadratic at 2)
and its photograph (``repeat.format_mm``: the paper's P-30 at 150 x 100 mm), never the paper's
where the run changed it."""

from __future__ import annotations

from sim.studies.wolf.schema import SCHEMA

_NAMES = {1: "linear polynomial", 2: "quadratic", 3: "cubic", 4: "quartic", 5: "quintic"}
_WORDS = {3: "three", 6: "six", 10: "ten", 15: "fifteen", 21: "twenty-one"}


def terms(degree: int) -> int:
    """Terms per axis of a full 2-D polynomial of ``degree`` (the paper's cubic: 10)."""
    return (degree + 1) * (degree + 2) // 2


def polynomial(degree: int, counted: bool = False) -> str:
    """``"cubic"`` (``counted``: ``"ten-term cubic"``) for degree 3, ``"quadratic"``
    (``"six-term quadratic"``) for 2, ``"degree-6 polynomial"`` beyond the named ones."""
    name = _NAMES.get(int(degree), f"degree-{int(degree)} polynomial")
    if not counted:
        return name
    n = terms(int(degree))
    return f"{_WORDS.get(n, n)}-term {name}"


#: the P-30 phototheodolite's format (mm), the paper's photographs of Tables 1 and 2
P30_MM = (150.0, 100.0)


def photograph(format_mm) -> str:
    """``"P-30"`` for the paper's 150 x 100 mm format, else ``"120 x 90 mm"``."""
    w, h = (float(v) for v in format_mm)
    return "P-30" if (w, h) == P30_MM else f"{w:g} x {h:g} mm"


def amplitudes(cfg: dict) -> str:
    """How the field amplitudes (``field.*_um``) came about: the defaults were chosen so the
    'before' rows look like the paper's; a run with other amplitudes says so."""
    keys = [k for k in SCHEMA if k.startswith("field.") and k.endswith("_um")]
    changed = [k for k in keys if cfg[k] != SCHEMA[k].default]
    if not changed:
        return "The field amplitudes (field.*) were chosen so these look like the paper's"
    return (
        f"This run's field amplitudes differ from the defaults chosen so these look like the "
        f"paper's ({', '.join(changed)})"
    )
