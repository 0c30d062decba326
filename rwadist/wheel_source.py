"""One wheel's disturbance sources for the PSD, from a model (file) or a preset, under the assumed-modes rule.

The rule, decided here for :func:`rwadist.psd`, ``rwadist psd`` and every wheel of a wheels set: a wheel
whose suspension modes are assumed (``analytical.modes_assumed``: a catalogue datasheet wheel) runs
hard-mounted -- Melody's model of its lines, as its datasheet states -- unless ``assumed_modes`` asks for
its assumed modes; ``empirical`` runs any wheel hard-mounted.
"""
from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from . import broadband as bb
from . import catalogue
from .errors import ParameterError
from .model import WheelModel
from .model import load as load_model
from .presets import preset as preset_description


@dataclass(frozen=True)
class WheelSource:
    """One wheel's line sources and what they rest on.

    lines : rwadist.broadband.WheelLines
        The coherent line sources (h, C in SI per (rad/s)², directions).
    name : str
        What the wheel was read from: the model file, the model's name, or the preset's name.
    model : WheelModel
        Its model (``wheel.max_speed_rpm``, ``analytical.unconstrained``).
    modes_assumed : bool
        Its suspension modes are assumed (a datasheet wheel), not measured.
    hard_mounted : bool
        Run as Melody's model of its lines (no modes): asked for, or its modes assumed and not asked for.
    """

    lines: object
    name: str
    model: WheelModel
    modes_assumed: bool
    hard_mounted: bool

    @property
    def on_assumed_modes(self) -> bool:
        """Its outputs rest on assumed (datasheet) suspension modes."""
        return self.modes_assumed and not self.hard_mounted


def source_model(model=None, preset: str | None = None) -> tuple:
    """(WheelModel, name) of ``model`` (a WheelModel or a model-file path) or of the preset ``preset``.

    A preset's model is its catalogue entry (with its provenance and ``modes_assumed``), else the virtual
    stand's description of it.  :class:`ParameterError` for both or neither, or an unknown preset."""
    if preset and model is not None:
        raise ParameterError("preset", f"{preset!r} given beside a model: give a model or a preset, not both")
    if preset:
        return catalogue.preset_model(preset) or preset_description(preset).to_model(), str(preset)
    if model is None:
        raise ParameterError("model", "missing: give a model (a WheelModel or a model-file path) or a preset")
    if isinstance(model, (str, Path)):
        return load_model(model), str(model)
    if isinstance(model, WheelModel):
        return model, model.name
    raise ParameterError("model", f"a {type(model).__name__}: expected a WheelModel or a model-file path")


def wheel_source(model=None, *, preset: str | None = None, empirical: bool = False,
                 assumed_modes: bool = False) -> WheelSource:
    """The line sources of one wheel (:class:`WheelSource`) from a model (file) or a preset.

    empirical : bool
        Melody's model of the harmonics alone (hard mounted), else the extended model (modal amplification).
    assumed_modes : bool
        Run a wheel whose suspension modes are assumed through those modes (default: hard-mounted).
    """
    m, name = source_model(model, preset)
    assumed = catalogue.modes_assumed(m)
    hard = bool(empirical or (assumed and not assumed_modes))
    if preset:
        lines = bb.preset_lines(preset, hard)
    else:
        lines = bb.empirical_lines(m) if hard else bb.extended_lines_from_model(m, name)
    return WheelSource(lines, name, m, assumed, hard)
