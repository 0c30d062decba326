/* Random FMI call orders in C, for memory checkers (AddressSanitizer + UndefinedBehaviorSanitizer, valgrind): the
 * state machine's paths of the native wheel FMU, FMI 2.0 or (built with -DFMI3) FMI 3.0.  Each order instantiates
 * the FMU, leads it into one of its states (instantiated, initialization mode, stepping, terminated, after an error)
 * and makes random calls of every kind, in order or not: set-up, initialisation, steps (legal speeds and bad ones),
 * terminate, reset, getters and setters of good, wrong-typed and unknown value references (NULL arrays too), FMU
 * states got, set, serialized into good and short buffers, deserialized from good, truncated and corrupted bytes,
 * freed; then frees the instance (and the states still held).  The checker is the judge of memory; this host checks
 * that no call answers Fatal or an unknown status and that every Error was logged.  Used by tests/test_fmu_memcheck.py.
 *
 *   c_orders LIB GUID N_ORDERS SEED
 *
 * Prints "orders <n> calls <c> errors <e> steps <s> failures <f>" (s: steps taken) and exits 0 only when f == 0. */
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#ifdef _WIN32
#include <windows.h>
#define lib_open(p) ((void *)LoadLibraryA(p))
#define lib_sym(l, n) ((void *)GetProcAddress((HMODULE)(l), n))
#else
#include <dlfcn.h>
#define lib_open(p) dlopen(p, RTLD_NOW | RTLD_LOCAL)
#define lib_sym(l, n) dlsym(l, n)
#endif

#ifdef FMI3
#include "fmi3/fmi3Functions.h"
typedef fmi3Instance Inst;
typedef fmi3FMUState State;
typedef fmi3Status Status;
typedef fmi3Int32 Int;
#define ERROR_STATUS fmi3Error
#define F(name) fmi3##name
#else
#include "fmi2/fmi2Functions.h"
typedef fmi2Component Inst;
typedef fmi2FMUstate State;
typedef fmi2Status Status;
typedef fmi2Integer Int;
#define ERROR_STATUS fmi2Error
#define F(name) fmi2##name
#endif

static long n_calls, n_errors, n_logged, failures, n_steps;
static unsigned long long rng_state;

static unsigned rnd(unsigned n) /* 0 .. n-1 (xorshift64*) */
{
    rng_state ^= rng_state >> 12, rng_state ^= rng_state << 25, rng_state ^= rng_state >> 27;
    return (unsigned)((rng_state * 2685821657736338717ULL) >> 33) % n;
}

#ifdef FMI3
static void logger(fmi3InstanceEnvironment env, fmi3Status status, fmi3String category, fmi3String message)
{
    (void)env, (void)category, (void)message;
    n_logged += status == fmi3Error;
}
#else
static void logger(fmi2ComponentEnvironment env, fmi2String name, fmi2Status status, fmi2String category,
                   fmi2String message, ...)
{
    (void)env, (void)name, (void)category, (void)message;
    n_logged += status == fmi2Error;
}
#endif

/* the FMI functions this host calls: member, FMI 3.0 name, FMI 2.0 name */
#define FUNCTIONS(X)                                                                                              \
    X(free_instance, FreeInstance, FreeInstance) X(enter, EnterInitializationMode, EnterInitializationMode)       \
    X(exit_init, ExitInitializationMode, ExitInitializationMode) X(terminate, Terminate, Terminate)               \
    X(reset, Reset, Reset) X(do_step, DoStep, DoStep) X(get_state, GetFMUState, GetFMUstate)                      \
    X(set_state, SetFMUState, SetFMUstate) X(free_state, FreeFMUState, FreeFMUstate)                              \
    X(state_size, SerializedFMUStateSize, SerializedFMUstateSize)                                                 \
    X(serialize, SerializeFMUState, SerializeFMUstate) X(deserialize, DeserializeFMUState, DeSerializeFMUstate)   \
    X(get_real, GetFloat64, GetReal) X(set_real, SetFloat64, SetReal) X(set_int, SetInt32, SetInteger)
#ifdef FMI3
#define TYPE_OF(n3, n2) fmi3##n3##TYPE
#define NAME_OF(n3, n2) "fmi3" #n3
#define ENTER_ARGS , fmi3False, 0.0, 0.0, fmi3False, 0.0
#define STEP_ARGS , &flag, &flag, &flag, &last
#define N_VALUES(n) , (n)
static fmi3Boolean flag;
static fmi3Float64 last;
#else
#define TYPE_OF(n3, n2) fmi2##n2##TYPE
#define NAME_OF(n3, n2) "fmi2" #n2
#define ENTER_ARGS
#define STEP_ARGS
#define N_VALUES(n)
#endif
#define MEMBER(m, n3, n2) TYPE_OF(n3, n2) *m;
static struct { FUNCTIONS(MEMBER) } fmi;

static void check(Status s, long logged_before)
{
    n_calls++;
    const char *failed = NULL;
    if ((int)s < 0 || (int)s > (int)ERROR_STATUS)
        failed = "a status Fatal or unknown";
    else if (s == ERROR_STATUS && n_logged == logged_before)
        failed = "an Error without a logged message";
    n_errors += s == ERROR_STATUS;
    if (failed && failures++ < 10)
        fprintf(stderr, "FAILED (call %ld): %s (status %d)\n", n_calls, failed, (int)s);
}
static long logged_before;
/* the call expr, checked (the messages logged before it counted first) */
#define CALL(expr) (logged_before = n_logged, check((expr), logged_before))

/* one random call (or a new run) on instance c at host time *t; states: the FMU states held (up to 4) */
static void random_call(Inst c, double *t, State states[4], char *blob, size_t *blob_size)
{
    static const unsigned vrs[] = {0, 1, 4, 14, 26, 37, 38, 99, 100000};
    unsigned vr = vrs[rnd(9)], k = rnd(4);
    double v[12] = {0}, speed = 100.0 + 0.05 * rnd(5), h = rnd(8) ? 1e-3 : (rnd(2) ? NAN : 5.0);
    Int seed = rnd(3) ? (Int)rnd(5) : -5;
    size_t size = 0;
    Status s;
    const unsigned vr_speed = 0;
    switch (rnd(18)) {
    case 0: CALL(fmi.enter(c ENTER_ARGS)); break;
    case 1: CALL(fmi.exit_init(c)); break;
    case 15: /* a new run, stepping */
        CALL(fmi.reset(c));
        CALL(fmi.enter(c ENTER_ARGS));
        CALL(fmi.set_real(c, &vr_speed, 1, &speed N_VALUES(1)));
        CALL(fmi.exit_init(c));
        *t = 0.0;
        break;
    case 2:
    case 16:
    case 17:
        logged_before = n_logged;
        s = fmi.do_step(c, *t, h, 1 STEP_ARGS);
        check(s, logged_before);
        n_steps += s == 0;
        *t += s == 0 ? h : 0.0;
        break;
    case 3: CALL(fmi.terminate(c)); break;
    case 4:
    case 14: CALL(fmi.reset(c)); *t = 0.0; break;
    case 5: CALL(fmi.get_real(c, &vr, rnd(8) ? 1 : 0, v N_VALUES(1))); break;
    case 6: v[0] = rnd(6) ? speed : INFINITY; CALL(fmi.set_real(c, &vr, 1, v N_VALUES(1))); break;
    case 7: CALL(fmi.set_int(c, &vr, 1, &seed N_VALUES(1))); break;
    case 8: CALL(fmi.get_real(c, NULL, 2, v N_VALUES(2))); break;
    case 9: CALL(fmi.get_state(c, &states[k])); break;
    case 10: CALL(fmi.set_state(c, rnd(6) ? states[k] : NULL)); break;
    case 11: CALL(fmi.free_state(c, &states[k])); break;
    case 12:
        if (states[k]) {
            CALL(fmi.state_size(c, states[k], &size));
            CALL(fmi.serialize(c, states[k], (void *)blob, rnd(4) ? (size < 65536 ? size : 65536) : size / 2));
            *blob_size = size < 65536 ? size : 0;
        }
        break;
    default:
        if (*blob_size) {
            State s = NULL;
            size = rnd(3) ? *blob_size : rnd((unsigned)*blob_size);
            if (!rnd(4))
                blob[rnd((unsigned)*blob_size)] ^= 0x5a;
            CALL(fmi.deserialize(c, (const void *)blob, size, &s));
            if (s)
                CALL(fmi.set_state(c, s)), CALL(fmi.free_state(c, &s));
        }
    }
}

int main(int argc, char **argv)
{
    if (argc < 5) {
        fprintf(stderr, "usage: %s LIB GUID N_ORDERS SEED\n", argv[0]);
        return 2;
    }
    void *lib = lib_open(argv[1]);
    if (!lib) {
        fprintf(stderr, "cannot load %s\n", argv[1]);
        return 2;
    }
#define LOAD(m, n3, n2)                                                                                           \
    if (!(fmi.m = (TYPE_OF(n3, n2) *)lib_sym(lib, NAME_OF(n3, n2)))) {                                            \
        fprintf(stderr, "missing %s\n", NAME_OF(n3, n2));                                                        \
        return 2;                                                                                                 \
    }
    FUNCTIONS(LOAD)
#ifdef FMI3
    fmi3InstantiateCoSimulationTYPE *instantiate =
        (fmi3InstantiateCoSimulationTYPE *)lib_sym(lib, "fmi3InstantiateCoSimulation");
#else
    fmi2InstantiateTYPE *instantiate = (fmi2InstantiateTYPE *)lib_sym(lib, "fmi2Instantiate");
    fmi2CallbackFunctions cb = {logger, calloc, free, NULL, NULL};
#endif
    if (!instantiate)
        return 2;
    const int orders = atoi(argv[3]);
    rng_state = 0x9e3779b97f4a7c15ULL ^ (unsigned long long)atoll(argv[4]);
    static char blob[65536];
    for (int o = 0; o < orders; o++) {
#ifdef FMI3
        Inst c = instantiate("orders", argv[2], NULL, fmi3False, fmi3True, fmi3False, fmi3False, NULL, 0, NULL, logger,
                             NULL);
#else
        Inst c = instantiate("orders", fmi2CoSimulation, argv[2], "", &cb, fmi2False, fmi2True);
#endif
        if (!c) {
            fprintf(stderr, "instantiate failed\n");
            return 3;
        }
        State states[4] = {NULL, NULL, NULL, NULL};
        size_t blob_size = 0;
        double t = 0.0, v = 100.0;
        const unsigned vr_speed = 0;
        const int prefix = o % 5; /* instantiated, initialization mode, stepping, terminated, after an error */
        if (prefix >= 1)
            CALL(fmi.enter(c ENTER_ARGS)), CALL(fmi.set_real(c, &vr_speed, 1, &v N_VALUES(1)));
        if (prefix >= 2)
            CALL(fmi.exit_init(c)), CALL(fmi.do_step(c, t, 1e-3, 1 STEP_ARGS)), t += 1e-3;
        if (prefix == 3)
            CALL(fmi.terminate(c));
        if (prefix == 4)
            CALL(fmi.do_step(c, t + 1.0, 1e-3, 1 STEP_ARGS));
        for (int k = 0, n = 10 + (int)rnd(40); k < n; k++)
            random_call(c, &t, states, blob, &blob_size);
        for (int k = 0; k < 4; k++)
            if (states[k])
                CALL(fmi.free_state(c, &states[k]));
        fmi.free_instance(c);
    }
    printf("orders %d calls %ld errors %ld steps %ld failures %ld\n", orders, n_calls, n_errors, n_steps, failures);
    return failures ? 1 : 0;
}
