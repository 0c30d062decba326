/* rwadist wheel FMU in C: FMI 3.0 co-simulation, no Python anywhere.
 *
 * The same model, kernel and runtime as the FMI 2.0 FMU (rwadist_wheel_fmu.c): wheel_model.h from the model file,
 * rwadist_wheel_runtime.h (one step), the wrapper layer rwadist_wheel_instance.h (the FMI state machine, variables
 * by value reference, the FMU state).  This file is the FMI 3.0 API only: the same variables and value references
 * as the FMI 2.0 FMU (Float64 for Real, Int32 for Integer) plus the independent variable `time`; co-simulation
 * without event mode, intermediate update or clocks (ExitInitializationMode leads to Step Mode).  Every function
 * of the FMI 3.0 API is exported; those of model exchange, scheduled execution, clocks and the types this FMU has no
 * variable of answer fmi3Error with a logged message. */
#include "fmi3Functions.h"
#include "rwadist_wheel_instance.h"

#define VR_TIME N_VR /* the independent variable (FMI 3.0 asks for one) */

typedef struct {
    Wheel w;                         /* first: an fmi3Instance is a Wheel * */
    fmi3InstanceEnvironment env;
    fmi3LogMessageCallback log;
} Fmi3Wheel;

static Wheel *as_wheel(fmi3Instance c) { return (Wheel *)c; }

static void log_fmi3(void *env, RwStatus status, const char *category, const char *message)
{
    const Fmi3Wheel *f = (const Fmi3Wheel *)env;
    if (f->log)
        f->log(f->env, (fmi3Status)status, category, message);
}

#define WHEEL_OR_ERROR(c)                                                                                         \
    Wheel *w = as_wheel(c);                                                                                       \
    if (!w)                                                                                                       \
        return fmi3Error;

/* a value array of the length of the value-reference array (every variable is a scalar) */
static int scalars(Wheel *w, const char *fn, size_t nvr, size_t nv)
{
    if (nvr == nv)
        return 1;
    fail(w, "%s: %zu values for %zu value references: every variable of this FMU is a scalar", fn, nv, nvr);
    return 0;
}

FMI3_Export const char *fmi3GetVersion(void) { return fmi3Version; }

FMI3_Export fmi3Status fmi3SetDebugLogging(fmi3Instance c, fmi3Boolean on, size_t n, const fmi3String cat[])
{
    (void)n, (void)cat;
    WHEEL_OR_ERROR(c)
    w->logging_on = on != fmi3False;
    return fmi3OK;
}

FMI3_Export fmi3Instance fmi3InstantiateCoSimulation(fmi3String name, fmi3String token, fmi3String resources,
                                                     fmi3Boolean visible, fmi3Boolean loggingOn,
                                                     fmi3Boolean eventModeUsed, fmi3Boolean earlyReturnAllowed,
                                                     const fmi3ValueReference required[], size_t nRequired,
                                                     fmi3InstanceEnvironment env, fmi3LogMessageCallback logMessage,
                                                     fmi3IntermediateUpdateCallback intermediateUpdate)
{
    (void)name, (void)resources, (void)visible, (void)earlyReturnAllowed, (void)required, (void)intermediateUpdate;
    Fmi3Wheel tmp;
    memset(&tmp, 0, sizeof tmp);
    tmp.env = env;
    tmp.log = logMessage;
    tmp.w.logger = log_fmi3;
    tmp.w.log_env = &tmp;
    if (!token || strcmp(token, RW_GUID) != 0) {
        fail(&tmp.w, "fmi3InstantiateCoSimulation: instantiation token %s does not match this FMU's %s",
             token ? token : "(null)", RW_GUID);
        return NULL;
    }
    if (eventModeUsed) {
        fail(&tmp.w, "fmi3InstantiateCoSimulation: eventModeUsed = true, but this FMU has no event mode "
                     "(hasEventMode = false): instantiate it with eventModeUsed = false");
        return NULL;
    }
    if (nRequired) {
        fail(&tmp.w, "fmi3InstantiateCoSimulation: %zu required intermediate variables, but this FMU provides no "
                     "intermediate update (providesIntermediateUpdate = false)", nRequired);
        return NULL;
    }
    Fmi3Wheel *f = calloc(1, sizeof *f);
    if (!f) {
        fail(&tmp.w, "fmi3InstantiateCoSimulation: out of memory");
        return NULL;
    }
    *f = tmp;
    Wheel *w = &f->w;
    w->log_env = f;
    w->logging_on = loggingOn != fmi3False;
    w->mode = ST_INSTANTIATED;
    set_defaults(w);
    logf_(w, RW_OK, "logAll", "rwadist wheel (native C FMU, FMI 3.0): %s", RW_PHYSICS);
    return f;
}

FMI3_Export fmi3Instance fmi3InstantiateModelExchange(fmi3String name, fmi3String token, fmi3String resources,
                                                      fmi3Boolean visible, fmi3Boolean loggingOn,
                                                      fmi3InstanceEnvironment env, fmi3LogMessageCallback logMessage)
{
    (void)name, (void)token, (void)resources, (void)visible, (void)loggingOn;
    if (logMessage)
        logMessage(env, fmi3Error, "logStatusError", "rwadist wheel: fmi3InstantiateModelExchange: this FMU is for "
                                                     "co-simulation only");
    return NULL;
}

FMI3_Export fmi3Instance fmi3InstantiateScheduledExecution(fmi3String name, fmi3String token, fmi3String resources,
                                                           fmi3Boolean visible, fmi3Boolean loggingOn,
                                                           fmi3InstanceEnvironment env,
                                                           fmi3LogMessageCallback logMessage,
                                                           fmi3ClockUpdateCallback clockUpdate,
                                                           fmi3LockPreemptionCallback lockPreemption,
                                                           fmi3UnlockPreemptionCallback unlockPreemption)
{
    (void)name, (void)token, (void)resources, (void)visible, (void)loggingOn, (void)clockUpdate;
    (void)lockPreemption, (void)unlockPreemption;
    if (logMessage)
        logMessage(env, fmi3Error, "logStatusError", "rwadist wheel: fmi3InstantiateScheduledExecution: this FMU is "
                                                     "for co-simulation only");
    return NULL;
}

FMI3_Export void fmi3FreeInstance(fmi3Instance c)
{
    Wheel *w = as_wheel(c);
    if (!w)
        return;
    free_model(w);
    free(c);
}

FMI3_Export fmi3Status fmi3EnterInitializationMode(fmi3Instance c, fmi3Boolean tolDef, fmi3Float64 tol,
                                                   fmi3Float64 t0, fmi3Boolean stopDef, fmi3Float64 stop)
{
    WHEEL_OR_ERROR(c)
    if (!allowed(w, IN(ST_INSTANTIATED), "fmi3EnterInitializationMode"))
        return fmi3Error;
    if (!isfinite(t0))
        return (fmi3Status)fail(w, "fmi3EnterInitializationMode: start time %g is not finite", t0);
    if (stopDef && !(stop >= t0))
        return (fmi3Status)fail(w, "fmi3EnterInitializationMode: stop time %g s is before the start time %g s", stop,
                                t0);
    if (tolDef && !(tol > 0 && isfinite(tol)))
        return (fmi3Status)fail(w, "fmi3EnterInitializationMode: tolerance %g is not a positive number", tol);
    w->mu.t_host = t0;
    w->mode = ST_INIT;
    return fmi3OK;
}

FMI3_Export fmi3Status fmi3ExitInitializationMode(fmi3Instance c)
{
    WHEEL_OR_ERROR(c)
    if (!allowed(w, IN(ST_INIT), "fmi3ExitInitializationMode"))
        return fmi3Error;
    return (fmi3Status)exit_initialization(w);
}

FMI3_Export fmi3Status fmi3EnterEventMode(fmi3Instance c)
{
    WHEEL_OR_ERROR(c)
    return (fmi3Status)fail(w, "fmi3EnterEventMode: illegal call sequence: this FMU has no event mode "
                               "(hasEventMode = false)");
}

FMI3_Export fmi3Status fmi3EnterStepMode(fmi3Instance c)
{
    WHEEL_OR_ERROR(c)
    return (fmi3Status)fail(w, "fmi3EnterStepMode: illegal call sequence: without event mode, "
                               "fmi3ExitInitializationMode leads to Step Mode directly");
}

FMI3_Export fmi3Status fmi3Terminate(fmi3Instance c)
{
    WHEEL_OR_ERROR(c)
    if (!allowed(w, IN(ST_STEP), "fmi3Terminate"))
        return fmi3Error;
    w->mode = ST_TERMINATED;
    return fmi3OK;
}

FMI3_Export fmi3Status fmi3Reset(fmi3Instance c)
{
    WHEEL_OR_ERROR(c)
    free_model(w);
    set_defaults(w);
    w->mode = ST_INSTANTIATED;
    return fmi3OK;
}

/* ------------------------------------------------------------------ variables */
FMI3_Export fmi3Status fmi3GetFloat64(fmi3Instance c, const fmi3ValueReference vr[], size_t nvr, fmi3Float64 v[],
                                      size_t nv)
{
    WHEEL_OR_ERROR(c)
    if (!scalars(w, "fmi3GetFloat64", nvr, nv))
        return fmi3Error;
    if (!allowed(w, READABLE, "fmi3GetFloat64") || !arrays_ok(w, "fmi3GetFloat64", nvr, vr, v))
        return fmi3Error;
    for (size_t i = 0; i < nvr; i++) {
        if (vr[i] == VR_TIME)
            v[i] = w->mu.t_host;
        else if (get_reals(w, "fmi3GetFloat64", &vr[i], 1, &v[i]) != RW_OK)
            return fmi3Error;
    }
    return fmi3OK;
}

FMI3_Export fmi3Status fmi3SetFloat64(fmi3Instance c, const fmi3ValueReference vr[], size_t nvr,
                                      const fmi3Float64 v[], size_t nv)
{
    WHEEL_OR_ERROR(c)
    if (!scalars(w, "fmi3SetFloat64", nvr, nv))
        return fmi3Error;
    for (size_t i = 0; i < nvr && vr; i++)
        if (vr[i] == VR_TIME)
            return (fmi3Status)fail(w, "fmi3SetFloat64: value reference %u is the independent variable time", vr[i]);
    return (fmi3Status)set_reals(w, "fmi3SetFloat64", vr, nvr, v);
}

FMI3_Export fmi3Status fmi3GetInt32(fmi3Instance c, const fmi3ValueReference vr[], size_t nvr, fmi3Int32 v[],
                                    size_t nv)
{
    WHEEL_OR_ERROR(c)
    return scalars(w, "fmi3GetInt32", nvr, nv) ? (fmi3Status)get_seed(w, "fmi3GetInt32", vr, nvr, v) : fmi3Error;
}

FMI3_Export fmi3Status fmi3SetInt32(fmi3Instance c, const fmi3ValueReference vr[], size_t nvr, const fmi3Int32 v[],
                                    size_t nv)
{
    WHEEL_OR_ERROR(c)
    return scalars(w, "fmi3SetInt32", nvr, nv) ? (fmi3Status)set_seed(w, "fmi3SetInt32", vr, nvr, v) : fmi3Error;
}

FMI3_Export fmi3Status fmi3GetBoolean(fmi3Instance c, const fmi3ValueReference vr[], size_t nvr, fmi3Boolean v[],
                                      size_t nv)
{
    WHEEL_OR_ERROR(c)
    _Static_assert(sizeof(fmi3Boolean) == 1, "fmi3Boolean is one byte");
    return scalars(w, "fmi3GetBoolean", nvr, nv) ? (fmi3Status)get_bools(w, "fmi3GetBoolean", vr, nvr, v, 0)
                                                 : fmi3Error;
}

FMI3_Export fmi3Status fmi3SetBoolean(fmi3Instance c, const fmi3ValueReference vr[], size_t nvr,
                                      const fmi3Boolean v[], size_t nv)
{
    WHEEL_OR_ERROR(c)
    return scalars(w, "fmi3SetBoolean", nvr, nv) ? (fmi3Status)set_bools(w, "fmi3SetBoolean", vr, nvr, v, 0)
                                                 : fmi3Error;
}

FMI3_Export fmi3Status fmi3GetString(fmi3Instance c, const fmi3ValueReference vr[], size_t nvr, fmi3String v[],
                                     size_t nv)
{
    WHEEL_OR_ERROR(c)
    return scalars(w, "fmi3GetString", nvr, nv) ? (fmi3Status)get_strings(w, "fmi3GetString", vr, nvr, v)
                                                : fmi3Error;
}

FMI3_Export fmi3Status fmi3SetString(fmi3Instance c, const fmi3ValueReference vr[], size_t nvr,
                                     const fmi3String v[], size_t nv)
{
    WHEEL_OR_ERROR(c)
    return scalars(w, "fmi3SetString", nvr, nv) ? (fmi3Status)set_strings(w, "fmi3SetString", vr, nvr, v)
                                                : fmi3Error;
}

/* the types this FMU has no variable of: every value reference is refused */
static fmi3Status no_variable(fmi3Instance c, const char *fn, size_t nvr, const fmi3ValueReference vr[])
{
    WHEEL_OR_ERROR(c)
    if (!nvr)
        return fmi3OK;
    return (fmi3Status)fail(w, "%s: value reference %u: this FMU has no variable of this type", fn, vr ? vr[0] : 0u);
}

#define NO_TYPE(T)                                                                                                \
    FMI3_Export fmi3Status fmi3Get##T(fmi3Instance c, const fmi3ValueReference vr[], size_t nvr, fmi3##T v[],    \
                                      size_t nv)                                                                  \
    {                                                                                                             \
        (void)v, (void)nv;                                                                                        \
        return no_variable(c, "fmi3Get" #T, nvr, vr);                                                             \
    }                                                                                                             \
    FMI3_Export fmi3Status fmi3Set##T(fmi3Instance c, const fmi3ValueReference vr[], size_t nvr,                  \
                                      const fmi3##T v[], size_t nv)                                               \
    {                                                                                                             \
        (void)v, (void)nv;                                                                                        \
        return no_variable(c, "fmi3Set" #T, nvr, vr);                                                             \
    }
NO_TYPE(Float32)
NO_TYPE(Int8)
NO_TYPE(UInt8)
NO_TYPE(Int16)
NO_TYPE(UInt16)
NO_TYPE(UInt32)
NO_TYPE(Int64)
NO_TYPE(UInt64)

FMI3_Export fmi3Status fmi3GetBinary(fmi3Instance c, const fmi3ValueReference vr[], size_t nvr, size_t sizes[],
                                     fmi3Binary v[], size_t nv)
{
    (void)sizes, (void)v, (void)nv;
    return no_variable(c, "fmi3GetBinary", nvr, vr);
}
FMI3_Export fmi3Status fmi3SetBinary(fmi3Instance c, const fmi3ValueReference vr[], size_t nvr, const size_t sizes[],
                                     const fmi3Binary v[], size_t nv)
{
    (void)sizes, (void)v, (void)nv;
    return no_variable(c, "fmi3SetBinary", nvr, vr);
}
FMI3_Export fmi3Status fmi3GetClock(fmi3Instance c, const fmi3ValueReference vr[], size_t nvr, fmi3Clock v[])
{
    (void)v;
    return no_variable(c, "fmi3GetClock", nvr, vr);
}
FMI3_Export fmi3Status fmi3SetClock(fmi3Instance c, const fmi3ValueReference vr[], size_t nvr, const fmi3Clock v[])
{
    (void)v;
    return no_variable(c, "fmi3SetClock", nvr, vr);
}

/* ------------------------------------------------------------------ stepping */
FMI3_Export fmi3Status fmi3DoStep(fmi3Instance c, fmi3Float64 t, fmi3Float64 h, fmi3Boolean noSetPrior,
                                  fmi3Boolean *eventHandlingNeeded, fmi3Boolean *terminateSimulation,
                                  fmi3Boolean *earlyReturn, fmi3Float64 *lastSuccessfulTime)
{
    (void)noSetPrior;
    WHEEL_OR_ERROR(c)
    fmi3Status s = fmi3Error;
    if (allowed(w, IN(ST_STEP), "fmi3DoStep"))
        s = (fmi3Status)do_step(w, t, h);
    if (eventHandlingNeeded)
        *eventHandlingNeeded = fmi3False;
    if (terminateSimulation)
        *terminateSimulation = fmi3False;
    if (earlyReturn)
        *earlyReturn = fmi3False;
    if (lastSuccessfulTime)
        *lastSuccessfulTime = w->mu.t_host;
    return s;
}

FMI3_Export fmi3Status fmi3GetOutputDerivatives(fmi3Instance c, const fmi3ValueReference vr[], size_t nvr,
                                                const fmi3Int32 orders[], fmi3Float64 v[], size_t nv)
{
    (void)vr, (void)nvr, (void)orders, (void)v, (void)nv;
    WHEEL_OR_ERROR(c)
    return (fmi3Status)fail(w, "fmi3GetOutputDerivatives: not supported (maxOutputDerivativeOrder = 0)");
}

/* ------------------------------------------------------------------ FMU state (rwadist_wheel_instance.h) */
FMI3_Export fmi3Status fmi3GetFMUState(fmi3Instance c, fmi3FMUState *s)
{
    WHEEL_OR_ERROR(c)
    return (fmi3Status)get_state(w, "fmi3GetFMUState", s);
}

FMI3_Export fmi3Status fmi3SetFMUState(fmi3Instance c, fmi3FMUState s)
{
    WHEEL_OR_ERROR(c)
    return (fmi3Status)set_state(w, "fmi3SetFMUState", s);
}

FMI3_Export fmi3Status fmi3FreeFMUState(fmi3Instance c, fmi3FMUState *s)
{
    (void)c;
    if (s) {
        free(*s);
        *s = NULL;
    }
    return fmi3OK;
}

FMI3_Export fmi3Status fmi3SerializedFMUStateSize(fmi3Instance c, fmi3FMUState s, size_t *size)
{
    WHEEL_OR_ERROR(c)
    if (!s || !size)
        return (fmi3Status)fail(w, "fmi3SerializedFMUStateSize: no state or no size pointer given");
    *size = ((const Blob *)s)->size;
    return fmi3OK;
}

FMI3_Export fmi3Status fmi3SerializeFMUState(fmi3Instance c, fmi3FMUState s, fmi3Byte buf[], size_t size)
{
    WHEEL_OR_ERROR(c)
    return (fmi3Status)serialize_state(w, "fmi3SerializeFMUState", s, (char *)buf, size);
}

FMI3_Export fmi3Status fmi3DeserializeFMUState(fmi3Instance c, const fmi3Byte buf[], size_t size, fmi3FMUState *s)
{
    WHEEL_OR_ERROR(c)
    return (fmi3Status)deserialize_state(w, "fmi3DeserializeFMUState", (const char *)buf, size, s);
}

/* ------------------------------------------------------------------ not supported by this FMU */
#define UNSUPPORTED(NAME, WHY, ...)                                                                               \
    FMI3_Export fmi3Status NAME(fmi3Instance c, __VA_ARGS__)                                                      \
    {                                                                                                             \
        WHEEL_OR_ERROR(c)                                                                                         \
        return (fmi3Status)fail(w, #NAME ": not supported (" WHY ")");                                            \
    }
#define UNSUPPORTED0(NAME, WHY)                                                                                   \
    FMI3_Export fmi3Status NAME(fmi3Instance c)                                                                   \
    {                                                                                                             \
        WHEEL_OR_ERROR(c)                                                                                         \
        return (fmi3Status)fail(w, #NAME ": not supported (" WHY ")");                                            \
    }
#define CS_ONLY "a co-simulation FMU without event mode"
#define NO_CLOCKS "this FMU has no clocks"

UNSUPPORTED(fmi3GetNumberOfVariableDependencies, "the modelDescription lists none", fmi3ValueReference vr,
            size_t *n)
UNSUPPORTED(fmi3GetVariableDependencies, "the modelDescription lists none", fmi3ValueReference dependent,
            size_t elementIndicesOfDependent[], fmi3ValueReference independents[],
            size_t elementIndicesOfIndependents[], fmi3DependencyKind kinds[], size_t n)
UNSUPPORTED(fmi3GetDirectionalDerivative, "providesDirectionalDerivatives = false",
            const fmi3ValueReference unknowns[], size_t nUnknowns, const fmi3ValueReference knowns[], size_t nKnowns,
            const fmi3Float64 seed[], size_t nSeed, fmi3Float64 sensitivity[], size_t nSensitivity)
UNSUPPORTED(fmi3GetAdjointDerivative, "providesAdjointDerivatives = false", const fmi3ValueReference unknowns[],
            size_t nUnknowns, const fmi3ValueReference knowns[], size_t nKnowns, const fmi3Float64 seed[],
            size_t nSeed, fmi3Float64 sensitivity[], size_t nSensitivity)
UNSUPPORTED0(fmi3EnterConfigurationMode, "this FMU has no structural parameters")
UNSUPPORTED0(fmi3ExitConfigurationMode, "this FMU has no structural parameters")
UNSUPPORTED(fmi3GetIntervalDecimal, NO_CLOCKS, const fmi3ValueReference vr[], size_t n, fmi3Float64 intervals[],
            fmi3IntervalQualifier qualifiers[])
UNSUPPORTED(fmi3GetIntervalFraction, NO_CLOCKS, const fmi3ValueReference vr[], size_t n, fmi3UInt64 counters[],
            fmi3UInt64 resolutions[], fmi3IntervalQualifier qualifiers[])
UNSUPPORTED(fmi3GetShiftDecimal, NO_CLOCKS, const fmi3ValueReference vr[], size_t n, fmi3Float64 shifts[])
UNSUPPORTED(fmi3GetShiftFraction, NO_CLOCKS, const fmi3ValueReference vr[], size_t n, fmi3UInt64 counters[],
            fmi3UInt64 resolutions[])
UNSUPPORTED(fmi3SetIntervalDecimal, NO_CLOCKS, const fmi3ValueReference vr[], size_t n,
            const fmi3Float64 intervals[])
UNSUPPORTED(fmi3SetIntervalFraction, NO_CLOCKS, const fmi3ValueReference vr[], size_t n,
            const fmi3UInt64 counters[], const fmi3UInt64 resolutions[])
UNSUPPORTED(fmi3SetShiftDecimal, NO_CLOCKS, const fmi3ValueReference vr[], size_t n, const fmi3Float64 shifts[])
UNSUPPORTED(fmi3SetShiftFraction, NO_CLOCKS, const fmi3ValueReference vr[], size_t n, const fmi3UInt64 counters[],
            const fmi3UInt64 resolutions[])
UNSUPPORTED0(fmi3EvaluateDiscreteStates, CS_ONLY)
UNSUPPORTED(fmi3UpdateDiscreteStates, CS_ONLY, fmi3Boolean *discreteStatesNeedUpdate,
            fmi3Boolean *terminateSimulation, fmi3Boolean *nominalsChanged, fmi3Boolean *valuesChanged,
            fmi3Boolean *nextEventTimeDefined, fmi3Float64 *nextEventTime)
UNSUPPORTED0(fmi3EnterContinuousTimeMode, CS_ONLY)
UNSUPPORTED(fmi3CompletedIntegratorStep, CS_ONLY, fmi3Boolean noSetFMUStatePriorToCurrentPoint,
            fmi3Boolean *enterEventMode, fmi3Boolean *terminateSimulation)
UNSUPPORTED(fmi3SetTime, CS_ONLY, fmi3Float64 time)
UNSUPPORTED(fmi3SetContinuousStates, CS_ONLY, const fmi3Float64 x[], size_t n)
UNSUPPORTED(fmi3GetContinuousStateDerivatives, CS_ONLY, fmi3Float64 dx[], size_t n)
UNSUPPORTED(fmi3GetEventIndicators, CS_ONLY, fmi3Float64 z[], size_t n)
UNSUPPORTED(fmi3GetContinuousStates, CS_ONLY, fmi3Float64 x[], size_t n)
UNSUPPORTED(fmi3GetNominalsOfContinuousStates, CS_ONLY, fmi3Float64 nominals[], size_t n)
UNSUPPORTED(fmi3GetNumberOfEventIndicators, CS_ONLY, size_t *n)
UNSUPPORTED(fmi3GetNumberOfContinuousStates, CS_ONLY, size_t *n)
UNSUPPORTED(fmi3ActivateModelPartition, "not a scheduled-execution FMU", fmi3ValueReference clock,
            fmi3Float64 activationTime)
