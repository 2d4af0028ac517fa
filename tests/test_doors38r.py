"""The classes of the review R38 (a fresh reading of session 37's merges), one case each; each
failed on the code before its fix.

* a requirement with an extra (``pyproject.toml``'s ``dask[distributed]``): :mod:`sim.venv_check`
  checked the distribution by its name alone, so a ``.venv`` from which ``distributed`` was
  removed (``pip uninstall distributed``) was taken for whole by ``make venv`` and every target
  (each ``--executor dask`` test failed). The requirements an extra adds are checked too, one
  line naming the missing one.
"""

from __future__ import annotations

from importlib import metadata

from sim import venv_check


def _pyproject(tmp_path, dep: str):
    p = tmp_path / "pyproject.toml"
    p.write_text(f'[project]\nname = "sim"\ndependencies = ["{dep}"]\n', encoding="utf-8")
    return p


def test_a_requirements_extra_is_checked(tmp_path, monkeypatch):
    real = metadata.requires

    def requires(name):  # dask's extra x asks for a distribution that is not installed
        if name == "dask":
            return ['no-such-dist-38r>=1; extra == "x"', 'also-absent-38r; extra == "y"']
        return real(name)

    monkeypatch.setattr(metadata, "requires", requires)
    words = venv_check.problem(_pyproject(tmp_path, "dask[x]>=2023.1"))
    assert words is not None and "lacks no-such-dist-38r" in words, words
    assert "dask[x]>=2023.1" in words
    # another extra's requirement and the name alone are not asked for
    assert venv_check.problem(_pyproject(tmp_path, "dask>=2023.1")) is None
    assert venv_check.problem(_pyproject(tmp_path, "dask[z]>=2023.1")) is None
