"""Issue 16 acceptance numbers in one run (the tests assert them; this prints them):

1. empirical-only model: FMU outputs (pythonfmu and native) vs the closed-form C·Ω² lines;
2. HR16-75: fundamental |F|/(U_s·Ω²) and |T|/(U_d·Ω²) at 3000 and 6000 rpm, by default and with
   --assumed-modes, in both FMUs, in `rwadist psd` (line envelope), in the coupling kit (blocked lines of
   coupling.wheel_spec_from_model) and in a `psd --wheels` set (rwadist.mounting.load_wheels);
3. native FMU vs pythonfmu FMU vs rwadist.extended_time.simulate_time, spin-up 0→3000 rpm and reversal ±1500 rpm,
   every effect class on (simulate_time: the line effects; it has no ripple or floor);
4. floor multisine, native vs pythonfmu, same seed;
5. fmpy validate problems and ldd of the native binary.

    .venv/bin/python benchmarks/issue16_acceptance.py
"""
from __future__ import annotations

import json
import subprocess
import sys
import tempfile
import zipfile
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))

from test_fmu_models import closed_form_lines, empirical_only  # noqa: E402
from test_fmu_native import (  # noqa: E402
    EFFECTS,
    LINE_EFFECTS,
    mount_params,
    reversal,
    slope,
    spin_up,
    wheel_doc,
    worst,
)

from rwadist import catalogue  # noqa: E402
from rwadist import extended as ext  # noqa: E402
from rwadist import model as model_io  # noqa: E402
from rwadist.extended_time import simulate_time  # noqa: E402
from rwadist.fmu import hosts  # noqa: E402
from rwadist.fmu.build import build_fmu  # noqa: E402
from rwadist.fmu.native_build import build_native_fmu  # noqa: E402

RPM = 2 * np.pi / 60


def main() -> int:
    with tempfile.TemporaryDirectory(prefix="rwadist_i16_") as tmp:
        tmp = Path(tmp)
        doc = empirical_only()
        t = np.arange(1001) * 1e-3
        for kind, build in (("pythonfmu", build_fmu), ("native", build_native_fmu)):
            path = build(doc, tmp / f"emp_{kind}.fmu")
            errs = []
            for rpm in (3000.0, -1700.0):
                w = rpm * RPM
                out = hosts.run_fmpy(path, t, {"wheel_speed": np.full(t.size, w)}, {})
                ref = closed_form_lines(doc, w, t)
                errs.append(np.max(np.abs(out[:, :6] - ref)) / np.max(np.abs(ref)))
            print(f"1. empirical-only, {kind:9s}: max |FMU - C*Omega^2 lines| / peak = {max(errs):.2e} (target 1e-9)")

        hr = json.loads(catalogue.path("honeywell-hr16-75").read_text())
        an = hr["analytical"]
        for flag in (False, True):
            for kind, build in (("pythonfmu", build_fmu), ("native", build_native_fmu)):
                path = build(hr, tmp / f"hr_{kind}_{flag}.fmu", assumed_modes=flag)
                for rpm in (3000.0, 6000.0):
                    w = rpm * RPM
                    out = hosts.run_fmpy(path, np.arange(2001) * 1e-3, {"wheel_speed": np.full(2001, w)},
                                         {"start_steady": True})
                    f, tq = np.hypot(out[-1, 0], out[-1, 1]), np.hypot(out[-1, 3], out[-1, 4])
                    print(f"2. HR16-75 FMU {kind:9s} {'--assumed-modes' if flag else 'default        '} {rpm:5.0f} rpm: "
                          f"|F|/(U_s W^2) - 1 = {f / (an['U_s_kg_m'] * w**2) - 1:+.2e}, "
                          f"|T|/(U_d W^2) - 1 = {tq / (an['U_d_kg_m2'] * w**2) - 1:+.2e}")
        from rwadist.cli import main as cli
        for flag in ([], ["--assumed-modes"]):
            out = tmp / f"psd{len(flag)}.csv"
            cli(["psd", "--preset", "honeywell-hr16-75", "--speed-rpm", "0:6000", "--fmax", "120", "--n-freq", "1201",
                 "--n-speeds", "200", "-o", str(out), *flag])
            env = np.loadtxt(tmp / f"psd{len(flag)}_envelope.csv", delimiter=",", skiprows=1)
            for rpm in (3000, 6000):
                i = int(np.argmin(np.abs(env[:, 0] - rpm / 60)))
                w = rpm * RPM
                print(f"2. HR16-75 psd {'--assumed-modes' if flag else 'default        '} {rpm:5d} rpm: "
                      f"F/(U_s W^2) - 1 = {env[i, 1] / (an['U_s_kg_m'] * w**2) - 1:+.2e}, "
                      f"T/(U_d W^2) - 1 = {env[i, 4] / (an['U_d_kg_m2'] * w**2) - 1:+.2e}; note file: "
                      f"{(tmp / f'psd{len(flag)}_ASSUMED_MODES.txt').exists()}")

        import warnings

        from test_assumed_modes_default import _fundamental, _plant, _wheels_file

        from rwadist import coupling as cp
        from rwadist.coupling.performance import wheel_spec_from_model
        from rwadist.mounting import load_wheels
        omega = np.array([3000.0, 6000.0]) * RPM
        U_s, U_d = an["U_s_kg_m"], an["U_d_kg_m2"]
        for flag in (False, True):
            with warnings.catch_warnings(record=True) as caught:
                warnings.simplefilter("always")
                spec = wheel_spec_from_model(catalogue.load("honeywell-hr16-75"), assumed_modes=flag)
            F = _fundamental(cp.line_responses(_plant(), [spec], omega))
            for i, rpm in enumerate((3000, 6000)):
                print(f"2. HR16-75 coupling {'assumed_modes=True' if flag else 'default           '} {rpm:5d} rpm: "
                      f"|F|/(U_s W^2) - 1 = {abs(F[i, 0]) / (U_s * omega[i]**2) - 1:+.2e}, "
                      f"|T|/(U_d W^2) - 1 = {abs(F[i, 3]) / (U_d * omega[i]**2) - 1:+.2e}; warning: "
                      f"{'; '.join(str(c.message)[:60] for c in caught)}")
            for w in load_wheels(_wheels_file(tmp), assumed_modes=flag)[:1]:
                a = w.lines.amplitudes(omega)[:, np.nonzero(w.lines.h == 1.0)[0], :]
                for i, rpm in enumerate((3000, 6000)):
                    print(f"2. HR16-75 psd --wheels {'--assumed-modes' if flag else 'default        '} {rpm:5d} rpm: "
                          f"|F|/(U_s W^2) - 1 = {np.abs(a[i, :, 0]).max() / (U_s * omega[i]**2) - 1:+.2e}, "
                          f"|T|/(U_d W^2) - 1 = {np.abs(a[i, :, 3]).max() / (U_d * omega[i]**2) - 1:+.2e} "
                          f"({w.meta['modes_assumed']})")

        full = wheel_doc(EFFECTS)
        native, python = build_native_fmu(full, tmp / "c.fmu"), build_fmu(full, tmp / "p.fmu")
        lines_doc = wheel_doc(LINE_EFFECTS)
        native_l = build_native_fmu(lines_doc, tmp / "cl.fmu")
        m = model_io.from_json(lines_doc)
        p = ext.params_from_model(m)
        for profile in (spin_up, reversal):
            tt, w = profile()
            inputs = {"wheel_speed": w, "wheel_acceleration": slope(tt, w)}
            a = hosts.run_fmpy(native, tt, inputs, mount_params(5))
            b = hosts.run_fmpy(python, tt, inputs, mount_params(5))
            ref = simulate_time(p, ext.lines_from_model(m, p), tt, w, seed=5)
            c = hosts.run_fmpy(native_l, tt, inputs, {"use_wheel_acceleration": True, "seed": 5})
            print(f"3. {profile.__name__:8s}: native vs pythonfmu (every effect) {np.max(worst(a, b)):.2e}; "
                  f"native vs simulate_time (line effects) {np.max(worst(c[:, :6], ref)):.2e} (relative to peak)")
        tt = np.arange(1501) * 1e-3
        w = np.full(tt.size, 2000 * RPM)
        for seed in (-1, 7):
            par = {"seed": seed, "imbalance": False, "harmonics": False, "speed_ripple": False}
            a = hosts.run_fmpy(native, tt, {"wheel_speed": w}, par)
            b = hosts.run_fmpy(python, tt, {"wheel_speed": w}, par)
            print(f"4. floor multisine seed {seed:2d}: native vs pythonfmu {np.max(worst(a, b)):.2e}")

        from fmpy.validation import validate_fmu
        print(f"5. fmpy validate (native): {len(validate_fmu(str(native)))} problems")
        with zipfile.ZipFile(native) as z:
            so = next(n for n in z.namelist() if n.endswith(".so"))
            z.extract(so, tmp / "x")
        ldd = subprocess.run(["ldd", str(tmp / "x" / so)], capture_output=True, text=True).stdout
        print("5. ldd native binary:", ", ".join(ln.split()[0] for ln in ldd.splitlines()),
              "| libpython:", "yes" if "python" in ldd.lower() else "no")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
