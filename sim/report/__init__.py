"""Report: the Markdown report, figure helpers and the verification of results."""
