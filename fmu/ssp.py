"""An SSP 1.0 file of a reaction-wheel assembly: one native wheel FMU per wheel of a ``wheels.json``.

:func:`build_assembly_ssp` reads the wheels file with :func:`rwadist.mounting.load_wheels` (the reader of
``rwadist psd --wheels``), builds one native FMI 2.0 FMU per distinct wheel model (``resources/<model>.fmu``;
wheels of one model share it) and writes ``SystemStructure.ssd`` with one component per wheel:

* the wheel's mounting as SSP parameters (``dcm_11 .. dcm_33``, wheel -> spacecraft, and ``r_x, r_y, r_z``, the
  interface point in the spacecraft frame, m), bound inline (``ssd:ParameterBindings``);
* its speed law as SSP parameters too: ``wheel_speed`` starts at the law's mean speed (rad/s; a tied wheel at
  ``ratio`` times its root's), and ``seed`` gives each wheel its own line phases (wheel k: seed k + 1; a
  phase-locked tie shares its root's seed: identical rotors locked together); the law itself (distribution, range,
  tie) is in the component's ``org.rwadist.wheel`` annotation;
* its connectors: the inputs ``wheel_speed`` and ``wheel_acceleration``, the bound parameters, and the outputs
  ``Fx .. Tz`` (wheel frame, at the interface) and ``Fx_sc .. Tz_sc``.

The assembly's loads: every component's ``Fx_sc .. Tz_sc`` are already its loads moved to the spacecraft reference
point in the spacecraft frame (F_sc = R F, T_sc = R T + r x F_sc), so the assembly's force and torque at the
reference point are their sum, which the host forms (design choice: no summing FMU -- a feed-through FMU between
the wheels and the structure would delay the sum by one communication step in a Jacobi master such as libcosim).
The system has no connections of its own (libcosim's SSP reader takes element-to-element connections only): the
host drives each component's ``wheel_speed`` (a tied wheel at ``ratio`` times its root's, as the annotation says).
"""
from __future__ import annotations

import os
import re
import tempfile
import zipfile
from pathlib import Path
from xml.sax.saxutils import quoteattr

import numpy as np

from .native_build import VARIABLES, build_native_fmu

SSD_NS = ('xmlns:ssd="http://ssp-standard.org/SSP1/SystemStructureDescription" '
          'xmlns:ssc="http://ssp-standard.org/SSP1/SystemStructureCommon" '
          'xmlns:ssv="http://ssp-standard.org/SSP1/SystemStructureParameterValues"')
OUTPUTS = [v[0] for v in VARIABLES if v[2] == "output"]
UNITS = {v[0]: v[5] for v in VARIABLES}
SSC_TYPES = {"Real": "ssc:Real", "Integer": "ssc:Integer", "Boolean": "ssc:Boolean", "String": "ssc:String"}
SSV_TYPES = {"Real": "ssv:Real", "Integer": "ssv:Integer"}
TYPES = {v[0]: v[1] for v in VARIABLES}


class NoSpeedLaw:
    """The speed law of a wheel its wheels.json entry gives none for (``wheel_speed`` starts at 0)."""

    def __repr__(self) -> str:
        return "no speed law"


NO_LAW = NoSpeedLaw()


def _support(law) -> tuple:
    """(lowest, highest) speed of a law, rad/s (a property on some laws, a method on others)."""
    sup = law.support
    lo, hi = sup() if callable(sup) else sup
    return float(lo), float(hi)


def law_mean(law) -> float:
    """Mean speed (rad/s) of a speed law of :mod:`rwadist.speed_laws` (its pdf over its support); 0 without one."""
    if law is NO_LAW or law is None:
        return 0.0
    lo, hi = _support(law)
    w = np.linspace(lo, hi, 20001)
    p = np.asarray(law.pdf(w), float)
    area = np.trapezoid(p, w)
    return float(np.trapezoid(p * w, w) / area) if area > 0 else 0.5 * (lo + hi)


def _root(wheels, i):
    """(root index, speed ratio, phase-locked all the way) of wheel i."""
    ratio, lock = 1.0, True
    while wheels[i].tie is not None:
        ratio *= wheels[i].tie.ratio
        lock = lock and wheels[i].tie.phase_lock
        i = wheels[i].tie.to
    return i, ratio, lock


def wheel_parameters(wheels) -> list:
    """Per wheel: {parameter: value} of the SSP (mounting, seed, wheel_speed start), in the order of ``wheels``."""
    out = []
    for i, ws in enumerate(wheels):
        root, ratio, lock = _root(wheels, i)
        R = ws.mounting.R
        p = {f"dcm_{a + 1}{b + 1}": float(R[a, b]) for a in range(3) for b in range(3)}
        p.update({f"r_{ax}": float(x) for ax, x in zip("xyz", ws.mounting.position_m)})
        p["seed"] = (root if ws.tie is not None and lock else i) + 1
        p["wheel_speed"] = ratio * law_mean(wheels[root].law)
        out.append(p)
    return out


def _law_text(ws, wheels) -> dict:
    """The org.rwadist.wheel annotation's attributes of one wheel."""
    if ws.tie is not None:
        t = ws.tie
        return {"tie_to": wheels[t.to].name, "tie_ratio": f"{t.ratio:g}", "phase_lock": str(bool(t.phase_lock)).lower(),
                "phase_offset_deg": f"{np.degrees(t.phase_offset):g}"}
    if ws.law is NO_LAW:
        return {"speed_law": "none given (wheel_speed starts at 0)"}
    lo, hi = _support(ws.law)
    return {"speed_law": repr(ws.law), "speed_min_rad_s": repr(float(lo)), "speed_max_rad_s": repr(float(hi))}


def _component(name: str, source: str, params: dict, annotation: dict) -> list:
    x = [f'      <ssd:Component name={quoteattr(name)} source={quoteattr(source)} '
         'type="application/x-fmu-sharedlibrary">', '        <ssd:Connectors>']
    for var in ("wheel_speed", "wheel_acceleration"):
        x.append(f'          <ssd:Connector name="{var}" kind="input"><ssc:Real unit="{UNITS[var]}"/></ssd:Connector>')
    for var in params:
        if var in ("wheel_speed",):
            continue
        unit = f' unit="{UNITS[var]}"' if TYPES[var] == "Real" and UNITS[var] else ""
        x.append(f'          <ssd:Connector name="{var}" kind="parameter"><{SSC_TYPES[TYPES[var]]}{unit}/>'
                 '</ssd:Connector>')
    for var in OUTPUTS:
        x.append(f'          <ssd:Connector name="{var}" kind="output"><ssc:Real unit="{UNITS[var]}"/></ssd:Connector>')
    x += ['        </ssd:Connectors>', '        <ssd:ParameterBindings>', '          <ssd:ParameterBinding>',
          '            <ssd:ParameterValues>',
          f'              <ssv:ParameterSet version="1.0" name={quoteattr(name + " mounting and speed")}>',
          '                <ssv:Parameters>']
    for var, value in params.items():
        x.append(f'                  <ssv:Parameter name="{var}"><{SSV_TYPES[TYPES[var]]} value="{value!r}"/>'
                 '</ssv:Parameter>')
    x += ['                </ssv:Parameters>', '              </ssv:ParameterSet>', '            </ssd:ParameterValues>',
          '          </ssd:ParameterBinding>', '        </ssd:ParameterBindings>', '        <ssd:Annotations>',
          '          <ssc:Annotation type="org.rwadist.wheel">',
          '            <rw:Wheel xmlns:rw="urn:rwadist:ssp" '
          + " ".join(f"{k}={quoteattr(v)}" for k, v in annotation.items()) + '/>',
          '          </ssc:Annotation>', '        </ssd:Annotations>', '      </ssd:Component>']
    return x


def system_description(name: str, wheels, sources: list, params: list) -> str:
    """SystemStructure.ssd of the assembly (see the module docstring)."""
    x = ['<?xml version="1.0" encoding="UTF-8"?>',
         f'<ssd:SystemStructureDescription {SSD_NS} version="1.0" name={quoteattr(name)} '
         'generationTool="rwadist (fmu/ssp.py)">',
         f'  <ssd:System name={quoteattr(name)} description="Reaction-wheel assembly: each component\'s Fx_sc .. '
         'Tz_sc are its loads at the spacecraft reference point in the spacecraft frame; the assembly\'s loads are '
         'their sum">', '    <ssd:Elements>']
    for ws, source, p in zip(wheels, sources, params):
        x += _component(ws.name, source, p, _law_text(ws, wheels))
    x += ['    </ssd:Elements>', '  </ssd:System>', '  <ssd:DefaultExperiment startTime="0.0" stopTime="10.0"/>',
          '</ssd:SystemStructureDescription>']
    return "\n".join(x) + "\n"


def _stem(text: str) -> str:
    return re.sub(r"[^A-Za-z0-9_]+", "_", text).strip("_") or "wheel"


def build_assembly_ssp(wheels_path, output, *, name: str | None = None, default_model=None,
                       assumed_modes: bool = False, windows: bool | None = None) -> tuple:
    """Write the SSP 1.0 file ``output`` (.ssp) of the assembly in ``wheels_path`` (a ``rwadist psd --wheels``
    file); returns (path, notes).  ``name``: the system's name (default the file's stem).  ``default_model``: the model (path, dict or WheelModel) of wheels that name
    none.  ``assumed_modes`` and ``windows``: as :func:`fmu.native_build.build_native_fmu`.  ``notes``: what the
    SSP cannot carry (a phase offset of a phase lock), one line each."""
    from rwadist import catalogue
    from rwadist.mounting import load_wheels
    from rwadist.presets import preset

    output = Path(output)
    if output.suffix != ".ssp":
        raise ValueError(f"output {str(output)!r} must end in .ssp")
    wheels = load_wheels(wheels_path, (lambda: None) if default_model is not None else None, NO_LAW,
                         assumed_modes=assumed_modes)
    params = wheel_parameters(wheels)
    notes = [f"{ws.name}: phase_offset_deg {np.degrees(ws.tie.phase_offset):g} of its phase lock is not carried (the "
             f"wheel FMU has no rotor-angle offset); it runs with {wheels[ws.tie.to].name}'s line phases"
             for ws in wheels if ws.tie is not None and ws.tie.phase_lock and ws.tie.phase_offset != 0.0]
    output.parent.mkdir(parents=True, exist_ok=True)
    with tempfile.TemporaryDirectory(prefix="rwadist_ssp_") as tmp:
        fmus: dict = {}             # model reference -> resources/<name>.fmu
        sources = []
        for ws in wheels:
            ref = ws.model_ref
            if ref not in fmus:
                if ref.startswith("preset "):
                    name = ref[len("preset "):]
                    model = catalogue.preset_model(name) or preset(name).to_model()
                elif ref == "command-line model":
                    model = default_model
                else:
                    model = ref
                stem = _stem(Path(ref).stem if not ref.startswith(("preset ", "command-line")) else ref)
                while f"resources/{stem}.fmu" in fmus.values():
                    stem += "_"
                build_native_fmu(model, Path(tmp) / f"{stem}.fmu", assumed_modes=assumed_modes, windows=windows)
                fmus[ref] = f"resources/{stem}.fmu"
            sources.append(fmus[ref])
        ssd = system_description(name or output.stem, wheels, sources, params)
        tmp_out = output.with_name(output.name + ".tmp")
        with zipfile.ZipFile(tmp_out, "w", zipfile.ZIP_DEFLATED) as z:
            z.writestr(zipfile.ZipInfo("SystemStructure.ssd", date_time=(2026, 1, 1, 0, 0, 0)), ssd)
            for src in sorted(set(sources)):
                z.write(Path(tmp) / Path(src).name, src)
        os.replace(tmp_out, output)
    return output, notes
