"""Readers and writers of test-data files, one module per file format.

Kept free of imports on purpose: :mod:`rwadist.hdf5` and the lab-format
modules import :mod:`rwadist.formats.records` and
:mod:`rwadist.formats.timebase`, and :mod:`rwadist.data` (the public data API)
imports them all through :mod:`rwadist.formats.registry`, so no module imports
back up the chain.
"""
