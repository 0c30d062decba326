"""Stand and modes on the default path, over the wheel family (issue 33, Build items 1 and 2).

Every cell is a steady test of one wheel of tests/family_wheel.py (generated without rwadist's physics: mass 2-15 kg,
I_zz/I_rr 1.2-2.2, modes 50-600 Hz, bearing-like lines, its own speed range and sample rate), written to disk in the
interchange format and diagnosed by the command a user types, ``rwadist diagnose DIR -o OUT`` (no model; run through
:func:`rwadist.cli.main` in this process), its summary.json read back.  Cells:

* ``clean``: the wheel alone.  Counted: effects added besides ``suspension_modes`` (0 expected); every mode within 2 %.
* ``fixture k x MODE``: a test-stand resonance on every channel (tests/family_effects.Fixture, ζ 0.03, peak gain 5)
  at k = 0.5, 0.75, 1.0, 1.25, 1.5 x each suspension mode's frequency.  Counted: every mode within 2 % of the truth or
  listed in the effect's ``unconstrained``; a wheel-mode resonance (``fixed_resonance`` role ``wheel_mode``) added.
* ``counter_rotation``: 30 % of the radial imbalance's power counter-rotating; ``speed_sidebands``: the imbalance
  modulated at 0.06 x the speed, depth 0.4.  Counted: the class named, other classes added, modes within 2 %.

Prints one line per cell and the totals.  Run with ``nice -n 10`` (one diagnosis takes 5-60 s on one core):

    nice -n 10 python benchmarks/standmodes_family.py [--wheels 0,4] [--factors 0.5,1.0,1.5] [--cells clean,fixture]
"""
from __future__ import annotations

import argparse
import contextlib
import io
import json
import sys
import tempfile
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parent / "tests"))

import family_effects as fe  # noqa: E402
import family_wheel as fw  # noqa: E402

from rwadist.cli import main as rwadist_main  # noqa: E402

MODE_TOL = 0.02
FACTORS = (0.5, 0.75, 1.0, 1.25, 1.5)
MODE_NAMES = ("radial_translation", "rocking", "axial")


def diagnose_dir(data, wheel, work: Path) -> dict:
    """``rwadist diagnose DIR -o OUT`` on the cell's data; its summary.json."""
    d = fw.write_steady(data, work / "data", wheel.name)
    out = work / "out"
    with contextlib.redirect_stdout(io.StringIO()), contextlib.redirect_stderr(io.StringIO()):
        code = rwadist_main(["diagnose", str(d), "-o", str(out)])
    if code not in (0, None):
        raise RuntimeError(f"rwadist diagnose exited {code}")
    return json.loads((out / "summary.json").read_text())


def modes_verdict(summary: dict, wheel) -> tuple:
    """(every mode within MODE_TOL or declared unconstrained, text of the modes)."""
    found = [e for e in summary["effects"] if e["kind"] == "suspension_modes"]
    if not found:
        return False, "no suspension_modes"
    e = found[0]
    unc = set(e.get("unconstrained") or [])
    ok, parts = True, []
    for name, truth in wheel.modes_hz().items():
        got = e.get(f"{name}_Hz")
        err = (got / truth - 1.0) if got else float("nan")
        good = name in unc or abs(err) <= MODE_TOL
        ok &= good
        parts.append(f"{name[:5]} {err:+.2%}{' unc' if name in unc else ''}{'' if good else ' BAD'}")
    return ok, ", ".join(parts)


def cells(wheel, kinds, factors):
    if "clean" in kinds:
        yield "clean", (), None
    if "fixture" in kinds:
        for name in MODE_NAMES:
            for k in factors:
                f = k * wheel.modes_hz()[name]
                if f < 0.45 * wheel.sample_rate:
                    yield f"fixture {k:g}x{name[:5]} {f:.0f}Hz", (fe.Fixture(f_hz=f),), "fixture"
    if "counter_rotation" in kinds:
        yield "counter_rotation", (fe.CounterRotation(fraction=0.3),), "counter_rotation"
    if "speed_sidebands" in kinds:
        yield "speed_sidebands", (fe.SpeedSidebands(per_rev=0.06, depth=0.4),), "speed_sidebands"


def judge(summary, wheel, expect) -> dict:
    kinds = [e["kind"] for e in summary["effects"]]
    modes_ok, modes_text = modes_verdict(summary, wheel)
    extra = [k for k in kinds if k != "suspension_modes"]
    invented = [e for e in summary["effects"] if e["kind"] == "fixed_resonance" and e.get("role") == "wheel_mode"]
    if expect is None:
        ok = not extra
    elif expect == "fixture":
        ok = not invented
        extra = [k for k in extra if k != "fixed_resonance"]
        extra += ["fixed_resonance(wheel_mode)"] * len(invented)
    else:
        ok = expect in kinds
        extra = [k for k in extra if k != expect]
    return {"named_ok": ok, "modes_ok": modes_ok, "modes": modes_text, "others": extra}


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--wheels", default=",".join(str(i) for i in range(len(fw.FAMILY_TABLE))))
    ap.add_argument("--factors", default=",".join(f"{k:g}" for k in FACTORS))
    ap.add_argument("--cells", default="clean,fixture,counter_rotation,speed_sidebands")
    ap.add_argument("--n-speeds", type=int, default=16)
    ap.add_argument("--n-samples", type=int, default=4096)
    ap.add_argument("--json", help="write every cell's verdict here")
    args = ap.parse_args(argv)
    family = fw.family()
    wheels = [family[int(i)] for i in args.wheels.split(",")]
    factors = [float(x) for x in args.factors.split(",")]
    kinds = args.cells.split(",")
    rows = []
    for wheel in wheels:
        speeds = fw.np.linspace(wheel.min_rpm, wheel.max_rpm, args.n_speeds)
        for label, effects, expect in cells(wheel, kinds, factors):
            data = fw.steady(wheel, speeds_rpm=speeds, n_samples=args.n_samples, noise=0.01, seed=1,
                             effects=effects)
            t0 = time.perf_counter()
            with tempfile.TemporaryDirectory() as tmp:
                s = diagnose_dir(data, wheel, Path(tmp))
            v = judge(s, wheel, expect)
            v.update(wheel=wheel.name, cell=label, expect=expect, seconds=time.perf_counter() - t0,
                     effects=[e["kind"] for e in s["effects"]], error_after=s.get("error_after"))
            rows.append(v)
            flag = "ok " if v["named_ok"] and v["modes_ok"] and not v["others"] else "BAD"
            print(f"{flag} {wheel.name:9s} {label:34s} modes: {v['modes']}; others {v['others']}; "
                  f"{v['seconds']:.0f} s", flush=True)
    print("\ntotals")
    for group in ("clean", "fixture", "counter_rotation", "speed_sidebands"):
        sel = [r for r in rows if (r["expect"] or "clean") == group]
        if not sel:
            continue
        named = sum(r["named_ok"] for r in sel)
        modes = sum(r["modes_ok"] for r in sel)
        alone = sum(not r["others"] for r in sel)
        what = {"clean": "0 effects added", "fixture": "no wheel-mode resonance invented"}.get(group,
                                                                                                f"{group} named")
        print(f"  {group:17s} {len(sel):3d} cells: {what} {named}/{len(sel)}, every mode within 2 % or unconstrained "
              f"{modes}/{len(sel)}, nothing else added {alone}/{len(sel)}")
    if args.json:
        Path(args.json).write_text(json.dumps(rows, indent=1))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
