"""Open world of ``rwadist diagnose`` on the wheel family (issue 33, items 3 and 4): effects no class describes,
injected into wheels rwadist's tests were not tuned on, diagnosed on the command a user types.

Data: the wheels of tests/family_wheel.py (eight wheels, 2-15 kg, I_zz/I_rr 1.2-2.2, modes 50-600 Hz, bearing-like
lines, 3000-10000 rpm, 2-10 kHz; numpy only, nothing of rwadist), each with one of the effects below written
into its runs through the generator's own hooks (written here with numpy: none of them is a diagnose class, and
each differs from the family's own unknown kinds of tests/family_effects.py), saved in the interchange format and
diagnosed by ``rwadist diagnose DATA -o R`` (no model: the default path; a subprocess) and its summary.json read.

==================== ================= =========================================================================
effect               signature         what is injected
==================== ================= =========================================================================
mains_pickup         fixed_line        60, 180 and 300 Hz (odd orders of 60 Hz mains), each channel its own
                                       phase in each run (differential pickup), 4 x the channel's noise std
torque_crosstalk     channel_copy      Tz carries 0.3 x Tx (a load cell's torque axis cross-sensitive to another)
softening_mode       moving_resonance  a resonance on the radial forces (zeta 0.03, peak gain 5) whose frequency
                                       falls with speed, f_r = 0.8 f_trans (1 - 0.4 Omega/Omega_max)
torque_hump          broadband_hump    band-limited noise on Tx, Ty, Tz (second-order band-pass, Q 6) centred at
                                       1.6 x the rocking mode, 10 dB over the noise at its centre, every speed
remount_step         run_change        every third run (speed order) with all its lines 3.5 dB stronger (the
                                       wheel re-mounted between runs)
inverter_sidebands   sideband_line     a carrier at 0.17 x the sample rate on every channel, 8 x the channel's
                                       noise std, with sidebands at +- p x the spin frequency of 0.35 x it (an
                                       inverter modulated by a motor of p pole pairs: p = 1, 2, 3, 4 by wheel)
speed_gain           line_property     every channel's gain 1 - 0.08 Omega/Omega_max before the sensor noise (a
                                       load cell warming with speed: trial16 tempgain); right when a gain_trend
                                       record reads the gain's change over the speed range within 25 %
amplifier_distortion distorted         one radial channel through y = x + a2 x^2/s + a3 x^3/s^2 (s its RMS), by
                                       wheel Fx 2 %/2 %, Ty 3 % odd, Fy 2 % even, Tx 0.5 %/0.5 %; right when
                                       data_quality holds a ``distorted`` record of that channel, its orders
                                       within 15 % (rwadist.channel_distortion: put right before the search)
==================== ================= =========================================================================

A cell passes when a record of the right signature is where the injection is (:func:`right`) and no class beyond
the wheel's ``suspension_modes`` is added; a clean cell when nothing is described and nothing is added.  The
acceptance (issue 33): right in >= 90 % of the cells, 0 classes added.  For the pickup cells the two figures of
merit are printed against the clean cell's (item 4: one narrow line must never read "1.1 x the clean level").

Run (each cell 10-120 s on a free core; nice it)::

    nice -n 10 python benchmarks/diagnose_open_world.py                   # 8 wheels x (clean + 5 effects)
    python benchmarks/diagnose_open_world.py --wheels 0,4 --kinds clean,mains_pickup
    python benchmarks/diagnose_open_world.py --json rows.json --keep /tmp/cells
    python benchmarks/diagnose_open_world.py --seed 2 --wheels 1,3           # other phases and noise
"""
from __future__ import annotations

import argparse
import json
import shutil
import subprocess
import sys
import tempfile
import time
from dataclasses import replace
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))

import family_wheel as fw  # noqa: E402

#: per wheel: (number of speeds, samples per run, noise as a fraction of the top-speed imbalance load)
CONDITIONS = {0: (20, 8192, 0.01), 1: (16, 8192, 0.003), 2: (20, 4096, 0.03), 3: (20, 8192, 0.01),
              4: (20, 4096, 0.01), 5: (16, 16384, 0.01), 6: (20, 4096, 0.003), 7: (16, 8192, 0.03)}
CH = {c: i for i, c in enumerate(fw.CHANNELS)}


class MainsPickup:
    """60 Hz mains orders, differential: each channel and run its own phase, ``level`` x the channel's noise std."""

    signature = "fixed_line"

    def __init__(self, freqs_hz=(60.0, 180.0, 300.0), level=4.0):
        self.freqs_hz, self.level = tuple(freqs_hz), level

    def cell_signal(self, t, omega, run, rng, wheel, std):
        ph = rng.uniform(0, 2 * np.pi, (len(self.freqs_hz), 6))
        out = np.zeros((6, t.size))
        for f, p in zip(self.freqs_hz, ph):
            out += self.level * std[:, None] * np.cos(2 * np.pi * f * t[None, :] + p[:, None])
        return out

    def truth(self):
        return {"kind": "mains_pickup", "freqs_hz": self.freqs_hz, "level_x_noise_std": self.level}


class TorqueCrosstalk:
    """Channel ``target`` += kappa x channel ``source`` (the cell's own cross-sensitivity)."""

    signature = "channel_copy"

    def __init__(self, source="Tx", target="Tz", kappa=0.3):
        self.source, self.target, self.kappa = source, target, kappa

    def mixing(self):
        m = np.eye(6)
        m[CH[self.target], CH[self.source]] = self.kappa
        return m

    def truth(self):
        return {"kind": "torque_crosstalk", "source": self.source, "target": self.target, "kappa": self.kappa}


class SofteningMode:
    """A resonance H(r) = (1 − r² + 2jgζr)/(1 − r² + 2jζr), r = f/f_r, on the radial force channels, its frequency
    falling with speed: f_r = f0 (1 − drop·Ω/Ω_max)."""

    signature = "moving_resonance"

    def __init__(self, f0_hz, omega_max, drop=0.4, zeta=0.03, gain=5.0):
        self.f0_hz, self.omega_max, self.drop, self.zeta, self.gain_ = f0_hz, omega_max, drop, zeta, gain

    def f_r(self, omega):
        return self.f0_hz * (1.0 - self.drop * abs(omega) / self.omega_max)

    def gain(self, f_hz, omega):
        r = np.asarray(f_hz, float) / self.f_r(omega)
        h = (1 - r**2 + 2j * self.gain_ * self.zeta * r) / (1 - r**2 + 2j * self.zeta * r)
        g = np.ones((np.size(f_hz), 6), dtype=complex)
        g[:, [CH["Fx"], CH["Fy"]]] = h[:, None]
        return g

    def truth(self):
        return {"kind": "softening_mode", "f_at_rest_hz": self.f0_hz, "f_at_top_hz": self.f_r(self.omega_max)}


class TorqueHump:
    """Noise through a second-order band-pass (centre ``f_hz``, quality q) on the torque channels, ``rise_db`` over
    the channel's white noise at the centre."""

    signature = "broadband_hump"

    def __init__(self, f_hz, q=6.0, rise_db=10.0):
        self.f_hz, self.q, self.rise_db = f_hz, q, rise_db

    def cell_signal(self, t, omega, run, rng, wheel, std):
        n, fs = t.size, 1.0 / (t[1] - t[0])
        f = np.fft.rfftfreq(n, 1 / fs)
        r = f / self.f_hz
        shape = 1.0 / (1.0 + self.q**2 * (r - 1.0 / np.maximum(r, 1e-12)) ** 2)      # |H|², 1 at the centre
        # white noise of std s has a one-sided PSD 2s²/fs: the hump adds (10^(rise/10) − 1) × that at the centre
        out = np.zeros((6, n))
        for c in ("Tx", "Ty", "Tz"):
            spec = rng.standard_normal(f.size) + 1j * rng.standard_normal(f.size)
            scale = np.sqrt((10 ** (self.rise_db / 10) - 1) * shape * n / 2.0) * std[CH[c]]
            out[CH[c]] = np.fft.irfft(spec * scale, n)
        return out

    def truth(self):
        return {"kind": "torque_hump", "f_hz": self.f_hz, "q": self.q, "rise_db": self.rise_db}


class RemountStep:
    """Every ``every``-th run (from the second, in speed order) with all its line loads ``step_db`` stronger."""

    signature = "run_change"

    def __init__(self, step_db=3.5, every=3):
        self.step_db, self.every = step_db, every

    def stepped(self, run):
        return run % self.every == 1

    def components(self, comp, omega, run, rng, wheel):
        g = 10 ** (self.step_db / 20) if self.stepped(run) else 1.0
        return fw.Components(comp.direction, comp.w, comp.sense, comp.c * g, comp.tag)

    def truth(self):
        return {"kind": "remount_step", "step_db": self.step_db, "every": self.every}


class InverterSidebands:
    """A carrier at ``f_c`` Hz on every channel, ``level`` x the channel's noise std, one phase per run, and its
    sidebands at f_c ± p·Ω/2π of ``side`` x it, each its own phase."""

    signature = "sideband_line"

    def __init__(self, f_c, p, level=8.0, side=0.35):
        self.f_c, self.p, self.level, self.side = f_c, p, level, side

    def cell_signal(self, t, omega, run, rng, wheel, std):
        out = np.zeros((6, t.size))
        for f, a in ((self.f_c, 1.0), (self.f_c - self.p * omega / (2 * np.pi), self.side),
                     (self.f_c + self.p * omega / (2 * np.pi), self.side)):
            out += a * self.level * std[:, None] * np.cos(2 * np.pi * f * t + rng.uniform(0, 2 * np.pi))
        return out

    def truth(self):
        return {"kind": "inverter_sidebands", "carrier_hz": self.f_c, "pole_pairs": self.p, "side": self.side}


class SpeedGain:
    """Every channel's gain 1 − ``k``·Ω/Ω_max at every frequency (the sensor noise added after it)."""

    signature = "line_property"

    def __init__(self, omega_max, k=0.08):
        self.omega_max, self.k = omega_max, k

    def gain(self, f_hz, omega):
        return np.full((np.size(f_hz), 6), 1.0 - self.k * abs(omega) / self.omega_max, dtype=complex)

    def change_db(self, omega_min):
        """The lines' change of power from ``omega_min`` to Ω_max, dB."""
        return 20 * np.log10((1 - self.k) / (1 - self.k * abs(omega_min) / self.omega_max))

    def truth(self):
        return {"kind": "speed_gain", "k": self.k, "omega_max_rad_s": self.omega_max}


class AmplifierDistortion:
    """One radial channel through a signal chain that is not linear, y = x + a2·x²/σ + a3·x³/σ² (σ the run's RMS of
    the channel, noise included: the amplifier sees the sensor's output); the channel and the orders by wheel."""

    signature = "distorted"         # a data_quality record (rwadist.channel_distortion), not a description
    CASES = (("Fx", 0.02, 0.02), ("Ty", 0.0, 0.03), ("Fy", 0.02, 0.0), ("Tx", 0.005, 0.005))

    def __init__(self, index: int):
        self.channel, self.a2, self.a3 = self.CASES[index % len(self.CASES)]

    def apply(self, data):
        signals = data.signals.copy()
        x = signals[:, CH[self.channel], :]
        s = x.std(axis=1, keepdims=True)
        signals[:, CH[self.channel], :] = x + self.a2 * x**2 / s + self.a3 * x**3 / s**2
        return replace(data, signals=signals)

    def truth(self):
        return {"kind": "amplifier_distortion", "channel": self.channel, "a2": self.a2, "a3": self.a3}


KINDS = ("clean", "mains_pickup", "torque_crosstalk", "softening_mode", "torque_hump", "remount_step",
         "inverter_sidebands", "speed_gain", "amplifier_distortion")


def make_effect(kind: str, wheel):
    if kind == "mains_pickup":
        return MainsPickup()
    if kind == "torque_crosstalk":
        return TorqueCrosstalk()
    if kind == "softening_mode":
        return SofteningMode(0.8 * wheel.f_trans, wheel.max_rpm * fw.RPM)
    if kind == "torque_hump":
        return TorqueHump(1.6 * wheel.f_rock)
    if kind == "remount_step":
        return RemountStep()
    if kind == "inverter_sidebands":
        # p = 1, 2, 3, 4 by the family's index (wheels "family-N")
        return InverterSidebands(0.17 * wheel.sample_rate, float(1 + int(wheel.name.rsplit("-", 1)[-1]) % 4))
    if kind == "speed_gain":
        return SpeedGain(wheel.max_rpm * fw.RPM)
    if kind == "amplifier_distortion":
        return AmplifierDistortion(int(wheel.name.rsplit("-", 1)[-1]))
    raise ValueError(kind)


def right(kind: str, effect, wheel, speeds_rpm, recs: list) -> bool:
    """Whether a record of the effect's signature is where the injection is."""
    if kind == "amplifier_distortion":       # the channel named, its law read within 15 % (an order absent: ~0)
        return any(r["channel"] == effect.channel and all(
            r[key] is not None and abs(r[key] - a) <= 0.15 * max(a, 0.1 * max(effect.a2, effect.a3)) for key, a in
            (("second_order", effect.a2), ("third_order", effect.a3))) for r in recs)
    mine = [r for r in recs if r["signature"] == effect.signature]
    if kind == "mains_pickup":
        band = [f for f in effect.freqs_hz if f < fw.ANTI_ALIAS * wheel.sample_rate]
        return all(any(abs(r["f_Hz"][0] - f) < 1.0 for r in mine) for f in band)
    if kind == "torque_crosstalk":
        p = [r["parameters"] for r in mine]
        return any(x.get("source") == effect.source and x.get("target") == effect.target
                   and abs(x.get("gain", 0) / effect.kappa - 1) < 0.1 for x in p)
    if kind == "softening_mode":
        lo, hi = effect.f_r(wheel.max_rpm * fw.RPM), effect.f0_hz
        return any({"Fx", "Fy"} <= set(r["channels"]) and r["parameters"].get("slope_Hz_per_Hz_of_spin", 0) < 0
                   and r["f_Hz"][0] < hi and r["f_Hz"][1] > lo for r in mine)
    if kind == "torque_hump":
        return any(set(r["channels"]) <= {"Tx", "Ty", "Tz"}
                   and abs(r["parameters"]["peak_Hz"] / effect.f_hz - 1) < 0.15 for r in mine)
    if kind == "inverter_sidebands":
        return any(abs(r["parameters"].get("carrier_Hz", 0) - effect.f_c) < 1.0 and r["parameters"].get("sides") == [-1, 1]
                   and abs(r["parameters"].get("h", 0) / effect.p - 1) < 2e-3 for r in mine)
    if kind == "speed_gain":
        truth = effect.change_db(min(speeds_rpm) * fw.RPM)
        return any(r["parameters"].get("property") == "gain_trend"
                   and abs(r["parameters"]["change_dB"] / truth - 1) < 0.25 for r in mine)
    if kind == "remount_step":
        stepped = {round(float(s), 3) for i, s in enumerate(speeds_rpm) if effect.stepped(i)}
        for r in mine:
            flagged = {round(float(s), 3) for s in r["parameters"].get("run_speeds_rpm", [])}
            if flagged and len(flagged & stepped) >= 0.5 * len(stepped) and len(flagged & stepped) >= 0.5 * len(flagged):
                return True
        return False
    raise ValueError(kind)


def run_diagnose(data_dir: Path, report_dir: Path) -> tuple:
    """``rwadist diagnose DATA -o R`` (the console script beside this interpreter): (summary or None, console)."""
    exe = Path(sys.executable).parent / "rwadist"
    cmd = [str(exe) if exe.exists() else (shutil.which("rwadist") or "rwadist"), "diagnose", str(data_dir),
           "-o", str(report_dir)]
    proc = subprocess.run(cmd, capture_output=True, text=True)
    summary = report_dir / "summary.json"
    if proc.returncode != 0 or not summary.exists():
        return None, proc.stdout + proc.stderr
    return json.loads(summary.read_text()), proc.stdout


def cell(i: int, wheel, kind: str, work: Path, seed: int = 1) -> dict:
    n_speeds, n_samples, noise = CONDITIONS[i]
    wheel = replace(wheel, n_speeds=n_speeds, n_samples=n_samples)
    speeds = np.linspace(wheel.min_rpm, wheel.max_rpm, n_speeds)
    effect = None if kind == "clean" else make_effect(kind, wheel)
    # seed 1 is the wheel's own index (the cells as first measured); another seed draws other phases and noise
    hooked = effect is not None and not hasattr(effect, "apply")
    data = fw.steady(wheel, speeds_rpm=speeds, noise=noise, seed=i + 1000 * (seed - 1),
                     effects=[effect] if hooked else [])
    if effect is not None and not hooked:
        data = effect.apply(data)
    d = fw.write_steady(data, work / f"w{i}_{kind}" / "data", wheel.name)
    t0 = time.perf_counter()
    summary, console = run_diagnose(d, work / f"w{i}_{kind}" / "report")
    row = {"wheel": i, "kind": kind, "seconds": time.perf_counter() - t0}
    if summary is None:
        row.update(ok=False, failed=console[-2000:], added=[], described=[])
        return row
    recs = summary.get("unexplained") or []
    added = [e["kind"] for e in summary["effects"] if e["kind"] != "suspension_modes"]
    row.update(added=added, described=[r["signature"] for r in recs],
               error=(summary["error_after"], summary.get("narrow_line_error_after")),
               where=[f"{r['signature']} {r['f_Hz'][0]:.4g}-{r['f_Hz'][1]:.4g} Hz {'+'.join(r['channels'])}"
                      for r in recs])
    if effect is None:
        row["ok"] = not recs and not added
    else:
        found = ([r for r in summary.get("data_quality", []) if r.get("type") == effect.signature]
                 if effect.signature == "distorted" else recs)
        row["right"] = right(kind, effect, wheel, speeds, found)
        row["ok"] = row["right"] and not added
        row["truth"] = effect.truth()
    return row


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--wheels", default=",".join(str(i) for i in CONDITIONS))
    ap.add_argument("--kinds", default=",".join(KINDS))
    ap.add_argument("--json", default=None, help="write the rows here")
    ap.add_argument("--keep", default=None, help="keep the cells' data and reports in this folder")
    ap.add_argument("--seed", type=int, default=1, help="1: the cells as first measured; others: other draws")
    args = ap.parse_args(argv)
    family = fw.family()
    work = Path(args.keep) if args.keep else Path(tempfile.mkdtemp(prefix="rwadist_open_world_"))
    rows = []
    try:
        for i in (int(x) for x in args.wheels.split(",")):
            clean_err = None
            for kind in args.kinds.split(","):
                r = cell(i, family[i], kind, work, args.seed)
                if kind == "clean":
                    clean_err = r.get("error")
                elif clean_err and r.get("error") and kind == "mains_pickup":
                    r["vs_clean"] = [a / b if b else float("nan") for a, b in zip(r["error"], clean_err)]
                rows.append(r)
                vs = (f" power {r['vs_clean'][0]:.2f}x / narrow-line {r['vs_clean'][1]:.1f}x clean"
                      if "vs_clean" in r else "")
                print(f"wheel {i} {kind:17s} {'PASS' if r['ok'] else 'FAIL'}  added {r['added'] or '-'}  described "
                      f"{r.get('where') or '-'}{vs}  ({r['seconds']:.0f} s)", flush=True)
                if "failed" in r:
                    print("   diagnose failed:", r["failed"][-400:])
    finally:
        if not args.keep:
            shutil.rmtree(work, ignore_errors=True)
    print("\nsummary (cells passing: right signature where injected, no class added; clean: nothing described)")
    for kind in args.kinds.split(","):
        sel = [r for r in rows if r["kind"] == kind]
        n_ok = sum(r["ok"] for r in sel)
        n_added = sum(bool(r["added"]) for r in sel)
        print(f"  {kind:17s} {n_ok}/{len(sel)} = {100.0 * n_ok / max(len(sel), 1):.0f} %   cells with a class "
              f"added: {n_added}")
    unknown = [r for r in rows if r["kind"] != "clean"]
    if unknown:
        n = sum(r["ok"] for r in unknown)
        print(f"  all effects       {n}/{len(unknown)} = {100.0 * n / len(unknown):.0f} % (acceptance >= 90 %), "
              f"classes added in {sum(bool(r['added']) for r in unknown)} cells (acceptance 0)")
        n = sum(bool(r.get("right")) for r in unknown)
        print(f"  right signature where injected, whatever else: {n}/{len(unknown)} = {100.0 * n / len(unknown):.0f} %")
        # a wheel whose clean cell already gets a class (the default path's own miss, not the effect's) apart
        sound = {r["wheel"] for r in rows if r["kind"] == "clean" and not r["added"]}
        on = [r for r in unknown if r["wheel"] in sound]
        if on and len(on) < len(unknown):
            n = sum(r["ok"] for r in on)
            print(f"  on the wheels whose clean cell gets no class ({', '.join(str(w) for w in sorted(sound))}): "
                  f"{n}/{len(on)} = {100.0 * n / len(on):.0f} %; per effect: " + ", ".join(
                      f"{k} {sum(r['ok'] for r in on if r['kind'] == k)}/{sum(r['kind'] == k for r in on)}"
                      for k in dict.fromkeys(r["kind"] for r in on)))
    vs = [r["vs_clean"] for r in rows if "vs_clean" in r]
    if vs:
        a = np.array(vs)
        print(f"  pickup cells: power-weighted error {np.min(a[:, 0]):.2f}-{np.max(a[:, 0]):.2f}x clean, narrow-line "
              f"error {np.min(a[:, 1]):.1f}-{np.max(a[:, 1]):.1f}x clean")
    if args.json:
        Path(args.json).write_text(json.dumps(rows, indent=1, default=float))
    return 0


if __name__ == "__main__":
    sys.exit(main())
