"""Monte-Carlo machinery: configuration, the chunked runner, its store, the code hash,
the work estimate, sweeps."""
