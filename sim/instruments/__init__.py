"""Observation models by instrument family: Brown's ranges, the grid plate, the
stereoplotter as monocomparator, the encoder chain, the scanner and block of independent models."""
