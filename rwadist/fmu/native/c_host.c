/* A minimal co-simulation host in C (no Python), for FMI 2.0 or (built with -DFMI3) FMI 3.0: loads an FMU's shared
 * library (dlopen; LoadLibrary on Windows), instantiates it, sets parameters, and steps a wheel-speed ramp with
 * fmiXDoStep.  Used by tests/test_fmu_native.py (outputs of a host without Python), tests/test_fmu_win64.py (the
 * same host cross-compiled for Windows runs the FMU's win64 / x86_64-windows DLL under Wine, FMI 2.0 and 3.0) and
 * benchmarks/bench_fmu_native.py (steps per second of the native step alone).
 *
 *   c_host LIB GUID N_STEPS H W0 W1 [name=value ...] [resources=URI] [every=K]
 *
 * The speed ramps linearly from W0 to W1 rad/s over the N steps (input value reference 0, the acceleration input 1
 * gets the slope); name=value sets a parameter by value reference: r<vr>=x (Real / Float64), i<vr>=n (Integer /
 * Int32), b<vr>=0|1 (Boolean).  resources=URI is the fmi2Instantiate resource location (file:///.../resources;
 * FMI 3.0: the resource path): the native C FMU needs none (default ""), the pythonfmu FMU needs it (it imports its
 * slave from there; the host then needs libpython loaded, e.g. LD_PRELOAD).  Prints the 12 outputs (value
 * references 26..37) after the last step with %.17g, then "cpu_steps_per_s <rate>" (process CPU time) and
 * "steps_per_s <rate>" (wall clock) to stderr.  every=K: the 12 outputs after every K-th step too (one line each, the
 * step number then the outputs, %.17g), before the final ones. */
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#ifdef FMI3
#include "fmi3/fmi3Functions.h"
typedef fmi3Instance Inst;
typedef fmi3Status Status;
typedef fmi3ValueReference Vr;
#define OK_OR_WARNING(s) ((s) <= fmi3Warning)
#else
#include "fmi2/fmi2Functions.h"
typedef fmi2Component Inst;
typedef fmi2Status Status;
typedef fmi2ValueReference Vr;
#define OK_OR_WARNING(s) ((s) <= fmi2Warning)
#endif

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

/* the FMI functions this host calls: member, FMI 3.0 name, FMI 2.0 name */
#define FUNCTIONS(X)                                                                                              \
    X(enter, EnterInitializationMode, EnterInitializationMode) X(exit_init, ExitInitializationMode,               \
                                                                 ExitInitializationMode)                          \
    X(set_real, SetFloat64, SetReal) X(set_int, SetInt32, SetInteger) X(set_bool, SetBoolean, SetBoolean)         \
    X(get_real, GetFloat64, GetReal) X(do_step, DoStep, DoStep) X(terminate, Terminate, Terminate)                \
    X(free_instance, FreeInstance, FreeInstance)
#ifdef FMI3
#define TYPE_OF(n3, n2) fmi3##n3##TYPE
#define NAME_OF(n3, n2) "fmi3" #n3
#define N_VALUES(n) , (n)
#else
#define TYPE_OF(n3, n2) fmi2##n2##TYPE
#define NAME_OF(n3, n2) "fmi2" #n2
#define N_VALUES(n)
#endif
#define MEMBER(m, n3, n2) TYPE_OF(n3, n2) *m;
static struct { FUNCTIONS(MEMBER) } fmi;

#ifdef FMI3
static void logger(fmi3InstanceEnvironment env, fmi3Status status, fmi3String category, fmi3String message)
{
    (void)env;
    fprintf(stderr, "[%d %s] %s\n", (int)status, category ? category : "", message);
}
#else
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
#endif

/* the FMI functions from lib; 0 when one is missing */
static int load(Lib lib)
{
#define LOAD(m, n3, n2)                                                                                           \
    if (!(fmi.m = (TYPE_OF(n3, n2) *)lib_sym(lib, NAME_OF(n3, n2)))) {                                            \
        fprintf(stderr, "missing %s\n", NAME_OF(n3, n2));                                                         \
        return 0;                                                                                                 \
    }
    FUNCTIONS(LOAD)
    return 1;
}

/* instantiate and enter initialization mode (start time 0); NULL on failure */
static Inst start(Lib lib, const char *guid, const char *resources)
{
#ifdef FMI3
    fmi3InstantiateCoSimulationTYPE *instantiate =
        (fmi3InstantiateCoSimulationTYPE *)lib_sym(lib, "fmi3InstantiateCoSimulation");
    Inst c = instantiate ? instantiate("c_host", guid, resources[0] ? resources : NULL, fmi3False, fmi3False,
                                       fmi3False, fmi3False, NULL, 0, NULL, logger, NULL)
                         : NULL;
    if (!c || !OK_OR_WARNING(fmi.enter(c, fmi3False, 0.0, 0.0, fmi3False, 0.0)))
        return NULL;
#else
    static fmi2CallbackFunctions cb = {logger, calloc, free, NULL, NULL};
    fmi2InstantiateTYPE *instantiate = (fmi2InstantiateTYPE *)lib_sym(lib, "fmi2Instantiate");
    fmi2SetupExperimentTYPE *setup = (fmi2SetupExperimentTYPE *)lib_sym(lib, "fmi2SetupExperiment");
    Inst c = instantiate && setup ? instantiate("c_host", fmi2CoSimulation, guid, resources, &cb, fmi2False,
                                                fmi2False)
                                  : NULL;
    if (!c || !OK_OR_WARNING(setup(c, fmi2False, 0.0, 0.0, fmi2False, 0.0)) || !OK_OR_WARNING(fmi.enter(c)))
        return NULL;
#endif
    return c;
}

/* one name=value argument (r<vr>=x, i<vr>=n, b<vr>=0|1): 0 when malformed or refused */
static int set_parameter(Inst c, const char *arg)
{
    const char *eq = strchr(arg, '=');
    if (!eq)
        return 0;
    const Vr vr = (Vr)atoi(arg + 1);
    if (arg[0] == 'r') {
        const double v = atof(eq + 1);
        return OK_OR_WARNING(fmi.set_real(c, &vr, 1, &v N_VALUES(1)));
    }
    if (arg[0] == 'i') {
        const int v = atoi(eq + 1);
        return OK_OR_WARNING(fmi.set_int(c, &vr, 1, &v N_VALUES(1)));
    }
#ifdef FMI3
    const fmi3Boolean v = atoi(eq + 1) != 0;
#else
    const fmi2Boolean v = atoi(eq + 1) != 0;
#endif
    return OK_OR_WARNING(fmi.set_bool(c, &vr, 1, &v N_VALUES(1)));
}

/* the ramp: n steps of h from w0 to w1 rad/s; y: the 12 outputs after the last; every: print every K-th step */
static int ramp(Inst c, long n, double h, double w0, double w1, long every, double y[12])
{
    const Vr in[2] = {0, 1};
    Vr out_vr[12];
    for (int k = 0; k < 12; k++)
        out_vr[k] = (Vr)(26 + k);
    double u[2] = {w0, n > 0 ? (w1 - w0) / (n * h) : 0.0};
    if (!OK_OR_WARNING(fmi.set_real(c, in, 2, u N_VALUES(2))) || !OK_OR_WARNING(fmi.exit_init(c)))
        return 3;
    for (long k = 0; k < n; k++) {
        u[0] = w0 + (w1 - w0) * (double)k / (double)n;
        Status s = fmi.set_real(c, in, 2, u N_VALUES(2));
#ifdef FMI3
        fmi3Boolean flag;
        fmi3Float64 last;
        s = OK_OR_WARNING(s) ? fmi.do_step(c, k * h, h, fmi3True, &flag, &flag, &flag, &last) : s;
#else
        s = OK_OR_WARNING(s) ? fmi.do_step(c, k * h, h, fmi2True) : s;
#endif
        if (!OK_OR_WARNING(s) || !OK_OR_WARNING(fmi.get_real(c, out_vr, 12, y N_VALUES(12)))) {
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
    return 0;
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
    if (!load(lib))
        return 2;
    const long n = atol(argv[3]);
    const double h = atof(argv[4]), w0 = atof(argv[5]), w1 = atof(argv[6]);
    const char *resources = "";
    long every = 0;
    for (int i = 7; i < argc; i++)
        if (strncmp(argv[i], "resources=", 10) == 0)
            resources = argv[i] + 10;
        else if (strncmp(argv[i], "every=", 6) == 0)
            every = atol(argv[i] + 6);
    Inst c = start(lib, argv[2], resources);
    if (!c)
        return 3;
    for (int i = 7; i < argc; i++)
        if (strncmp(argv[i], "resources=", 10) != 0 && strncmp(argv[i], "every=", 6) != 0 &&
            !set_parameter(c, argv[i]))
            return 3;
    double y[12] = {0};
    const double a = wall_s(), cpu0 = cpu_s();
    const int rc = ramp(c, n, h, w0, w1, every, y);
    if (rc)
        return rc;
    const double dc = cpu_s() - cpu0, dt = wall_s() - a;
    for (int k = 0; k < 12; k++)
        printf("%.17g\n", y[k]);
    /* CPU time of this process too (a loaded machine time-slices the wall clock); the wall-clock rate last */
    fprintf(stderr, "cpu_steps_per_s %.6g\n", n / dc);
    fprintf(stderr, "steps_per_s %.6g\n", n / dt);
    fmi.terminate(c);
    fmi.free_instance(c);
    lib_close(lib);
    return 0;
}
