"""Claims: the claim book, the intervals and the verdict rules."""
