"""Command-line layers: thin, one module per wing, common options and the one-line error contract in :mod:`.common`."""

import os

# Every command's work is small-matrix numerics: one BLAS thread, set here, before any command module
# loads numpy (several threads on tiny matrices only contend, with each other and with ngspice).
for _var in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_var, "1")
