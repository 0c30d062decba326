"""jitter_vs_speed (the command's path: outputs only, so the coupled and 'iii' outputs of wheels sharing their line
frequencies come from the adjoint solve P·Lc⁻¹; the plant's modal sum over G's upper triangle; the interface matrix
written in place node by node) against an independent route: python-control's state-space assembly of each practice
(:func:`rwadist.coupling.practice_systems`) evaluated at every line's and sideband's own frequency with the wheel's
free loads (:func:`rwadist.coupling.free_lines`), the speed ripple written out as explicit sideband lines
(:func:`rwadist.extended_ripple.ripple_coefficients`, as tests/test_coupling_effects.py).  Wheels on three nodes of a
modal plant, two on one node; three wheels share their lines (adjoint), one has a ripple (direct solve)."""
from dataclasses import replace

import numpy as np
import pytest

from rwadist import coupling as cp
from rwadist import extended as ext
from rwadist.extended_ripple import Ripple, ripple_coefficients, ripple_order
from rwadist.presets import preset
from rwadist.units import RPM_TO_RAD_S


def _sideband_lines(lines, ripple, omega, k_max):
    """The lines under ``ripple`` at speed ``omega`` (rad/s, > 0) as explicit lines at f_offset + k·f_r."""
    dw = float(ripple.delta(omega))
    out = []
    for ln in lines:
        k, c = ripple_coefficients(ln.h * dw / (2 * np.pi * ripple.f_hz), dw / omega, 2.0, k_max)
        out += [replace(ln, C=ln.C * abs(ck), phase=ln.phase + np.angle(ck), f_offset=ln.f_offset + kk * ripple.f_hz)
                for kk, ck in zip(k, c)]
    return out


def _state_space_rms(plant, specs, omega, lines_of):
    """{practice: RMS (n_perf,)} at speed ``omega`` from the assembled state-space systems: each wheel's lines
    grouped by frequency (coherent), groups and wheels incoherent."""
    atts = [(cp.wheel(w.params, omega, w.housing_mass, w.housing_inertia), w.mount) for w in specs]
    free = []
    for k, w in enumerate(specs):
        f, W = cp.free_lines(w.params, lines_of(k), omega)
        fu, inv = np.unique(np.round(f[0], 9), return_inverse=True)
        Wg = np.zeros((fu.size, 6), dtype=complex)
        np.add.at(Wg, np.ravel(inv), W[0])
        free.append((fu, Wg))
    f_all, where = np.unique(np.concatenate([fu for fu, _ in free]), return_inverse=True)
    where = np.split(np.ravel(where), np.cumsum([fu.size for fu, _ in free])[:-1])
    rms = {}
    for prac, sys in cp.practice_systems(plant, atts).items():
        H = cp.frf(sys, f_all)[:plant.n_perf]                         # every wheel's lines at once
        ms = np.zeros(plant.n_perf)
        for k, (fu, Wg) in enumerate(free):
            y = np.einsum("ijl,lj->li", H[:, 6 * k:6 * k + 6, where[k]], Wg)
            ms += np.sum(np.abs(y) ** 2, axis=0) / 2
        rms[prac] = np.sqrt(ms)
    return rms


def test_jitter_rms_is_the_state_space_assembly_at_every_line_and_sideband():
    plant = cp.random_modal_plant(n_modes=16, n_nodes=3, n_perf=2, f_range=(2.0, 400.0), zeta=0.02, seed=4)
    desc = preset("ithaco-e")
    p = replace(desc.extended, height=0.04)
    lines = tuple(ln for ln in ext.lines_from_model(desc.to_model(), p) if ln.h in (1.0, 2.0, 2.96, 4.42))
    axes, nodes = [(1, 0, 0), (0, 1, 0), (0, 0, 1), (1, 1, 1)], [0, 1, 2, 2]
    specs = [cp.WheelSpec(p, lines, cp.Mount(nodes[i], cp.spin_axis_dcm(axes[i]), (0.1 * i, -0.05, 0.1)),
                          housing_mass=2.0, housing_inertia=(0.02, 0.02, 0.03), name=f"E{i}") for i in range(4)]
    rip = Ripple(6.0, 1.0, 200.0, 0.5)
    specs[3] = replace(specs[3], ripple=rip)
    speeds = np.array([700.0, 2300.0]) * RPM_TO_RAD_S
    jr = cp.jitter_vs_speed(plant, specs, speeds)
    k_max = ripple_order(lines, speeds, rip)
    assert k_max >= 2
    for s, om in enumerate(speeds):
        ref = _state_space_rms(plant, specs, om,
                               lambda k: _sideband_lines(lines, rip, om, k_max) if k == 3 else lines)
        for prac in cp.PRACTICES:
            assert jr.rms[prac][s] == pytest.approx(ref[prac], rel=1e-9, abs=0), (prac, om)
    # the adjoint's outputs are the direct solve's (line_responses, which also computes the coupled loads)
    lr = cp.line_responses(plant, specs, speeds)
    for prac in cp.PRACTICES:
        assert jr.rms[prac] == pytest.approx(lr.rms(prac), rel=1e-12, abs=0)
