"""Which package defines each study: study name -> module (data; imported on demand).

The code hash (:mod:`sim.mc.codehash`) reads it to find a study's code; the study registry
(:func:`sim.studies.get_study`) imports the module named here.
"""

MODULES = {
    "brown_dilution": "sim.studies.brown",
    "brown_table1": "sim.studies.brown",
    "gridplate_two_plates": "sim.studies.gridplate",
    "salsig_encoders": "sim.studies.salsig",
    "wolf_polynomial": "sim.studies.wolf",
    "agnard_block": "sim.studies.agnard",
    "brown_design": "sim.studies.design",
    "network": "sim.studies.network",
}
