/* Native layer of the rwadist wheel FMU (Linux): an FMI 2.0 status adapter in front of
 * pythonfmu's library, and the step kernel of rwadist/fmu/runtime.py in C.
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
 * parameter set after initialisation (silently not applied) and an unknown value reference with fmi2OK), by the
 * rules of rwadist_fmi_rules.h (the native FMU's too): a call out of order, a fixed parameter set after
 * initialisation, an output set, or a value reference that is not a variable of the wheel FMU's type asked is
 * answered with fmi2Error and a logged message, without reaching pythonfmu; any fmi2Error (refused here or by the
 * slave) then moves the instance to FMI 2.0's error state, from which fmi2Reset and fmi2FreeInstance lead on (this
 * FMU has no FMU state).  The variables are those of rwadist/fmu/slave.py (VARIABLES of rwadist/fmu/native_build.py; a test
 * compares them with rwadist_fmi_rules.h).
 *
 * rwadist_kernel_step() is WheelRuntime.step of rwadist/fmu/runtime.py: the kernel of rwadist_kernel.h,
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

/* ------------------------------------------------------------------ instances' states and loggers */
#include "rwadist_fmi_rules.h"

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
    set_mode(c, rw_error_state(2, mode_of(c)));
    return fmi2Error;
}

/* 1 when `call` (the FMI function fn) is allowed in c's state; else fmi2Error logged (error state), 0 */
static int allowed(fmi2Component c, RwCall call, const char *fn)
{
    const int mode = mode_of(c);
    if (mode < 0)
        return 0; /* not an instance of this FMU (NULL or freed): nothing to log to */
    if (rw_allowed(2, mode, call))
        return 1;
    char message[768];
    rw_refusal(message, sizeof message, 2, call, mode, fn);
    refuse(c, "rwadist wheel: %s", message);
    return 0;
}

/* n value references of `type` to get or set (set: settable ones, in a state their causality allows) */
static int vrs_ok(fmi2Component c, const char *fn, const fmi2ValueReference vr[], size_t n, const void *v, RwType type,
                  int set)
{
    if (n && (!vr || !v)) {
        refuse(c, "rwadist wheel: %s: %zu values asked with a NULL array", fn, n);
        return 0;
    }
    int parameters = 0;
    for (size_t i = 0; i < n; i++) {
        RwCausality causality;
        const RwType t = rw_variable(2, vr[i], &causality);
        const char *why = set ? rw_not_settable(2, vr[i], type) : NULL;
        if (!why && t != type)
            why = t == RW_NO_TYPE ? "is no variable of this FMU" : "is a variable of another type";
        if (why) {
            refuse(c, "rwadist wheel: %s: value reference %u%s%s%s %s (this call %s %s variables)", fn, vr[i],
                   vr[i] < N_VR ? " (" : "", vr[i] < N_VR ? RW_VAR_NAMES[vr[i]] : "", vr[i] < N_VR ? ")" : "", why,
                   set ? "sets" : "gets", RW_TYPE_NAMES[0][type]);
            return 0;
        }
        parameters |= causality == RW_PARAMETER;
    }
    return allowed(c, !set ? RW_GET : parameters ? RW_SET_PARAMETER : RW_SET_INPUT, fn);
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
 * (or Warning) answer the instance moves to state NEXT (-1: stays), after an Error to FMI 2.0's error state */
#define CHECKED(NAME, PARAMS, ARGS, CHECK, NEXT)                                                                  \
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
        else if (r >= fmi2Error)                                                                                  \
            set_mode(c, rw_error_state(2, mode_of(c)));                                                           \
        return r;                                                                                                 \
    }

static int setup_ok(fmi2Component c, fmi2Boolean tolDef, fmi2Real tol, fmi2Real t0, fmi2Boolean stopDef, fmi2Real stop)
{
    const char *fn = "rwadist wheel: fmi2SetupExperiment";
    if (!allowed(c, RW_SETUP_EXPERIMENT, "fmi2SetupExperiment"))
        return 0;
    if (!isfinite(t0))
        return !refuse(c, "%s: start time %g is not finite: give the run's start time in s", fn, t0);
    if (stopDef && !(stop >= t0))
        return !refuse(c, "%s: stop time %g s is before the start time %g s: give a stop time after the start, or "
                          "none", fn, stop, t0);
    if (tolDef && !(tol > 0 && isfinite(tol)))
        return !refuse(c, "%s: tolerance %g is not a positive number: give one > 0, or none", fn, tol);
    return 1;
}

CHECKED(fmi2SetupExperiment,
        (fmi2Component c, fmi2Boolean tolDef, fmi2Real tol, fmi2Real t0, fmi2Boolean stopDef, fmi2Real stop),
        (c, tolDef, tol, t0, stopDef, stop), setup_ok(c, tolDef, tol, t0, stopDef, stop), -1)
CHECKED(fmi2EnterInitializationMode, (fmi2Component c), (c),
        allowed(c, RW_ENTER_INIT, "fmi2EnterInitializationMode"), ST_INIT)
CHECKED(fmi2ExitInitializationMode, (fmi2Component c), (c), allowed(c, RW_EXIT_INIT, "fmi2ExitInitializationMode"),
        ST_STEP)
CHECKED(fmi2Terminate, (fmi2Component c), (c), allowed(c, RW_TERMINATE, "fmi2Terminate"), ST_TERMINATED)
CHECKED(fmi2Reset, (fmi2Component c), (c), allowed(c, RW_RESET, "fmi2Reset"), ST_INSTANTIATED)
/* the getters and setters of each type (vrs_ok checks the references and the state) */
#define VARIABLES_OF(T, RW)                                                                                       \
    CHECKED(fmi2Get##T, (fmi2Component c, const fmi2ValueReference vr[], size_t n, fmi2##T v[]), (c, vr, n, v),  \
            vrs_ok(c, "fmi2Get" #T, vr, n, v, RW, 0), -1)                                                         \
    CHECKED(fmi2Set##T, (fmi2Component c, const fmi2ValueReference vr[], size_t n, const fmi2##T v[]),          \
            (c, vr, n, v), vrs_ok(c, "fmi2Set" #T, vr, n, v, RW, 1), -1)
VARIABLES_OF(Real, RW_REAL)
VARIABLES_OF(Integer, RW_INTEGER)
VARIABLES_OF(Boolean, RW_BOOLEAN)
VARIABLES_OF(String, RW_STRING)
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
/* a refused step: the slave flags it and returns False, which pythonfmu reports as Discard (fmi2Error here) */
CHECKED(fmi2DoStep, (fmi2Component c, fmi2Real t, fmi2Real h, fmi2Boolean noPrior), (c, t, h, noPrior),
        allowed(c, RW_DO_STEP, "fmi2DoStep"), -1)
EXPORT fmi2Status fmi2CancelStep(fmi2Component c)
{
    return refuse(c, "rwadist wheel: fmi2CancelStep: illegal call sequence: steps are synchronous, no step is in "
                     "progress to cancel");
}
#define STATUS(T)                                                                                                 \
    CHECKED(fmi2Get##T##Status, (fmi2Component c, const fmi2StatusKind k, fmi2##T * v), (c, k, v),                \
            allowed(c, RW_GET_STATUS, "fmi2Get" #T "Status"), -1)
CHECKED(fmi2GetStatus, (fmi2Component c, const fmi2StatusKind k, fmi2Status *v), (c, k, v),
        allowed(c, RW_GET_STATUS, "fmi2GetStatus"), -1)
STATUS(Real)
STATUS(Integer)
STATUS(Boolean)
STATUS(String)

/* ------------------------------------------------------------------ step kernel (rwadist_kernel.h) */
#include "rwadist_kernel.h"

EXPORT void rwadist_kernel_step(const double *cfg, double *st, double *out, double omega, double wd0, double alpha,
                                double h)
{
    rwadist_kernel_step_impl(cfg, st, out, omega, wd0, alpha, h);
}
