"""Write the catalogue's model files from their sources; every number and assumption is here.

    python -m rwadist.catalogue.build_catalogue      # rewrites rwadist/catalogue/*.json

Sources:

* Ithaco TW-50E300 (E wheel) and TW-16B32 (B wheel): Masterson 1999, Tables 2.2, 2.3,
  3.3, 3.4, 4.2 -- through :mod:`rwadist.presets`, which converts and documents them.
* Honeywell HR12/HR14/HR16: mass, static and dynamic imbalance and maximum speed as
  collected in the Basilisk simulator's wheel factory (AVSLab/basilisk,
  src/utilities/simIncludeRW.py, functions Honeywell_HR12/14/16; checked at commit
  babdff7a, 2026-07-24).  Basilisk's U_s is in kg·m and U_d in kg·m², as here.  Its
  spin inertia is Js = maxMomentum / Omega_max (the same function), which gives the
  thin-disc radius R = sqrt(2 Js / M) used here (Basilisk sets the rotor mass equal to
  the wheel mass of the spec sheet; so do we -- an assumption).
* S2E sample-satellite wheel: ut-issl/s2e-core,
  example/settings/sample_satellite/components/rw_disturbance_csv_files/
  radial_{force,torque}_harmonics_coefficients.csv (12 lines each, columns h, C),
  used by src/components/real/aocs/reaction_wheel_jitter.cpp as
  C·ω²·sin(phase) with ω in rad/s, so C is already SI per (rad/s)² (kg·m, kg·m²).
  reaction_wheel.ini of the same sample: rotor inertia 1e-4 kg·m², 6000 rpm.  The
  issue that asked for this entry calls it a Sinclair RW-0.003; the S2E files do not
  name the wheel, so the entry is named after its source.

Datasheet-only wheels (Honeywell, S2E) have no measured modes.  Their analytical
sections are assumptions, written into each file: the suspension is scaled so the
modes sit at the E wheel's fitted frequencies (radial translation 227.7 Hz, rocking
54.9 Hz at rest, axial 70 Hz; thesis Table 4.2/2.3) with its damping ratios, i.e.
a wheel of the same construction class -- replace them with a fit
(`rwadist fit --extended`) as soon as test data exist.  Their ``analytical`` sections carry
``modes_assumed: true``: every command runs such a wheel hard-mounted (its datasheet lines) unless
``--assumed-modes`` opts in to the assumed modes.
"""
from __future__ import annotations

import json
import math
from pathlib import Path

from .. import extended as ext
from ..model import SCHEMA, SCHEMA_VERSION, Harmonic, WheelModel, to_json
from ..units import G_CM2_TO_KG_M2, G_CM_TO_KG_M, RPM_TO_RAD_S

HERE = Path(__file__).parent
DATE = "2026-11-22"

#: Basilisk simIncludeRW.py Honeywell table: name -> (max momentum N·m·s, mass kg, U_s kg·m, U_d kg·m²)
HONEYWELL = {
    "honeywell-hr16-100": (100.0, 12.0, 4.8e-6, 15.4e-7),
    "honeywell-hr16-75": (75.0, 10.4, 3.8e-6, 11.5e-7),
    "honeywell-hr16-50": (50.0, 9.0, 2.8e-6, 7.7e-7),
    "honeywell-hr14-75": (75.0, 10.6, 4.8e-6, 13.7e-7),
    "honeywell-hr14-50": (50.0, 8.5, 3.5e-6, 9.1e-7),
    "honeywell-hr14-25": (25.0, 7.5, 2.2e-6, 4.6e-7),
    "honeywell-hr12-50": (50.0, 9.5, 4.4e-6, 9.1e-7),
    "honeywell-hr12-25": (25.0, 7.0, 2.4e-6, 4.6e-7),
    "honeywell-hr12-12": (12.0, 6.0, 1.5e-6, 2.2e-7),
}
HONEYWELL_MAX_RPM = 6000.0
BASILISK = ("Basilisk simulator wheel factory, AVSLab/basilisk src/utilities/simIncludeRW.py "
            "(Honeywell_HR12/HR14/HR16), commit babdff7a (2026-07-24); Honeywell HR12/HR14/HR16 data sheets")

#: S2E sample wheel: (h, C) radial force kg·m and radial torque kg·m², 12 lines each
S2E_FORCE = [(1.01, 2.18e-07), (14.5, 8.10e-09), (10.67, 4.46e-09), (8.73, 4.32e-09), (6.78, 3.50e-09),
             (1.99, 2.96e-09), (9.63, 2.92e-09), (11.65, 2.70e-09), (14.88, 1.90e-09), (11.95, 1.77e-09),
             (7.76, 1.51e-09), (6.33, 1.25e-09)]
S2E_TORQUE = [(1.01, 6.30e-09), (14.49, 3.70e-10), (13.82, 1.47e-10), (8.88, 1.23e-10), (6.78, 1.05e-10),
              (9.62, 9.70e-11), (13.44, 9.50e-11), (11.65, 8.70e-11), (1.98, 7.10e-11), (13.07, 5.30e-11),
              (5.8, 4.50e-11), (14.87, 3.70e-11)]
S2E_SOURCE = ("ut-issl/s2e-core example/settings/sample_satellite/components/rw_disturbance_csv_files/"
              "radial_force_harmonics_coefficients.csv and radial_torque_harmonics_coefficients.csv "
              "(used as C·ω², ω rad/s, in src/components/real/aocs/reaction_wheel_jitter.cpp), commit 62e395d0 "
              "(2025-01-24); rotor inertia 1e-4 kg·m² and 6000 rpm from reaction_wheel.ini of the same sample")

#: E-wheel modal frequencies (Hz) and damping ratios, thesis Table 4.2 / Table 2.3
E_MODES = {"radial_translation": 227.7, "rocking": 54.9, "axial_translation": 70.0}
E_ZETA = {"radial_translation": 0.167, "rocking": 0.040, "axial_translation": 0.05}


def assumed_params(mass: float, radius: float, U_s: float, U_d: float) -> ext.ExtendedParams:
    """A datasheet-only wheel: thin disc, modes at the E wheel's frequencies and damping."""
    I_zz, I_rr = ext.thin_disc(mass, radius)
    w = {k: 2 * math.pi * f for k, f in E_MODES.items()}
    k_r, k_rock, k_z = mass * w["radial_translation"] ** 2, I_rr * w["rocking"] ** 2, mass * w["axial_translation"] ** 2
    return ext.ExtendedParams(
        mass=mass, I_zz=I_zz, I_rr=I_rr,
        k_r=k_r, c_r=2 * E_ZETA["radial_translation"] * math.sqrt(k_r * mass),
        k_rock=k_rock, c_rock=2 * E_ZETA["rocking"] * math.sqrt(k_rock * I_rr),
        k_z=k_z, c_z=2 * E_ZETA["axial_translation"] * math.sqrt(k_z * mass),
        height=0.0, U_s=U_s, U_d=U_d)


ASSUMED_MODES = ("assumed: suspension scaled so the modes sit at the Ithaco E wheel's fitted frequencies "
                 "(radial translation 227.7 Hz, rocking 54.9 Hz at rest, axial 70 Hz; thesis Tables 4.2, 2.3) "
                 "with its damping ratios (0.167, 0.040, 0.05); thin-disc inertias; height 0")


def honeywell(name: str) -> WheelModel:
    h_max, mass, U_s, U_d = HONEYWELL[name]
    js = h_max / (HONEYWELL_MAX_RPM * RPM_TO_RAD_S)
    radius = math.sqrt(2 * js / mass)
    p = assumed_params(mass, radius, U_s, U_d)
    return WheelModel(
        name=name,
        wheel={"mass_kg": mass, "radius_m": radius, "max_speed_rpm": HONEYWELL_MAX_RPM,
               "max_momentum_Nms": h_max, "spin_inertia_kg_m2": js},
        empirical={"radial_force": [Harmonic(h=1.0, C=U_s, sense="co")],
                   "radial_torque": [Harmonic(h=1.0, C=U_d, sense="co")],
                   "axial_force": [], "axial_torque": []},
        analytical=dict(ext.params_to_dict(p), modes_assumed=True),
        provenance={
            "source": BASILISK,
            "measured": {
                "mass_kg": "datasheet",
                "U_s, U_d": "datasheet imbalance (values to be read as limits: a balanced unit is below them)",
                "max_speed_rpm": "datasheet",
                "radius_m": "derived: thin disc with Js = max momentum / max speed (Basilisk's rule)",
                "harmonics": "fundamental only (imbalance); higher harmonics not known",
                "analytical": ASSUMED_MODES,
            },
            "datasheet_limits": {"U_s_kg_m": U_s, "U_d_kg_m2": U_d},
            "date": DATE,
        })


def s2e_sample() -> WheelModel:
    inertia, max_rpm = 1.0e-4, 6000.0
    # size not given: assume the thin-disc radius of a 0.13 kg rotor with that inertia (a CubeSat wheel
    # of the 3 mN·m·s class); only the modal assumption uses it
    mass = 0.13
    radius = math.sqrt(2 * inertia / mass)
    p = assumed_params(mass, radius, S2E_FORCE[0][1], S2E_TORQUE[0][1])
    return WheelModel(
        name="s2e-sample-rw",
        wheel={"mass_kg": mass, "radius_m": radius, "max_speed_rpm": max_rpm, "spin_inertia_kg_m2": inertia},
        empirical={"radial_force": [Harmonic(h=h, C=c) for h, c in S2E_FORCE],
                   "radial_torque": [Harmonic(h=h, C=c) for h, c in S2E_TORQUE],
                   "axial_force": [], "axial_torque": []},
        analytical=dict(ext.params_to_dict(p), modes_assumed=True),
        provenance={
            "source": S2E_SOURCE,
            "measured": {
                "harmonics": "fitted to measurement by the S2E authors (12 radial force and 12 radial torque lines; "
                             "the files do not name the wheel; the issue that requested the entry attributes them to "
                             "a Sinclair RW-0.003)",
                "spin_inertia_kg_m2, max_speed_rpm": "simulator sample configuration",
                "mass_kg": "assumed (0.13 kg), only for the thin-disc radius of the assumed modes",
                "analytical": ASSUMED_MODES,
                "U_s, U_d": "the h = 1.01 lines (treated as the imbalances)",
                "sense": "not known: S2E applies (x, y) = C·ω²·(sin, cos) of the phase, which turns clockwise "
                         "about +z for positive speed; whether that reflects the wheel or the simulator's "
                         "convention is not stated, so the file leaves the sense unset (the extended model "
                         "then assumes co-rotating)",
            },
            "date": DATE,
        })


def ithaco(name: str) -> WheelModel:
    from ..presets import preset

    wheel = preset(name)
    model = wheel.to_model()
    is_e = name == "ithaco-e"
    limits = ({"U_s_kg_m": 1.8 * G_CM_TO_KG_M, "U_d_kg_m2": 60 * G_CM2_TO_KG_M2} if is_e
              else {"U_s_kg_m": 1.5 * G_CM_TO_KG_M, "U_d_kg_m2": 40 * G_CM2_TO_KG_M2})
    model.provenance = {
        "source": "Masterson, R. A. (1999), Development and validation of empirical and analytical reaction wheel "
                  "disturbance models, MIT; " + ("Tables 2.2, 2.3, 3.4, 4.2" if is_e else "Tables 2.2, 2.3, 3.3"),
        "measured": {
            "harmonics": "fitted to hard-mounted test data (Table 3.4)" if is_e else "fitted to test data (Table 3.3)",
            "analytical": ("stiffness, damping, imbalances fitted to data (Table 4.2, U_d as printed); axial mode "
                           "frequency from the maker (Table 2.3), axial damping assumed 0.05; height 0 (no lever arm, "
                           "thesis Eq. 4.96)") if is_e else
                          ("modes from the maker (Table 2.3); damping ratios assumed equal to the E wheel's; "
                           "U_s, U_d from the h = 0.99 lines of Table 3.3"),
            "senses": "inferred from the whirl each harmonic excites (Tables 3.6/3.7 for E, §3.2.1 for B)",
            "mass_kg, radius_m, max_speed_rpm": "datasheet (Table 2.2; Table 4.2)",
        },
        "datasheet_limits": limits,
        "notes": wheel.notes,
        "date": DATE,
    }
    model.wheel = dict(model.wheel, max_speed_rpm=wheel.max_speed_rpm)
    return model


def all_models() -> dict:
    models = {n: ithaco(n) for n in ("ithaco-e", "ithaco-b")}
    models.update({n: honeywell(n) for n in HONEYWELL})
    models["s2e-sample-rw"] = s2e_sample()
    return models


def main() -> None:
    for name, model in all_models().items():
        doc = to_json(model)
        assert doc["schema"] == SCHEMA and doc["schema_version"] == SCHEMA_VERSION
        (HERE / f"{name}.json").write_text(json.dumps(doc, indent=2) + "\n")
        print(f"wrote {name}.json")


if __name__ == "__main__":
    main()
