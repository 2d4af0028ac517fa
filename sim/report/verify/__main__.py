"""``python -m sim.report.verify``."""

import sys

from sim.threads import interrupt_while_loading

loaded = interrupt_while_loading("sim verify")  # Ctrl-C during the imports: one line, exit 130
from sim.report.verify.cli import main  # noqa: E402
from sim.stops import run_program  # noqa: E402

sys.exit(run_program("sim verify", main, loaded))  # a late signal: the command's code stands
