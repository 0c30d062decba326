"""The errors rwadist raises on purpose: one root, four kinds (all exported by :mod:`rwadist`).

::

    RwadistError                        the root: bad input of any kind, never a bug
    ├── DataError(ValueError)           bad test data or input file: file, field, value
    ├── ModelError(ValueError)          bad model file or entry (rwadist.schema; the FMU runtime's too)
    │   └── ModelFileError(DataError)   a model file read by the kit (both a ModelError and a DataError)
    ├── ParameterError(ValueError)      a bad value given to a function (parameter, value)
    └── MissingDependencyError(ImportError)   an optional package a function needs is not installed

Each error names what was wrong where the library knows it: the file and field (``DataError``,
``ModelError``) or the function's parameter (``ParameterError("presence", "2.0: ...")``); the library never
names a command-line flag.  The command line (:mod:`rwadist.cli`) translates a parameter to its flag
(``--presence``) and reports every RwadistError as bad input (exit 2); any other exception is an internal
error (exit 3, traceback in a file).  The kinds subclass ``ValueError`` (``ImportError``) as before, so an
``except ValueError`` written against earlier versions still catches them.

:class:`RwadistWarning` is the category of the library's warnings about results resting on something the
user should know (assumed suspension modes, speeds beyond the rated one, modes the data did not constrain).
"""
from __future__ import annotations

from collections.abc import Iterator
from contextlib import contextmanager

from .schema import ModelError, RwadistError

__all__ = ["RwadistError", "DataError", "ModelError", "ParameterError", "MissingDependencyError",
           "RwadistWarning"]


class DataError(RwadistError, ValueError):
    """Bad input data; ``DataError(file, field, message)`` reads ``"<file>: <field>: <message>"``.

    ``file`` (a path, or what the data came from), ``field`` (a column, key or setting of it) are kept as
    attributes, the message says what value was wrong and what to do."""

    def __init__(self, file, field_name, message):
        self.file = str(file)
        self.field = field_name
        super().__init__(f"{file}: {field_name}: {message}")


class ParameterError(RwadistError, ValueError):
    """A bad value given to a function: ``ParameterError(parameter, problem)`` reads ``"<parameter>: <problem>"``.

    ``parameter`` is the function's argument as the caller wrote it (``"presence"``, ``"speed_rpm"``); the
    problem starts with the value given.  ``ParameterError(message)`` alone is a bad combination of values
    no single parameter is to blame for (``parameter`` is then None)."""

    def __init__(self, parameter: str, problem: str | None = None):
        self.parameter = None if problem is None else parameter
        self.problem = parameter if problem is None else problem
        super().__init__(self.problem if self.parameter is None else f"{parameter}: {problem}")


class MissingDependencyError(RwadistError, ImportError):
    """An optional package is not installed: ``MissingDependencyError(package, needed_for, extra)``.

    ``package`` the import name (``"fmpy"``), ``needed_for`` what asked for it (``"the FMU check"``),
    ``extra`` the rwadist extra that installs it (``"fmu"``), or None."""

    def __init__(self, package: str, needed_for: str, extra: str | None = None):
        self.package, self.needed_for, self.extra = package, needed_for, extra
        how = f"pip install 'rwadist[{extra}]'" if extra else f"pip install {package}"
        super().__init__(f"{needed_for} needs the Python package {package!r}, which is not installed: {how}",
                         name=package)


class RwadistWarning(UserWarning):
    """A result rests on something its user should know (assumed modes, extrapolated speeds, ...).

    ``RwadistWarning(text, parameter)`` reads ``"<parameter>: <text>"`` when it is about the value of a parameter
    (kept as ``parameter`` and ``text``, for the command line to name the flag instead)."""

    def __init__(self, text: str, parameter: str | None = None):
        self.text, self.parameter = text, parameter
        super().__init__(text if parameter is None else f"{parameter}: {text}")


class UnresolvedLinesWarning(RwadistWarning):
    """An empirical fit detected harmonics it did not measure apart from a line beside them (the model lacks them:
    :func:`rwadist.fit_warnings.unresolved_warning`); the extended fit measures them, and ``rwadist fit --extended``
    silences it."""


@contextmanager
def own_models(who: str) -> Iterator[None]:
    """Within: a :class:`ModelError` is raised by a model the library made itself (``who``, e.g. "the diagnosis"),
    never by the user's input, which was checked before: re-raised as a RuntimeError, an internal error (exit 3 with
    its traceback in a file), not bad input (a new user's fixture on the rocking mode, no model given, got "error:
    <model>: effects[2]..." and exit 2)."""
    try:
        yield
    except ModelError as exc:
        raise RuntimeError(f"{who} made a model that does not validate: {exc}") from exc
