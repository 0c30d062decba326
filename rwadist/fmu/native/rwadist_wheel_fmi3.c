/* rwadist wheel FMU in C: FMI 3.0 co-simulation, no Python anywhere.
 *
 * The same model, kernel and runtime as the FMI 2.0 FMU (rwadist_wheel_fmu.c): wheel_model.h from the model file,
 * rwadist_wheel_runtime.h (one step), the wrapper layer rwadist_wheel_instance.h (the FMI state machine, variables
 * by value reference, the FMU state).  This file is the FMI 3.0 API only: the same variables and value references
 * as the FMI 2.0 FMU (Float64 for Real, Int32 for Integer) plus the independent variable `time`; co-simulation
 * without event mode, intermediate update or clocks (ExitInitializationMode leads to Step Mode).  Every function
 * of the FMI 3.0 API is exported; those of model exchange, scheduled execution, clocks and the types this FMU has no
 * variable of answer fmi3Error with a logged message.  As FMI 3.0 says, any fmi3Error moves the instance to
 * Terminated (rwadist_fmi_rules.h); fmi3SetFMUState with a state stored before, or fmi3Reset, lead on from there. */
#include "fmi3Functions.h"
#include "rwadist_wheel_instance.h"

typedef struct {
    Wheel w;                         /* first: an fmi3Instance is a Wheel * */
    fmi3InstanceEnvironment env;
    fmi3LogMessageCallback log;
} Fmi3Wheel;

static void log_fmi3(void *env, RwStatus status, const char *category, const char *message)
{
    const Fmi3Wheel *f = (const Fmi3Wheel *)env;
    if (f->log)
        f->log(f->env, (fmi3Status)status, category, message);
}

/* the instance c (its Wheel as w), or fmi3Error for NULL; CALL(c, expr): the body of a function returning expr's
 * status as an fmi3Status */
#define WHEEL_OR_ERROR(c)                                                                                         \
    Wheel *w = (Wheel *)(c);                                                                                      \
    if (!w)                                                                                                       \
        return fmi3Error;
#define CALL(c, expr)                                                                                             \
    WHEEL_OR_ERROR(c)                                                                                             \
    return (fmi3Status)(expr)

FMI3_Export const char *fmi3GetVersion(void) { return fmi3Version; }

FMI3_Export fmi3Status fmi3SetDebugLogging(fmi3Instance c, fmi3Boolean on, size_t n, const fmi3String cat[])
{
    (void)n, (void)cat;
    WHEEL_OR_ERROR(c)
    w->logging_on = on != fmi3False;
    return fmi3OK;
}

/* why an instantiation is refused (NULL: it is not) */
static const char *instantiation_refused(fmi3String token, fmi3Boolean eventModeUsed, size_t nRequired)
{
    if (!token || strcmp(token, RW_GUID) != 0)
        return "the instantiation token does not match this FMU's: the host read another FMU's model description; "
               "load this FMU's";
    if (eventModeUsed)
        return "eventModeUsed = true, but this FMU has no event mode (hasEventMode = false): instantiate it with "
               "eventModeUsed = false";
    if (nRequired)
        return "required intermediate variables given, but this FMU provides no intermediate update "
               "(providesIntermediateUpdate = false): give none";
    return NULL;
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
    const char *why = instantiation_refused(token, eventModeUsed, nRequired);
    if (why) {
        fail(&tmp.w, "fmi3InstantiateCoSimulation: %s", why);
        return NULL;
    }
    Fmi3Wheel *f = calloc(1, sizeof *f);
    if (!f) {
        fail(&tmp.w, "fmi3InstantiateCoSimulation: out of memory");
        return NULL;
    }
    *f = tmp;
    f->w.log_env = f;
    instantiated(&f->w, 3, loggingOn != fmi3False);
    return f;
}

/* the instantiations of the other interface types: NULL, logged */
static fmi3Instance not_cosimulation(fmi3InstanceEnvironment env, fmi3LogMessageCallback logMessage, const char *fn)
{
    char message[256];
    snprintf(message, sizeof message, "rwadist wheel: %s: this FMU is for co-simulation only: instantiate it with "
             "fmi3InstantiateCoSimulation", fn);
    if (logMessage)
        logMessage(env, fmi3Error, "logStatusError", message);
    return NULL;
}

/* ------------------------------------------------------------------ the run */
FMI3_Export void fmi3FreeInstance(fmi3Instance c)
{
    if (!c)
        return;
    free_model((Wheel *)c);
    free(c);
}

FMI3_Export fmi3Status fmi3EnterInitializationMode(fmi3Instance c, fmi3Boolean tolDef, fmi3Float64 tol,
                                                   fmi3Float64 t0, fmi3Boolean stopDef, fmi3Float64 stop)
{
    WHEEL_OR_ERROR(c)
    const char *fn = "fmi3EnterInitializationMode";
    const RwStatus s = setup_experiment(w, fn, tolDef, tol, t0, stopDef, stop);
    return (fmi3Status)(s == RW_OK ? enter_initialization(w, fn) : s);
}

FMI3_Export fmi3Status fmi3ExitInitializationMode(fmi3Instance c)
{
    CALL(c, exit_initialization(w, "fmi3ExitInitializationMode"));
}

FMI3_Export fmi3Status fmi3Terminate(fmi3Instance c) { CALL(c, terminate(w, "fmi3Terminate")); }
FMI3_Export fmi3Status fmi3Reset(fmi3Instance c) { CALL(c, reset(w, "fmi3Reset")); }

FMI3_Export fmi3Status fmi3DoStep(fmi3Instance c, fmi3Float64 t, fmi3Float64 h, fmi3Boolean noSetPrior,
                                  fmi3Boolean *eventHandlingNeeded, fmi3Boolean *terminateSimulation,
                                  fmi3Boolean *earlyReturn, fmi3Float64 *lastSuccessfulTime)
{
    (void)noSetPrior;
    WHEEL_OR_ERROR(c)
    const fmi3Status s = (fmi3Status)do_step(w, "fmi3DoStep", t, h);
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

/* ------------------------------------------------------------------ variables (rwadist_wheel_instance.h) */
_Static_assert(sizeof(fmi3Boolean) == 1, "fmi3Boolean is one byte");
_Static_assert(sizeof(fmi3Int32) == sizeof(int), "fmi3Int32 is an int");

/* fmi3Get##T / fmi3Set##T of the variables of type RW (value arrays of C type C) */
#define VARIABLES_OF(T, RW, C)                                                                                    \
    FMI3_Export fmi3Status fmi3Get##T(fmi3Instance c, const fmi3ValueReference vr[], size_t nvr, C v[], size_t nv) \
    {                                                                                                             \
        CALL(c, get_vars(w, "fmi3Get" #T, RW, vr, nvr, (void *)v, nv));                                          \
    }                                                                                                             \
    FMI3_Export fmi3Status fmi3Set##T(fmi3Instance c, const fmi3ValueReference vr[], size_t nvr, const C v[],    \
                                      size_t nv)                                                                  \
    {                                                                                                             \
        CALL(c, set_vars(w, "fmi3Set" #T, RW, vr, nvr, (const void *)v, nv));                                    \
    }
VARIABLES_OF(Float64, RW_REAL, fmi3Float64)
VARIABLES_OF(Int32, RW_INTEGER, fmi3Int32)
VARIABLES_OF(Boolean, RW_BOOLEAN, fmi3Boolean)
VARIABLES_OF(String, RW_STRING, fmi3String)

/* ------------------------------------------------------------------ FMU state (rwadist_wheel_instance.h) */
FMI3_Export fmi3Status fmi3GetFMUState(fmi3Instance c, fmi3FMUState *s)
{
    CALL(c, get_state(w, "fmi3GetFMUState", s));
}

FMI3_Export fmi3Status fmi3SetFMUState(fmi3Instance c, fmi3FMUState s)
{
    CALL(c, set_state(w, "fmi3SetFMUState", s));
}

FMI3_Export fmi3Status fmi3FreeFMUState(fmi3Instance c, fmi3FMUState *s)
{
    CALL(c, free_state(w, "fmi3FreeFMUState", s));
}

FMI3_Export fmi3Status fmi3SerializedFMUStateSize(fmi3Instance c, fmi3FMUState s, size_t *size)
{
    CALL(c, serialized_size(w, "fmi3SerializedFMUStateSize", s, size));
}

FMI3_Export fmi3Status fmi3SerializeFMUState(fmi3Instance c, fmi3FMUState s, fmi3Byte buf[], size_t size)
{
    CALL(c, serialize_state(w, "fmi3SerializeFMUState", s, (char *)buf, size));
}

FMI3_Export fmi3Status fmi3DeserializeFMUState(fmi3Instance c, const fmi3Byte buf[], size_t size, fmi3FMUState *s)
{
    CALL(c, deserialize_state(w, "fmi3DeserializeFMUState", (const char *)buf, size, s));
}

/* ------------------------------------------------------------------ not supported by this FMU: fmi3Error, logged.
 * These functions ignore their arguments by design (no unused-parameter warnings for them). */
#if defined(__GNUC__)
#pragma GCC diagnostic ignored "-Wunused-parameter"
#endif
FMI3_Export fmi3Instance fmi3InstantiateModelExchange(fmi3String name, fmi3String token, fmi3String resources,
                                                      fmi3Boolean visible, fmi3Boolean loggingOn,
                                                      fmi3InstanceEnvironment env, fmi3LogMessageCallback logMessage)
{
    return not_cosimulation(env, logMessage, "fmi3InstantiateModelExchange");
}

FMI3_Export fmi3Instance fmi3InstantiateScheduledExecution(fmi3String name, fmi3String token, fmi3String resources,
                                                           fmi3Boolean visible, fmi3Boolean loggingOn,
                                                           fmi3InstanceEnvironment env,
                                                           fmi3LogMessageCallback logMessage,
                                                           fmi3ClockUpdateCallback clockUpdate,
                                                           fmi3LockPreemptionCallback lockPreemption,
                                                           fmi3UnlockPreemptionCallback unlockPreemption)
{
    return not_cosimulation(env, logMessage, "fmi3InstantiateScheduledExecution");
}

/* the types this FMU has no variable of */
#define NO_VARIABLES_OF(T)                                                                                        \
    FMI3_Export fmi3Status fmi3Get##T(fmi3Instance c, const fmi3ValueReference vr[], size_t nvr, fmi3##T v[],    \
                                      size_t nv)                                                                  \
    {                                                                                                             \
        CALL(c, no_variable(w, "fmi3Get" #T, 0, nvr, vr));                                                        \
    }                                                                                                             \
    FMI3_Export fmi3Status fmi3Set##T(fmi3Instance c, const fmi3ValueReference vr[], size_t nvr,                  \
                                      const fmi3##T v[], size_t nv)                                               \
    {                                                                                                             \
        CALL(c, no_variable(w, "fmi3Set" #T, 1, nvr, vr));                                                        \
    }
NO_VARIABLES_OF(Float32)
NO_VARIABLES_OF(Int8)
NO_VARIABLES_OF(UInt8)
NO_VARIABLES_OF(Int16)
NO_VARIABLES_OF(UInt16)
NO_VARIABLES_OF(UInt32)
NO_VARIABLES_OF(Int64)
NO_VARIABLES_OF(UInt64)

FMI3_Export fmi3Status fmi3GetBinary(fmi3Instance c, const fmi3ValueReference vr[], size_t nvr, size_t sizes[],
                                     fmi3Binary v[], size_t nv)
{
    CALL(c, no_variable(w, "fmi3GetBinary", 0, nvr, vr));
}
FMI3_Export fmi3Status fmi3SetBinary(fmi3Instance c, const fmi3ValueReference vr[], size_t nvr, const size_t sizes[],
                                     const fmi3Binary v[], size_t nv)
{
    CALL(c, no_variable(w, "fmi3SetBinary", 1, nvr, vr));
}
FMI3_Export fmi3Status fmi3GetClock(fmi3Instance c, const fmi3ValueReference vr[], size_t nvr, fmi3Clock v[])
{
    CALL(c, no_variable(w, "fmi3GetClock", 0, nvr, vr));
}
FMI3_Export fmi3Status fmi3SetClock(fmi3Instance c, const fmi3ValueReference vr[], size_t nvr, const fmi3Clock v[])
{
    CALL(c, no_variable(w, "fmi3SetClock", 1, nvr, vr));
}

FMI3_Export fmi3Status fmi3EnterEventMode(fmi3Instance c)
{
    CALL(c, REFUSE(w, "fmi3EnterEventMode: illegal call sequence: this FMU has no event mode (hasEventMode = "
                      "false): step it with fmi3DoStep"));
}

FMI3_Export fmi3Status fmi3EnterStepMode(fmi3Instance c)
{
    CALL(c, REFUSE(w, "fmi3EnterStepMode: illegal call sequence: without event mode, fmi3ExitInitializationMode "
                      "leads to Step Mode directly"));
}

#define UNSUPPORTED(NAME, WHY, ...)                                                                               \
    FMI3_Export fmi3Status NAME(fmi3Instance c, __VA_ARGS__) { CALL(c, unsupported(w, #NAME, WHY)); }
#define UNSUPPORTED0(NAME, WHY)                                                                                   \
    FMI3_Export fmi3Status NAME(fmi3Instance c) { CALL(c, unsupported(w, #NAME, WHY)); }
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
UNSUPPORTED(fmi3GetOutputDerivatives, "maxOutputDerivativeOrder = 0", const fmi3ValueReference vr[], size_t nvr,
            const fmi3Int32 orders[], fmi3Float64 v[], size_t nv)
