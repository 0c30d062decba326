"""rwadist: reaction wheel assembly micro-vibration from test data.

The way in from Python (each with units and shapes in its docstring)::

    import rwadist
    test = rwadist.simulate_test("ithaco-e", speeds_rpm=range(600, 2401, 100))   # or rwadist.read(path)
    fit = rwadist.fit(test)                    # empirical harmonics C·Ω²: fit.model is a WheelModel
    rwadist.save_model(fit.model, "wheel.json")
    diag = rwadist.diagnose(test, fit.model)   # effects the model lacks, judged on held-out speeds
    res = rwadist.psd(fit.model, (600, 2400), empirical=True)   # broadband PSD over a speed range

- :func:`read`, :func:`simulate_test`, :func:`simulate_sweep`: test data (steady runs; sweeps are sliced);
- :func:`fit`, :func:`fit_extended`: the empirical and extended models;
- :func:`diagnose`: what a model leaves out of the data;
- :func:`psd`, :func:`write_nastran`, :func:`campbell`: broadband PSD over a speed distribution (one wheel, or
  several in the spacecraft frame), its NASTRAN cards, the Campbell diagram;
- :func:`build_fmu`: the FMU of a model;
- :class:`WheelModel`, :func:`load_model`, :func:`save_model`: the versioned model file;
- :class:`RwadistError` and its kinds :class:`DataError`, :class:`ModelError`, :class:`ParameterError`,
  :class:`MissingDependencyError` (:mod:`rwadist.errors`); :class:`RwadistWarning`.

Under it, one module per step: ``data`` (interchange format) -> ``sweep`` (quasi-steady slices) ->
``spectra`` (Welch PSDs) -> ``empirical`` (fitted harmonic model) -> ``compare``/``report`` and
``model`` (the model file); ``extended`` (rotor model), ``diagnose``, ``broadband`` (PSD),
``teststand``/``presets`` (synthetic tests).  SI units inside; rpm only at the edges.
"""
import sys as _sys

# not ``from typing import TYPE_CHECKING``: importing typing takes ~7 ms, a window in which a Ctrl-C would still
# be Python's traceback (mypy reads any name TYPE_CHECKING as True)
TYPE_CHECKING = False

#: The public names and the module each lives in, imported on first use (PEP 562): ``import rwadist`` loads no
#: numpy or scipy, so the command's first instruction (:mod:`rwadist.__main__`) runs before them and a Ctrl-C
#: during those imports is one line, not a traceback.
_LAZY = {**dict.fromkeys(("WheelModel", "build_fmu", "campbell", "diagnose", "fit", "fit_extended", "load_model",
                          "psd", "read", "save_model", "simulate_sweep", "simulate_test", "write_nastran"), "api"),
         **dict.fromkeys(("DataError", "MissingDependencyError", "ModelError", "ParameterError", "RwadistError",
                          "RwadistWarning"), "errors")}

if TYPE_CHECKING:
    from types import ModuleType as _ModuleType

    from .api import (
        WheelModel,
        build_fmu,
        campbell,
        diagnose,
        fit,
        fit_extended,
        load_model,
        psd,
        read,
        save_model,
        simulate_sweep,
        simulate_test,
        write_nastran,
    )
    from .errors import DataError, MissingDependencyError, ModelError, ParameterError, RwadistError, RwadistWarning
else:           # the same class, without importing ``types`` (another window before the entry point's handler)
    _ModuleType = type(_sys)
del TYPE_CHECKING


def __getattr__(name: str):
    module = _LAZY.get(name)
    if module is None:
        raise AttributeError(f"module 'rwadist' has no attribute {name!r}")
    import importlib  # here, not at the top: see TYPE_CHECKING

    value = getattr(importlib.import_module(f".{module}", __name__), name)
    globals()[name] = value         # once: later reads find it without this function
    return value


def __dir__() -> list:
    return sorted(set(globals()) | set(_LAZY))


__version__ = "0.1.0"

#: API functions named like a submodule (``rwadist/diagnose/``, ``rwadist/campbell.py``).  Importing a
#: submodule binds it as an attribute of its package, which would replace the function: ``rwadist.diagnose``
#: must stay the function.  The submodules are reached by ``from rwadist.diagnose import Context`` (through
#: ``sys.modules``), never as attributes of the package.
_SHADOWED_SUBMODULES = frozenset({"diagnose", "campbell"})


class _Package(_ModuleType):
    """The ``rwadist`` package object: binding a submodule over an API function of its name is skipped."""

    def __setattr__(self, name, value):
        if name in _SHADOWED_SUBMODULES and isinstance(value, _ModuleType):
            return
        super().__setattr__(name, value)


_sys.modules[__name__].__class__ = _Package

__all__ = ["read", "simulate_test", "simulate_sweep", "fit", "fit_extended", "diagnose", "psd", "write_nastran",
           "campbell", "build_fmu", "WheelModel", "load_model", "save_model", "RwadistError", "DataError", "ModelError", "ParameterError",
           "MissingDependencyError", "RwadistWarning", "__version__"]
