"""Effect families of ``rwadist diagnose``: one module per family, each behind the protocol of
:mod:`rwadist.diagnose.effects.base` and listed in its registry.

Every module of this package is imported here (a new family is one new file: nothing else to edit);
:data:`EFFECT_CLASSES` is the registry in ``order``.
"""
from __future__ import annotations

import importlib
import pkgutil

from .base import REGISTRY, Effect, register, schema_entry

for _info in sorted(pkgutil.iter_modules(__path__), key=lambda m: m.name):
    if _info.name != "base":
        importlib.import_module(f"{__name__}.{_info.name}")

#: The effect families in the order the search asks them for candidates.
EFFECT_CLASSES = tuple(sorted(REGISTRY.values(), key=lambda cls: cls.order))

__all__ = ["EFFECT_CLASSES", "REGISTRY", "Effect", "register", "schema_entry"]
