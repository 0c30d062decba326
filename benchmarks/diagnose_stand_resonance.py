"""Open case of issue 14 (item 3): E modal data with a 180 Hz test-stand resonance on all six channels.

What diagnose should do with no model: name ``suspension_modes`` (rocking within 2 % of 54.9 Hz) and the
fixture as ``fixed_resonance`` (role ``test_stand``) at 180 Hz beside them, never inside them.
What it does today (printed by this script): it names neither.  Run: ``python benchmarks/diagnose_stand_resonance.py``
(about a minute).
"""
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))

from rwadist import api  # noqa: E402
from rwadist.inject import parse, simulate_with_injections  # noqa: E402
from rwadist.presets import preset  # noqa: E402

SPEEDS = np.linspace(300.0, 3000.0, 30)


def main():
    test = simulate_with_injections(preset("ithaco-e"), [parse("fixed_resonance:f_hz=180")], SPEEDS,
                                    physics="extended", sample_rate=3840.0, n_samples=8192, noise=0.01, seed=0)
    d = api.diagnose(test)
    kinds = [e["kind"] for e in d.model.effects]
    for e in d.model.effects:
        print({k: (round(v, 4) if isinstance(v, float) else v) for k, v in dict(e).items()
               if k not in ("evidence", "psd_ref")})
    print(f"error {d.error_before:.4g} -> {d.error_after:.4g}")
    ok = bool(kinds) and kinds[0] == "suspension_modes" and any(
        e["kind"] == "fixed_resonance" and abs(e["f_Hz"] / 180.0 - 1) < 0.02 for e in d.model.effects)
    print("expected (suspension_modes first, fixture at 180 Hz beside them):", "yes" if ok else "NO")


if __name__ == "__main__":
    main()
