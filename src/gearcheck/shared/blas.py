"""One BLAS thread for the numerical work whose numbers gearcheck writes.

A multi-threaded BLAS splits a matrix product's sums between its threads, and how it splits them depends on the
machine's cores: the time runs' named signals (a member's motion, ``q @ T.T``) and the cross-check's spectral
lines (a projection ``exp(-i w t) @ x``) then differ in their last bits from one machine to another, and so do
the reports and tables written from them (hub-drive's README cross-check: 1103 numbers of its report.json, at
1e-15).  The products are tall and thin (tens of thousands of samples by tens of coordinates), so one thread costs
nothing: hub-drive's lumped run took 0.28 s on one thread and 0.51 s (0.91 s of CPU) on two, the README
cross-check the same wall time and a tenth less CPU.  The harmonic methods' solves run on one thread too: SuperLU
factors a Hill matrix by many small BLAS calls, each of which a second thread only slows (a 40-coordinate chain on
a 13 x 13 lattice, 6760 unknowns: 0.5-0.8 s on one thread, 6.5-15 s on OpenBLAS's two while other processes
kept both cores busy, and 0.4-0.6 s on either on an idle machine).  Large dense problems (the modes of a big user
model) keep every thread.
"""

from __future__ import annotations

import functools

from threadpoolctl import threadpool_limits


def one_blas_thread(function):
    """``function`` run with the BLAS and OpenMP libraries on one thread (their limits restored after)."""

    @functools.wraps(function)
    def on_one_thread(*args, **kwargs):
        with threadpool_limits(limits=1):
            return function(*args, **kwargs)

    return on_one_thread
