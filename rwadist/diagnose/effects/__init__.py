"""Effect families of ``rwadist diagnose``: each behind the protocol of :mod:`rwadist.diagnose.effects.base` and
listed in its registry.

A family is the diagnose hypothesis of one effect kind and lives with its element (:mod:`rwadist.effects`):
``rwadist/effects/<kind>_diagnose.py``.  Every such module is imported here (a new family is one new file: nothing
else to edit); a family registered from elsewhere (a test's toy kind) is asked as soon as it is registered.
:func:`family_classes` lists the registry in ``order``.
"""
from __future__ import annotations

import importlib
import pkgutil

from ... import effects as _elements
from .base import REGISTRY, Effect, register, schema_entry

for _info in sorted(pkgutil.iter_modules(_elements.__path__), key=lambda m: m.name):
    if _info.name.endswith(_elements.DIAGNOSE_SUFFIX):
        importlib.import_module(f"{_elements.__name__}.{_info.name}")


def family_classes() -> tuple:
    """The effect families in the order the search asks them for candidates (the registry as it is now)."""
    return tuple(sorted(REGISTRY.values(), key=lambda cls: cls.order))


__all__ = ["REGISTRY", "Effect", "family_classes", "register", "schema_entry"]
