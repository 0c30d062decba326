"""Fuzz sample of mutated model files through model show / psd / campbell / fmu build (issue 17; the full
run: benchmarks/fuzz_all.py --surface models).  Never a traceback, never a known-invalid value used."""
import fuzz_cases as fz


def test_fuzz_model_files(tmp_path):
    cases = [c for c in fz.model_cases(40, 2, tmp_path) if c[0][0] != "fmu"]   # fmu builds: the benchmark
    results = [(fz.run_case(argv, names, invalid), what) for argv, names, invalid, what in cases]
    bad = [(r, what) for r, what in results if r[0] not in ("ok", "clear")]
    assert not bad, bad[:5]
    assert fz.tally(r for r, _ in results)["clear"] >= 5


def test_fuzz_model_files_through_every_consumer(tmp_path):
    """A model valid everywhere or nowhere (issue 36): mutated files (values beyond any wheel's, NaN, strings, misspelt
    keys, a missing section, unknown effect kinds, absurd effect parameters) through model show, psd, campbell, the
    API and the coupling kit: never a traceback, never accepted by one consumer and refused by another."""
    import fuzz_surfaces as fs

    results = []      # diagnose and fmu build (seconds each) run in the full fuzz only: no dataset needed here
    for path, invalid, what, consumers, data in fs.model_consumer_cases(10, 11, tmp_path, tmp_path / "unused"):
        out = fs.run_model_case(path, invalid, [c for c in consumers if c not in fs.SLOW], data, tmp_path)
        results += [(c, r, what) for c, r in out.items()]
    bad = [(c, r, what) for c, r, what in results if r[0] not in ("ok", "clear")]
    assert not bad, bad[:5]
    assert sum(r[0] == "clear" for _, r, _ in results) >= 15


def _issue_model(tmp_path, name, change):
    import json

    doc = fz.model_document()
    change(doc)
    path = tmp_path / f"{name}.json"
    path.write_text(json.dumps(doc, allow_nan=True))
    return path


def test_the_issues_model_files_are_refused_by_every_consumer_naming_the_field(tmp_path):
    """The audit's cases: C and h of 1e308 passed model show, campbell and fmu build --native; a speed ripple of
    1e308 rad/s crashed psd; max_speed_rpm "fast" and a NaN C_stderr passed everywhere; 'empirial' gave an
    imbalance-only PSD and an FMU without harmonics; 20 000 harmonics hung campbell."""
    import math
    import time

    cases = {
        "C": (lambda d: d["empirical"]["radial_force"][0].update(C=1e308), "empirical.radial_force[0].C"),
        "h": (lambda d: d["empirical"]["radial_force"][0].update(h=1e308), "empirical.radial_force[0].h"),
        "ripple": (lambda d: d["effects"].append({"kind": "speed_ripple", "f_ripple_Hz": 4.0,
                                                  "delta_omega_rad_s": 1e308, "omega_ref_rad_s": 200.0}),
                   "delta_omega_rad_s"),
        "fast": (lambda d: d["wheel"].update(max_speed_rpm="fast"), "wheel.max_speed_rpm"),
        "stderr": (lambda d: d["empirical"]["radial_force"][0].update(C_stderr=math.nan), "C_stderr"),
        "empirial": (lambda d: d.update(empirial=d.pop("empirical")), "empirial"),
        "many": (lambda d: d["empirical"].update(radial_force=[{"h": 1 + 0.001 * i, "C": 1e-7}
                                                               for i in range(20000)]), "empirical.radial_force"),
        "exponent": (lambda d: d["effects"].append({"kind": "amplitude_law", "direction": "radial_force", "h": 2.0,
                                                    "exponent": 1000.0, "amplitude_ref": 0.01,
                                                    "omega_ref_rad_s": 200.0}), "exponent"),
    }
    for name, (change, field) in cases.items():
        path = _issue_model(tmp_path, name, change)
        for argv in (["model", "show", path],
                     ["campbell", path, "-o", tmp_path / "c.csv"],
                     ["psd", path, "--speed-rpm", "600:2400", "--n-freq", "201", "-o", tmp_path / "p.csv"]):
            t0 = time.perf_counter()
            outcome, msg = fz.run_case(argv, [path.name], True)
            assert outcome == "clear" and field in msg, (name, argv[0], outcome, msg)
            assert time.perf_counter() - t0 < 30
    path = _issue_model(tmp_path, "C_fmu", cases["C"][0])
    outcome, msg = fz.run_case(["fmu", "build", path, "--native", "-o", tmp_path / "w.fmu"], [path.name], True)
    assert outcome == "clear" and "C" in msg and not (tmp_path / "w.fmu").exists()
