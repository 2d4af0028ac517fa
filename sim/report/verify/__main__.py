"""``python -m sim.report.verify``."""

import sys

from sim.threads import interrupt_while_loading

loaded = interrupt_while_loading("sim verify")  # Ctrl-C during the imports: one line, exit 130
from sim.report.verify.cli import main  # noqa: E402

loaded()

sys.exit(main())
