"""The native FMU's Windows binary (issue 35): cross-compiled with mingw-w64 into binaries/win64 (FMI 3.0:
x86_64-windows), it imports system DLLs only, and the project's C host, cross-compiled too and run under Wine,
gives the outputs of the Linux binary driven by the same host over a spin-up 0 → 6000 rpm with every effect on --
for the FMI 2.0 FMU and for the FMI 3.0 FMU (the host built for FMI 3.0).

Needs Debian's mingw-w64 gcc (gcc-mingw-w64-x86-64-win32) and wine64.  .ci/run installs them and sets
RWADIST_REQUIRE_WIN64=1 (as does CI=true): then their absence fails these tests instead of skipping them."""
from __future__ import annotations

import os
import re
import shutil
import subprocess
import sys
import zipfile
from pathlib import Path

import numpy as np
import pytest

from rwadist.fmu.build import native_supported

pytestmark = pytest.mark.skipif(not (native_supported() and shutil.which(os.environ.get("CC", "cc"))),
                                reason="the native FMU's binary is built on Linux x86-64 with a C compiler")

from rwadist.fmu.native_build import (  # noqa: E402
    MINGW_HINT,
    PLATFORMS,
    build_native_fmu,
    compile_c_host,
    windows_compiler,
)

sys.path.insert(0, str(Path(__file__).resolve().parent))
from test_fmu_native import POS, R, wheel_doc  # noqa: E402

#: Windows DLLs every Windows has (the C runtime msvcrt, or the UCRT's api sets)
SYSTEM_DLLS = re.compile(r"^(kernel32|msvcrt|ucrtbase|api-ms-win-crt-[a-z0-9-]+)\.dll$", re.I)


def wine() -> str | None:
    """The Wine loader for 64-bit programs (Debian's wine64 puts it in /usr/lib/wine)."""
    for name in ("wine64", "wine"):
        if path := shutil.which(name):
            return path
    return "/usr/lib/wine/wine64" if os.access("/usr/lib/wine/wine64", os.X_OK) else None


def _need(what: str, ok: bool) -> None:
    """Skip without the tool, except where the run requires it (RWADIST_REQUIRE_WIN64=1, set by .ci/run, or CI=true):
    there its absence fails."""
    if ok:
        return
    message = f"{what} not found: {MINGW_HINT}; apt-get install wine64"
    if os.environ.get("RWADIST_REQUIRE_WIN64") or os.environ.get("CI"):
        pytest.fail(f"{message} (required here: .ci/run installs them)")
    pytest.skip(message)


@pytest.fixture(scope="module")
def extracted(tmp_path_factory):
    """The native FMUs (FMI 2.0 in wheel/, FMI 3.0 in wheel3/) of the wheel with every effect class, with Linux and
    Windows binaries, unzipped."""
    _need("mingw-w64 (x86_64-w64-mingw32-gcc)", windows_compiler() is not None)
    d = tmp_path_factory.mktemp("win64")
    for version, folder in ((2, "wheel"), (3, "wheel3")):
        fmu = build_native_fmu(wheel_doc(), d / f"{folder}.fmu", tag="win", windows=True, fmi_version=version)
        with zipfile.ZipFile(fmu) as z:
            z.extractall(d / folder)
    return d


@pytest.mark.parametrize("version", [2, 3])
def test_dll_imports_system_dlls_only(extracted, version):
    """objdump -p of the DLL: it imports KERNEL32 and the C runtime only, and exports the FMI functions."""
    folder = "wheel" if version == 2 else "wheel3"
    dll = extracted / folder / "binaries" / PLATFORMS[version]["windows"] / "RwadistWheelC_win.dll"
    objdump = shutil.which("x86_64-w64-mingw32-objdump") or shutil.which("objdump")
    res = subprocess.run([objdump, "-p", str(dll)], capture_output=True, text=True, check=True)
    imports = re.findall(r"DLL Name: (\S+)", res.stdout)
    print(f"FMI {version}.0 win64 DLL imports:", imports)
    assert imports and all(SYSTEM_DLLS.match(name) for name in imports), imports
    names = ("Instantiate", "DoStep", "GetReal", "SerializeFMUstate", "FreeInstance") if version == 2 else (
        "InstantiateCoSimulation", "DoStep", "GetFloat64", "SerializeFMUState", "FreeInstance")
    for fn in names:
        assert re.search(rf"\]\s+fmi{version}{fn}\b", res.stdout), fn


@pytest.mark.parametrize("version", [2, 3])
def test_c_host_under_wine_equals_linux(extracted, version):
    """Spin-up 0 → 6000 rpm in 2 s (1-ms steps, acceleration input, seed 3), every effect class on, a mounting
    off the reference point: the 12 outputs after every step from the Windows DLL (c_host.exe under Wine) equal the
    Linux library's (c_host) within 1e-12 of the largest output; FMI 2.0 and FMI 3.0 (hosts built for each)."""
    _need("wine64", wine() is not None)
    d, folder = extracted, "wheel" if version == 2 else "wheel3"
    host = compile_c_host(d / f"c_host{version}", fmi_version=version)
    host_exe = compile_c_host(d / f"c_host{version}.exe", windows=True, fmi_version=version)
    md = (d / folder / "modelDescription.xml").read_text()
    guid = re.search(r'(?:guid|instantiationToken)="([^"]+)"', md).group(1)
    params = ["i4=3", "b3=1"] + [f"r{14 + 3 * i + j}={float(R[i][j])!r}" for i in range(3) for j in range(3)] + \
        [f"r{23 + k}={float(POS[k])!r}" for k in range(3)]
    args = [guid, "2000", "1e-3", "0", repr(6000 * np.pi / 30), *params, "every=1"]
    lib = d / folder / "binaries" / PLATFORMS[version]["linux"] / "RwadistWheelC_win.so"
    dll = d / folder / "binaries" / PLATFORMS[version]["windows"] / "RwadistWheelC_win.dll"
    linux = subprocess.run([str(host), str(lib), *args], capture_output=True, text=True, check=True)
    env = dict(os.environ, WINEDEBUG="-all")
    windows = subprocess.run([wine(), str(host_exe), str(dll), *args], capture_output=True, text=True, env=env,
                             timeout=600)
    assert windows.returncode == 0, windows.stderr[-2000:]

    def rows(text):
        return np.array([[float(x) for x in ln.split()[1:]] for ln in text.splitlines() if len(ln.split()) == 13])

    a, b = rows(windows.stdout), rows(linux.stdout)
    assert a.shape == b.shape == (2000, 12)
    err = np.max(np.abs(a - b)) / np.max(np.abs(b))
    print(f"FMI {version}.0 win64 (Wine) vs linux64, 2000 steps 0 -> 6000 rpm, every effect: max |diff| / max |y| = "
          f"{err:.3g}")
    assert err <= 1e-12


def test_folder_names_and_linux_only_fallback(extracted, tmp_path, monkeypatch):
    """The binaries are where the standards put them, as fmpy (an independent reader) finds them: FMI 2.0 in
    binaries/linux64 and binaries/win64 (FMI 2.0.4 section 2.3), FMI 3.0 in binaries/<arch>-<os> (FMI 3.0.2 section
    2.5.1.4: x86_64-linux, x86_64-windows); without mingw-w64 the build warns how to get it and writes the Linux binary
    only."""
    import fmpy

    from rwadist.presets import preset
    for folder, linux, windows in (("wheel", fmpy.platform, "win64"), ("wheel3", fmpy.platform_tuple,
                                                                       "x86_64-windows")):
        assert sorted(p.name for p in (extracted / folder / "binaries").iterdir()) == sorted([linux, windows])
        assert set(fmpy.supported_platforms(str(extracted / folder))) == {"c-code", "linux64", "win64"}
    monkeypatch.setenv("RWADIST_MINGW_CC", "no-such-mingw-gcc")
    with pytest.warns(RuntimeWarning, match="gcc-mingw-w64-x86-64"):
        fmu = build_native_fmu(preset("ithaco-e").to_model(), tmp_path / "linux_only.fmu")
    names = zipfile.ZipFile(fmu).namelist()
    assert any(n.startswith("binaries/linux64/") for n in names) and not any("win64" in n for n in names)


def test_ci_script_requires_the_windows_tests():
    """.ci/run installs the one mingw-w64 toolchain the build uses and wine64, and sets RWADIST_REQUIRE_WIN64 before
    pytest runs, so that the Windows tests fail rather than skip on CI."""
    text = (Path(__file__).resolve().parents[1] / ".ci" / "run").read_text()
    assert re.search(r"^export RWADIST_REQUIRE_WIN64=1$", text, re.M), "not set"
    assert text.index("export RWADIST_REQUIRE_WIN64=1") < text.index("\npytest ")
    assert "gcc-mingw-w64-x86-64-win32" in text and " gcc-mingw-w64-x86-64 " not in text


def test_cli_says_how_to_get_the_windows_binary(tmp_path, monkeypatch, capsys):
    """Without mingw-w64, `rwadist fmu build --native` writes the Linux-only FMU and a note naming the Debian package;
    the line it prints lists the binaries the FMU carries."""
    from rwadist.cli import main
    monkeypatch.setenv("RWADIST_MINGW_CC", "no-such-mingw-gcc")
    assert main(["fmu", "build", "--native", "--preset", "ithaco-e", "-o", str(tmp_path / "w.fmu")]) == 0
    out = capsys.readouterr().out
    assert "note: no Windows binary" in out and "gcc-mingw-w64-x86-64" in out and "binaries: linux64)" in out
