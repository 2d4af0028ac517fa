"""Agnard, Nolette & Gagnon: a scanner, a block of independent models and its data
snooping."""
