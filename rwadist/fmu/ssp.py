"""An SSP 1.0 file of a reaction-wheel assembly: one native wheel FMU per wheel of a ``wheels.json``.

:func:`build_assembly_ssp` reads the wheels file with :func:`rwadist.mounting.load_wheels` (the reader of
``rwadist psd --wheels``), builds one native FMI 2.0 FMU per distinct wheel model (``resources/<model>.fmu``; wheels
of one model share it) and the speed-command FMU (:mod:`fmu.speed_command`), and writes ``SystemStructure.ssd``:

* **the assembly's inputs**: the component ``speed_command``, with one input ``speed_<wheel>`` (rad/s) per
  independently driven wheel, starting at the mean speed of its speed law (a ParameterBinding); its output
  ``wheel_speed_<wheel>`` is connected to that wheel's ``wheel_speed`` and to the ``wheel_speed`` of every wheel tied
  to it, through an ``ssc:LinearTransformation`` whose factor is the tie ratio (-1: counter-rotating).  (A component,
  not system connectors: SSP hosts such as libcosim connect element to element only.)  In a Jacobi master such as
  libcosim the wheels run one communication step behind the command, as for any connection;
* **one component per wheel** (named as in wheels.json): its mounting as SSP parameters bound inline (``dcm_11 ..
  dcm_33``, wheel -> spacecraft; ``r_x, r_y, r_z``, the interface point in the spacecraft frame, m) and ``seed``, its
  own line phases (wheel k: k + 1; a phase-locked tie shares its root's: identical rotors locked together);
* **the speed laws as system parameters** (``<wheel>_speed_law``: uniform, truncated normal, histogram or none;
  ``_speed_min``, ``_speed_max``, ``_speed_mean`` rad/s; a truncated normal's ``_speed_normal_mean`` and
  ``_speed_normal_std``; a histogram's ``_speed_table``, a CSV in resources/), **the ties** (``<wheel>_tie_to``,
  ``_tie_ratio``, ``_phase_lock``, ``_phase_offset`` rad) and **the mountings** again (``<wheel>_dcm_11`` ..,
  ``<wheel>_r_x`` ..): system-level parameter connectors with their values bound at the system.  No connection
  touches them (libcosim reads them and ignores them; another SSP tool shows them as the assembly's parameters).

The assembly's loads: every wheel's ``Fx_sc .. Tz_sc`` are already its loads moved to the spacecraft reference point
in the spacecraft frame (F_sc = R F, T_sc = R T + r x F_sc), so the assembly's force and torque at the reference
point are their sum, which the host forms (no summing FMU: in a Jacobi master it would add a step of delay).
The archive is reproducible: the same wheels.json, models and options give the same bytes.
"""
from __future__ import annotations

import os
import re
import tempfile
import zipfile
from pathlib import Path
from xml.sax.saxutils import quoteattr

import numpy as np

from rwadist.presets import preset

from .native_build import VARIABLES, build_native_fmu, windows_compiler
from .speed_command import build_speed_command, variable_names

SSD_NS = ('xmlns:ssd="http://ssp-standard.org/SSP1/SystemStructureDescription" '
          'xmlns:ssc="http://ssp-standard.org/SSP1/SystemStructureCommon" '
          'xmlns:ssv="http://ssp-standard.org/SSP1/SystemStructureParameterValues"')
OUTPUTS = [v[0] for v in VARIABLES if v[2] == "output"]
UNITS = {v[0]: v[5] for v in VARIABLES}
TYPES = {v[0]: v[1] for v in VARIABLES}
#: the units the SSD uses, as SI base-unit exponents
SSD_UNITS = {"rad/s": {"s": -1, "rad": 1}, "rad": {"rad": 1}, "m": {"m": 1}, "1": {}, "N": {"kg": 1, "m": 1, "s": -2},
             "N.m": {"kg": 1, "m": 2, "s": -2}, "rad/s2": {"s": -2, "rad": 1}}
COMMAND = "speed_command"


class NoSpeedLaw:
    """The speed law of a wheel its wheels.json entry gives none for (its command starts at 0 rad/s)."""

    def __repr__(self) -> str:
        return "no speed law"


NO_LAW = NoSpeedLaw()


def _support(law) -> tuple:
    """(lowest, highest) speed of a law, rad/s (a property on some laws, a method on others)."""
    sup = law.support
    lo, hi = sup() if callable(sup) else sup
    return float(lo), float(hi)


def law_mean(law) -> float:
    """Mean speed (rad/s) of a speed law of :mod:`rwadist.speed_laws`: closed forms for the uniform, truncated normal
    and histogram laws, else the integral of its pdf over its support; 0 without a law."""
    from rwadist import speed_laws as sl
    if law is NO_LAW or law is None:
        return 0.0
    if isinstance(law, sl.Uniform):
        return 0.5 * (float(law.lo) + float(law.hi))
    if isinstance(law, sl.TruncatedNormal):
        return float(law._dist.mean())
    if isinstance(law, sl.Histogram):
        e, p = np.asarray(law.edges, float), np.asarray(law.pdf_values, float)
        return float(np.sum(p * (e[1:] ** 2 - e[:-1] ** 2)) / 2 / np.sum(p * np.diff(e)))
    lo, hi = _support(law)
    w = np.linspace(lo, hi, 20001)
    p = np.asarray(law.pdf(w), float)
    area = np.trapezoid(p, w)
    return float(np.trapezoid(p * w, w) / area) if area > 0 else 0.5 * (lo + hi)


def tie_root(wheels, i) -> tuple:
    """(root index, speed ratio, phase-locked all the way, phase offset rad) of wheel i."""
    ratio, lock, offset = 1.0, True, 0.0
    while wheels[i].tie is not None:
        ratio *= wheels[i].tie.ratio
        lock = lock and wheels[i].tie.phase_lock
        offset += wheels[i].tie.phase_offset
        i = wheels[i].tie.to
    return i, ratio, lock, offset


def wheel_parameters(wheels) -> list:
    """Per wheel: {parameter: value} bound on its component (mounting, seed), in the order of ``wheels``."""
    out = []
    for i, ws in enumerate(wheels):
        root, _, lock, _ = tie_root(wheels, i)
        R = ws.mounting.R
        p = {f"dcm_{a + 1}{b + 1}": float(R[a, b]) for a in range(3) for b in range(3)}
        p.update({f"r_{ax}": float(x) for ax, x in zip("xyz", ws.mounting.position_m)})
        p["seed"] = (root if ws.tie is not None and lock else i) + 1
        out.append(p)
    return out


def _stem(text: str) -> str:
    return re.sub(r"[^A-Za-z0-9_]+", "_", text).strip("_") or "wheel"


def wheel_stems(wheels) -> list:
    """Each wheel's name as an identifier (letters, digits, _), unique within the assembly."""
    out: list = []
    for ws in wheels:
        stem = _stem(ws.name)
        while stem in out:
            stem += "_"
        out.append(stem)
    return out


def law_parameters(ws, stem: str, tables: dict) -> dict:
    """The system parameters {name: (SSV type, value, unit)} of wheel ``ws``'s own speed law; a histogram's table
    goes to ``tables`` {resource name: CSV text}."""
    from rwadist import speed_laws as sl
    law = ws.law
    if law is NO_LAW:
        return {f"{stem}_speed_law": ("String", "none", None), f"{stem}_speed_mean": ("Real", 0.0, "rad/s")}
    kind = {sl.Uniform: "uniform", sl.TruncatedNormal: "truncated normal", sl.Histogram: "histogram"}.get(
        type(law), type(law).__name__)
    lo, hi = _support(law)
    out = {f"{stem}_speed_law": ("String", kind, None), f"{stem}_speed_min": ("Real", lo, "rad/s"),
           f"{stem}_speed_max": ("Real", hi, "rad/s"), f"{stem}_speed_mean": ("Real", law_mean(law), "rad/s")}
    if isinstance(law, sl.TruncatedNormal):
        out[f"{stem}_speed_normal_mean"] = ("Real", float(law.mean), "rad/s")
        out[f"{stem}_speed_normal_std"] = ("Real", float(law.std), "rad/s")
    if isinstance(law, sl.Histogram):
        name = f"resources/{stem}_speed_law.csv"
        e, p = np.asarray(law.edges, float), np.asarray(law.pdf_values, float)
        tables[name] = "lo_rad_s,hi_rad_s,pdf_s_per_rad\n" + "".join(
            f"{a!r},{b!r},{c!r}\n" for a, b, c in zip(e[:-1], e[1:], p))
        out[f"{stem}_speed_table"] = ("String", name, None)
    return out


def system_parameters(wheels, params: list, tables: dict) -> dict:
    """Every system parameter {name: (SSV type, value, unit)}: the speed laws or ties, and the mountings."""
    out: dict = {}
    for i, (ws, stem) in enumerate(zip(wheels, wheel_stems(wheels))):
        if ws.tie is None:
            out.update(law_parameters(ws, stem, tables))
        else:
            t = ws.tie
            out.update({f"{stem}_tie_to": ("String", wheels[t.to].name, None),
                        f"{stem}_tie_ratio": ("Real", float(t.ratio), "1"),
                        f"{stem}_phase_lock": ("Boolean", bool(t.phase_lock), None),
                        f"{stem}_phase_offset": ("Real", float(t.phase_offset), "rad")})
        out.update({f"{stem}_{k}": ("Real", v, UNITS[k]) for k, v in params[i].items() if k != "seed"})
    return out


def _value(typ: str, value, unit) -> str:
    if typ == "Boolean":
        value = "true" if value else "false"
    elif typ == "Real":
        value = repr(float(value))
    return f'<ssv:{typ} value={quoteattr(str(value))}' + (f' unit="{unit}"' if unit else "") + '/>'


def _parameter_binding(set_name: str, values: dict, indent: str) -> list:
    """ssd:ParameterBindings with one inline parameter set of ``values`` {name: (type, value, unit)}."""
    x = [f'{indent}<ssd:ParameterBindings>', f'{indent}  <ssd:ParameterBinding>', f'{indent}    <ssd:ParameterValues>',
         f'{indent}      <ssv:ParameterSet version="1.0" name={quoteattr(set_name)}>', f'{indent}        <ssv:Parameters>']
    x += [f'{indent}          <ssv:Parameter name={quoteattr(k)}>{_value(*v)}</ssv:Parameter>'
          for k, v in values.items()]
    return x + [f'{indent}        </ssv:Parameters>', f'{indent}      </ssv:ParameterSet>',
                f'{indent}    </ssd:ParameterValues>', f'{indent}  </ssd:ParameterBinding>', f'{indent}</ssd:ParameterBindings>']


def _connector(name: str, kind: str, typ: str, unit, indent: str) -> str:
    unit_attr = f' unit="{unit}"' if unit and typ == "Real" else ""
    return f'{indent}<ssd:Connector name={quoteattr(name)} kind="{kind}"><ssc:{typ}{unit_attr}/></ssd:Connector>'


def _wheel_component(name: str, source: str, params: dict) -> list:
    ind = "          "
    x = [f'      <ssd:Component name={quoteattr(name)} source={quoteattr(source)} '
         'type="application/x-fmu-sharedlibrary">', '        <ssd:Connectors>']
    x += [_connector(v, "input", "Real", UNITS[v], ind) for v in ("wheel_speed", "wheel_acceleration")]
    x += [_connector(v, "parameter", TYPES[v], UNITS[v], ind) for v in params]
    x += [_connector(v, "output", "Real", UNITS[v], ind) for v in OUTPUTS]
    x += ['        </ssd:Connectors>']
    x += _parameter_binding(f"{name} mounting and seed", {k: (TYPES[k], v, UNITS[k]) for k, v in params.items()},
                            "        ")
    return x + ['      </ssd:Component>']


def _command_component(source: str, names: list, means: list) -> list:
    inputs, outputs = variable_names(names)
    ind = "          "
    x = [f'      <ssd:Component name="{COMMAND}" source={quoteattr(source)} type="application/x-fmu-sharedlibrary" '
         'description="the assembly\'s speed inputs (rad/s), one per independently driven wheel">',
         '        <ssd:Connectors>']
    x += [_connector(v, "input", "Real", "rad/s", ind) for v in inputs]
    x += [_connector(v, "output", "Real", "rad/s", ind) for v in outputs] + ['        </ssd:Connectors>']
    x += _parameter_binding("speed laws' mean speeds", {v: ("Real", m, "rad/s") for v, m in zip(inputs, means)},
                            "        ")
    return x + ['      </ssd:Component>']


def _connections(wheels) -> list:
    """speed_command.wheel_speed_<root> -> <wheel>.wheel_speed, a tied wheel's scaled by its ratio."""
    x, stems = ['    <ssd:Connections>'], wheel_stems(wheels)
    for i, ws in enumerate(wheels):
        root, ratio, _, _ = tie_root(wheels, i)
        start = (f'      <ssd:Connection startElement="{COMMAND}" '
                 f'startConnector={quoteattr("wheel_speed_" + stems[root])} '
                 f'endElement={quoteattr(ws.name)} endConnector="wheel_speed"')
        x.append(start + ("/>" if ratio == 1.0 else
                          f'>\n        <ssc:LinearTransformation factor="{ratio!r}" offset="0.0"/>\n'
                          '      </ssd:Connection>'))
    return x + ['    </ssd:Connections>']


def system_description(name: str, wheels, sources: list, params: list, command_source: str, tables: dict) -> str:
    """SystemStructure.ssd of the assembly (see the module docstring)."""
    roots = [i for i, ws in enumerate(wheels) if ws.tie is None]
    system = system_parameters(wheels, params, tables)
    x = ['<?xml version="1.0" encoding="UTF-8"?>',
         f'<ssd:SystemStructureDescription {SSD_NS} version="1.0" name={quoteattr(name)} '
         'generationTool="rwadist (rwadist/fmu/ssp.py)">',
         f'  <ssd:System name={quoteattr(name)} description="Reaction-wheel assembly: speed_command\'s inputs drive '
         'the wheels; each wheel\'s Fx_sc .. Tz_sc are its loads at the spacecraft reference point in the spacecraft '
         'frame; the assembly\'s loads are their sum">', '    <ssd:Connectors>']
    x += [_connector(k, "parameter", t, u, "      ") for k, (t, _, u) in system.items()]
    x += ['    </ssd:Connectors>'] + _parameter_binding("speed laws, ties and mountings", system, "    ")
    stems = wheel_stems(wheels)
    x += ['    <ssd:Elements>'] + _command_component(command_source, [stems[i] for i in roots],
                                                       [law_mean(wheels[i].law) for i in roots])
    for ws, source, p in zip(wheels, sources, params):
        x += _wheel_component(ws.name, source, p)
    x += ['    </ssd:Elements>'] + _connections(wheels) + ['  </ssd:System>', '  <ssd:Units>']
    x += [f'    <ssc:Unit name="{u}"><ssc:BaseUnit ' + " ".join(f'{k}="{v}"' for k, v in e.items()) + '/></ssc:Unit>'
          for u, e in SSD_UNITS.items()]
    x += ['  </ssd:Units>', '  <ssd:DefaultExperiment startTime="0.0" stopTime="10.0"/>',
          '</ssd:SystemStructureDescription>']
    return "\n".join(x) + "\n"


def _build_fmus(wheels, tmp: Path, default_model, assumed_modes: bool, windows: bool) -> list:
    """resources/<name>.fmu of each wheel's model (one per distinct model), built in ``tmp``."""
    from rwadist import catalogue

    fmus: dict = {}             # model reference -> resources/<name>.fmu
    sources = []
    for ws in wheels:
        ref = ws.model_ref
        if ref not in fmus:
            if ref.startswith("preset "):
                preset_name = ref[len("preset "):]
                model = catalogue.preset_model(preset_name) or preset(preset_name).to_model()
            else:
                model = default_model if ref == "command-line model" else ref
            stem = _stem(Path(ref).stem if not ref.startswith(("preset ", "command-line")) else ref)
            while f"resources/{stem}.fmu" in fmus.values():
                stem += "_"
            build_native_fmu(model, tmp / f"{stem}.fmu", assumed_modes=assumed_modes, windows=windows,
                             reproducible=True)
            fmus[ref] = f"resources/{stem}.fmu"
        sources.append(fmus[ref])
    return sources


def build_assembly_ssp(wheels_path, output, *, name: str | None = None, default_model=None,
                       assumed_modes: bool = False, windows: bool | None = None) -> tuple:
    """Write the SSP 1.0 file ``output`` (.ssp) of the assembly in ``wheels_path`` (a ``rwadist psd --wheels``
    file); returns (path, notes).  ``name``: the system's name (default the file's stem).  ``default_model``: the
    model (path, dict or WheelModel) of wheels that name none.  ``assumed_modes`` and ``windows``: as
    :func:`fmu.native_build.build_native_fmu`.  ``notes``: what the SSP cannot carry (a phase offset of a phase
    lock), one line each."""
    from rwadist.mounting import load_wheels

    output = Path(output)
    if output.suffix != ".ssp":
        raise ValueError(f"output {str(output)!r} must end in .ssp")
    wheels = load_wheels(wheels_path, (lambda: None) if default_model is not None else None, NO_LAW,
                         assumed_modes=assumed_modes)
    if windows is None:
        windows = windows_compiler() is not None
    params = wheel_parameters(wheels)
    notes = [f"{ws.name}: phase_offset_deg {np.degrees(ws.tie.phase_offset):g} of its phase lock is not applied (the "
             f"wheel FMU has no rotor-angle offset); it runs with {wheels[ws.tie.to].name}'s line phases"
             for ws in wheels if ws.tie is not None and ws.tie.phase_lock and ws.tie.phase_offset != 0.0]
    output.parent.mkdir(parents=True, exist_ok=True)
    with tempfile.TemporaryDirectory(prefix="rwadist_ssp_") as tmp:
        sources = _build_fmus(wheels, Path(tmp), default_model, assumed_modes, windows)
        roots = [(stem, ws) for stem, ws in zip(wheel_stems(wheels), wheels) if ws.tie is None]
        build_speed_command([stem for stem, _ in roots], [law_mean(ws.law) for _, ws in roots],
                            Path(tmp) / f"{COMMAND}.fmu", windows=windows)
        tables: dict = {}
        ssd = system_description(name or output.stem, wheels, sources, params, f"resources/{COMMAND}.fmu", tables)
        files = {"SystemStructure.ssd": ssd.encode(), **{k: v.encode() for k, v in tables.items()},
                 **{src: (Path(tmp) / Path(src).name).read_bytes()
                    for src in {*sources, f"resources/{COMMAND}.fmu"}}}
        tmp_out = output.with_name(output.name + ".tmp")
        with zipfile.ZipFile(tmp_out, "w", zipfile.ZIP_DEFLATED) as z:
            for member in sorted(files):
                z.writestr(zipfile.ZipInfo(member, date_time=(2026, 1, 1, 0, 0, 0)), files[member],
                           compress_type=zipfile.ZIP_DEFLATED)
        os.replace(tmp_out, output)
    return output, notes
