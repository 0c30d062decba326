"""The user's command gives the same diagnosis whichever SIMD kernels numpy picks for the machine.

numpy chooses its loops at run time from the CPU's extensions (AVX2, AVX-512, ...); their sums and single-precision
functions round differently, by an ulp here and there.  A diagnosis that turns on such a difference is not a property
of the data: on an AVX-512 machine a least squares left a planar force line's co/counter split, which its power
does not see, at 0.470 instead of 0.500, and a ``counter_rotation`` of the x/y phase's 0.4999 was added to family
wheel 1 with a channel copy (Fy += 0.2·Fx, tests/test_channel_copy_radial_pair.py), which AVX2 machines never showed.
Here the same data are diagnosed twice by ``rwadist diagnose DATA -o R``, once with every dispatched extension numpy
found on this machine turned off (``NPY_DISABLE_CPU_FEATURES``: its baseline loops): the same effects, the same
unexplained signatures, the modes within 1e-6.
"""
import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

sys.path.insert(0, str(Path(__file__).resolve().parent))

import family_wheel as fw  # noqa: E402

TARGETS_ON = ("import numpy as np; u = np._core._multiarray_umath; "
              "print(' '.join(f for f in u.__cpu_dispatch__ if u.__cpu_features__.get(f)))")


def _env(disable: str | None) -> dict:
    """This process's environment with numpy's ``NPY_DISABLE_CPU_FEATURES`` set to ``disable`` (None: unset)."""
    env = {k: v for k, v in os.environ.items() if k != "NPY_DISABLE_CPU_FEATURES"}
    return env if disable is None else env | {"NPY_DISABLE_CPU_FEATURES": disable}


def _targets_on(env: dict) -> str:
    """The SIMD targets numpy dispatches to in a fresh process with ``env`` (empty: its baseline loops only)."""
    return subprocess.run([sys.executable, "-c", TARGETS_ON], env=env, capture_output=True, text=True,
                          check=True).stdout.strip()


def _diagnose(data: Path, out: Path, env: dict) -> dict:
    subprocess.run([sys.executable, "-m", "rwadist", "diagnose", str(data), "-o", str(out)], env=env,
                   capture_output=True, text=True, check=True)
    return json.loads((out / "summary.json").read_text())


@pytest.mark.slow
def test_a_channel_copy_is_diagnosed_alike_with_numpys_simd_kernels_on_and_off(tmp_path):
    on = _targets_on(_env(None))
    if not on:
        pytest.skip("numpy dispatches no SIMD extension on this machine: there is nothing to turn off")
    assert _targets_on(_env(on)) == ""                  # the second child really runs numpy's baseline loops
    wheel = fw.family()[1]
    data = fw.steady(wheel, noise=0.01, seed=1)
    data.signals[:, fw.CHANNELS.index("Fy")] += 0.2 * data.signals[:, fw.CHANNELS.index("Fx")].copy()
    path = fw.write_steady(data, tmp_path / "data", wheel.name)
    native = _diagnose(path, tmp_path / "native", _env(None))
    baseline = _diagnose(path, tmp_path / "baseline", _env(on))
    assert [e["kind"] for e in native["effects"]] == [e["kind"] for e in baseline["effects"]] == ["suspension_modes"]
    assert [u["signature"] for u in native["unexplained"]] == [u["signature"] for u in baseline["unexplained"]]
    modes = [next(e for e in s["effects"] if e["kind"] == "suspension_modes") for s in (native, baseline)]
    for name in ("radial_translation", "rocking", "axial"):
        assert modes[0][f"{name}_Hz"] == pytest.approx(modes[1][f"{name}_Hz"], rel=1e-6)
        assert modes[0][f"{name}_Hz"] == pytest.approx(wheel.modes_hz()[name], rel=0.02)
    assert native["error_after"] == pytest.approx(baseline["error_after"], rel=1e-3)
