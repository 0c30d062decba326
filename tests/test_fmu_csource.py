"""The native FMUs' C sources (issue 35): one table of the FMI rules and variables (rwadist/fmu/native/rwadist_fmi_rules.h)
that agrees with the modelDescriptions' variables (rwadist/fmu/native_build.py VARIABLES), and no compiler warning under
-Wall -Wextra in either FMI version's sources or the pythonfmu FMU's native layer."""
from __future__ import annotations

import os
import shutil
import subprocess
import zipfile
from pathlib import Path

import pytest

from rwadist.fmu.build import native_supported

CC = shutil.which(os.environ.get("CC", "cc"))
pytestmark = pytest.mark.skipif(not (native_supported() and CC), reason="needs a C compiler on Linux x86-64")

from rwadist.fmu.native_build import C_SOURCES, VARIABLES, VR_TIME, build_native_fmu  # noqa: E402
from rwadist.fmu.runtime import SWITCH_SLOTS, fmu_switches  # noqa: E402

NATIVE = Path(__file__).resolve().parents[1] / "rwadist" / "fmu" / "native"
PRINT_TABLE = r"""
#include <stdio.h>
#include "rwadist_fmi_rules.h"
int main(void)
{
    static const char *const causality[] = {"input", "parameter", "output", "independent", "none"};
    static const char *const type[] = {"Real", "Integer", "Boolean", "String", "none"};
    for (int fmi = 2; fmi <= 3; fmi++)
        for (unsigned vr = 0; vr < 45; vr++) {
            RwCausality c;
            const RwType t = rw_variable(fmi, vr, &c);
            printf("%d %u %s %s %s\n", fmi, vr, t == RW_NO_TYPE ? "-" : RW_VAR_NAMES[vr], type[t], causality[c]);
        }
    return 0;
}
"""


def test_rules_header_variables_are_the_model_descriptions(tmp_path):
    """Every value reference's name, type and causality in the C table equals the modelDescription's (FMI 2.0: the
    38 variables; FMI 3.0: those plus time), and no other value reference is a variable."""
    (tmp_path / "table.c").write_text(PRINT_TABLE)
    exe = tmp_path / "table"
    subprocess.run([CC, f"-I{NATIVE}", "-o", str(exe), str(tmp_path / "table.c")], check=True)
    got = {}
    for line in subprocess.run([str(exe)], capture_output=True, text=True, check=True).stdout.splitlines():
        fmi, vr, name, typ, caus = line.split()
        got[int(fmi), int(vr)] = (name, typ, caus)
    # the effect switches are named by their elements (wheel_model.h RW_SWITCH_NAMES), the rules only know the slots
    switches = {name for name, _ in fmu_switches()}
    assert len(switches) == SWITCH_SLOTS
    for fmi in (2, 3):
        want = {vr: ("effect_switch" if name in switches else name, typ, "parameter" if caus == "parameter" else caus)
                for vr, (name, typ, caus, *_rest) in enumerate(VARIABLES)}
        if fmi == 3:
            want[VR_TIME] = ("time", "Real", "independent")
        table = {vr: v for (f, vr), v in got.items() if f == fmi and v[0] != "-"}
        assert table == want, {vr: (table.get(vr), want.get(vr)) for vr in set(table) | set(want)
                               if table.get(vr) != want.get(vr)}


@pytest.mark.parametrize("version", [2, 3])
def test_sources_compile_without_warnings(tmp_path, version):
    """The FMU's sources/ (its API file with the wrapper layer, runtime and kernel) under -Wall -Wextra -Werror with
    the host compiler and, where installed, mingw-w64; the pythonfmu FMU's native layer too."""
    from rwadist.fmu.native_build import windows_compiler
    from rwadist.presets import preset
    fmu = build_native_fmu(preset("ithaco-e").to_model(), tmp_path / "w.fmu", fmi_version=version, windows=False)
    with zipfile.ZipFile(fmu) as z:
        z.extractall(tmp_path / "x")
    src = tmp_path / "x" / "sources"
    flags = ["-std=gnu11", "-Wall", "-Wextra", "-Werror", "-fsyntax-only", f"-I{src}"]
    for cc in filter(None, (CC, windows_compiler())):
        res = subprocess.run([cc, *flags, str(src / C_SOURCES[version])], capture_output=True, text=True)
        assert res.returncode == 0, f"{cc}:\n{res.stderr[:3000]}"
    if version == 2:
        res = subprocess.run([CC, "-std=gnu11", "-Wall", "-Wextra", "-Werror", "-fsyntax-only",
                              str(NATIVE / "rwadist_fmu_native.c")], capture_output=True, text=True)
        assert res.returncode == 0, res.stderr[:3000]
