"""Issue 14 (item 3): E modal data with a 180 Hz test-stand resonance on all six channels, no model given.

Expected: diagnose names ``suspension_modes`` (rocking within 2 % of the thesis's 54.9 Hz) and the fixture as a
``fixed_resonance`` of role ``test_stand`` at 180 Hz (within 1 %) beside them, never inside them, and nothing
else.  Prints every effect (4 significant digits: the radial-torque C's are ~1e-7, four decimals print them
as 0.0), the numbers against the truth and the time.  Run: ``python benchmarks/diagnose_stand_resonance.py``
(a few minutes on a shared machine).  The same check on small data: tests/test_diagnose_stand.py.
"""
import time

import numpy as np

from rwadist import api
from rwadist.inject import parse, simulate_with_injections
from rwadist.presets import preset

SPEEDS = np.linspace(300.0, 3000.0, 30)
F_STAND = 180.0
ROCKING_HZ = 54.9          # thesis Table 4.2 wheel E: sqrt(k d²/I_rr)/2π at rest (tests/independent_wheel.py)


def _fmt(v):
    return f"{v:.4g}" if isinstance(v, float) else v


def main():
    test = simulate_with_injections(preset("ithaco-e"), [parse(f"fixed_resonance:f_hz={F_STAND:g}")], SPEEDS,
                                    physics="extended", sample_rate=3840.0, n_samples=8192, noise=0.01, seed=0)
    t0 = time.perf_counter()
    d = api.diagnose(test)
    dt = time.perf_counter() - t0
    for e in d.model.effects:
        print({k: _fmt(v) for k, v in dict(e).items() if k not in ("evidence", "psd_ref", "whirl", "gain_law")})
    print(f"error {d.error_before:.4g} -> {d.error_after:.4g}; diagnose {dt:.0f} s")
    kinds = [e["kind"] for e in d.model.effects]
    modes = [e for e in d.model.effects if e["kind"] == "suspension_modes"]
    stand = [e for e in d.model.effects if e["kind"] == "fixed_resonance" and e["role"] == "test_stand"]
    if modes:
        print(f"rocking {modes[0]['rocking_Hz']:.4g} Hz (truth {ROCKING_HZ} Hz, "
              f"{100 * (modes[0]['rocking_Hz'] / ROCKING_HZ - 1):+.2f} %)")
    if stand:
        print(f"stand {stand[0]['f_Hz']:.4g} Hz (truth {F_STAND:g} Hz, {100 * (stand[0]['f_Hz'] / F_STAND - 1):+.2f} %)")
    ok = (sorted(kinds) == ["fixed_resonance", "suspension_modes"] and kinds[0] == "suspension_modes"
          and abs(modes[0]["rocking_Hz"] / ROCKING_HZ - 1) < 0.02 and abs(stand[0]["f_Hz"] / F_STAND - 1) < 0.01)
    print("expected (suspension_modes, then the fixture at 180 Hz beside them, nothing else):", "yes" if ok else "NO")


if __name__ == "__main__":
    main()
