"""rwadist: reaction wheel assembly micro-vibration from test data.

Data flow, one module per step: ``data`` (interchange format) -> ``sweep``
(quasi-steady slices) -> ``spectra`` (Welch PSDs, waterfall) -> ``empirical``
(fitted harmonic model) -> ``compare``/``report`` (model vs data) and
``model`` (the versioned model file).  ``teststand`` makes synthetic tests.
SI units inside; rpm only at the edges.
"""
__version__ = "0.1.0"
