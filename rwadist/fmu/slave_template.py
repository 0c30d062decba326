"""pythonfmu slave module of the rwadist wheel FMU (template).

``rwadist/fmu/build.py`` copies this file into the FMU under a module name unique to each build and renames the class
``RwadistWheelSlave`` to a unique name as well (the FMU's model identifier), so FMUs of different builds load side
by side in one process; it also rewrites the two BUILD_ lines.  The slave itself is ``rwadist_fmu_slave.py`` in
the FMU's ``resources/`` (a copy of ``rwadist/fmu/slave.py``), loaded here under a name unique to this module; this file
stays short because pythonfmu 0.7 compiles it again at every fmi2Instantiate (below).
"""
import ctypes

# Work around a pythonfmu bug (0.7.0; its sources to mid-2025 have it): on every fmi2Instantiate
# its native layer (findClass) re-executes this module's source in the module's __dict__ and then
# calls Py_DECREF on that dict, a reference it only borrowed (PyModule_GetDict).  Each instance
# leaves the dict's count one short; after a few dozen instances in one process the garbage
# collector trips over live objects and the host segfaults.  This line runs once per execution
# of the module and gives that count back (an import is one execution more: a harmless +1).
ctypes.pythonapi.Py_IncRef(ctypes.py_object(globals()))

# pythonfmu's findClass (0.7.0, every fmi2Instantiate) compiles and re-executes this file with a fresh locals
# dict, takes every class it finds there and, for each, never releases the list it makes of the class's __mro__,
# nor the repr and UTF-8 bytes it makes of each entry, nor the UTF-8 bytes of the name it picks (the class whose
# __mro__ holds Fmi2Slave deepest); it then takes the module's attribute of that name.  Classes made anew at each
# instantiation would stay alive with all their methods (~60 kB per instance); the slave class's own five-entry
# __mro__ would leave ~1 kB per instance.  So on such a re-execution (the module's dict, here globals(), already
# holds the slave class, and locals() is another dict) only a stand-in made at import is bound, under the
# one-letter name W (the UTF-8 bytes of a one-letter name are a shared constant): its metaclass shows findClass a
# two-entry __mro__ whose reprs are strings made once (rwadist/fmu/slave.py, find_class_stand_in); the module's W is the
# slave class.  What pythonfmu leaks per instance is then a two-entry list, one bytes object and the resources
# path it inserts into sys.path: 219 bytes with a 26-character path (tests/test_fmu_memory.py).
if "RwadistWheelSlave" in globals() and globals() is not locals():
    W = globals()["_FIND_CLASS_STAND_IN"]
else:
    import importlib.util
    import os
    import sys
    from typing import TYPE_CHECKING

    #: set by rwadist/fmu/build.py for each build (this line is rewritten): the physics the model file carries
    BUILD_PHYSICS = "extended model: harmonics through the measured suspension modes"
    #: set by rwadist/fmu/build.py (this line is rewritten): start value of the ``modes`` parameter -- False for a model
    #: without suspension and for assumed (datasheet) modes unless the build opted in (--assumed-modes)
    BUILD_MODES_DEFAULT = True
    SLAVE_FILE = "rwadist_fmu_slave.py"

    def _load_slave():
        """The slave implementation beside this file, as module ``<this module>_slave`` (loaded once)."""
        name = f"{__name__}_slave"
        mod = sys.modules.get(name)
        if mod is None:
            path = os.path.join(os.path.dirname(os.path.abspath(__file__)), SLAVE_FILE)
            spec = importlib.util.spec_from_file_location(name, path)
            if spec is None or spec.loader is None:
                raise ImportError(f"rwadist FMU: cannot load the slave implementation {path}")
            mod = importlib.util.module_from_spec(spec)
            sys.modules[name] = mod
            try:
                spec.loader.exec_module(mod)
            except BaseException:
                sys.modules.pop(name, None)
                raise
        return mod

    if TYPE_CHECKING:            # the type checker reads the slave's source module (rwadist/fmu/slave.py)
        from . import slave as _slave
    else:
        _slave = _load_slave()

    class RwadistWheelSlave(_slave.WheelSlave):
        description = _slave.DESCRIPTION_HEAD + BUILD_PHYSICS
        modes_default = BUILD_MODES_DEFAULT

    W = RwadistWheelSlave
    _FIND_CLASS_STAND_IN = _slave.find_class_stand_in()
