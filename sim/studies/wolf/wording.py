"""How the texts of ``wolf_polynomial`` name the run's correction polynomial (``calib.degree``):
the paper's ten-term cubic at degree 3, the run's own otherwise (a six-term quadratic at 2),
never the paper's where the run changed it."""

from __future__ import annotations

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
