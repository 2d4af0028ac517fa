"""Brown's multilaterative comparator (1968): ranges from four stations, the P-position
adjustment, the error budget, the datum and its Bayesian cross-check."""
