"""The pythonfmu co-simulation slave of the rwadist wheel FMU (:class:`WheelSlave`).

``rwadist/fmu/build.py`` ships this file verbatim in the FMU's ``resources/`` as ``rwadist_fmu_slave.py``, beside the
physics (``rwadist_fmu_runtime.py``, a copy of ``rwadist/fmu/runtime.py``, numpy only) and the wheel
(``wheel_model.json``); rwadist itself is not needed by the host.  The FMU's slave module (``rwadist/fmu/slave_template.py``
rendered per build under a module name unique to the build) loads this file under a name unique to that module and
subclasses :class:`WheelSlave` under the build's class name, so FMUs of different builds load side by side in one
process.  The slave lives here, not in that module, because pythonfmu 0.7 compiles that module's source again at
every fmi2Instantiate (rwadist/fmu/slave_template.py): ~1.3 MB of transient allocations per instance for the whole slave,
which fragmented the host's heap (issue 17, benchmarks/fmu_memory.py).

Bad input never raises out of ``do_step`` (pythonfmu turns an exception into fmi2Fatal): the
slave logs the problem with status fmi2Error (category logStatusError), flags it to the FMU's
native layer (``binaries/linux64/<id>.so``, see rwadist/fmu/build.py) and returns False; the native
layer then returns fmi2Error from the FMI call (pythonfmu alone would report fmi2Discard).  The
state is left at the last good step, so the host may retry (e.g. with a smaller step or a
corrected input).  The same native library carries the C step kernel the runtime uses.
"""
import ctypes
import importlib.util
import math
import os
import struct
import sys
import weakref
from xml.etree.ElementTree import Element, SubElement

from pythonfmu import (
    Boolean,
    DefaultExperiment,
    Fmi2Causality,
    Fmi2Initial,
    Fmi2Slave,
    Fmi2Variability,
    Integer,
    Real,
    String,
)
from pythonfmu.enums import Fmi2Status

RUNTIME_FILE = "rwadist_fmu_runtime.py"
MODEL_FILE = "wheel_model.json"
#: unit -> SI base-unit exponents (kg, m, s, rad) for the UnitDefinitions of modelDescription.xml
UNITS = {"N": dict(kg=1, m=1, s=-2), "N.m": dict(kg=1, m=2, s=-2), "rad/s": dict(s=-1, rad=1),
         "rad/s2": dict(s=-2, rad=1), "s": dict(s=1), "m": dict(m=1), "Hz": dict(s=-1), "1": {}}
OUTPUTS = (("Fx", "N", "force the wheel exerts on its interface, wheel frame x"),
           ("Fy", "N", "force on the interface, wheel frame y"),
           ("Fz", "N", "force on the interface, wheel frame z (spin axis)"),
           ("Tx", "N.m", "torque on the interface about wheel x, at the interface point"),
           ("Ty", "N.m", "torque on the interface about wheel y, at the interface point"),
           ("Tz", "N.m", "torque on the interface about wheel z (axial-torque harmonics)"))


class RealU(Real):
    """pythonfmu Real with a unit attribute."""

    def __init__(self, name, unit=None, **kwargs):
        super().__init__(name, **kwargs)
        self.unit = unit

    def to_xml(self):
        node = super().to_xml()
        if self.unit is not None:
            node.find("Real").set("unit", self.unit)
        return node


#: library path -> (ctypes.CDLL or None, its rwadist_kernel_step or None): opened once per process.  A CDLL
#: defines a ctypes class of its own and is a reference cycle (it caches its functions, which refer back to
#: it): one per instance was garbage only a full collection frees (issue 17, benchmarks/fmu_memory.py).
_NATIVE_LAYERS: dict[str, tuple] = {}


def _native_layer(resources, model_identifier, rt):
    """(library, kernel): the FMU's rwadist native library (ctypes.CDLL) and its step kernel, or (None, None)
    where it is absent (plain pythonfmu build, or a platform it was not built for)."""
    if not sys.platform.startswith("linux"):
        return None, None
    path = os.path.join(os.path.dirname(os.path.abspath(resources)), "binaries", "linux64",
                        model_identifier + ".so")
    layer = _NATIVE_LAYERS.get(path)
    if layer is None:
        try:
            lib = ctypes.CDLL(path)
            lib.rwadist_fmu_native_version
        except (OSError, AttributeError):
            lib = None
        layer = _NATIVE_LAYERS[path] = (lib, None if lib is None else rt.load_kernel(lib._name))
    return layer


#: pythonfmu libraries whose exit is guarded (:func:`_guard_pythonfmu_exit`), once per process
_EXIT_GUARDED: set[str] = set()


def _elf_function_offsets(path, names):
    """{name: offset from the load base} of the functions ``names`` found in the ELF64 (little-endian) file's
    ``.symtab`` section (a function pythonfmu builds with hidden visibility is there, not in ``.dynsym``);
    empty for another format or a stripped file."""
    with open(path, "rb") as fh:
        data = fh.read()
    if data[:4] != b"\x7fELF" or data[4] != 2 or data[5] != 1:
        return {}
    (shoff,) = struct.unpack_from("<Q", data, 0x28)
    shentsize, shnum = struct.unpack_from("<HH", data, 0x3A)
    sections = [struct.unpack_from("<IIQQQQIIQQ", data, shoff + i * shentsize) for i in range(shnum)]
    for _, kind, _, _, offset, size, link, _, _, _ in sections:
        if kind != 2:       # SHT_SYMTAB
            continue
        strings = sections[link][4]
        found = {}
        for name_at, info, _, _, value, _ in struct.iter_unpack("<IBBHQQ", data[offset:offset + size]):
            if info & 0xF == 2 and value:       # STT_FUNC, defined
                start = strings + name_at
                name = data[start:data.index(b"\0", start)].decode("ascii", "replace")
                if name in names:
                    found[name] = value
        return found
    return {}


def _guard_pythonfmu_exit(library):
    """Make pythonfmu's library ``library`` release its interpreter state at process exit before its own static
    destructor does, so its ELF destructor no longer frees it a second time (issue 17).

    pythonfmu 0.7 keeps a namespace-scope ``std::shared_ptr<PyState>``: at exit, ``__run_exit_handlers`` first
    runs the C++ destructor of that shared_ptr (it frees the 128-byte control block: no instance holds a copy,
    since ``createInstance`` stores it in the instance's data only after constructing the instance from that
    data; so with instances alive or all freed), then ``_dl_fini`` runs the library's
    ``__attribute__((destructor)) onLibraryUnload`` -> ``finalizePythonInterpreter`` -> ``pyState = nullptr`` on
    the destroyed shared_ptr, which releases the freed control block again: valgrind's "Invalid read of size 4
    ... in finalizePythonInterpreter ... 8 bytes inside a block of size 128 free'd", and with glibc's malloc a
    decrement inside a freed chunk (its free-list link): ``corrupted double-linked list`` /
    ``free(): corrupted unsorted chunks`` at exit.  Registering ``finalizePythonInterpreter`` itself with
    ``__cxa_atexit`` here (after the library's static constructors registered that destructor) runs it first:
    the shared_ptr is released while alive and then holds null, so the static destructor and the ELF
    destructor find nothing to release.  ``finalizePythonInterpreter`` is hidden, so its address is the
    library's exported ``fmi2Instantiate`` moved by the two functions' distance in ``.symtab``.  Nothing is
    done where that is not found (another platform or a stripped library)."""
    if library in _EXIT_GUARDED or not sys.platform.startswith("linux") or not os.path.isfile(library):
        return
    _EXIT_GUARDED.add(library)
    try:
        offsets = _elf_function_offsets(library, {"finalizePythonInterpreter", "fmi2Instantiate"})
        if len(offsets) != 2:
            return
        lib = ctypes.CDLL(library)  # loaded already (this call runs inside it); ctypes keeps it loaded to exit
        base = ctypes.cast(lib.fmi2Instantiate, ctypes.c_void_p).value - offsets["fmi2Instantiate"]
        at_exit = ctypes.CDLL(None).__cxa_atexit
        at_exit.argtypes, at_exit.restype = [ctypes.c_void_p] * 3, ctypes.c_int
        at_exit(base + offsets["finalizePythonInterpreter"], None, None)
    except (OSError, AttributeError, ValueError, IndexError, struct.error):
        return


def _drop_duplicate_path(entry):
    """Remove all but the first ``entry`` from sys.path: pythonfmu inserts the resources folder at its head at
    every fmi2Instantiate (0.7.0), so sys.path grows by one entry per instance without this."""
    at = [i for i, p in enumerate(sys.path) if p == entry]
    for i in reversed(at[1:]):
        del sys.path[i]


def _load_runtime(resources):
    name = f"{__name__}_runtime"
    mod = sys.modules.get(name)
    if mod is None:
        path = os.path.join(resources, RUNTIME_FILE)
        spec = importlib.util.spec_from_file_location(name, path)
        if spec is None or spec.loader is None:
            raise ImportError(f"rwadist FMU: cannot load the wheel runtime {path}")
        mod = importlib.util.module_from_spec(spec)
        spec.loader.exec_module(mod)
        sys.modules[name] = mod
    return mod


def _live(ref: "weakref.ref[WheelSlave]") -> "WheelSlave":
    """The slave a variable's getter or setter reaches through the weak reference ``ref`` (see
    WheelSlave.__init__); ReferenceError once the instance is gone."""
    slave = ref()
    if slave is None:
        raise ReferenceError("rwadist wheel: the FMU instance this variable belongs to was freed")
    return slave


class _FixedRepr:
    """An object whose repr is a string made once."""
    __slots__ = ("text",)

    def __init__(self, text):
        self.text = text

    def __repr__(self):
        return self.text


class _FindClassView(type):
    """Metaclass of :func:`find_class_stand_in`: its classes' ``__mro__`` attribute is a fixed tuple of
    :class:`_FixedRepr` (their method resolution itself is type's, untouched)."""

    _find_class_mro: tuple      # set in each class's namespace by find_class_stand_in

    @property
    def __mro__(cls):
        return cls._find_class_mro


def find_class_stand_in():
    """The class a build's slave module shows pythonfmu's findClass (rwadist/fmu/slave_template.py): its ``__mro__``
    has two entries whose reprs are strings made here once, the first empty, the second Fmi2Slave's."""
    return _FindClassView("FindClassStandIn", (), {
        "_find_class_mro": (_FixedRepr(""), _FixedRepr(repr(Fmi2Slave)))})


#: the modelDescription's description, before the build's physics sentence
DESCRIPTION_HEAD = "Reaction-wheel micro-vibration, time domain; outputs in wheel and spacecraft frames. Physics: "


class WheelSlave(Fmi2Slave):
    """The wheel slave; each build subclasses it under its own class name (the FMU's model identifier) and sets
    ``description`` (DESCRIPTION_HEAD + the physics its model file carries) and ``modes_default``."""
    author = "rwadist"
    description = DESCRIPTION_HEAD + "extended model: harmonics through the measured suspension modes"
    #: start value of the ``modes`` parameter -- False for a model without suspension and for assumed
    #: (datasheet) modes unless the build opted in (--assumed-modes)
    modes_default = True
    default_experiment = DefaultExperiment(start_time=0.0, stop_time=1.0, step_size=1e-3)

    # No reference cycle may lead to the instance: pythonfmu frees it with one Py_DECREF at fmi2FreeInstance, and
    # an instance in a cycle (with its model's arrays) would wait for a full garbage collection, which a host
    # with many objects runs rarely -- the process grew by MBs over 1000 instantiate/free cycles (issue 17).
    # The variables' getters and setters therefore reach the instance through a weak reference.
    def __init__(self, **kwargs):
        super().__init__(**kwargs)
        if self.resources is not None:
            _drop_duplicate_path(self.resources)
        me = weakref.ref(self)
        self.rt = _load_runtime(self.resources)
        self.wheel_speed = 0.0
        self.wheel_acceleration = 0.0
        self.model_file = ""
        self.use_wheel_acceleration = False
        self.seed = -1
        self.imbalance = True
        self.harmonics = True
        self.modes = self.modes_default
        self.start_steady = False
        # the effect switches (their elements name them: rt.fmu_switches()), all on
        self._switches = self.rt.fmu_switches()
        for name, _ in self._switches:
            setattr(self, name, True)
        self.floor_resolution = 0.1
        self.max_acceleration = 500.0
        self.max_step_size = 0.01
        self.dcm = [1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0]
        self.pos = [0.0, 0.0, 0.0]
        self._y = [0.0] * 12
        self.model = None       # WheelRuntime once initialised without error
        self._floor_warned = False
        self.error: str | None = "not initialised"
        self._t_start = 0.0         # fmi2SetupExperiment's start time
        self._t_next = None         # the communication point the next step must start at
        self._native, self._kernel = _native_layer(self.resources, type(self).__name__, self.rt)
        binaries = os.path.join(os.path.dirname(os.path.abspath(self.resources)), "binaries", "linux64")
        for stem in (type(self).__name__ + "_pythonfmu", type(self).__name__):   # with / without the native layer
            _guard_pythonfmu_exit(os.path.join(binaries, stem + ".so"))
        self._flag_error = None if self._native is None else self._native.rwadist_fmu_flag_error

        inp, par, out = Fmi2Causality.input, Fmi2Causality.parameter, Fmi2Causality.output
        fixed, cont = Fmi2Variability.fixed, Fmi2Variability.continuous
        self.register_variable(RealU("wheel_speed", "rad/s", causality=inp, variability=cont,
                                     description="wheel speed, signed (positive about +z of the wheel frame)"))
        self.register_variable(RealU("wheel_acceleration", "rad/s2", causality=inp, variability=cont,
                                     description="wheel acceleration over the coming step; used when "
                                                 "use_wheel_acceleration is true, else derived from wheel_speed"))
        self.register_variable(String("model_file", causality=par, variability=fixed,
                                      description="model file (rwadist.model JSON); empty: the one in the FMU "
                                                  "resources"))
        self.register_variable(Boolean("use_wheel_acceleration", causality=par, variability=fixed,
                                       description="take the acceleration from the wheel_acceleration input "
                                                   "(else the previous step's mean rate of wheel_speed)"))
        self.register_variable(Integer("seed", causality=par, variability=fixed,
                                       description="random line phases from this seed; -1: the model file's "
                                                   "phases (0)"))
        self.register_variable(Boolean("imbalance", causality=par, variability=fixed,
                                       description="static and dynamic imbalance (h = 1) on"))
        self.register_variable(Boolean("harmonics", causality=par, variability=fixed,
                                       description="all other empirical harmonics on"))
        self.register_variable(Boolean("modes", causality=par, variability=fixed,
                                       description="suspension modes on (off: internal loads reach the "
                                                   "interface directly)"))
        self.register_variable(Boolean("start_steady", causality=par, variability=fixed,
                                       description="start from the steady state at the first speed instead "
                                                   "of rest"))
        for name, description in self._switches:
            self.register_variable(Boolean(name, causality=par, variability=fixed, description=description))
        self.register_variable(RealU("floor_resolution", "Hz", causality=par, variability=fixed,
                                     description="frequency spacing of the broadband-floor multisine (it repeats "
                                                 "after 1/floor_resolution s)"))
        self.register_variable(RealU("max_acceleration", "rad/s2", causality=par, variability=fixed,
                                     description="largest |dΩ/dt| accepted; a faster speed change is an error"))
        self.register_variable(RealU("max_step_size", "s", causality=par, variability=fixed,
                                     description="largest communication step accepted"))
        for i in range(3):
            for j in range(3):
                k = 3 * i + j
                self.register_variable(RealU(
                    f"dcm_{i + 1}{j + 1}", "1", causality=par, variability=fixed,
                    description=f"mounting DCM wheel -> spacecraft, row {i + 1} column {j + 1}",
                    getter=lambda k=k: _live(me).dcm[k], setter=lambda v, k=k: _live(me).dcm.__setitem__(k, float(v))))
        for i, ax in enumerate("xyz"):
            self.register_variable(RealU(
                f"r_{ax}", "m", causality=par, variability=fixed,
                description=f"interface position in the spacecraft frame, {ax}",
                getter=lambda i=i: _live(me).pos[i], setter=lambda v, i=i: _live(me).pos.__setitem__(i, float(v))))
        self._vr_speed = self.vars_by_name("wheel_speed")
        self._vr_accel = self.vars_by_name("wheel_acceleration")
        self._out_index = {}
        for frame, off, suffix, where in (("wheel", 0, "", "wheel frame"),
                                          ("spacecraft", 6, "_sc", "spacecraft frame, about its reference point")):
            for i, (ch, unit, desc) in enumerate(OUTPUTS):
                k = off + i
                self.register_variable(RealU(
                    ch + suffix, unit, causality=out, variability=cont, initial=Fmi2Initial.exact,
                    description=desc if frame == "wheel" else f"{ch} in the {where}",
                    getter=lambda k=k: _live(me)._y[k]))
                self._out_index[self.vars_by_name(ch + suffix)] = k
        self._index_reals()

    def register_variable(self, var, nested=True):
        """pythonfmu's register_variable, with the default getter and setter of a plain (not nested) name
        reaching the instance through a weak reference: pythonfmu's own close over the instance and the
        variable, two reference cycles per variable (see __init__)."""
        if not (nested and "." in var.name):
            me, name = weakref.ref(self), var.local_name
            if var.getter is None:
                var.getter = lambda: getattr(me(), name)
            if var.setter is None and hasattr(self, name) and var.variability != Fmi2Variability.constant:
                var.setter = lambda v: setattr(me(), name, v)
        super().register_variable(var, nested)

    def vars_by_name(self, name):
        """Value reference of the registered variable ``name``."""
        for vr, var in self.vars.items():
            if var.name == name:
                return vr
        raise KeyError(name)

    # Hosts read the outputs (libcosim: every Real) and set the speed every step: a value list
    # indexed by value reference answers them directly instead of pythonfmu's per-variable
    # getter loop (same values, a fraction of the time).  Reals change only through set_real
    # (inputs, parameters) and _set_outputs, which keep the list current.
    def _index_reals(self):
        vrs = sorted(self.vars)
        self._rv: list[float | None] = [None] * (vrs[-1] + 1)
        rv = self._rv
        for vr, var in self.vars.items():
            if isinstance(var, Real):
                rv[vr] = float(var.getter())
        outs = sorted(self._out_index)
        self._out0 = outs[0]
        if outs != list(range(outs[0], outs[0] + len(outs))) or \
                [self._out_index[v] for v in outs] != list(range(len(outs))):
            raise RuntimeError("outputs must have consecutive value references in output order")

    def _set_outputs(self, y):
        self._y = y
        self._rv[self._out0:self._out0 + len(y)] = y

    # No exception may leave a method pythonfmu calls: its native layer then releases the slave's
    # Python objects once (handle_py_exception) and again when the host frees the instance -- a
    # double free that crashes the host later.  A wrong value reference or type is logged, flagged
    # (fmi2Error through the native layer) and answered with NaN, 0, False or "" values.
    def _refuse(self, what, exc, n, fill):
        self._log_error(f"{what}: {exc}")
        return [fill] * n

    def get_real(self, vrs):
        rv = self._rv
        try:
            out = [rv[vr] for vr in vrs]
        except (IndexError, TypeError):
            out = [None]
        if None in out:
            try:
                return super().get_real(vrs)    # names the unknown or non-Real variable
            except Exception as exc:
                return self._refuse("fmi2GetReal", exc, len(vrs), math.nan)
        return out

    def set_real(self, vrs, values):
        rv = self._rv
        for vr, v in zip(vrs, values):
            try:
                if vr == self._vr_speed:
                    self.wheel_speed = v
                elif vr == self._vr_accel:
                    self.wheel_acceleration = v
                else:
                    super().set_real([vr], [v])
                rv[vr] = float(v)
            except Exception as exc:
                self._log_error(f"fmi2SetReal of value reference {vr}: {exc}")

    def get_integer(self, vrs):
        try:
            return super().get_integer(vrs)
        except Exception as exc:
            return self._refuse("fmi2GetInteger", exc, len(vrs), 0)

    def get_boolean(self, vrs):
        try:
            return super().get_boolean(vrs)
        except Exception as exc:
            return self._refuse("fmi2GetBoolean", exc, len(vrs), False)

    def get_string(self, vrs):
        try:
            return super().get_string(vrs)
        except Exception as exc:
            return self._refuse("fmi2GetString", exc, len(vrs), "")

    def set_integer(self, vrs, values):
        try:
            super().set_integer(vrs, values)
        except Exception as exc:
            self._log_error(f"fmi2SetInteger: {exc}")

    def set_boolean(self, vrs, values):
        try:
            super().set_boolean(vrs, values)
        except Exception as exc:
            self._log_error(f"fmi2SetBoolean: {exc}")

    def set_string(self, vrs, values):
        try:
            super().set_string(vrs, values)
        except Exception as exc:
            self._log_error(f"fmi2SetString: {exc}")

    # ------------------------------------------------------------ modelDescription
    def to_xml(self, model_options=dict()):
        root = super().to_xml(model_options)
        defs = Element("UnitDefinitions")
        for name, exps in UNITS.items():
            SubElement(SubElement(defs, "Unit", name=name), "BaseUnit", {k: str(v) for k, v in exps.items()})
        idx = list(root).index(root.find("CoSimulation")) + 1
        root.insert(idx, defs)
        return root

    # ------------------------------------------------------------ FMI
    def _log_error(self, msg):
        """Log ``msg`` at fmi2Error and flag it to the native layer (the FMI call returns fmi2Error)."""
        self.log(f"rwadist wheel: {msg}", Fmi2Status.error)
        if self._flag_error is not None:
            self._flag_error()

    def _fail(self, msg):
        self.error = msg
        self._log_error(msg)
        return False

    def setup_experiment(self, start_time, stop_time=None, tolerance=None):
        t0 = float(start_time)
        if not math.isfinite(t0):
            self._log_error(f"fmi2SetupExperiment: start time {t0!r} is not finite")
            return
        self._t_start = t0

    def exit_initialization_mode(self):
        rt = self.rt
        try:
            path = self.model_file or os.path.join(self.resources, MODEL_FILE)
            doc = rt.read_document(path)
            params, lines = rt.model_from_doc(doc, path)
            effects = rt.effects_from_doc(doc, path)
            laws = effects["laws"]
            seed = int(self.seed)
            if seed < -1:
                raise rt.ModelError(f"seed must be >= 0, or -1 for the model file's phases; got {seed}")
            self.model = rt.WheelRuntime(
                params, lines, seed=None if seed == -1 else seed, imbalance=bool(self.imbalance),
                harmonics=bool(self.harmonics), modes=bool(self.modes), start_steady=bool(self.start_steady),
                max_accel=float(self.max_acceleration), max_step=float(self.max_step_size),
                dcm=self.dcm, position=self.pos, kernel=self._kernel, floor_resolution=float(self.floor_resolution),
                **{name: bool(getattr(self, name)) for name, _ in self._switches}, **effects)
            for d, h in sorted(set(laws) - self.model.laws_used):
                self.log(f"rwadist wheel: amplitude_law of {d} h={h:g} matches no line of the model; ignored",
                         Fmi2Status.warning)
            for j, (d, h, f_mod, _) in enumerate(effects["sidebands"]):
                if j not in self.model.sidebands_used:
                    self.log(f"rwadist wheel: sidebands of {d} h={h:g} (f_mod {f_mod:g} Hz) match no line of the "
                             "model; ignored", Fmi2Status.warning)
            if params.get("modes_assumed") and self.modes:
                self.log("rwadist wheel: the suspension modes of this wheel are ASSUMED (datasheet wheel, not "
                         "measured); the outputs with modes = true are built on assumed values (modes = false: "
                         "hard-mounted, as the datasheet states)", Fmi2Status.warning)
            self.error = None
            w = float(self.wheel_speed)
            if math.isfinite(w):
                a = float(self.wheel_acceleration) if self.use_wheel_acceleration else 0.0
                self.model.outputs_now(w, a if math.isfinite(a) else 0.0)
                if not all(map(math.isfinite, self.model.y)):
                    raise rt.ModelError(f"the outputs at the initial wheel_speed = {w!r} rad/s are not finite")
                self._set_outputs(self.model.y)
            self._t_next = self._t_start
        except Exception as exc:   # never let it reach pythonfmu (it would be fmi2Fatal)
            self.model = None
            self._fail(f"initialisation failed: {exc}")

    def do_step(self, current_time, step_size):
        if self.model is None:
            return self._fail(f"cannot step: {self.error}")
        t_next = self._t_next
        if not (math.isfinite(current_time) and abs(current_time - t_next) <= 1e-9 * max(1.0, abs(current_time))):
            # FMI 2.0: a communication point is the previous one plus the previous step
            self._log_error(f"step rejected: communication point {current_time:.12g} s does not continue the last "
                            f"step (expected {t_next:.12g} s)")
            return False
        try:
            w = float(self.wheel_speed)
            a = float(self.wheel_acceleration) if self.use_wheel_acceleration else None
            # the model's clock is the host's: time since the start time (not the sum of the steps)
            y = self.model.step12(w, a, step_size, current_time - self._t_start)
            if not all(map(math.isfinite, y)):
                return self._fail(f"step at t = {current_time:.9g} s produced a non-finite output (wheel_speed = "
                                  f"{w!r} rad/s); the outputs keep the last finite values")
            self._set_outputs(y)
            self._t_next = current_time + step_size
            if self.model.has_floor and not self._floor_warned and self.model.floor_f_max * 2 * step_size > 1:
                self._floor_warned = True
                self.log(f"rwadist wheel: the broadband floors reach {self.model.floor_f_max:g} Hz, above the "
                         f"{0.5 / step_size:g} Hz a {step_size:g}-s step samples; that content folds back",
                         Fmi2Status.warning)
            return True
        except self.rt.ModelError as exc:
            return self._fail(f"step at t = {current_time:.9g} s rejected: {exc}")
        except Exception as exc:   # anything unforeseen: still no fmi2Fatal
            return self._fail(f"step at t = {current_time:.9g} s failed: {type(exc).__name__}: {exc}")
