"""The native FMU under memory checkers (issues 17, 35): a hostile C host (rwadist/fmu/native/c_stress.c: instantiate, step,
bad input, get/set/serialize/deserialize state from good, truncated, corrupted and NULL data, reset, free; many
cycles) and random call orders over the FMI state machine (rwadist/fmu/native/c_orders.c, FMI 2.0 and FMI 3.0: every call in
and out of order from every state, FMU states through errors and restores) run the FMU's own sources/ compiled with
AddressSanitizer + UndefinedBehaviorSanitizer (always, wherever gcc or clang has them) and, where valgrind is
installed, the shipped binaries under valgrind: no invalid read, write or free, no leak, and every expectation of the
hosts met (refusals are Error and logged, never Fatal; the replay from a saved state is bit-identical).
"""
from __future__ import annotations

import os
import shutil
import subprocess
import zipfile
from pathlib import Path

import pytest

from rwadist.fmu.build import native_supported

pytest.importorskip("fmpy")
CC = shutil.which(os.environ.get("CC", "cc"))
pytestmark = pytest.mark.skipif(not (native_supported() and CC),
                                reason="the native FMU's binary is built on Linux x86-64 with a C compiler")

import random  # noqa: E402

from test_fmu_native import wheel_doc  # noqa: E402

from rwadist.fmu.native_build import C_SOURCES, PLATFORMS, build_native_fmu  # noqa: E402

NATIVE = Path(__file__).resolve().parents[1] / "rwadist" / "fmu" / "native"
SANITIZE = ["-fsanitize=address,undefined", "-fno-sanitize-recover=all", "-fno-omit-frame-pointer", "-g", "-O1"]


@pytest.fixture(scope="module")
def unpacked(tmp_path_factory):
    """(folder of the extracted native FMU with every effect class, its GUID, its binary)."""
    from fmpy import read_model_description
    d = tmp_path_factory.mktemp("memcheck")
    fmu = build_native_fmu(wheel_doc(), d / "wheel.fmu", windows=False)
    with zipfile.ZipFile(fmu) as z:
        z.extractall(d / "x")
    md = read_model_description(fmu)
    return d / "x", md.guid, d / "x" / "binaries" / "linux64" / f"{md.coSimulation.modelIdentifier}.so"


def _cc(args, what):
    res = subprocess.run([CC, *args], capture_output=True, text=True)
    return res if res.returncode == 0 else pytest.fail(f"{what}: {' '.join(args)}\n{res.stderr}")


def _sanitizers_work(tmp_path) -> bool:
    """True when this compiler builds and runs an ASan+UBSan program (and ASan then catches a planted overflow)."""
    src = tmp_path / "planted.c"
    src.write_text("#include <stdlib.h>\nint main(int c, char **v) { (void)v; volatile char *p = malloc(8);\n"
                   "p[7 + c] = 1; free((void *)p); return 0; }\n")
    exe = tmp_path / "planted"
    # AddressSanitizer alone on the planted bug (UBSan's object-size check would report it first, differently)
    if subprocess.run([CC, "-fsanitize=address", "-g", "-o", str(exe), str(src)], capture_output=True).returncode != 0:
        return False
    res = subprocess.run([str(exe)], capture_output=True, text=True, timeout=60)
    return res.returncode != 0 and "heap-buffer-overflow" in res.stderr


def test_c_stress_host_under_address_sanitizer(unpacked, tmp_path):
    """The FMU's sources/ and the stress host, both built with -fsanitize=address,undefined: 40 cycles, every check
    passes, and ASan/UBSan/LeakSanitizer report nothing (a planted overflow shows the sanitizer is live)."""
    folder, guid, _ = unpacked
    if not _sanitizers_work(tmp_path):
        pytest.skip(f"{CC} cannot build or run AddressSanitizer programs here")
    lib, host = tmp_path / "wheel_asan.so", tmp_path / "c_stress_asan"
    src = folder / "sources"
    _cc([*SANITIZE, "-std=gnu11", "-fPIC", "-shared", "-fvisibility=hidden", f"-I{src}", "-o", str(lib),
         str(src / "rwadist_wheel_fmu.c"), "-lm"], "the FMU's sources with sanitizers")
    _cc([*SANITIZE, f"-I{NATIVE}", "-o", str(host), str(NATIVE / "c_stress.c"), "-ldl", "-lm"], "the stress host")
    env = dict(os.environ, ASAN_OPTIONS="detect_leaks=1:abort_on_error=0", UBSAN_OPTIONS="print_stacktrace=1")
    res = subprocess.run([str(host), str(lib), guid, "40"], capture_output=True, text=True, timeout=600, env=env)
    assert res.returncode == 0, res.stdout + res.stderr[-4000:]
    assert "Sanitizer" not in res.stderr and "runtime error" not in res.stderr, res.stderr[-4000:]
    checks, failures = (int(v) for v in res.stdout.split()[1::2])
    assert failures == 0 and checks > 40 * 300


@pytest.mark.skipif(shutil.which("valgrind") is None, reason="valgrind is not installed (ASan runs above)")
def test_c_stress_host_under_valgrind(unpacked, tmp_path):
    """The shipped binary under valgrind memcheck: 0 errors and no definite or indirect leak over 5 cycles."""
    _, guid, lib = unpacked
    host = tmp_path / "c_stress"
    _cc(["-O1", "-g", f"-I{NATIVE}", "-o", str(host), str(NATIVE / "c_stress.c"), "-ldl", "-lm"], "the stress host")
    res = subprocess.run(["valgrind", "--error-exitcode=9", "--leak-check=full", "--show-leak-kinds=definite,indirect",
                          "--errors-for-leak-kinds=definite,indirect", str(host), str(lib), guid, "5"],
                         capture_output=True, text=True, timeout=900)
    summary = [ln for ln in res.stderr.splitlines() if "ERROR SUMMARY" in ln]
    assert res.returncode == 0, res.stdout + res.stderr[-4000:]
    assert summary and " 0 errors from 0 contexts" in summary[-1], summary
    assert res.stdout.split()[3] == "0"


@pytest.fixture(scope="module")
def both_versions(tmp_path_factory):
    """{FMI version: (sources/ folder, GUID, shipped Linux binary)} of the wheel with every effect class."""
    from fmpy import read_model_description
    d = tmp_path_factory.mktemp("orders")
    out = {}
    for v in (2, 3):
        fmu = build_native_fmu(wheel_doc(), d / f"wheel{v}.fmu", fmi_version=v, windows=False)
        with zipfile.ZipFile(fmu) as z:
            z.extractall(d / f"x{v}")
        md = read_model_description(fmu)
        out[v] = (d / f"x{v}" / "sources", md.guid,
                  d / f"x{v}" / "binaries" / PLATFORMS[v]["linux"] / f"{md.coSimulation.modelIdentifier}.so")
    return out


def _orders_result(res) -> dict:
    assert res.returncode == 0, res.stdout + res.stderr[-4000:]
    words = res.stdout.split()
    return dict(zip(words[::2], map(int, words[1::2])))


@pytest.mark.parametrize("version", [2, 3])
def test_call_orders_under_address_sanitizer(both_versions, tmp_path, version):
    """400 random call orders (c_orders.c) on the FMU's sources built with ASan + UBSan: every Error logged, none
    Fatal, and no sanitizer report; the orders step the wheel and meet errors (the state machine's paths)."""
    src, guid, _ = both_versions[version]
    if not _sanitizers_work(tmp_path):
        pytest.skip(f"{CC} cannot build or run AddressSanitizer programs here")
    lib, host = tmp_path / "wheel_asan.so", tmp_path / "c_orders_asan"
    _cc([*SANITIZE, "-std=gnu11", "-fPIC", "-shared", "-fvisibility=hidden", f"-I{src}", "-o", str(lib),
         str(src / C_SOURCES[version]), "-lm"], "the FMU's sources with sanitizers")
    _cc([*SANITIZE, *(["-DFMI3"] if version == 3 else []), f"-I{NATIVE}", "-o", str(host), str(NATIVE / "c_orders.c"),
         "-ldl", "-lm"], "the call-order host")
    seed = int(os.environ.get("RWADIST_FUZZ_SEED", random.SystemRandom().randrange(1_000_000)))
    env = dict(os.environ, ASAN_OPTIONS="detect_leaks=1:abort_on_error=0", UBSAN_OPTIONS="print_stacktrace=1")
    res = subprocess.run([str(host), str(lib), guid, "400", str(seed)], capture_output=True, text=True, timeout=600,
                         env=env)
    assert "Sanitizer" not in res.stderr and "runtime error" not in res.stderr, (f"RWADIST_FUZZ_SEED={seed}", res.stderr[-4000:])
    got = _orders_result(res)
    print(f"FMI {version}.0, seed {seed}: {got}")
    assert got["failures"] == 0 and got["steps"] > 50 and got["errors"] > 1000, (seed, got)


@pytest.mark.skipif(shutil.which("valgrind") is None, reason="valgrind is not installed (ASan runs above)")
@pytest.mark.parametrize("version", [2, 3])
def test_call_orders_under_valgrind(both_versions, tmp_path, version):
    """The shipped binaries under valgrind memcheck through 100 random call orders: 0 errors, no definite or
    indirect leak."""
    _, guid, lib = both_versions[version]
    host = tmp_path / "c_orders"
    _cc(["-O1", "-g", *(["-DFMI3"] if version == 3 else []), f"-I{NATIVE}", "-o", str(host),
         str(NATIVE / "c_orders.c"), "-ldl", "-lm"], "the call-order host")
    seed = int(os.environ.get("RWADIST_FUZZ_SEED", random.SystemRandom().randrange(1_000_000)))
    res = subprocess.run(["valgrind", "--error-exitcode=9", "--leak-check=full", "--show-leak-kinds=definite,indirect",
                          "--errors-for-leak-kinds=definite,indirect", str(host), str(lib), guid, "100", str(seed)],
                         capture_output=True, text=True, timeout=900)
    summary = [ln for ln in res.stderr.splitlines() if "ERROR SUMMARY" in ln]
    assert summary and " 0 errors from 0 contexts" in summary[-1], (seed, summary, res.stderr[-3000:])
    assert _orders_result(res)["failures"] == 0
