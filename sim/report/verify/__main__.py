"""``python -m sim.report.verify``."""

import sys

from sim.ends import open_standard_streams  # noqa: E402
from sim.threads import interrupt_while_loading

open_standard_streams()  # 2>&-: before any file takes its descriptor
loaded = interrupt_while_loading("sim verify")  # Ctrl-C during the imports: one line, exit 130
from sim.ends import finish  # noqa: E402
from sim.mc.children import die_with_parent  # noqa: E402
from sim.report.verify.cli import main  # noqa: E402
from sim.stops import run_program  # noqa: E402

# make verify names its shell (SIM_STOP_WITH_PARENT=$$): SIGTERM to make (`timeout 1h make
# verify`) ends that shell only, and verify ran on, orphaned, and wrote the record after make
# had said "Terminated"; it now ends as after SIGTERM when the shell does
if (gone := die_with_parent()) is not None:
    print(f"sim verify: {gone}", file=sys.stderr)
    sys.exit(130)
sys.exit(finish("sim verify", lambda: run_program("sim verify", main, loaded)))  # sim.ends
