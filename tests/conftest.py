"""BLAS single-threaded in the test processes, as in every ``sim`` process (:mod:`sim.threads`):
the tests compare in-process runs with runs in worker processes bit for bit."""

from sim.threads import single_threaded_blas

single_threaded_blas()
