"""Coupling a reaction wheel to a flexible spacecraft (thesis ch. 5, issue 6).

components : wheel / rigid mass / spring-mass / isolated components (python-control StateSpace,
             interface acceleration in -> load out) and plants (StateSpace, modal data, rigid).
assemble   : acceleration-feedback assembly; the three practices of Table 5.1 as systems.
geometry   : mounts (DCM + lever arm) of 6-axis components on plant nodes.
performance: line responses (speed ripple included), broadband floors, jitter RMS vs speed, practice
             errors, speed-averaged PSD.
sweep      : the same over speeds / wheel sets in parallel with dask (local or a cluster).
"""
try:
    import control as _control  # noqa: F401  (python-control: every component is a control.StateSpace)
except ImportError:
    from ..errors import MissingDependencyError

    raise MissingDependencyError("control", "the coupling kit (rwadist.coupling)", "coupling") from None

from .assemble import PRACTICES, Assembly, Attachment, assemble, practice_systems
from .components import (
                         Component,
                         Plant,
                         example_spacecraft,
                         free_lines,
                         frf,
                         modal_plant,
                         plant_from_statespace,
                         random_modal_plant,
                         rigid_mass,
                         rigid_plant,
                         spring_mass,
                         spring_mass_plant,
                         wheel,
                         wheel_rigid_mass_matrix,
                         with_isolator,
)
from .errors import CouplingError, InterfaceMismatchError, NotARotationError, SingularInterfaceError, UnstablePlantError
from .geometry import Mount, check_dcm, load_transform, rotation, spin_axis_dcm
from .performance import (
                         Floor,
                         FloorResponses,
                         JitterResult,
                         LineResponses,
                         WheelSpec,
                         floor_grid,
                         floor_responses,
                         floors_from_effects,
                         jitter_vs_speed,
                         line_responses,
                         output_psd,
                         wheel_spec_from_model,
)
from .sweep import sweep

__all__ = [n for n in dir() if not n.startswith("_")]
