/* A hostile FMI 2.0 host in C for memory checkers (valgrind, AddressSanitizer): loads a wheel FMU's shared library
 * with dlopen and, CYCLES times, instantiates it, steps a speed ramp, feeds it bad input (non-finite speed, a
 * communication point that goes backwards, is NaN or skips ahead, bad step sizes, an unknown value reference; each
 * puts it in FMI 2.0's error state, where it must refuse to step, and a stored FMU state restores the run), gets,
 * sets, serializes and deserializes its FMU state (also from truncated and corrupted bytes, and NULL), checks the
 * replay from a saved state is bit-identical, resets it and frees it.  Every refusal must be fmi2Error; every
 * accepted step must give finite outputs.  Used by tests/test_fmu_memcheck.py and benchmarks/fmu_memory.py.
 *
 *   c_stress LIB.so GUID CYCLES [STATE [WARMUP [RESOURCES_URI]]]
 *
 * STATE 1 (default): the FMU supports FMU state (the native FMU); 0: it must refuse every state call with
 * fmi2Error (the pythonfmu FMU).  Prints "checks <n> failures <m>" and exits 0 only when m == 0; with WARMUP,
 * also "rss_growth_kB <g>": the resident set size at the end minus that after WARMUP cycles (-1: none).
 * RESOURCES_URI: the fmi2Instantiate resource location (file:///.../resources; the pythonfmu FMU needs it). */
#include <dlfcn.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "fmi2/fmi2Functions.h"

static int quiet_errors;

/* resident set size of this process, kB (0 where /proc/self/statm is unreadable) */
static long rss_kb(void)
{
    long pages = 0, resident = 0;
    FILE *f = fopen("/proc/self/statm", "r");
    if (!f)
        return 0;
    if (fscanf(f, "%ld %ld", &pages, &resident) != 2)
        resident = 0;
    fclose(f);
    return resident * (sysconf(_SC_PAGESIZE) / 1024);
}
static long checks, failures;

static void logger(fmi2ComponentEnvironment env, fmi2String name, fmi2Status status, fmi2String category,
                   fmi2String message, ...)
{
    (void)env, (void)name, (void)category;
    if (status == fmi2OK || (quiet_errors && status == fmi2Error))
        return; /* expected refusals and information are not printed */
    va_list ap;
    va_start(ap, message);
    fprintf(stderr, "[%d] ", (int)status);
    vfprintf(stderr, message, ap);
    fprintf(stderr, "\n");
    va_end(ap);
}

#define EXPECT(cond, what)                                                 \
    do {                                                                   \
        checks++;                                                          \
        if (!(cond)) {                                                     \
            failures++;                                                    \
            fprintf(stderr, "FAILED (cycle %d): %s\n", cycle, what);       \
        }                                                                  \
    } while (0)

#define LOAD(name)                                                      \
    name##TYPE *name = (name##TYPE *)dlsym(lib, #name);                 \
    if (!name) {                                                        \
        fprintf(stderr, "missing %s\n", #name);                         \
        return 2;                                                       \
    }

int main(int argc, char **argv)
{
    if (argc < 4) {
        fprintf(stderr, "usage: %s LIB.so GUID CYCLES [STATE 0|1]\n", argv[0]);
        return 2;
    }
    const int cycles = atoi(argv[3]);
    const int has_state = argc > 4 ? atoi(argv[4]) != 0 : 1;
    const int warmup = argc > 5 ? atoi(argv[5]) : -1;
    const char *resources = argc > 6 ? argv[6] : "";
    long rss_warm = 0;
    void *lib = dlopen(argv[1], RTLD_NOW | RTLD_LOCAL);
    if (!lib) {
        fprintf(stderr, "dlopen: %s\n", dlerror());
        return 2;
    }
    LOAD(fmi2Instantiate)
    LOAD(fmi2SetupExperiment)
    LOAD(fmi2EnterInitializationMode)
    LOAD(fmi2ExitInitializationMode)
    LOAD(fmi2SetReal)
    LOAD(fmi2SetInteger)
    LOAD(fmi2GetReal)
    LOAD(fmi2DoStep)
    LOAD(fmi2Reset)
    LOAD(fmi2Terminate)
    LOAD(fmi2FreeInstance)
    LOAD(fmi2GetFMUstate)
    LOAD(fmi2SetFMUstate)
    LOAD(fmi2FreeFMUstate)
    LOAD(fmi2SerializedFMUstateSize)
    LOAD(fmi2SerializeFMUstate)
    LOAD(fmi2DeSerializeFMUstate)
    fmi2CallbackFunctions cb = {logger, calloc, free, NULL, NULL};
    const fmi2ValueReference in[2] = {0, 1}, vr_seed = 4, vr_bad = 100000;
    fmi2ValueReference out_vr[12];
    for (int k = 0; k < 12; k++)
        out_vr[k] = 26 + k;
    const double h = 1e-3;
    enum { N = 60, SAVE = 20 };
    quiet_errors = 1;
    for (int cycle = 0; cycle < cycles; cycle++) {
        if (cycle == warmup)
            rss_warm = rss_kb();
        EXPECT(fmi2Instantiate("bad", fmi2CoSimulation, "not-the-guid", resources, &cb, fmi2False, fmi2True) == NULL,
               "a wrong GUID is refused");
        fmi2Component c = fmi2Instantiate("stress", fmi2CoSimulation, argv[2], resources, &cb, fmi2False, fmi2True);
        if (!c) {
            fprintf(stderr, "instantiate failed\n");
            return 3;
        }
        const fmi2Integer seed = cycle % 7;
        double u[2] = {10.0, 200.0}, y[12], first[N][12], again[N][12];
        EXPECT(fmi2SetupExperiment(c, fmi2False, 0.0, 0.0, fmi2False, 0.0) == fmi2OK, "setup");
        EXPECT(fmi2EnterInitializationMode(c) == fmi2OK, "enter initialisation");
        EXPECT(fmi2SetInteger(c, &vr_seed, 1, &seed) == fmi2OK, "seed");
        EXPECT(fmi2SetReal(c, in, 2, u) == fmi2OK, "inputs");
        EXPECT(fmi2ExitInitializationMode(c) == fmi2OK, "exit initialisation");
        fmi2FMUstate saved = NULL;
        fmi2Byte *blob = NULL;
        size_t size = 0;
        for (int k = 0; k < N; k++) {
            if (k == SAVE && has_state) { /* (a refused state call would end the run: they come later) */
                fmi2Status s = fmi2GetFMUstate(c, &saved);
                EXPECT(has_state ? (s == fmi2OK && saved) : s == fmi2Error, "fmi2GetFMUstate");
                s = fmi2SerializedFMUstateSize(c, saved, &size);
                EXPECT(has_state ? (s == fmi2OK && size > 0) : s == fmi2Error, "fmi2SerializedFMUstateSize");
                if (has_state && size) {
                    blob = malloc(size);
                    EXPECT(fmi2SerializeFMUstate(c, saved, blob, size) == fmi2OK, "fmi2SerializeFMUstate");
                    EXPECT(fmi2SerializeFMUstate(c, saved, blob, size / 2) == fmi2Error, "a short buffer is refused");
                    EXPECT(fmi2SetFMUstate(c, saved) == fmi2OK, "the state just stored ends the error state");
                }
            }
            u[0] = 10.0 + 0.2 * k;
            EXPECT(fmi2SetReal(c, in, 2, u) == fmi2OK && fmi2DoStep(c, k * h, h, fmi2True) == fmi2OK &&
                       fmi2GetReal(c, out_vr, 12, first[k]) == fmi2OK, "a good step");
            for (int j = 0; j < 12; j++)
                EXPECT(isfinite(first[k][j]), "finite outputs");
        }
        /* bad input: each refused with fmi2Error, outputs unchanged; FMI 2.0 then puts the instance in its error
         * state: a state stored before restores the run (the native FMU), else only a reset leads on */
        const double tn = N * h, nan = NAN, inf = INFINITY;
        double y0[12];
        fmi2GetReal(c, out_vr, 12, y0);
        fmi2FMUstate before = NULL;
        if (has_state)
            EXPECT(fmi2GetFMUstate(c, &before) == fmi2OK, "a checkpoint before the bad input");
        const struct { double t, h, w; const char *what; } bad[] = {
            {tn, h, nan, "a NaN speed"},          {tn, h, inf, "an infinite speed"},
            {tn, h, 1e308, "a speed jump to 1e308"}, {tn - h, h, 22.0, "a communication point going backwards"},
            {nan, h, 22.0, "a NaN communication point"}, {tn + 5 * h, h, 22.0, "a communication point skipping ahead"},
            {tn, -h, 22.0, "a negative step"},       {tn, 0.0, 22.0, "a zero step"},
            {tn, nan, 22.0, "a NaN step"},            {tn, 1e9, 22.0, "a huge step"},
        };
        for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
            double v[2] = {bad[i].w, 0.0};
            fmi2SetReal(c, in, 2, v);
            EXPECT(fmi2DoStep(c, bad[i].t, bad[i].h, fmi2True) == fmi2Error, bad[i].what);
            EXPECT(fmi2GetReal(c, out_vr, 12, y) == fmi2OK && memcmp(y, y0, sizeof y) == 0, "outputs unchanged");
            EXPECT(fmi2DoStep(c, tn, h, fmi2True) == fmi2Error, "no step in the error state");
            if (has_state)
                EXPECT(fmi2SetFMUstate(c, before) == fmi2OK, "the checkpoint restores the run");
        }
        const double one = 1.0;
        EXPECT(fmi2SetReal(c, &vr_bad, 1, &one) == fmi2Error, "an unknown value reference is refused");
        EXPECT(fmi2GetReal(c, &vr_bad, 1, y) == fmi2Error, "an unknown value reference is refused (get)");
        u[0] = 22.0;
        if (has_state) {
            EXPECT(fmi2SetFMUstate(c, before) == fmi2OK, "the checkpoint restores the run");
            EXPECT(fmi2SetReal(c, in, 2, u) == fmi2OK && fmi2DoStep(c, tn, h, fmi2True) == fmi2OK, "the host goes on");
            EXPECT(fmi2FreeFMUstate(c, &before) == fmi2OK, "free the checkpoint");
        }
        /* FMU state: replay from the saved state; hostile states refused */
        EXPECT(fmi2SetFMUstate(c, NULL) == fmi2Error, "fmi2SetFMUstate(NULL) is refused");
        if (has_state) {
            EXPECT(fmi2SetFMUstate(c, saved) == fmi2OK, "fmi2SetFMUstate");
            for (int k = SAVE; k < N; k++) {
                u[0] = 10.0 + 0.2 * k;
                fmi2SetReal(c, in, 2, u);
                EXPECT(fmi2DoStep(c, k * h, h, fmi2True) == fmi2OK, "replay step");
                fmi2GetReal(c, out_vr, 12, again[k]);
            }
            EXPECT(memcmp(first[SAVE], again[SAVE], sizeof(double) * 12 * (N - SAVE)) == 0, "bit-identical replay");
            fmi2FMUstate copy = NULL;
            EXPECT(fmi2DeSerializeFMUstate(c, blob, size, &copy) == fmi2OK && copy, "fmi2DeSerializeFMUstate");
            EXPECT(fmi2SetFMUstate(c, copy) == fmi2OK, "set the deserialized state");
            EXPECT(fmi2FreeFMUstate(c, &copy) == fmi2OK && !copy, "free the deserialized state");
            fmi2FMUstate junk = NULL;
            EXPECT(fmi2DeSerializeFMUstate(c, blob, size / 3, &junk) == fmi2Error && !junk, "a truncated state");
            memset(blob, 0x5a, size / 2);
            EXPECT(fmi2DeSerializeFMUstate(c, blob, size, &junk) == fmi2Error && !junk, "a corrupted state");
            EXPECT(fmi2DeSerializeFMUstate(c, blob, 0, &junk) == fmi2Error && !junk, "an empty state");
            EXPECT(fmi2FreeFMUstate(c, &saved) == fmi2OK && !saved, "fmi2FreeFMUstate");
        } else {
            fmi2FMUstate junk = NULL;
            fmi2Byte bytes[16] = {0};
            EXPECT(fmi2SetFMUstate(c, (fmi2FMUstate)bytes) == fmi2Error, "fmi2SetFMUstate refused");
            EXPECT(fmi2DeSerializeFMUstate(c, bytes, sizeof bytes, &junk) == fmi2Error && !junk,
                   "fmi2DeSerializeFMUstate refused");
        }
        free(blob);
        EXPECT(fmi2FreeFMUstate(c, NULL) == fmi2OK, "freeing no state is a no-op");
        if (cycle % 2 || !has_state) { /* without FMU state, the error state leaves a reset only */
            EXPECT(fmi2Reset(c) == fmi2OK, "reset");
            EXPECT(fmi2SetupExperiment(c, fmi2False, 0.0, 0.0, fmi2False, 0.0) == fmi2OK &&
                       fmi2EnterInitializationMode(c) == fmi2OK && fmi2SetInteger(c, &vr_seed, 1, &seed) == fmi2OK,
                   "re-initialise after reset");
            u[0] = 10.0;
            u[1] = 200.0;
            EXPECT(fmi2SetReal(c, in, 2, u) == fmi2OK && fmi2ExitInitializationMode(c) == fmi2OK,
                   "exit initialisation after reset");
            for (int k = 0; k < SAVE + 3; k++) {
                u[0] = 10.0 + 0.2 * k;
                fmi2SetReal(c, in, 2, u);
                fmi2DoStep(c, k * h, h, fmi2True);
                fmi2GetReal(c, out_vr, 12, y);
                if (k < N)
                    EXPECT(memcmp(y, first[k], sizeof y) == 0, "reset replays bit for bit");
            }
        }
        fmi2Terminate(c);
        fmi2FreeInstance(c);
    }
    printf("checks %ld failures %ld\n", checks, failures);
    if (warmup >= 0)
        printf("rss_growth_kB %ld\n", rss_kb() - rss_warm);
    dlclose(lib);
    return failures ? 1 : 0;
}
