"""Wolf & Pearsall (1976): a stereoplotter used as a monocomparator, its error field
and the cubic polynomial calibration."""
