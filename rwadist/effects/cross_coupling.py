"""``cross_coupling``: a load-cell reference offset: the measured torques carry r × F."""
from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import ClassVar

import numpy as np

from ..schema import COUNT, LEVER_ARM, MAX_LENGTH_M, check, numbers, optional, register
from .element import Element


@register
@dataclass(frozen=True, eq=False, kw_only=True)
class CrossCoupling(Element):
    """A load-cell offset r (m, wheel frame): T_measured = T + r × F.  Measurement only."""

    KIND: ClassVar[str] = "cross_coupling"
    ORDER: ClassVar[int] = 50
    r_m: np.ndarray = field(metadata=check(LEVER_ARM))
    r_stderr_m: np.ndarray | None = field(default=None, metadata=check(optional(numbers(length=3, ge=0.0, le=MAX_LENGTH_M))))
    n_points: int | None = field(default=None, metadata=check(COUNT))

    @classmethod
    def describe(cls, e: Mapping) -> str:
        r = np.asarray(e["r_m"], dtype=float) * 1e3
        se = e.get("r_stderr_m")
        err = "" if se is None else " ±(" + ", ".join(f"{x:.1f}" for x in np.asarray(se, dtype=float) * 1e3) + ")"
        # + 0.0: a component that rounds to zero is written 0.0, not -0.0
        return "load-cell reference offset r = (" + ", ".join(f"{float(f'{x:.1f}') + 0.0:.1f}" for x in r) + \
            f"){err} mm"

    # ------------------------------------------------------------------ injection
    #: ``cross_coupling:r_x=0,r_y=0,r_z=-0.06,force_noise=0``: load-cell offset, torques += r × F of the noise-free
    #: forces (the sensors' noise comes after the geometry: correcting T − r × F then moves the force noise into the
    #: torques); force_noise: extra white sensor noise on Fx, Fy, Fz of std force_noise·C1·Ω_max² (C1 the
    #: radial-force fundamental), after the offset.  The load cell's own geometry: applied last, on the total force
    #: the cell measures (the simulation's and every noise-free content injected before it)
    INJECT: ClassVar[Mapping] = {"r_x": 0.0, "r_y": 0.0, "r_z": -0.06, "force_noise": 0.0}
    INJECT_SIGNED: ClassVar[tuple] = ("r_x", "r_y", "r_z")
    INJECT_LAST: ClassVar[bool] = True
    INJECT_CLEAN: ClassVar[bool] = True

    @classmethod
    def inject_run(cls, spec, run, index, stand):
        forces = ("Fx", "Fy", "Fz")
        if stand.clean is None:
            F = np.column_stack([run.signals[c] for c in forces])
        else:
            F = np.column_stack([stand.clean.runs[index].signals[c] + run.signals[c] - stand.forces_before[index][c]
                                 for c in forces])
        T = np.cross(np.array([spec["r_x"], spec["r_y"], spec["r_z"]])[None, :], F)
        for j, c in enumerate(("Tx", "Ty", "Tz")):
            run.signals[c] = run.signals[c] + T[:, j]
        if spec["force_noise"] > 0:
            std = spec["force_noise"] * stand.wheel.fundamental_C("radial_force") * stand.w_max**2
            for c in forces:
                run.signals[c] = run.signals[c] + stand.rng.normal(0.0, std, run.n_samples)
