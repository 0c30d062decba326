/* Native layer of the rwadist wheel FMU (Linux): an FMI 2.0 status adapter in front of
 * pythonfmu's library, and the step kernel of fmu/runtime.py in C.
 *
 * Why: pythonfmu 0.7 reports a do_step that returns False as fmi2Discard and any Python
 * exception as fmi2Fatal; the FMI way to refuse bad input is fmi2Error.  The Python slave calls
 * rwadist_fmu_flag_error() (through ctypes, on the calling thread) when it refuses an input; the
 * adapter then returns fmi2Error from the FMI call in progress.  Every fmi2 function is forwarded
 * to pythonfmu's library, shipped beside this one as <modelIdentifier>_pythonfmu.so, except the FMU-state
 * functions, refused here with fmi2Error (see fmi2GetFMUstate).
 *
 * It also keeps the FMI 2.0 state machine of each instance (pythonfmu 0.7 keeps none: it answered
 * fmi2ExitInitializationMode without fmi2EnterInitializationMode, fmi2DoStep after fmi2Terminate, a fixed
 * parameter set after initialisation (silently not applied) and an unknown value reference with fmi2OK): a call
 * out of order, a fixed parameter set after initialisation, an output set, or a value reference that is not a
 * variable of the wheel FMU's type asked is answered with fmi2Error and a logged message, without reaching
 * pythonfmu; the instance stays in its state.  The variables are those of fmu/slave.py (VARIABLES of
 * fmu/native_build.py; tests/test_fmu_statemachine.py checks every one).
 *
 * rwadist_kernel_step() is WheelRuntime.step of fmu/runtime.py: the kernel of rwadist_kernel.h,
 * shared with the pure-C FMU (rwadist_wheel_fmu.c). */
#define _GNU_SOURCE
#include <dlfcn.h>
#include <math.h>
#include <pthread.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* ------------------------------------------------------------------ FMI 2.0 types (by value) */
typedef void *fmi2Component;
typedef void *fmi2ComponentEnvironment;
typedef void *fmi2FMUstate;
typedef unsigned int fmi2ValueReference;
typedef double fmi2Real;
typedef int fmi2Integer;
typedef int fmi2Boolean;
typedef char fmi2Char;
typedef const fmi2Char *fmi2String;
typedef char fmi2Byte;
typedef int fmi2Status; /* fmi2OK 0, Warning 1, Discard 2, Error 3, Fatal 4, Pending 5 */
typedef int fmi2Type;
typedef int fmi2StatusKind;
enum { fmi2OK = 0, fmi2Discard = 2, fmi2Error = 3 };

typedef void (*fmi2CallbackLogger)(fmi2ComponentEnvironment, fmi2String, fmi2Status, fmi2String, fmi2String, ...);
typedef struct {
    fmi2CallbackLogger logger;
    void *(*allocateMemory)(size_t, size_t);
    void (*freeMemory)(void *);
    void (*stepFinished)(fmi2ComponentEnvironment, fmi2Status);
    fmi2ComponentEnvironment componentEnvironment;
} fmi2CallbackFunctions;

#define EXPORT __attribute__((visibility("default")))

/* ------------------------------------------------------------------ error flag */
static __thread int error_flag;

/* Called by the Python slave on the thread of the FMI call that refuses an input. */
EXPORT void rwadist_fmu_flag_error(void) { error_flag = 1; }
/* 1 when this library is the adapter (lets the slave and the tests tell). */
EXPORT int rwadist_fmu_native_version(void) { return 1; }

static fmi2Status adapt(fmi2Status s)
{
    int flagged = error_flag;
    error_flag = 0;
    if (flagged && s < fmi2Error)
        return fmi2Error;
    return s;
}

/* ------------------------------------------------------------------ loading pythonfmu's library */
static void *inner;
static char inner_error[8192];

static void *load_inner(void)
{
    if (inner)
        return inner;
    Dl_info info;
    if (!dladdr((void *)&rwadist_fmu_flag_error, &info) || !info.dli_fname) {
        snprintf(inner_error, sizeof inner_error, "rwadist FMU: cannot locate its own library");
        return NULL;
    }
    char path[4096];
    const char *dot = strrchr(info.dli_fname, '.');
    const char *slash = strrchr(info.dli_fname, '/');
    size_t stem = (dot && (!slash || dot > slash)) ? (size_t)(dot - info.dli_fname) : strlen(info.dli_fname);
    if (stem + 32 >= sizeof path) {
        snprintf(inner_error, sizeof inner_error, "rwadist FMU: library path too long");
        return NULL;
    }
    memcpy(path, info.dli_fname, stem);
    snprintf(path + stem, sizeof path - stem, "_pythonfmu%s", dot && (!slash || dot > slash) ? dot : ".so");
    inner = dlopen(path, RTLD_NOW | RTLD_LOCAL);
    if (!inner)
        snprintf(inner_error, sizeof inner_error, "rwadist FMU: cannot load %s: %s", path, dlerror());
    return inner;
}

static void *sym(const char *name)
{
    void *h = load_inner();
    return h ? dlsym(h, name) : NULL;
}

/* forward NAME(args) to the inner library; POST post-processes the status */
#define FORWARD(RET, NAME, PARAMS, ARGS, FAIL, POST)                     \
    EXPORT RET NAME PARAMS                                               \
    {                                                                    \
        static RET(*fn) PARAMS;                                          \
        if (!fn)                                                         \
            fn = (RET(*) PARAMS)sym(#NAME);                              \
        if (!fn)                                                         \
            return FAIL;                                                 \
        error_flag = 0;                                                  \
        RET r = fn ARGS;                                                 \
        return POST(r);                                                  \
    }

/* ------------------------------------------------------------------ instances' loggers (for refusals made here) */
/* instance states (as the native FMU's rwadist_wheel_instance.h) */
enum { ST_INSTANTIATED = 0, ST_INIT = 1, ST_STEP = 2, ST_TERMINATED = 3, ST_FAILED = 4, N_ST = 5 };
#define IN(s) (1u << (s))
#define ANY_STATE (IN(ST_INSTANTIATED) | IN(ST_INIT) | IN(ST_STEP) | IN(ST_TERMINATED) | IN(ST_FAILED))
#define SETTABLE (IN(ST_INSTANTIATED) | IN(ST_INIT) | IN(ST_STEP))
#define READABLE (IN(ST_INIT) | IN(ST_STEP) | IN(ST_TERMINATED) | IN(ST_FAILED))
static const char *const STATE_NAMES[N_ST] = {"instantiated", "initialization mode", "stepping", "terminated",
                                             "failed (initialisation failed)"};
static const char *const STATE_NEXT[N_ST] = {
    "enter initialization mode first", "exit initialization mode first", "the instance is stepping",
    "the instance is terminated: reset it (or free it) to run again",
    "initialisation failed (see the error logged then): reset the instance or free it"};

/* the wheel FMU's variables by type (value references of fmu/slave.py) */
enum { T_REAL, T_INTEGER, T_BOOLEAN, T_STRING };
static int var_type(fmi2ValueReference vr)
{
    if (vr <= 1 || (vr >= 11 && vr <= 37))
        return T_REAL;
    if (vr == 4)
        return T_INTEGER;
    if (vr == 3 || (vr >= 5 && vr <= 10))
        return T_BOOLEAN;
    if (vr == 2)
        return T_STRING;
    return -1;
}
static const char *const TYPE_NAMES[4] = {"Real", "Integer", "Boolean", "String"};

typedef struct Known {
    fmi2Component c;
    int mode;
    fmi2CallbackLogger logger;
    fmi2ComponentEnvironment env;
    char name[128];
    struct Known *next;
} Known;
static Known *known;
static pthread_mutex_t known_lock = PTHREAD_MUTEX_INITIALIZER;

static void remember(fmi2Component c, const fmi2CallbackFunctions *f, fmi2String name)
{
    Known *k = calloc(1, sizeof *k);
    if (!k)
        return; /* refusals of this instance are then not logged; their status still says so */
    k->c = c;
    k->logger = f ? f->logger : NULL;
    k->env = f ? f->componentEnvironment : NULL;
    snprintf(k->name, sizeof k->name, "%s", name ? name : "");
    pthread_mutex_lock(&known_lock);
    k->next = known;
    known = k;
    pthread_mutex_unlock(&known_lock);
}

static void forget(fmi2Component c)
{
    pthread_mutex_lock(&known_lock);
    for (Known **p = &known; *p; p = &(*p)->next)
        if ((*p)->c == c) {
            Known *k = *p;
            *p = k->next;
            free(k);
            break;
        }
    pthread_mutex_unlock(&known_lock);
}

/* fmi2Error with a message (printf format) logged through instance c's logger (when it has one) */
static fmi2Status refuse(fmi2Component c, const char *fmt, ...)
{
    fmi2CallbackLogger logger = NULL;
    fmi2ComponentEnvironment env = NULL;
    char name[128] = "";
    pthread_mutex_lock(&known_lock);
    for (Known *k = known; k; k = k->next)
        if (k->c == c && c) {
            logger = k->logger;
            env = k->env;
            memcpy(name, k->name, sizeof name);
            break;
        }
    pthread_mutex_unlock(&known_lock);
    char message[1024];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(message, sizeof message, fmt, ap);
    va_end(ap);
    /* the message is the format itself: hosts whose logger cannot read varargs (ctypes callbacks, e.g. fmpy)
     * still see it; no '%' may remain */
    for (char *q = message; *q; q++)
        if (*q == '%')
            *q = '?';
    if (logger)
        logger(env, name, fmi2Error, "logStatusError", message);
    return fmi2Error;
}

/* the state of instance c (-1: not an instance of this library) */
static int mode_of(fmi2Component c)
{
    int mode = -1;
    pthread_mutex_lock(&known_lock);
    for (Known *k = known; k; k = k->next)
        if (k->c == c && c) {
            mode = k->mode;
            break;
        }
    pthread_mutex_unlock(&known_lock);
    return mode;
}

static void set_mode(fmi2Component c, int mode)
{
    pthread_mutex_lock(&known_lock);
    for (Known *k = known; k; k = k->next)
        if (k->c == c && c) {
            k->mode = mode;
            break;
        }
    pthread_mutex_unlock(&known_lock);
}

/* 1 when `fn` is allowed in c's state (mask of IN(state)); else fmi2Error logged, 0 */
static int allowed(fmi2Component c, unsigned mask, const char *fn)
{
    const int mode = mode_of(c);
    if (mode < 0)
        return 0; /* not an instance of this FMU (NULL or freed): nothing to log to */
    if (mask & IN(mode))
        return 1;
    char states[160] = "";
    for (int st = 0; st < N_ST; st++)
        if (mask & IN(st)) {
            const size_t len = strlen(states);
            snprintf(states + len, sizeof states - len, "%s%s", len ? ", " : "", STATE_NAMES[st]);
        }
    refuse(c, "rwadist wheel: %s: illegal call sequence: the instance is %s; %s is allowed when %s (%s)", fn,
           STATE_NAMES[mode], fn, states[0] ? states : "never", STATE_NEXT[mode]);
    return 0;
}

/* value references of type `type` (set: inputs always, fixed parameters before the end of initialisation) */
static int vrs_ok(fmi2Component c, const char *fn, const fmi2ValueReference vr[], size_t n, const void *v, int type,
                  int set)
{
    if (n && (!vr || !v)) {
        refuse(c, "rwadist wheel: %s: %zu values asked with a NULL array", fn, n);
        return 0;
    }
    const int mode = mode_of(c);
    for (size_t i = 0; i < n; i++) {
        if (var_type(vr[i]) != type) {
            refuse(c, "rwadist wheel: %s: value reference %u is not a%s %s variable of this FMU", fn, vr[i],
                   type == T_INTEGER ? "n" : "", TYPE_NAMES[type]);
            return 0;
        }
        if (set && vr[i] >= 26) {
            refuse(c, "rwadist wheel: %s: value reference %u is an output", fn, vr[i]);
            return 0;
        }
        if (set && vr[i] > 1 && mode != ST_INSTANTIATED && mode != ST_INIT) {
            refuse(c, "rwadist wheel: %s: value reference %u is a fixed parameter; set it before the end of "
                      "initialisation (the instance is %s)", fn, vr[i], STATE_NAMES[mode]);
            return 0;
        }
    }
    return 1;
}

EXPORT const char *fmi2GetTypesPlatform(void) { return "default"; }
EXPORT const char *fmi2GetVersion(void) { return "2.0"; }

/* The GUID of the FMU this library belongs to, from its modelDescription.xml (the library is
 * <FMU>/binaries/linux64/<id>.so), into out; 0 where that file cannot be read or holds no guid.
 * pythonfmu 0.7 does not compare the GUID a host passes to fmi2Instantiate with its own (FMI 2.0 2.1.5:
 * a mismatch must return NULL), so this layer does. */
static int own_guid(char *out, size_t size)
{
    Dl_info info;
    if (!dladdr((void *)&rwadist_fmu_flag_error, &info) || !info.dli_fname)
        return 0;
    char path[4096];
    snprintf(path, sizeof path, "%s", info.dli_fname);
    for (int up = 0; up < 3; up++) { /* <id>.so, linux64, binaries */
        char *slash = strrchr(path, '/');
        if (!slash)
            return 0;
        *slash = '\0';
    }
    if (strlen(path) + sizeof "/modelDescription.xml" > sizeof path)
        return 0;
    strcat(path, "/modelDescription.xml");
    FILE *f = fopen(path, "rb");
    if (!f)
        return 0;
    char head[65536]; /* the guid attribute is on the root element, in the first lines */
    size_t n = fread(head, 1, sizeof head - 1, f);
    fclose(f);
    head[n] = '\0';
    const char *at = strstr(head, " guid=\"");
    if (!at)
        return 0;
    at += strlen(" guid=\"");
    const char *end = strchr(at, '"');
    if (!end || (size_t)(end - at) >= size)
        return 0;
    memcpy(out, at, (size_t)(end - at));
    out[end - at] = '\0';
    return 1;
}

EXPORT fmi2Component fmi2Instantiate(fmi2String instanceName, fmi2Type fmuType, fmi2String guid,
                                     fmi2String resourceLocation, const fmi2CallbackFunctions *functions,
                                     fmi2Boolean visible, fmi2Boolean loggingOn)
{
    static fmi2Component (*fn)(fmi2String, fmi2Type, fmi2String, fmi2String, const fmi2CallbackFunctions *,
                               fmi2Boolean, fmi2Boolean);
    if (!fn)
        fn = (fmi2Component(*)(fmi2String, fmi2Type, fmi2String, fmi2String, const fmi2CallbackFunctions *,
                               fmi2Boolean, fmi2Boolean))sym("fmi2Instantiate");
    if (!fn) {
        if (functions && functions->logger)
            functions->logger(functions->componentEnvironment, instanceName, fmi2Error, "logStatusError", "%s",
                              inner_error[0] ? inner_error : "rwadist FMU: pythonfmu library lacks fmi2Instantiate");
        return NULL;
    }
    char expected[256];
    if (own_guid(expected, sizeof expected) && (!guid || strcmp(guid, expected) != 0)) {
        if (functions && functions->logger) {
            char message[1024];
            snprintf(message, sizeof message,
                     "fmi2Instantiate: GUID %s is not this FMU's (%s, in its modelDescription.xml): the host read "
                     "another FMU's model description; load this FMU's", guid ? guid : "(null)", expected);
            for (char *p = message; *p; p++) /* the message is the format (see refuse): no '%' from the host */
                if (*p == '%')
                    *p = '?';
            functions->logger(functions->componentEnvironment, instanceName, fmi2Error, "logStatusError", message);
        }
        return NULL;
    }
    error_flag = 0;
    fmi2Component c = fn(instanceName, fmuType, guid, resourceLocation, functions, visible, loggingOn);
    if (c)
        remember(c, functions, instanceName); /* mode ST_INSTANTIATED (0) */
    return c;
}

EXPORT void fmi2FreeInstance(fmi2Component c)
{
    static void (*fn)(fmi2Component);
    if (!fn)
        fn = (void (*)(fmi2Component))sym("fmi2FreeInstance");
    forget(c);
    if (fn)
        fn(c);
}

FORWARD(fmi2Status, fmi2SetDebugLogging, (fmi2Component c, fmi2Boolean on, size_t n, const fmi2String cat[]),
        (c, on, n, cat), fmi2Error, adapt)

/* forward NAME(args) to the inner library when CHECK holds (else fmi2Error, logged by CHECK); after an OK
 * (or Warning) answer the instance moves to state NEXT (-1: stays), after an Error to state ON_ERROR (-1: stays) */
#define CHECKED(NAME, PARAMS, ARGS, CHECK, NEXT, ON_ERROR)                                                        \
    EXPORT fmi2Status NAME PARAMS                                                                                 \
    {                                                                                                             \
        static fmi2Status(*fn) PARAMS;                                                                            \
        if (!fn)                                                                                                  \
            fn = (fmi2Status(*) PARAMS)sym(#NAME);                                                                \
        if (!fn || !(CHECK))                                                                                      \
            return fmi2Error;                                                                                     \
        error_flag = 0;                                                                                           \
        const fmi2Status r = adapt(fn ARGS);                                                                      \
        if (r <= 1 && (NEXT) >= 0)                                                                                \
            set_mode(c, NEXT);                                                                                    \
        else if (r >= fmi2Error && (ON_ERROR) >= 0)                                                               \
            set_mode(c, ON_ERROR);                                                                                \
        return r;                                                                                                 \
    }

static int setup_ok(fmi2Component c, fmi2Boolean tolDef, fmi2Real tol, fmi2Real t0, fmi2Boolean stopDef, fmi2Real stop)
{
    if (!allowed(c, IN(ST_INSTANTIATED), "fmi2SetupExperiment"))
        return 0;
    if (!isfinite(t0))
        return !refuse(c, "rwadist wheel: fmi2SetupExperiment: start time %g is not finite", t0);
    if (stopDef && !(stop >= t0))
        return !refuse(c, "rwadist wheel: fmi2SetupExperiment: stop time %g s is before the start time %g s", stop, t0);
    if (tolDef && !(tol > 0 && isfinite(tol)))
        return !refuse(c, "rwadist wheel: fmi2SetupExperiment: tolerance %g is not a positive number", tol);
    return 1;
}

CHECKED(fmi2SetupExperiment,
        (fmi2Component c, fmi2Boolean tolDef, fmi2Real tol, fmi2Real t0, fmi2Boolean stopDef, fmi2Real stop),
        (c, tolDef, tol, t0, stopDef, stop), setup_ok(c, tolDef, tol, t0, stopDef, stop), -1, -1)
CHECKED(fmi2EnterInitializationMode, (fmi2Component c), (c),
        allowed(c, IN(ST_INSTANTIATED), "fmi2EnterInitializationMode"), ST_INIT, -1)
CHECKED(fmi2ExitInitializationMode, (fmi2Component c), (c), allowed(c, IN(ST_INIT), "fmi2ExitInitializationMode"),
        ST_STEP, ST_FAILED)
CHECKED(fmi2Terminate, (fmi2Component c), (c), allowed(c, IN(ST_STEP), "fmi2Terminate"), ST_TERMINATED, -1)
CHECKED(fmi2Reset, (fmi2Component c), (c), allowed(c, ANY_STATE, "fmi2Reset"), ST_INSTANTIATED, -1)
CHECKED(fmi2GetReal, (fmi2Component c, const fmi2ValueReference vr[], size_t n, fmi2Real v[]), (c, vr, n, v),
        allowed(c, READABLE, "fmi2GetReal") && vrs_ok(c, "fmi2GetReal", vr, n, v, T_REAL, 0), -1, -1)
CHECKED(fmi2GetInteger, (fmi2Component c, const fmi2ValueReference vr[], size_t n, fmi2Integer v[]), (c, vr, n, v),
        allowed(c, READABLE, "fmi2GetInteger") && vrs_ok(c, "fmi2GetInteger", vr, n, v, T_INTEGER, 0), -1, -1)
CHECKED(fmi2GetBoolean, (fmi2Component c, const fmi2ValueReference vr[], size_t n, fmi2Boolean v[]), (c, vr, n, v),
        allowed(c, READABLE, "fmi2GetBoolean") && vrs_ok(c, "fmi2GetBoolean", vr, n, v, T_BOOLEAN, 0), -1, -1)
CHECKED(fmi2GetString, (fmi2Component c, const fmi2ValueReference vr[], size_t n, fmi2String v[]), (c, vr, n, v),
        allowed(c, READABLE, "fmi2GetString") && vrs_ok(c, "fmi2GetString", vr, n, v, T_STRING, 0), -1, -1)
CHECKED(fmi2SetReal, (fmi2Component c, const fmi2ValueReference vr[], size_t n, const fmi2Real v[]), (c, vr, n, v),
        allowed(c, SETTABLE, "fmi2SetReal") && vrs_ok(c, "fmi2SetReal", vr, n, v, T_REAL, 1), -1, -1)
CHECKED(fmi2SetInteger, (fmi2Component c, const fmi2ValueReference vr[], size_t n, const fmi2Integer v[]),
        (c, vr, n, v), allowed(c, SETTABLE, "fmi2SetInteger") && vrs_ok(c, "fmi2SetInteger", vr, n, v, T_INTEGER, 1),
        -1, -1)
CHECKED(fmi2SetBoolean, (fmi2Component c, const fmi2ValueReference vr[], size_t n, const fmi2Boolean v[]),
        (c, vr, n, v), allowed(c, SETTABLE, "fmi2SetBoolean") && vrs_ok(c, "fmi2SetBoolean", vr, n, v, T_BOOLEAN, 1),
        -1, -1)
CHECKED(fmi2SetString, (fmi2Component c, const fmi2ValueReference vr[], size_t n, const fmi2String v[]),
        (c, vr, n, v), allowed(c, SETTABLE, "fmi2SetString") && vrs_ok(c, "fmi2SetString", vr, n, v, T_STRING, 1),
        -1, -1)
/* FMU state is refused (the modelDescription says canGetAndSetFMUstate = canSerializeFMUstate = false):
 * pythonfmu's own implementation saves the variables only, not the wheel's modal and phase states, so a
 * host rolling back with it would get silently wrong results.  Nothing is forwarded. */
#define STATE_REFUSED "the pythonfmu wheel FMU does not support FMU state (canGetAndSetFMUstate and " \
                      "canSerializeFMUstate are false); use the native FMU (rwadist fmu build --native) to roll back"

EXPORT fmi2Status fmi2GetFMUstate(fmi2Component c, fmi2FMUstate *s)
{
    if (s)
        *s = NULL;
    return refuse(c, "fmi2GetFMUstate: " STATE_REFUSED);
}

EXPORT fmi2Status fmi2SetFMUstate(fmi2Component c, fmi2FMUstate s)
{
    (void)s;
    return refuse(c, "fmi2SetFMUstate: " STATE_REFUSED);
}

EXPORT fmi2Status fmi2FreeFMUstate(fmi2Component c, fmi2FMUstate *s)
{
    if (!s || !*s)
        return fmi2OK; /* nothing was handed out: nothing to free */
    return refuse(c, "fmi2FreeFMUstate: not a state of this FMU (it hands out none)");
}

EXPORT fmi2Status fmi2SerializedFMUstateSize(fmi2Component c, fmi2FMUstate s, size_t *n)
{
    (void)s;
    if (n)
        *n = 0;
    return refuse(c, "fmi2SerializedFMUstateSize: " STATE_REFUSED);
}

EXPORT fmi2Status fmi2SerializeFMUstate(fmi2Component c, fmi2FMUstate s, fmi2Byte b[], size_t n)
{
    (void)s, (void)b, (void)n;
    return refuse(c, "fmi2SerializeFMUstate: " STATE_REFUSED);
}

EXPORT fmi2Status fmi2DeSerializeFMUstate(fmi2Component c, const fmi2Byte b[], size_t n, fmi2FMUstate *s)
{
    (void)b, (void)n;
    if (s)
        *s = NULL;
    return refuse(c, "fmi2DeSerializeFMUstate: " STATE_REFUSED);
}

/* no derivatives (providesDirectionalDerivative false, canInterpolateInputs false, maxOutputDerivativeOrder 0) */
EXPORT fmi2Status fmi2GetDirectionalDerivative(fmi2Component c, const fmi2ValueReference u[], size_t nu,
                                               const fmi2ValueReference z[], size_t nz, const fmi2Real dv[],
                                               fmi2Real dz[])
{
    (void)u, (void)nu, (void)z, (void)nz, (void)dv, (void)dz;
    return refuse(c, "rwadist wheel: fmi2GetDirectionalDerivative: not supported");
}
EXPORT fmi2Status fmi2SetRealInputDerivatives(fmi2Component c, const fmi2ValueReference vr[], size_t n,
                                              const fmi2Integer order[], const fmi2Real v[])
{
    (void)vr, (void)n, (void)order, (void)v;
    return refuse(c, "rwadist wheel: fmi2SetRealInputDerivatives: not supported (canInterpolateInputs = false)");
}
EXPORT fmi2Status fmi2GetRealOutputDerivatives(fmi2Component c, const fmi2ValueReference vr[], size_t n,
                                               const fmi2Integer order[], fmi2Real v[])
{
    (void)vr, (void)n, (void)order, (void)v;
    return refuse(c, "rwadist wheel: fmi2GetRealOutputDerivatives: not supported (maxOutputDerivativeOrder = 0)");
}
/* a refused step: the slave flags it and returns False, which pythonfmu reports as Discard.  After a failed
 * initialisation the slave refuses every step itself, repeating why initialisation failed */
CHECKED(fmi2DoStep, (fmi2Component c, fmi2Real t, fmi2Real h, fmi2Boolean noPrior), (c, t, h, noPrior),
        allowed(c, IN(ST_STEP) | IN(ST_FAILED), "fmi2DoStep"), -1, -1)
EXPORT fmi2Status fmi2CancelStep(fmi2Component c)
{
    return refuse(c, "rwadist wheel: fmi2CancelStep: illegal call sequence: steps are synchronous, no step is in "
                     "progress to cancel");
}
CHECKED(fmi2GetStatus, (fmi2Component c, const fmi2StatusKind k, fmi2Status *v), (c, k, v),
        allowed(c, IN(ST_STEP) | IN(ST_TERMINATED), "fmi2GetStatus"), -1, -1)
CHECKED(fmi2GetRealStatus, (fmi2Component c, const fmi2StatusKind k, fmi2Real *v), (c, k, v),
        allowed(c, IN(ST_STEP) | IN(ST_TERMINATED), "fmi2GetRealStatus"), -1, -1)
CHECKED(fmi2GetIntegerStatus, (fmi2Component c, const fmi2StatusKind k, fmi2Integer *v), (c, k, v),
        allowed(c, IN(ST_STEP) | IN(ST_TERMINATED), "fmi2GetIntegerStatus"), -1, -1)
CHECKED(fmi2GetBooleanStatus, (fmi2Component c, const fmi2StatusKind k, fmi2Boolean *v), (c, k, v),
        allowed(c, IN(ST_STEP) | IN(ST_TERMINATED), "fmi2GetBooleanStatus"), -1, -1)
CHECKED(fmi2GetStringStatus, (fmi2Component c, const fmi2StatusKind k, fmi2String *v), (c, k, v),
        allowed(c, IN(ST_STEP) | IN(ST_TERMINATED), "fmi2GetStringStatus"), -1, -1)

/* ------------------------------------------------------------------ step kernel (rwadist_kernel.h) */
#include "rwadist_kernel.h"

EXPORT void rwadist_kernel_step(const double *cfg, double *st, double *out, double omega, double wd0, double alpha,
                                double h)
{
    rwadist_kernel_step_impl(cfg, st, out, omega, wd0, alpha, h);
}
