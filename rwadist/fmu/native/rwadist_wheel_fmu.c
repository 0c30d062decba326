/* rwadist wheel FMU in C: FMI 2.0 co-simulation, no Python anywhere.
 *
 * The model (lines, amplitude laws, senses, suspension, diagnosed effects) is compiled in from
 * wheel_model.h, which rwadist/fmu/native_build.py generates from the model file.  One step is
 * WheelRuntime.step12 of rwadist/fmu/runtime.py: input checks, derived acceleration, speed ripple, the
 * step kernel of rwadist_kernel.h (shared with the pythonfmu FMU's native layer), broadband-floor
 * multisine, spacecraft frame.  Random phases come from numpy's default_rng re-implemented in
 * rwadist_rng.h, so a `seed` gives the phases of the Python FMU.  Variables, value references,
 * parameters and units are those of the pythonfmu FMU (rwadist/fmu/slave_template.py), so a host can swap
 * one FMU for the other.
 *
 * FMI state machine: rwadist_fmi_rules.h and rwadist_wheel_instance.h (a call out of order is answered with fmi2Error
 * and a logged message).  Bad input (non-finite speed, a step the model does not resolve, a time that does not
 * continue the last step, a parameter out of range) is logged and answered with fmi2Error; the kernel state stays at
 * the last good step and, as FMI 2.0 says, the instance is then in the error state: fmi2SetFMUstate with a state
 * stored before (the run goes on from there) or fmi2Reset lead on.  FMU state: get/set and serialize/deserialize
 * (the parameters travel with the state: a state restores the run it was taken from, bit for bit).  This file only
 * adapts the FMI 2.0 types and names to the wrapper layer. */
#include "fmi2Functions.h"
#include "rwadist_wheel_instance.h"

/* ------------------------------------------------------------------ FMI 2.0 */
typedef struct {
    Wheel w;                         /* first: an fmi2Component is a Wheel * */
    fmi2CallbackFunctions cb;
    char name[256];
} Fmi2Wheel;

/* the runtime's logger -> the host's fmi2CallbackLogger (the message is its format: '%' doubled, so hosts whose
 * logger cannot read varargs, ctypes callbacks e.g. fmpy, still see it) */
static void log_fmi2(void *env, RwStatus status, const char *category, const char *message)
{
    const Fmi2Wheel *f = (const Fmi2Wheel *)env;
    char msg[2048];
    size_t j = 0;
    for (size_t i = 0; message[i] && j + 2 < sizeof msg; i++) {
        if (message[i] == '%')
            msg[j++] = '%';
        msg[j++] = message[i];
    }
    msg[j] = 0;
    if (f->cb.logger)
        f->cb.logger(f->cb.componentEnvironment, f->name, (fmi2Status)status, category, msg);
}

/* the instance c (its Wheel as w), or fmi2Error for NULL; CALL(c, expr): the body of a function returning expr's
 * status as an fmi2Status */
#define WHEEL_OR_ERROR(c)                                                                                         \
    Wheel *w = (Wheel *)(c);                                                                                      \
    if (!w)                                                                                                       \
        return fmi2Error;
#define CALL(c, expr)                                                                                             \
    WHEEL_OR_ERROR(c)                                                                                             \
    return (fmi2Status)(expr)

FMI2_Export const char *fmi2GetTypesPlatform(void) { return fmi2TypesPlatform; }
FMI2_Export const char *fmi2GetVersion(void) { return fmi2Version; }

FMI2_Export fmi2Status fmi2SetDebugLogging(fmi2Component c, fmi2Boolean on, size_t n, const fmi2String cat[])
{
    (void)n, (void)cat;
    WHEEL_OR_ERROR(c)
    w->logging_on = on != fmi2False;
    return fmi2OK;
}

FMI2_Export fmi2Component fmi2Instantiate(fmi2String name, fmi2Type type, fmi2String guid, fmi2String resources,
                                          const fmi2CallbackFunctions *functions, fmi2Boolean visible,
                                          fmi2Boolean loggingOn)
{
    (void)resources, (void)visible;
    if (!functions)
        return NULL;
    Fmi2Wheel tmp;
    memset(&tmp, 0, sizeof tmp);
    tmp.cb = *functions;
    snprintf(tmp.name, sizeof tmp.name, "%s", name ? name : "wheel");
    tmp.w.logger = log_fmi2;
    tmp.w.log_env = &tmp;
    if (type != fmi2CoSimulation) {
        fail(&tmp.w, "fmi2Instantiate: this FMU is for co-simulation only: instantiate it with fmi2CoSimulation");
        return NULL;
    }
    if (!guid || strcmp(guid, RW_GUID) != 0) {
        fail(&tmp.w, "fmi2Instantiate: GUID %s does not match this FMU's %s: the host read another FMU's model "
                     "description; load this FMU's", guid ? guid : "(null)", RW_GUID);
        return NULL;
    }
    Fmi2Wheel *f = calloc(1, sizeof *f);
    if (!f) {
        fail(&tmp.w, "fmi2Instantiate: out of memory");
        return NULL;
    }
    *f = tmp;
    f->w.log_env = f;
    instantiated(&f->w, 2, loggingOn != fmi2False);
    return f;
}

FMI2_Export void fmi2FreeInstance(fmi2Component c)
{
    if (!c)
        return;
    free_model((Wheel *)c);
    free(c);
}

FMI2_Export fmi2Status fmi2SetupExperiment(fmi2Component c, fmi2Boolean tolDef, fmi2Real tol, fmi2Real t0,
                                           fmi2Boolean stopDef, fmi2Real stop)
{
    CALL(c, setup_experiment(w, "fmi2SetupExperiment", tolDef, tol, t0, stopDef, stop));
}

FMI2_Export fmi2Status fmi2EnterInitializationMode(fmi2Component c)
{
    CALL(c, enter_initialization(w, "fmi2EnterInitializationMode"));
}

FMI2_Export fmi2Status fmi2ExitInitializationMode(fmi2Component c)
{
    CALL(c, exit_initialization(w, "fmi2ExitInitializationMode"));
}

FMI2_Export fmi2Status fmi2Terminate(fmi2Component c) { CALL(c, terminate(w, "fmi2Terminate")); }
FMI2_Export fmi2Status fmi2Reset(fmi2Component c) { CALL(c, reset(w, "fmi2Reset")); }

FMI2_Export fmi2Status fmi2GetReal(fmi2Component c, const fmi2ValueReference vr[], size_t n, fmi2Real v[])
{
    CALL(c, get_vars(w, "fmi2GetReal", RW_REAL, vr, n, v, n));
}

FMI2_Export fmi2Status fmi2SetReal(fmi2Component c, const fmi2ValueReference vr[], size_t n, const fmi2Real v[])
{
    CALL(c, set_vars(w, "fmi2SetReal", RW_REAL, vr, n, v, n));
}

FMI2_Export fmi2Status fmi2GetInteger(fmi2Component c, const fmi2ValueReference vr[], size_t n, fmi2Integer v[])
{
    CALL(c, get_vars(w, "fmi2GetInteger", RW_INTEGER, vr, n, v, n));
}

FMI2_Export fmi2Status fmi2SetInteger(fmi2Component c, const fmi2ValueReference vr[], size_t n, const fmi2Integer v[])
{
    CALL(c, set_vars(w, "fmi2SetInteger", RW_INTEGER, vr, n, v, n));
}

FMI2_Export fmi2Status fmi2GetBoolean(fmi2Component c, const fmi2ValueReference vr[], size_t n, fmi2Boolean v[])
{
    CALL(c, get_vars(w, "fmi2GetBoolean", RW_BOOLEAN, vr, n, v, n));
}

FMI2_Export fmi2Status fmi2SetBoolean(fmi2Component c, const fmi2ValueReference vr[], size_t n, const fmi2Boolean v[])
{
    CALL(c, set_vars(w, "fmi2SetBoolean", RW_BOOLEAN, vr, n, v, n));
}

FMI2_Export fmi2Status fmi2GetString(fmi2Component c, const fmi2ValueReference vr[], size_t n, fmi2String v[])
{
    CALL(c, get_vars(w, "fmi2GetString", RW_STRING, vr, n, v, n));
}

FMI2_Export fmi2Status fmi2SetString(fmi2Component c, const fmi2ValueReference vr[], size_t n, const fmi2String v[])
{
    CALL(c, set_vars(w, "fmi2SetString", RW_STRING, vr, n, v, n));
}

FMI2_Export fmi2Status fmi2DoStep(fmi2Component c, fmi2Real t, fmi2Real h, fmi2Boolean noSetPrior)
{
    (void)noSetPrior;
    CALL(c, do_step(w, "fmi2DoStep", t, h));
}

FMI2_Export fmi2Status fmi2GetRealStatus(fmi2Component c, const fmi2StatusKind k, fmi2Real *v)
{
    WHEEL_OR_ERROR(c)
    if (!admit(w, RW_GET_STATUS, "fmi2GetRealStatus"))
        return fmi2Error;
    if (k == fmi2LastSuccessfulTime && v) {
        *v = w->mu.t_host;
        return fmi2OK;
    }
    return (fmi2Status)REFUSE(w, "fmi2GetRealStatus: status kind %d not supported: ask fmi2LastSuccessfulTime", (int)k);
}

/* ------------------------------------------------------------------ FMU state (rwadist_wheel_instance.h) */
FMI2_Export fmi2Status fmi2GetFMUstate(fmi2Component c, fmi2FMUstate *s)
{
    CALL(c, get_state(w, "fmi2GetFMUstate", s));
}

FMI2_Export fmi2Status fmi2SetFMUstate(fmi2Component c, fmi2FMUstate s)
{
    CALL(c, set_state(w, "fmi2SetFMUstate", s));
}

FMI2_Export fmi2Status fmi2FreeFMUstate(fmi2Component c, fmi2FMUstate *s)
{
    CALL(c, free_state(w, "fmi2FreeFMUstate", s));
}

FMI2_Export fmi2Status fmi2SerializedFMUstateSize(fmi2Component c, fmi2FMUstate s, size_t *size)
{
    CALL(c, serialized_size(w, "fmi2SerializedFMUstateSize", s, size));
}

FMI2_Export fmi2Status fmi2SerializeFMUstate(fmi2Component c, fmi2FMUstate s, fmi2Byte buf[], size_t size)
{
    CALL(c, serialize_state(w, "fmi2SerializeFMUstate", s, buf, size));
}

FMI2_Export fmi2Status fmi2DeSerializeFMUstate(fmi2Component c, const fmi2Byte buf[], size_t size, fmi2FMUstate *s)
{
    CALL(c, deserialize_state(w, "fmi2DeSerializeFMUstate", buf, size, s));
}

/* ------------------------------------------------------------------ not supported by this FMU: fmi2Error, logged.
 * These functions ignore their arguments by design (no unused-parameter warnings for them). */
#if defined(__GNUC__)
#pragma GCC diagnostic ignored "-Wunused-parameter"
#endif
FMI2_Export fmi2Status fmi2CancelStep(fmi2Component c)
{
    CALL(c, REFUSE(w, "fmi2CancelStep: illegal call sequence: steps are synchronous, no step is in progress to "
                      "cancel"));
}
FMI2_Export fmi2Status fmi2GetStatus(fmi2Component c, const fmi2StatusKind k, fmi2Status *v)
{
    CALL(c, unsupported(w, "fmi2GetStatus", "steps are synchronous: no step is pending"));
}
FMI2_Export fmi2Status fmi2GetIntegerStatus(fmi2Component c, const fmi2StatusKind k, fmi2Integer *v)
{
    CALL(c, unsupported(w, "fmi2GetIntegerStatus", "this FMU has no integer status"));
}
FMI2_Export fmi2Status fmi2GetBooleanStatus(fmi2Component c, const fmi2StatusKind k, fmi2Boolean *v)
{
    CALL(c, unsupported(w, "fmi2GetBooleanStatus", "fmi2DoStep never returns fmi2Discard"));
}
FMI2_Export fmi2Status fmi2GetStringStatus(fmi2Component c, const fmi2StatusKind k, fmi2String *v)
{
    CALL(c, unsupported(w, "fmi2GetStringStatus", "steps are synchronous: no step is pending"));
}
FMI2_Export fmi2Status fmi2SetRealInputDerivatives(fmi2Component c, const fmi2ValueReference vr[], size_t n,
                                                   const fmi2Integer order[], const fmi2Real v[])
{
    CALL(c, unsupported(w, "fmi2SetRealInputDerivatives", "canInterpolateInputs = false"));
}
FMI2_Export fmi2Status fmi2GetRealOutputDerivatives(fmi2Component c, const fmi2ValueReference vr[], size_t n,
                                                    const fmi2Integer order[], fmi2Real v[])
{
    CALL(c, unsupported(w, "fmi2GetRealOutputDerivatives", "maxOutputDerivativeOrder = 0"));
}
FMI2_Export fmi2Status fmi2GetDirectionalDerivative(fmi2Component c, const fmi2ValueReference u[], size_t nu,
                                                    const fmi2ValueReference z[], size_t nz, const fmi2Real dv[],
                                                    fmi2Real dz[])
{
    CALL(c, unsupported(w, "fmi2GetDirectionalDerivative", "providesDirectionalDerivative = false"));
}
