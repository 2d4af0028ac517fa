"""What the last session left under issue 26 (brief L4), one case each; each failed on the code
before its fix.

* ``TQDM_NCOLS=abc`` (any ``TQDM_`` variable tqdm cannot read) ended ``sim.load(...)`` of the
  Python API in a traceback from ``tqdm.utils`` while ``sim.api`` was imported (only the
  command lines checked the variables): tqdm is imported by a bar only, and ``sim.load`` (or a
  bar, if the variable is set later) refuses with one :class:`sim.ConfigError` naming the
  variable (:func:`sim.mc.progress.check_environment`);
"""

import os
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
BROWN = ROOT / "studies" / "brown_table1.toml"


def _python(env: dict, *lines: str) -> subprocess.CompletedProcess:
    code = "\n".join(lines) + "\n"
    return subprocess.run(
        [sys.executable, "-c", code],
        capture_output=True,
        text=True,
        timeout=120,
        env={**os.environ, **env},
    )


def test_tqdm_variables_are_one_config_error_of_the_api_not_a_traceback_at_import():
    for env, name in (
        ({"TQDM_NCOLS": "abc"}, "TQDM_NCOLS"),
        ({"TQDM_POSITION": "1.5"}, "TQDM_POSITION"),
    ):
        p = _python(
            env,
            "import sim, sim.api, sim.mc.progress",  # importing is not using a bar
            "try:",
            f"    sim.load({str(BROWN)!r}, trials=40)",
            "except sim.ConfigError as e:",
            "    print('refused:', e)",
        )
        out = p.stdout.strip()
        assert p.returncode == 0 and p.stderr == "", (env, p.stderr)
        assert "\n" not in out and out.startswith(f"refused: {name}: tqdm cannot read it"), out


def test_a_tqdm_variable_set_after_loading_is_refused_by_the_bar():
    # TQDM_LOCK_ARGS=x passes tqdm's import and fails only when a bar is drawn
    p = _python(
        {},
        "import os, sim",
        "from sim.mc.progress import Progress",
        "os.environ['TQDM_LOCK_ARGS'] = 'x'",
        "try:",
        "    Progress(10, 'x')",
        "except sim.ConfigError as e:",
        "    print('refused:', e)",
    )
    out = p.stdout.strip()
    assert p.returncode == 0 and p.stderr == "", p.stderr
    assert out.startswith("refused: TQDM_LOCK_ARGS: tqdm cannot read it"), out


def test_good_tqdm_variables_still_run():
    p = _python(
        {"TQDM_NCOLS": "80"},
        "import sim",
        f"h = sim.load({str(BROWN)!r}, trials=40)",
        "print(type(h).__name__)",
    )
    assert p.returncode == 0 and p.stdout.strip() == "StudyHandle", p.stderr
