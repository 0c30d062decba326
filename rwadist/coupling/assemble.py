"""Assembly by acceleration feedback (Masterson 1999 §5.2, five steps) and the three practices
of its Table 5.1.

The five steps as done here:

(i)   components and arrangement: one plant, attachments (component + :class:`~rwadist.coupling.geometry.Mount`);
(ii)  free-free models with force inputs and acceleration outputs: the plant's accelerance;
(iii) one attachment point inverted per component: attached components are given in the
      inverted form, interface acceleration in -> load out (``f = Zc a + B w``), which is
      proper for a component whose interface is reached through springs (the thesis's H_ll of
      Eq. 5.15 is improper, its inverse of Eq. 5.19 is not);
(iv)  boundary conditions: a_component = Mt a_plant and plant load = Mtᵀ f_component, Mt the
      mounting's kinematic transform (rotation and lever arm; Eq. 5.12 with R = DCM);
(v)   assembly: the feedback loop is closed in state space.  With plant
      a = C_a x_p + D_a u and components f = C_c x_c + D_ca Mt a + D_cw w, the interface
      acceleration solves the algebraic loop (I − D_a Mtᵀ D_ca Mt) a = …; for a rigid plant
      (mass matrix M_p) the interface equation is (M_p − Mtᵀ D_ca Mt) a = …  Either matrix
      singular means the interface has no unique motion (rigid on rigid without mass):
      SingularInterfaceError.

Practices (Table 5.1), each a map from the components' **free** excitation w to the plant's
[performance outputs; interface accelerations]:

* 'coupled' (exact): w drives the assembled system;
* 'i'   : the hard-mounted loads B(s) w drive the plant alone;
* 'ii'  : the hard-mounted loads drive the plant plus each component's rigid mass (common practice);
* 'iii' : the hard-mounted loads are fed as the free excitation of the assembled system
  (the wheel's compliance counted twice, thesis Eq. 5.67).
"""
from __future__ import annotations

from dataclasses import dataclass

import control
import numpy as np

from . import geometry
from .components import Component, Plant, rigid_mass
from .errors import CouplingError, InterfaceMismatchError, SingularInterfaceError

PRACTICES = ("coupled", "i", "ii", "iii")
#: Condition number above which an interface matrix counts as singular.
SINGULAR_COND = 1e12


@dataclass(frozen=True)
class Attachment:
    """A component bolted to the plant: ``mount`` a :class:`~rwadist.coupling.geometry.Mount` (6-axis) or
    None (component interface = plant interface, same size)."""

    component: Component
    mount: geometry.Mount | None = None


@dataclass(frozen=True, eq=False)
class Assembly:
    """The coupled system.  ``sys`` inputs: [w of each attachment (in order), u_ext (loads applied
    directly at the plant interface, n_interface)]; outputs: [performance (n_perf), interface
    accelerations (n_interface), loads each attachment exerts on the plant (its own frame)]."""

    sys: control.StateSpace
    n_free: int
    n_interface: int
    n_perf: int
    n_loads: int

    def free_to(self, outputs: str = "perf") -> control.StateSpace:
        """Sub-system from the free excitation w to 'perf', 'accel', 'loads' or 'perf+accel'."""
        rows = {"perf": slice(0, self.n_perf),
                "accel": slice(self.n_perf, self.n_perf + self.n_interface),
                "perf+accel": slice(0, self.n_perf + self.n_interface),
                "loads": slice(self.n_perf + self.n_interface, None)}[outputs]
        return _sub(self.sys, rows, slice(0, self.n_free))

    def external_to(self, outputs: str = "perf") -> control.StateSpace:
        rows = {"perf": slice(0, self.n_perf),
                "accel": slice(self.n_perf, self.n_perf + self.n_interface),
                "perf+accel": slice(0, self.n_perf + self.n_interface),
                "loads": slice(self.n_perf + self.n_interface, None)}[outputs]
        return _sub(self.sys, rows, slice(self.n_free, None))


def _sub(sys, rows, cols):
    B, C, D = np.asarray(sys.B), np.asarray(sys.C), np.asarray(sys.D)
    return control.ss(sys.A, B[:, cols], C[rows, :], D[rows, cols])


def _stack_components(attachments, n_if):
    comps = [a.component for a in attachments]
    for a in attachments:
        if not isinstance(a.component, Component):
            raise CouplingError(f"attachment component must be a Component, got {type(a.component).__name__}")
    Mts = [geometry.selector(a.mount, a.component.n_interface, n_if) for a in attachments]
    Mt = np.vstack(Mts) if Mts else np.zeros((0, n_if))
    As, Bas, Bws, Cs, Das, Dws = [], [], [], [], [], []
    for c in comps:
        A, B, C, D = c.matrices()
        n = c.n_interface
        As.append(A)
        Bas.append(B[:, :n])
        Bws.append(B[:, n:])
        Cs.append(C)
        Das.append(D[:, :n])
        Dws.append(D[:, n:])
    nx = sum(A.shape[0] for A in As)
    nf = sum(c.n_interface for c in comps)
    nw = sum(c.n_free for c in comps)

    def bd(ms, r, c):
        out = np.zeros((r, c))
        i = j = 0
        for m in ms:
            out[i:i + m.shape[0], j:j + m.shape[1]] = m
            i += m.shape[0]
            j += m.shape[1]
        return out

    return (Mt, bd(As, nx, nx), bd(Bas, nx, nf), bd(Bws, nx, nw), bd(Cs, nf, nx), bd(Das, nf, nf),
            bd(Dws, nf, nw), nw)


def assemble(plant: Plant, attachments, name: str = "coupled") -> Assembly:
    """Couple ``attachments`` (list of :class:`Attachment` or (component, mount) pairs) to
    ``plant`` by acceleration feedback; returns an :class:`Assembly` (python-control StateSpace)."""
    atts = [a if isinstance(a, Attachment) else Attachment(*a) for a in attachments]
    n_if = plant.n_interface
    Mt, Ac, Bca, Bcw, Cc, Dca, Dcw, nw = _stack_components(atts, n_if)
    nxc = Ac.shape[0]
    nf = Mt.shape[0]
    n_perf = plant.n_perf
    Zmt = Mt.T @ Dca @ Mt                                   # Σ Mtᵀ D_ca Mt (minus the local masses)
    if plant.kind == "rigid":
        Mtot = plant.mass - Zmt
        _check_nonsingular(Mtot, "interface mass matrix (rigid plant + component masses)",
                           "rigid on rigid without mass: the interface has no mass in this direction")
        Minv = np.linalg.inv(Mtot)
        nxp = 0
        Ap = np.zeros((0, 0))
        Bp = np.zeros((0, n_if))
        Ka_x = Minv @ Mt.T @ Cc
        Ka_w = Minv @ Mt.T @ Dcw
        Ka_u = Minv
        Cy_x = plant.perf_matrix @ Ka_x
        Dy_w = plant.perf_matrix @ Ka_w
        Dy_u = plant.perf_matrix @ Ka_u
        Kf_x = Cc + Dca @ Mt @ Ka_x
        Kf_w = Dcw + Dca @ Mt @ Ka_w
        Kf_u = Dca @ Mt @ Ka_u
        Ku_x, Ku_w, Ku_u = Mt.T @ Kf_x, Mt.T @ Kf_w, Mt.T @ Kf_u + np.eye(n_if)
        A = Ac + Bca @ Mt @ Ka_x
        B = np.hstack([Bcw + Bca @ Mt @ Ka_w, Bca @ Mt @ Ka_u])
        C = np.vstack([Cy_x, Ka_x, Kf_x])
        D = np.vstack([np.hstack([Dy_w, Dy_u]), np.hstack([Ka_w, Ka_u]), np.hstack([Kf_w, Kf_u])])
    else:
        sys = plant.state_space()
        Ap, Bp, Cp, Dp = (np.asarray(x) for x in (sys.A, sys.B, sys.C, sys.D))
        nxp = Ap.shape[0]
        Ca, Cy, Da, Dy = Cp[:n_if], Cp[n_if:], Dp[:n_if], Dp[n_if:]
        L = np.eye(n_if) - Da @ Zmt
        _check_nonsingular(L, "interface loop matrix I − D_a Mtᵀ D_ca Mt",
                           "the algebraic loop between plant and components has no unique solution")
        Linv = np.linalg.inv(L)
        Ka_x = Linv @ np.hstack([Ca, Da @ Mt.T @ Cc])
        Ka_w = Linv @ Da @ Mt.T @ Dcw
        Ka_u = Linv @ Da
        Kf_x = np.hstack([np.zeros((nf, nxp)), Cc]) + Dca @ Mt @ Ka_x
        Kf_w = Dcw + Dca @ Mt @ Ka_w
        Kf_u = Dca @ Mt @ Ka_u
        Ku_x, Ku_w, Ku_u = Mt.T @ Kf_x, Mt.T @ Kf_w, Mt.T @ Kf_u + np.eye(n_if)
        A = np.zeros((nxp + nxc, nxp + nxc))
        A[:nxp, :nxp] = Ap
        A[nxp:, nxp:] = Ac
        A[:nxp] += Bp @ Ku_x
        A[nxp:] += Bca @ Mt @ Ka_x
        B = np.vstack([np.hstack([Bp @ Ku_w, Bp @ Ku_u]),
                       np.hstack([Bcw + Bca @ Mt @ Ka_w, Bca @ Mt @ Ka_u])])
        Cy_x = np.hstack([Cy, np.zeros((n_perf, nxc))]) + Dy @ Ku_x
        C = np.vstack([Cy_x, Ka_x, Kf_x])
        D = np.vstack([np.hstack([Dy @ Ku_w, Dy @ Ku_u]), np.hstack([Ka_w, Ka_u]), np.hstack([Kf_w, Kf_u])])
    inputs = [f"w{i}" for i in range(nw)] + [f"u{i}" for i in range(n_if)]
    outputs = list(plant.perf_names) + [f"a{i}" for i in range(n_if)] + [f"f{i}" for i in range(nf)]
    sys = control.ss(A, B, C, D, inputs=inputs, outputs=outputs, name=name)
    return Assembly(sys, nw, n_if, n_perf, nf)


def _check_nonsingular(M, what, meaning):
    if M.size == 0:
        return
    sv = np.linalg.svd(M, compute_uv=False)
    if sv.min() <= sv.max() / SINGULAR_COND or sv.max() == 0:
        _, _, Vt = np.linalg.svd(M)
        null = Vt[-1]
        raise SingularInterfaceError(f"singular interface: {what} has condition number "
                                     f"{(sv.max() / sv.min()) if sv.min() > 0 else np.inf:.3g} ({meaning}); "
                                     f"null direction {np.round(null, 6).tolist()}")


def _hard_mounted_block(atts, n_if):
    """w -> plant interface loads Σ Mtᵀ B_i w_i (B_i the hard-mounted transmission), and the
    block-diagonal hard-mounted system w -> stacked component loads."""
    hms = [a.component.hard_mounted() for a in atts]
    hm = hms[0]
    for h in hms[1:]:
        hm = control.append(hm, h)
    Mt = np.vstack([geometry.selector(a.mount, a.component.n_interface, n_if) for a in atts])
    return hm, Mt


def practice_systems(plant: Plant, attachments, practices=PRACTICES) -> dict:
    """StateSpace per practice (see module docstring): free excitation w of all attachments ->
    [performance outputs; plant interface accelerations]."""
    atts = [a if isinstance(a, Attachment) else Attachment(*a) for a in attachments]
    if not atts:
        raise CouplingError("practice_systems needs at least one attachment")
    out = {}
    hm, Mt = _hard_mounted_block(atts, plant.n_interface)
    to_plant = control.ss([], [], [], Mt.T) if hm.noutputs else None
    hm_plant = control.series(hm, to_plant)                   # w -> loads at the plant interface
    for p in practices:
        if p == "coupled":
            out[p] = assemble(plant, atts).free_to("perf+accel")
        elif p == "i":
            out[p] = control.series(hm_plant, assemble(plant, []).external_to("perf+accel"))
        elif p == "ii":
            rig = [Attachment(rigid_mass(a.component.rigid_mass, name=f"{a.component.name}_mass"), a.mount)
                   for a in atts]
            out[p] = control.series(hm_plant, assemble(plant, rig).external_to("perf+accel"))
        elif p == "iii":
            for a in atts:
                if a.component.n_free != a.component.n_interface:
                    raise InterfaceMismatchError(f"practice 'iii' feeds the measured loads as free excitation; "
                                                 f"{a.component.name} has {a.component.n_free} free inputs for "
                                                 f"{a.component.n_interface} interface loads")
            out[p] = control.series(hm, assemble(plant, atts).free_to("perf+accel"))
        else:
            raise CouplingError(f"unknown practice {p!r}; use {PRACTICES}")
    return out
