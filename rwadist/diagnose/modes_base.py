"""The wheel's base model that the suspension modes' fit gives the search: the fitted model without the loads of an
effect's form, which the search is left to name (``rwadist diagnose``'s ``suspension_modes``,
:mod:`rwadist.effects.suspension_modes_diagnose`)."""
from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:
    from ..model import Harmonic

#: Largest offset per revolution of a pair of lines beside a carrier that :func:`wheel_base` leaves to the search as
#: speed sidebands (the ``speed_sidebands`` family's own search range, 0.01-0.30 per rev)
SIDEBAND_MAX_PER_REV = 0.30
#: Two lines h0 − δ₁, h0 + δ₂ beside a carrier h0 are a speed-sideband pair when |δ₁ − δ₂| is within this fraction
#: of δ (plus 0.002 in h, the extended fit's own precision on h)
SIDEBAND_SYMMETRY = 0.05


def wheel_base(model) -> tuple:
    """(model, pairs): the wheel's model fitted from the data (:func:`rwadist.extended_fit.to_model`) without the loads
    of an effect's form, which the search is left to name (issue 33: an effect that is a wheel load of the model's own form is named,
    not absorbed into the fitted base):

    * the counter-rotating part of an imbalance (h = 1 of the radial force or torque): an imbalance rotates with the
      rotor, so a counter part there is a ``counter_rotation`` (support anisotropy, a planar load); its power goes
      back to the imbalance (U_s, U_d: the total free power kept, as ``counter_rotation`` splits it);
    * a pair of lines at h0 − δ and h0 + δ beside a stronger line h0 of the same direction and sense (δ up to
      :data:`SIDEBAND_MAX_PER_REV`, the two offsets within :data:`SIDEBAND_SYMMETRY`): ``speed_sidebands``, an
      amplitude modulation of h0 at δ times the speed.

    The other lines and their senses are the wheel's own content.  ``pairs``: the sideband pairs taken out, (direction,
    h0, h_lower, h_upper, C_lower, C_upper, number of measurements) each, as the extended fit measured them (close lines measured together on
    the records, :mod:`rwadist.extended_fit_close`: the ``speed_sidebands`` family proposes them as they are where its
    own search cannot resolve them from the carrier).  A model without an analytical section is returned as is."""
    import copy
    from dataclasses import replace

    from .. import extended as ext
    from ..schema import PARAM_KEYS

    analytical = getattr(model, "analytical", None)
    if not analytical:
        return model, ()
    out = copy.deepcopy(model)
    for d, key in (("radial_force", "U_s"), ("radial_torque", "U_d")):
        lines = out.empirical.get(d) or []
        counter = [x for x in lines if x.sense == "counter" and abs(x.h - 1.0) <= ext.IMBALANCE_H_TOL]
        if not counter:
            continue
        u = float(out.analytical[PARAM_KEYS[key]])
        total = float(np.sqrt(u**2 + sum(x.C**2 for x in counter)))
        scale = total / u if u > 0 else 0.0
        out.analytical[PARAM_KEYS[key]] = total
        out.empirical[d] = [replace(x, C=x.C * scale) if ext.is_imbalance(d, x.h, x.sense) else x
                            for x in lines if not any(x is c for c in counter)]
    pairs = []
    for d, lines in out.empirical.items():
        found = _sideband_pairs(lines)
        for (c, a, b) in found:
            pairs.append((d, float(c.h), float(a.h), float(b.h), float(a.C), float(b.C),
                          int((a.n_points or 0) + (b.n_points or 0))))
        out.empirical[d] = [x for x in lines if not any(x is y for _, a, b in found for y in (a, b))]
    return out, tuple(pairs)


def _sideband_pairs(lines) -> list:
    """(carrier, lower, upper) of the harmonics of one direction's ``lines`` that are speed-sideband pairs beside a
    stronger line of theirs (:func:`wheel_base`)."""
    out: list[tuple[Harmonic, Harmonic, Harmonic]] = []
    taken: list[Harmonic] = []
    for c in sorted(lines, key=lambda x: -x.C):
        if any(c is y for y in taken):
            continue
        lo = [x for x in lines if x.sense == c.sense and x.C < c.C and 0 < c.h - x.h <= SIDEBAND_MAX_PER_REV]
        hi = [x for x in lines if x.sense == c.sense and x.C < c.C and 0 < x.h - c.h <= SIDEBAND_MAX_PER_REV]
        for a in lo:
            b = min(hi, key=lambda x: abs((x.h - c.h) - (c.h - a.h)), default=None)
            if b is not None and abs((b.h - c.h) - (c.h - a.h)) <= SIDEBAND_SYMMETRY * (c.h - a.h) + 0.002 \
                    and not any(a is y or b is y for y in taken):
                out.append((c, a, b))
                taken += [c, a, b]
                break
    return out
