"""One element per effect kind: everything about one kind of diagnosed effect in one place (issue 34).

An *effect* is what ``rwadist diagnose`` adds to a wheel model besides its harmonics (the model file's ``effects``
list): a periodic speed ripple, a broadband floor, a load-cell offset, ...  In the style of ROSS's one element per
file, each kind is one element, ``rwadist/effects/<kind>.py``: a frozen dataclass derived from
:class:`rwadist.schema.Effect` and registered under its ``kind`` (:func:`rwadist.schema.register`).  It owns

- its fields: the model file's keys, each declared with its check, their JSON in and out and the checks across
  fields; the one reader of the model file (:func:`rwadist.schema.parse_effects`) reads every entry through it, and
  an entry read from a file is written back as read (loading and saving a file changes no byte);
- its one-line text for the console (``rwadist diagnose``, ``rwadist model show``);
- what it does to the wheel's loads, said in a few generic *actions* that every consumer knows without knowing any
  kind: an amplitude law of a line, a filter on the lines of some directions, an amplitude modulation of a line, a
  broadband floor on a channel, a periodic modulation of the wheel speed.  The line spectrum and PSD
  (:mod:`rwadist.broadband`), the extended model (:mod:`rwadist.extended`), the coupling kit and the FMUs (the numpy
  runtime, and the C kernel, which gets them compiled in when the FMU is built) apply the actions;
- its injection into the virtual test stand (``rwadist simulate-test --inject KIND:PARAM=VALUE``).

The element file imports numpy, :mod:`rwadist.schema` and :mod:`rwadist.units` only (and modules of this package
that do the same; :mod:`rwadist.effects.element` is the elements' base): the pythonfmu FMU ships these files byte for
byte beside its copies of the schema and the units (``rwadist fmu build``, a test pins the copies), where they read
a model file given to the FMU at run time on a host with Python and numpy alone.

Its diagnose hypothesis -- the family that proposes the kind from the residual of test data, fits it and is judged
on held-out speeds -- needs scipy and the diagnose engine, so it cannot live in the shipped file: it is the module
``rwadist/effects/<kind>_diagnose.py`` beside it (the element's link to it is that name), found by
:mod:`rwadist.diagnose.effects` and never imported by the element.

Adding a kind is one new file (two when ``rwadist diagnose`` should find it) plus its tests; no other module names
a kind.  A kind registered from anywhere else (a test's toy kind, a user's own) is read, written, shown and applied
the same way (tests/test_effect_elements.py).

The package: one module per kind (its element) and, beside it, ``<kind>_diagnose.py`` (its diagnose family);
:mod:`~rwadist.effects.element`, the elements' base (the hooks with their defaults, ``FMU_SWITCH``, the texts'
helpers) and :mod:`~rwadist.effects.actions`, the generic actions.  The modules that used to name the kinds
dispatch instead: :mod:`rwadist.schema` reads every registered kind; :mod:`rwadist.effects_text` shows the element's
line; :mod:`rwadist.inject` parses and applies the element's injection; :mod:`rwadist.broadband`,
:mod:`rwadist.extended`, ``rwadist.coupling.performance`` and ``rwadist.fmu`` apply the actions (the FMUs' effect
switches are named by the elements' ``FMU_SWITCH``; the pythonfmu FMU refuses a kind its shipped elements do not
read); :mod:`rwadist.diagnose` finds the families here and its ``State`` holds the effect objects, reading its
prediction from their ``contribute``.

Importing this package imports every element module of it (so the schema reads every kind); elements registered
by other modules are read once those are imported.
"""
from __future__ import annotations

import importlib
import pkgutil
from pathlib import Path

#: Suffix of the modules holding the diagnose hypothesis of a kind (scipy, the diagnose engine; not shipped).
DIAGNOSE_SUFFIX = "_diagnose"


def element_module_names() -> list:
    """Names of this package's modules that hold elements (numpy only): every module but the diagnose ones."""
    return [m.name for m in sorted(pkgutil.iter_modules(__path__), key=lambda m: m.name)
            if not m.ispkg and not m.name.endswith(DIAGNOSE_SUFFIX)]


def elements() -> list:
    """Every registered element class (:class:`~rwadist.effects.element.Element`, built in or registered elsewhere),
    in their ``ORDER``."""
    from ..schema import EFFECT_KINDS
    from .element import Element

    found = [c for c in EFFECT_KINDS.values() if isinstance(c, type) and issubclass(c, Element)]
    return sorted(found, key=lambda c: c.ORDER)


def shipped_files() -> list:
    """Paths of the files the pythonfmu FMU ships so its runtime reads every kind: this package's ``__init__.py``
    and its element modules."""
    here = Path(__file__).resolve().parent
    return [here / "__init__.py"] + [here / f"{name}.py" for name in element_module_names()]


for _name in element_module_names():
    importlib.import_module(f"{__name__}.{_name}")
