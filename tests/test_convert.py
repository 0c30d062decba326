"""`rwadist convert` round-trips every pair of formats (issue 15), steady tests and sweeps: same speeds, rates and
samples (bit-identical unless ASCII UFF, which stores 12 significant digits, is in the chain)."""
from __future__ import annotations

import itertools

import numpy as np
import pytest

from rwadist.cli import main
from rwadist.data import Run, SteadyTest, Sweep, read_data, write_steady, write_sweep

FS = 2048.0
N = 1024
FORMATS = ["csv", "h5", "uff", "uff-binary", "tdms", "mat", "mat73"]
EXT = {"csv": ".csv", "h5": ".h5", "uff": ".uff", "uff-binary": ".uff", "tdms": ".tdms", "mat": ".mat",
       "mat73": ".mat"}
UFF_ASCII_RTOL = 5e-12


def signals(seed, channels=("Fx", "Fy", "Fz", "Tx", "Ty", "Tz")):
    rng = np.random.default_rng(seed)
    return {ch: (1.0 if ch[0] == "F" else 0.01) * rng.standard_normal(N) for ch in channels}


@pytest.fixture(scope="module")
def sources(tmp_path_factory):
    root = tmp_path_factory.mktemp("src")
    steady = SteadyTest([Run(-104.72, FS, signals(1), name="a.csv"), Run(0.0, FS, signals(2), t0=3.5, name="b.csv"),
                         Run(251.3, FS, signals(3, ("Fx", "Fz", "Tz")), name="c.csv")], {"notes": "convert"})
    sweep = Sweep(time=0.25 + np.arange(N) / FS, signals=signals(4), sample_rate=FS,
                  tach=np.linspace(10.0, 250.0, N))
    return {"steady": (steady, write_steady(steady, root / "steady")),
            "sweep": (sweep, write_sweep(sweep, root / "sweep.csv"))}


def target(tmp_path, kind, fmt, tag):
    if fmt == "h5":
        return tmp_path / f"{tag}.h5", []
    if kind == "steady":
        return tmp_path / f"{tag}_{fmt}", ["--format", fmt]
    return tmp_path / f"{tag}_{fmt}{EXT[fmt]}", ["--format", fmt]


def convert(src, dst, extra):
    assert main(["convert", str(src), "-o", str(dst), *extra]) == 0


def records(obj):
    if isinstance(obj, SteadyTest):
        return [(r.speed, r.sample_rate, r.t0, r.signals) for r in obj.runs]
    return [(None, obj.sample_rate, float(obj.time[0]), dict(obj.signals, tach=obj.tach))]


@pytest.mark.parametrize("kind", ["steady", "sweep"])
@pytest.mark.parametrize("a, b", list(itertools.permutations(FORMATS, 2)))
def test_convert_round_trips_every_pair(tmp_path, sources, kind, a, b):
    original, csv_path = sources[kind]
    path_a, extra_a = target(tmp_path, kind, a, "a")
    path_b, extra_b = target(tmp_path, kind, b, "b")
    path_c, extra_c = target(tmp_path, kind, a, "c")
    convert(csv_path, path_a, extra_a)
    convert(path_a, path_b, extra_b)
    convert(path_b, path_c, extra_c)  # ... and back
    rtol = UFF_ASCII_RTOL if "uff" in (a, b) else 0.0
    for path in (path_b, path_c):
        back = read_data(path)
        for (s0, fs0, t00, sig0), (s1, fs1, t01, sig1) in zip(records(original), records(back)):
            assert fs1 == fs0
            assert t01 == pytest.approx(t00, rel=1e-12, abs=0 if rtol == 0 else 1e-12)
            if s0 is not None:
                assert s1 == pytest.approx(s0, rel=1e-15, abs=0)
            assert sorted(sig1) == sorted(sig0)
            for ch in sig0:
                if rtol == 0 and ch != "tach":
                    assert np.array_equal(sig1[ch].view(np.uint64), sig0[ch].view(np.uint64)), (path, ch)
                else:  # the tach goes through rpm and back (one product each way)
                    np.testing.assert_allclose(sig1[ch], sig0[ch], rtol=max(rtol, 4e-16), atol=0)
