"""Effect families of ``rwadist diagnose``: each behind the protocol of :mod:`rwadist.diagnose.effects.base` and
listed in its registry.

A family is the diagnose hypothesis of one effect kind and lives with its element (:mod:`rwadist.effects`):
``rwadist/effects/<kind>_diagnose.py``.  Every such module is imported by the first :func:`family_classes` (a new
family is one new file: nothing else to edit), not when this package is: a family module imports the diagnose
package, so importing one first (``import rwadist.effects.cross_coupling_diagnose``) ran this loop while it was half
made, and a family importing it (``lever_arm_noise_diagnose``) failed with a circular ImportError.  A family
registered from elsewhere (a test's toy kind) is asked as soon as it is registered.  :func:`family_classes` lists the
registry in ``order``.
"""
from __future__ import annotations

import importlib
import pkgutil

from ... import effects as _elements
from .base import REGISTRY, Effect, register, schema_entry

_loaded = False


def _load_families() -> None:
    """Import every family module of :mod:`rwadist.effects` (``<kind>_diagnose.py``: each registers itself), once."""
    global _loaded
    if _loaded:
        return
    for info in sorted(pkgutil.iter_modules(_elements.__path__), key=lambda m: m.name):
        if info.name.endswith(_elements.DIAGNOSE_SUFFIX):
            importlib.import_module(f"{_elements.__name__}.{info.name}")
    _loaded = True


def family_classes() -> tuple:
    """The effect families in the order the search asks them for candidates (the registry as it is now, every family
    module of :mod:`rwadist.effects` imported)."""
    _load_families()
    return tuple(sorted(REGISTRY.values(), key=lambda cls: cls.order))


__all__ = ["REGISTRY", "Effect", "family_classes", "register", "schema_entry"]
