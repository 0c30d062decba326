/* A minimal FMI 2.0 co-simulation host in C (no Python): loads an FMU's shared library (dlopen; LoadLibrary on
 * Windows), instantiates it, sets parameters, and steps a wheel-speed ramp with fmi2DoStep.  Used by
 * tests/test_fmu_native.py (outputs of a host without Python; the same host cross-compiled for Windows runs the
 * FMU's win64 DLL under Wine) and benchmarks/bench_fmu_native.py (steps per second of the native step alone).
 *
 *   c_host LIB GUID N_STEPS H W0 W1 [name=value ...] [resources=URI] [every=K]
 *
 * The speed ramps linearly from W0 to W1 rad/s over the N steps (input value reference 0, the
 * acceleration input 1 gets the slope); name=value sets a parameter by value reference:
 * r<vr>=x (Real), i<vr>=n (Integer), b<vr>=0|1 (Boolean).  resources=URI is the fmi2Instantiate resource
 * location (file:///.../resources): the native C FMU needs none (default ""), the pythonfmu FMU needs it (it
 * imports its slave from there; the host then needs libpython loaded, e.g. LD_PRELOAD).  Prints the 12 outputs (value references
 * 26..37) after the last step with %.17g, then "cpu_steps_per_s <rate>" (process CPU time) and
 * "steps_per_s <rate>" (wall clock) to stderr.  every=K: the 12 outputs after every K-th step too (one line each,
 * the step number then the outputs, %.17g), before the final ones. */
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "fmi2/fmi2Functions.h"

#ifdef _WIN32
#include <windows.h>
typedef HMODULE Lib;
static Lib lib_open(const char *path) { return LoadLibraryA(path); }
static void *lib_sym(Lib lib, const char *name) { return (void *)GetProcAddress(lib, name); }
static void lib_close(Lib lib) { FreeLibrary(lib); }
static const char *lib_error(void) { return "LoadLibrary failed"; }
/* seconds of the wall clock and of this process's CPU */
static double wall_s(void)
{
    LARGE_INTEGER f, c;
    QueryPerformanceFrequency(&f);
    QueryPerformanceCounter(&c);
    return (double)c.QuadPart / (double)f.QuadPart;
}
static double cpu_s(void)
{
    FILETIME a, b, k, u;
    GetProcessTimes(GetCurrentProcess(), &a, &b, &k, &u);
    return 1e-7 * (double)(((unsigned long long)u.dwHighDateTime << 32) | u.dwLowDateTime);
}
#else
#include <dlfcn.h>
typedef void *Lib;
static Lib lib_open(const char *path) { return dlopen(path, RTLD_NOW | RTLD_LOCAL); }
static void *lib_sym(Lib lib, const char *name) { return dlsym(lib, name); }
static void lib_close(Lib lib) { dlclose(lib); }
static const char *lib_error(void) { return dlerror(); }
static double wall_s(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}
static double cpu_s(void)
{
    struct timespec t;
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}
#endif

static void logger(fmi2ComponentEnvironment env, fmi2String name, fmi2Status status, fmi2String category,
                   fmi2String message, ...)
{
    (void)env;
    va_list ap;
    va_start(ap, message);
    fprintf(stderr, "[%s %d %s] ", name, (int)status, category);
    vfprintf(stderr, message, ap);
    fprintf(stderr, "\n");
    va_end(ap);
}

#define LOAD(T, name)                                                   \
    T name = (T)lib_sym(lib, #name);                                      \
    if (!name) {                                                        \
        fprintf(stderr, "missing %s\n", #name);                         \
        return 2;                                                       \
    }

int main(int argc, char **argv)
{
    if (argc < 7) {
        fprintf(stderr, "usage: %s LIB GUID N_STEPS H W0 W1 [r<vr>=x i<vr>=n b<vr>=0|1 ...] [every=K]\n", argv[0]);
        return 2;
    }
    Lib lib = lib_open(argv[1]);
    if (!lib) {
        fprintf(stderr, "cannot load %s: %s\n", argv[1], lib_error());
        return 2;
    }
    LOAD(fmi2InstantiateTYPE *, fmi2Instantiate)
    LOAD(fmi2SetupExperimentTYPE *, fmi2SetupExperiment)
    LOAD(fmi2EnterInitializationModeTYPE *, fmi2EnterInitializationMode)
    LOAD(fmi2ExitInitializationModeTYPE *, fmi2ExitInitializationMode)
    LOAD(fmi2SetRealTYPE *, fmi2SetReal)
    LOAD(fmi2SetIntegerTYPE *, fmi2SetInteger)
    LOAD(fmi2SetBooleanTYPE *, fmi2SetBoolean)
    LOAD(fmi2GetRealTYPE *, fmi2GetReal)
    LOAD(fmi2DoStepTYPE *, fmi2DoStep)
    LOAD(fmi2TerminateTYPE *, fmi2Terminate)
    LOAD(fmi2FreeInstanceTYPE *, fmi2FreeInstance)
    const long n = atol(argv[3]);
    const double h = atof(argv[4]), w0 = atof(argv[5]), w1 = atof(argv[6]);
    const char *resources = "";
    long every = 0;
    for (int i = 7; i < argc; i++)
        if (strncmp(argv[i], "resources=", 10) == 0)
            resources = argv[i] + 10;
        else if (strncmp(argv[i], "every=", 6) == 0)
            every = atol(argv[i] + 6);
    fmi2CallbackFunctions cb = {logger, calloc, free, NULL, NULL};
    fmi2Component c = fmi2Instantiate("c_host", fmi2CoSimulation, argv[2], resources, &cb, fmi2False, fmi2False);
    if (!c)
        return 3;
    if (fmi2SetupExperiment(c, fmi2False, 0.0, 0.0, fmi2False, 0.0) > fmi2Warning ||
        fmi2EnterInitializationMode(c) > fmi2Warning)
        return 3;
    for (int i = 7; i < argc; i++) {
        if (strncmp(argv[i], "resources=", 10) == 0 || strncmp(argv[i], "every=", 6) == 0)
            continue;
        const char kind = argv[i][0];
        char *eq = strchr(argv[i], '=');
        if (!eq)
            return 2;
        const fmi2ValueReference vr = (fmi2ValueReference)atoi(argv[i] + 1);
        fmi2Status s;
        if (kind == 'r') {
            const fmi2Real v = atof(eq + 1);
            s = fmi2SetReal(c, &vr, 1, &v);
        } else if (kind == 'i') {
            const fmi2Integer v = atoi(eq + 1);
            s = fmi2SetInteger(c, &vr, 1, &v);
        } else {
            const fmi2Boolean v = atoi(eq + 1) != 0;
            s = fmi2SetBoolean(c, &vr, 1, &v);
        }
        if (s > fmi2Warning)
            return 3;
    }
    const fmi2ValueReference in[2] = {0, 1};
    const double slope = n > 0 ? (w1 - w0) / (n * h) : 0.0;
    double u[2] = {w0, slope};
    if (fmi2SetReal(c, in, 2, u) > fmi2Warning || fmi2ExitInitializationMode(c) > fmi2Warning)
        return 3;
    fmi2ValueReference out_vr[12];
    double y[12];
    for (int k = 0; k < 12; k++)
        out_vr[k] = 26 + k;
    const double a = wall_s(), cpu0 = cpu_s();
    for (long k = 0; k < n; k++) {
        u[0] = w0 + (w1 - w0) * (double)k / (double)n;
        if (fmi2SetReal(c, in, 2, u) > fmi2Warning || fmi2DoStep(c, k * h, h, fmi2True) > fmi2Warning ||
            fmi2GetReal(c, out_vr, 12, y) > fmi2Warning) {
            fprintf(stderr, "step %ld failed\n", k);
            return 4;
        }
        if (every > 0 && (k + 1) % every == 0) {
            printf("%ld", k + 1);
            for (int j = 0; j < 12; j++)
                printf(" %.17g", y[j]);
            printf("\n");
        }
    }
    const double dc = cpu_s() - cpu0, dt = wall_s() - a;
    for (int k = 0; k < 12; k++)
        printf("%.17g\n", y[k]);
    /* CPU time of this process too (a loaded machine time-slices the wall clock); the wall-clock rate last */
    fprintf(stderr, "cpu_steps_per_s %.6g\n", n / dc);
    fprintf(stderr, "steps_per_s %.6g\n", n / dt);
    fmi2Terminate(c);
    fmi2FreeInstance(c);
    lib_close(lib);
    return 0;
}
