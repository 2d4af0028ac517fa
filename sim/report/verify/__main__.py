"""``python -m sim.report.verify``."""

import sys

from sim.report.verify.cli import main

sys.exit(main())
