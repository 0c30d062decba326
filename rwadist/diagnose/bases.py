"""The starting base of ``rwadist diagnose`` (the one rule of the library and the CLI): the model's lines as given
(``empirical``), or through the wheel's suspension modes (``extended``); ``auto`` chooses, and says when the search may
fit the modes from the data."""
from __future__ import annotations

from ..errors import ParameterError
from ..model import WheelModel

BASES = ("empirical", "extended", "auto")


def _modes_off(test) -> bool:
    """True when the test's record says the wheel's modes were off (a virtual-stand test made with modes=False)."""
    return test is not None and getattr(test, "meta", {}).get("modes") is False


def resolve_base(model: WheelModel | None, base: str = "empirical", test=None) -> str:
    """'empirical' or 'extended' for a ``base`` request (the one rule of the library and the CLI).

    'auto' is 'extended' when the model has an ``analytical`` section whose suspension modes are not
    assumed (a catalogue datasheet wheel carries ``analytical.modes_assumed``: its modes are guesses, the
    data's own are fitted instead, :func:`fits_modes_from_data`), unless the test's record says the wheel's
    modes were off (``test.meta["modes"] is False``: a virtual-stand test made with modes=False is
    hard-mounted C·Ω² truth); else 'empirical'.  'extended' without an analytical section is a ValueError.
    ``test``: the SteadyTest (or None: no record)."""
    from ..catalogue import modes_assumed

    if base not in BASES:
        raise ParameterError(f"diagnose: base must be one of {BASES}, got {base!r}")
    has = model is not None and bool(getattr(model, "analytical", None))
    if base == "auto":
        return "extended" if has and not modes_assumed(model) and not _modes_off(test) else "empirical"
    if base == "extended" and not has:
        raise ParameterError("base", "'extended' needs a model with an analytical section "
                             "(rwadist.extended.params_to_dict), e.g. preset('ithaco-e').to_model()")
    return base


def fits_modes_from_data(model: WheelModel | None, base: str = "empirical", test=None) -> bool:
    """True when the search may name the wheel's own ``suspension_modes``, fitted from the data, and carry on
    from that extended base: the request is 'auto', it resolves to 'empirical' (:func:`resolve_base`: no
    analytical model, or one whose modes are assumed) and the test does not record the modes off."""
    return base == "auto" and resolve_base(model, base, test) == "empirical" and not _modes_off(test)
