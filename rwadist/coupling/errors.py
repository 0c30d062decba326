"""Errors of the coupling package: bad values given to a coupling computation, :class:`rwadist.ParameterError`
(so ``except rwadist.RwadistError`` and ``except ValueError`` catch them)."""
from rwadist.errors import ParameterError


class CouplingError(ParameterError):
    """Bad input to a coupling computation."""


class InterfaceMismatchError(CouplingError):
    """Component and plant interfaces do not fit (sizes, nodes)."""


class UnstablePlantError(CouplingError):
    """A plant has a pole in the open right half plane."""


class SingularInterfaceError(CouplingError):
    """The interface equations have no unique solution (e.g. rigid on rigid without mass)."""


class NotARotationError(CouplingError):
    """A direction-cosine matrix that is not a proper rotation."""
