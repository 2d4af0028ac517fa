"""Agnard, Nolette & Gagnon: digital pugging and a block adjustment of independent models
(seed ``003_5ce730a990a7ebc5.txt``), study ``agnard_block``.

A block of 2 strips x 8 stereomodels (1:6 200, f = 152 mm, base 90 mm at photo scale) over
178 signalised points, photographs scanned at 600 DPI on a deforming desktop scanner,
pointing to half a pixel. Each trial draws a scanner, its grid calibration, the image
measurements, forms the models, and adjusts the block several ways: with and without the
scanner correction (Table 1), with 5 and 21 control points (Tables 2 and 3), with weak
control (the first pass), and with data snooping of the pass points under digital and
mechanical pugging. Trade-offs: scanner resolution x calibration, control layout, block
size; the unprinted five-point layout is explored in the consistent region (region.toml),
the re-centring error of mechanical pugging set to reproduce the printed share (an input).

Modules: :mod:`.schema` (config and checks), :mod:`.simulate` and :mod:`.chunks` (one chunk
of blocks and its adjustments), :mod:`.run` (through the runner), ``claims.toml`` +
:mod:`.claims` (scoring), :mod:`.region` (consistent region), :mod:`.figures`, :mod:`.report`.
"""

from __future__ import annotations

from sim.studies import Part, Study
from sim.studies.agnard.schema import NAME, SCHEMA, SEED, check

STUDIES = {
    NAME: Study(
        name=NAME,
        title="Agnard, Nolette & Gagnon: digital pugging, scanner "
        "calibration and a block of independent models",
        seed_file=SEED,
        schema=SCHEMA,
        run=Part("sim.studies.agnard.run", "run"),
        report=Part("sim.studies.agnard.report", "report"),
        check=check,
        order=50,
        data=Part("sim.studies.agnard.data_checks", "DATA"),
    )
}
