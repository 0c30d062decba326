"""Every module of ``rwadist`` imports when it is the first one imported (a user's script, a test file, a worker
process may start from any of them).

tests/test_architecture.py checks the import graph from the source; a registry's plug-in loading is no edge there
(rwadist.diagnose.effects imports every ``rwadist/effects/*_diagnose.py``), yet it made one at run time:
``import rwadist.effects.cross_coupling_diagnose`` in a fresh interpreter imported the diagnose package, whose
registry imported ``lever_arm_noise_diagnose``, which imports ``CrossCoupling`` from the half-made module (a circular
ImportError).  Here each module is imported first for real: in one fresh interpreter, every ``rwadist`` module
dropped from ``sys.modules`` before the next is imported (rwadist's own imports in the order of a fresh process; the
third-party libraries stay loaded, which a process per module would load again each time).
"""
from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]

#: modules not importable on their own by design: the FMU slave template is rendered into a built FMU by
#: rwadist/fmu/build.py and reads the FMU's resources when imported there
NOT_IMPORTED_ALONE = {"rwadist.fmu.slave_template"}

CHILD = """
import importlib, json, pkgutil, sys, traceback
import rwadist

names = sorted(m.name for m in pkgutil.walk_packages(rwadist.__path__, "rwadist."))
failed = {}
for name in names:
    for key in [k for k in sys.modules if k == "rwadist" or k.startswith("rwadist.")]:
        del sys.modules[key]
    try:
        importlib.import_module(name)
    except Exception:
        failed[name] = traceback.format_exc(limit=-3)
print(json.dumps({"names": names, "failed": failed}))
"""


@pytest.mark.slow
def test_every_module_imports_first():
    # run in the repository's root: the child's sys.path starts there (``-c``), so it imports these sources
    out = subprocess.run([sys.executable, "-c", CHILD], capture_output=True, text=True, check=True, cwd=ROOT)
    got = json.loads(out.stdout.strip().splitlines()[-1])
    assert len(got["names"]) > 100                      # the walk saw the package, not an empty path
    failed = {k: v for k, v in got["failed"].items() if k not in NOT_IMPORTED_ALONE}
    assert not failed, "modules that fail when imported first:\n" + "\n".join(f"{k}:\n{v}" for k, v in failed.items())
    assert set(got["failed"]) <= NOT_IMPORTED_ALONE
