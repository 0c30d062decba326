"""A 180 Hz test-stand resonance on all six channels of an E wheel, no model given (issues 14 item 3 and 33 item 1).

Two cases, each diagnosed as ``rwadist diagnose`` does with no model (:func:`rwadist.api.diagnose`):

* ``preset``: the preset ithaco-e wheel's modal data made by rwadist's own stand (300-3000 rpm, 30 speeds), the
  fixture injected by :mod:`rwadist.inject`;
* ``e-like``: the E wheel written out by a generator without rwadist's physics (tests/standmodes_wheel.py: the thesis
  wheel's broad radial translation, ζ 0.17, at 227.7 Hz), 300-2400 rpm, the fixture in the form whose gain returns
  to 1 above it ("peak" form, ζ 0.03, peak gain 5): the issue's E-like wheel, where the translation came out
  unconstrained and amplitude laws were invented.

Expected in both: ``suspension_modes`` with every mode within 2 % of the truth (or declared unconstrained) and the
fixture as a ``fixed_resonance`` of role ``test_stand`` within 1 % of its frequency beside them, never inside them,
and nothing else.  Prints every effect (4 significant digits: the radial-torque C's are ~1e-7), the numbers against
the truth and the time.  Run: ``python benchmarks/diagnose_stand_resonance.py [--case preset|e-like]`` (a few
minutes each on a shared machine).  The same checks on small data: tests/test_diagnose_stand.py,
tests/test_stand_joint.py.
"""
import argparse
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))

import standmodes_wheel as sw  # noqa: E402

from rwadist import api  # noqa: E402
from rwadist.inject import parse, simulate_with_injections  # noqa: E402
from rwadist.presets import preset  # noqa: E402

F_STAND = 180.0
#: the thesis's wheel E modes at rest (Hz): sqrt(k/M), sqrt(k d²/I_rr)/2π (tests/independent_wheel.py), axial 70 Hz
E_MODES_HZ = {"radial_translation": 227.7, "rocking": 54.9, "axial": 70.0}
MODE_TOL = 0.02
STAND_TOL = 0.01


def preset_case():
    test = simulate_with_injections(preset("ithaco-e"), [parse(f"fixed_resonance:f_hz={F_STAND:g}")],
                                    np.linspace(300.0, 3000.0, 30), physics="extended", sample_rate=3840.0,
                                    n_samples=8192, noise=0.01, seed=0)
    return test, E_MODES_HZ


def e_like_case():
    test, truth = sw.generate(sw.E_WHEEL, np.linspace(300.0, 2400.0, 30), sample_rate=3840.0, n_samples=8192,
                              noise=0.01, seed=0, fixtures=((F_STAND, 0.03, 5.0, "peak"),))
    return test, truth["modes_hz"]


CASES = {"preset": preset_case, "e-like": e_like_case}


def _fmt(v):
    return f"{v:.4g}" if isinstance(v, float) else v


def run(name: str) -> bool:
    test, truth = CASES[name]()
    t0 = time.perf_counter()
    d = api.diagnose(test)
    dt = time.perf_counter() - t0
    print(f"== {name}")
    for e in d.model.effects:
        print({k: _fmt(v) for k, v in dict(e).items() if k not in ("evidence", "psd_ref", "whirl", "gain_law")})
    print(f"error {d.error_before:.4g} -> {d.error_after:.4g}; diagnose {dt:.0f} s")
    kinds = [e["kind"] for e in d.model.effects]
    modes = [e for e in d.model.effects if e["kind"] == "suspension_modes"]
    stand = [e for e in d.model.effects if e["kind"] == "fixed_resonance" and e["role"] == "test_stand"]
    modes_ok = bool(modes)
    for m, f in truth.items():
        if not modes:
            break
        loose = m in (modes[0].get("unconstrained") or [])
        err = modes[0][f"{m}_Hz"] / f - 1
        modes_ok &= loose or abs(err) <= MODE_TOL
        print(f"{m} {modes[0][f'{m}_Hz']:.4g} Hz (truth {f:.4g} Hz, {100 * err:+.2f} %{', unconstrained' if loose else ''})")
    if stand:
        print(f"stand {stand[0]['f_Hz']:.4g} Hz (truth {F_STAND:g} Hz, {100 * (stand[0]['f_Hz'] / F_STAND - 1):+.2f} %)")
    ok = (sorted(kinds) == ["fixed_resonance", "suspension_modes"] and kinds[0] == "suspension_modes" and modes_ok
          and abs(stand[0]["f_Hz"] / F_STAND - 1) < STAND_TOL)
    print("expected (suspension_modes, then the fixture at 180 Hz beside them, nothing else):", "yes" if ok else "NO")
    return ok


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--case", choices=[*CASES, "all"], default="all")
    a = ap.parse_args(argv)
    for name in CASES if a.case == "all" else [a.case]:
        run(name)
    return 0


if __name__ == "__main__":
    sys.exit(main())
