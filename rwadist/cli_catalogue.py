"""`rwadist catalogue list/show` and `rwadist model compare`: the catalogue's wheels as tables for a reader
(headers, units, a verdict), kept out of cli.py."""
from __future__ import annotations

import json

from . import model as model_io

#: a fitted C within this fraction of the catalogue's counts as agreeing (the fit's typical scatter
#: on clean data is a few per cent; a catalogue value from a datasheet or a paper is no closer)
AGREE_FRACTION = 0.10


def cmd_catalogue_list(args) -> int:
    from . import catalogue

    print(f"{'name':<20} {'mass':>9}  {'lines':>13}  {'modes':<10}  source")
    for name in catalogue.names():
        m = catalogue.load(name)
        n = sum(len(m.harmonics(d)) for d in model_io.DIRECTIONS)
        src = str(m.provenance["source"])
        print(f"{name:<20} {m.wheel.get('mass_kg', float('nan')):6.2f} kg  {n:3d} harmonics  "
              f"{'analytical' if m.analytical else '          '}  {src[:70]}{'...' if len(src) > 70 else ''}")
    return 0


def cmd_catalogue_show(args) -> int:
    from . import catalogue

    m = catalogue.load(args.name)
    print(f"{m.name}: {json.dumps(m.wheel)}")
    print(f"source:   {m.provenance['source']}")
    print(f"date:     {m.provenance['date']}")
    print("measured:")
    for k, v in m.provenance["measured"].items():
        print(f"  {k}: {v}")
    if m.provenance.get("datasheet_limits"):
        print(f"datasheet limits: {json.dumps(m.provenance['datasheet_limits'])}")
    print(f"{'direction':<14} {'h':>7} {'C (SI)':>12}  sense")
    for d in model_io.DIRECTIONS:
        for h in m.harmonics(d):
            print(f"{d:<14} {h.h:7.3f} {h.C:12.4e}  {h.sense or ''}")
    if m.analytical:
        print("analytical: " + ", ".join(f"{k}={v:.4g}" for k, v in m.analytical.items() if isinstance(v, float)))
    return 0


def cmd_model_compare(args) -> int:
    from . import catalogue

    fitted = model_io.load(args.model)
    ref = catalogue.load(args.preset)
    res = catalogue.compare(fitted, ref)
    print(f"fitted {args.model} vs catalogue {args.preset}; C in SI per (rad/s)²: kg·m for forces, kg·m² for torques")
    print(f"{'direction':<14} {'h fit':>7} {'C fit':>11} {'h ' + args.preset:>14} {'C catalogue':>12} "
          f"{'fit/catalogue':>13}")
    ratios = []
    for d, hf, cf, hr, cr in res["harmonics"]:
        ratio = f"{cf / cr:13.2f}" if cf is not None and cr else f"{'-':>13}"
        if cf is not None and cr:
            ratios.append((abs(cf / cr - 1.0), d, hf))
        print(f"{d:<14} {'' if hf is None else f'{hf:7.3f}':>7} {'' if cf is None else f'{cf:11.3e}':>11} "
              f"{'' if hr is None else f'{hr:14.3f}':>14} {'' if cr is None else f'{cr:12.3e}':>12} {ratio}")
    only_fit = sum(1 for r in res["harmonics"] if r[3] is None)
    only_ref = sum(1 for r in res["harmonics"] if r[1] is None)
    if ratios:
        worst = max(ratios)
        agree = sum(1 for r in ratios if r[0] <= AGREE_FRACTION)
        print(f"verdict: {agree} of {len(ratios)} matched harmonics within ±{AGREE_FRACTION:.0%} of the catalogue "
              f"(largest deviation {worst[0]:.0%}: {worst[1].replace('_', ' ')} h {worst[2]:.3g}); "
              f"{only_fit} fitted only, {only_ref} in the catalogue only")
    else:
        print(f"verdict: no harmonic matched (h within 0.03); {only_fit} fitted only, {only_ref} in the catalogue only")
    flagged = False
    for name, mine, limit, above in res["imbalance"]:
        flagged |= above
        mark = "  ABOVE the datasheet limit" if above else ""
        unit = "kg·m" if name.endswith("_kg_m") else "kg·m²"
        # the words, and the model file's field the number comes from
        label = {"U_s_kg_m": "static imbalance", "U_d_kg_m2": "dynamic imbalance"}.get(name, "imbalance") + f" ({name})"
        print(f"{label}: fitted {'-' if mine is None else f'{mine:.3e} {unit}'}, limit "
              f"{'-' if limit is None else f'{limit:.3e} {unit}'}{mark}")
    return 1 if flagged else 0
