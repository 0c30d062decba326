"""A brushless motor's torque ripple: the candidate causes of an axial-torque line at a whole multiple of the speed.

The motor's electromagnetic torque acts about the spin axis: its ripple reaches the load cell's axial torque Tz
(the wheel's reaction on the housing), at whole multiples of the speed fixed by the motor's pole-pair count p and
slot count S, each line at a whole number h of revolutions:

- commutation of a three-phase motor: six switching steps per electrical revolution, p electrical revolutions per
  mechanical one: h = 6·p (and its multiples, 12·p, ...: the steps are not sinusoidal);
- a phase's gain or back-EMF unbalance (or a current sensor's gain mismatch): twice per electrical revolution,
  h = 2·p; a current sensor's offset: once per electrical revolution, h = p;
- cogging (the magnets' pull on the stator teeth, with the motor unpowered as well): h = LCM(S, 2·p), the number of
  positions per revolution where a pole edge meets a tooth edge; an even number, 4 at the least (S ≥ 3).

A commutation ripple follows the motor current (the torque the wheel is asked for), not Ω²; cogging is there at
every current.  The motor's p and S name the line; without them, the counts that can give h are named.
``tests/test_motor_causes.py`` checks the names against an enumeration of motors (p 1-12, S 3-48).
"""
from __future__ import annotations

import math

#: Pole-pair counts named (a reaction wheel's motor: 1-12 pole pairs, 2-24 poles).
POLE_PAIRS = (1, 12)
#: Slot counts cogging is named for.
SLOTS = (3, 48)
#: The direction whose lines a motor's torque ripple reaches.
MOTOR_DIRECTION = "axial_torque"


def _pairs(n: float) -> int | None:
    """``n`` as a pole-pair count when it is a whole number in :data:`POLE_PAIRS`, else None."""
    return int(n) if n == int(n) and POLE_PAIRS[0] <= n <= POLE_PAIRS[1] else None


def _counted(p: int) -> str:
    """'1 pole pair', '3 pole pairs'."""
    return f"{p} pole pair" + ("" if p == 1 else "s")


def cogging_motors(n: int) -> list:
    """The (slots, pole pairs) of :data:`SLOTS` × :data:`POLE_PAIRS` whose cogging order LCM(S, 2·p) is ``n``."""
    return [(s, p) for p in range(POLE_PAIRS[0], POLE_PAIRS[1] + 1) for s in range(SLOTS[0], SLOTS[1] + 1)
            if math.lcm(s, 2 * p) == n]


def motor_causes(h: float, resolution: float, direction: str) -> list:
    """Candidate motor causes (sentences) of a line at ratio ``h`` to the speed in ``direction``: [] unless the
    direction is the axial torque and h is a whole number ≥ 2 within twice ``resolution`` (in h)."""
    n = round(h)
    if direction != MOTOR_DIRECTION or n < 2 or abs(h - n) > 2 * resolution:
        return []
    out = []
    if n % 6 == 0:
        ps = [(k, p) for k in (1, 2, 3) if (p := _pairs(n / (6 * k))) is not None]
        if ps:
            out.append("commutation torque ripple of a three-phase motor (6 steps per electrical revolution): "
                       + ", or ".join(f"6·p with p = {_counted(p)}" if k == 1 else
                                      f"its {('2nd', '3rd')[k - 2]} multiple ({6 * k}·p) with p = {_counted(p)}"
                                      for k, p in ps))
    if (p := _pairs(n / 2)) is not None:
        out.append(f"a motor phase's gain or back-EMF unbalance (twice per electrical revolution): 2·p with p = "
                   f"{_counted(p)}")
    if (p := _pairs(n)) is not None:
        out.append(f"a motor current sensor's offset (once per electrical revolution): p = {_counted(p)}")
    motors = cogging_motors(n)
    if motors:
        shown = ", ".join(f"{s} slots/{2 * p} poles" for s, p in motors[:3]) + (", ..." if len(motors) > 3 else "")
        out.append(f"cogging of a motor whose slot and pole counts have the least common multiple {n} ({shown})")
    return out
