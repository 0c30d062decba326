/* rwadist wheel FMU in C: FMI 2.0 co-simulation, no Python anywhere.
 *
 * The model (lines, amplitude laws, senses, suspension, diagnosed effects) is compiled in from
 * wheel_model.h, which fmu/native_build.py generates from the model file.  One step is
 * WheelRuntime.step12 of fmu/runtime.py: input checks, derived acceleration, speed ripple, the
 * step kernel of rwadist_kernel.h (shared with the pythonfmu FMU's native layer), broadband-floor
 * multisine, spacecraft frame.  Random phases come from numpy's default_rng re-implemented in
 * rwadist_rng.h, so a `seed` gives the phases of the Python FMU.  Variables, value references,
 * parameters and units are those of the pythonfmu FMU (fmu/slave_template.py), so a host can swap
 * one FMU for the other.
 *
 * FMI state machine: rwadist_wheel_instance.h (a call out of order is answered with fmi2Error and a logged
 * message; the instance stays in its state).  Bad input (non-finite speed, a step the model does not resolve, a time that does not continue the
 * last step, a parameter out of range) is logged and answered with fmi2Error; the state stays at the
 * last good step, so the host may go on.  FMU state: get/set and serialize/deserialize (the
 * parameters travel with the state: a state restores the run it was taken from, bit for bit). */
#include "fmi2Functions.h"
#include "rwadist_wheel_instance.h"

/* ------------------------------------------------------------------ FMI 2.0 */
typedef struct {
    Wheel w;                         /* first: an fmi2Component is a Wheel * */
    fmi2CallbackFunctions cb;
    char name[256];
} Fmi2Wheel;

static Wheel *as_wheel(fmi2Component c) { return (Wheel *)c; }

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

#define WHEEL_OR_ERROR(c)                                                                                         \
    Wheel *w = as_wheel(c);                                                                                       \
    if (!w)                                                                                                       \
        return fmi2Error;

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
        fail(&tmp.w, "fmi2Instantiate: this FMU is for co-simulation only");
        return NULL;
    }
    if (!guid || strcmp(guid, RW_GUID) != 0) {
        fail(&tmp.w, "fmi2Instantiate: GUID %s does not match this FMU's %s", guid ? guid : "(null)", RW_GUID);
        return NULL;
    }
    Fmi2Wheel *f = calloc(1, sizeof *f);
    if (!f) {
        fail(&tmp.w, "fmi2Instantiate: out of memory");
        return NULL;
    }
    *f = tmp;
    Wheel *w = &f->w;
    w->log_env = f;
    w->logging_on = loggingOn != fmi2False;
    w->mode = ST_INSTANTIATED;
    set_defaults(w);
    logf_(w, RW_OK, "logAll", "rwadist wheel (native C FMU): %s", RW_PHYSICS);
    return f;
}

FMI2_Export void fmi2FreeInstance(fmi2Component c)
{
    Wheel *w = as_wheel(c);
    if (!w)
        return;
    free_model(w);
    free(c);
}

FMI2_Export fmi2Status fmi2SetupExperiment(fmi2Component c, fmi2Boolean tolDef, fmi2Real tol, fmi2Real t0,
                                           fmi2Boolean stopDef, fmi2Real stop)
{
    WHEEL_OR_ERROR(c)
    if (!allowed(w, IN(ST_INSTANTIATED), "fmi2SetupExperiment"))
        return fmi2Error;
    if (!isfinite(t0))
        return (fmi2Status)fail(w, "fmi2SetupExperiment: start time %g is not finite", t0);
    if (stopDef && !(stop >= t0))
        return (fmi2Status)fail(w, "fmi2SetupExperiment: stop time %g s is before the start time %g s", stop, t0);
    if (tolDef && !(tol > 0 && isfinite(tol)))
        return (fmi2Status)fail(w, "fmi2SetupExperiment: tolerance %g is not a positive number", tol);
    w->mu.t_host = t0;
    return fmi2OK;
}

FMI2_Export fmi2Status fmi2EnterInitializationMode(fmi2Component c)
{
    WHEEL_OR_ERROR(c)
    if (!allowed(w, IN(ST_INSTANTIATED), "fmi2EnterInitializationMode"))
        return fmi2Error;
    w->mode = ST_INIT;
    return fmi2OK;
}

FMI2_Export fmi2Status fmi2ExitInitializationMode(fmi2Component c)
{
    WHEEL_OR_ERROR(c)
    if (!allowed(w, IN(ST_INIT), "fmi2ExitInitializationMode"))
        return fmi2Error;
    return (fmi2Status)exit_initialization(w);
}

FMI2_Export fmi2Status fmi2Terminate(fmi2Component c)
{
    WHEEL_OR_ERROR(c)
    if (!allowed(w, IN(ST_STEP), "fmi2Terminate"))
        return fmi2Error;
    w->mode = ST_TERMINATED;
    return fmi2OK;
}

FMI2_Export fmi2Status fmi2Reset(fmi2Component c)
{
    WHEEL_OR_ERROR(c)
    free_model(w);
    set_defaults(w);
    w->mode = ST_INSTANTIATED;
    return fmi2OK;
}

FMI2_Export fmi2Status fmi2GetReal(fmi2Component c, const fmi2ValueReference vr[], size_t n, fmi2Real v[])
{
    WHEEL_OR_ERROR(c)
    return (fmi2Status)get_reals(w, "fmi2GetReal", vr, n, v);
}

FMI2_Export fmi2Status fmi2SetReal(fmi2Component c, const fmi2ValueReference vr[], size_t n, const fmi2Real v[])
{
    WHEEL_OR_ERROR(c)
    return (fmi2Status)set_reals(w, "fmi2SetReal", vr, n, v);
}

FMI2_Export fmi2Status fmi2GetInteger(fmi2Component c, const fmi2ValueReference vr[], size_t n, fmi2Integer v[])
{
    WHEEL_OR_ERROR(c)
    return (fmi2Status)get_seed(w, "fmi2GetInteger", vr, n, v);
}

FMI2_Export fmi2Status fmi2SetInteger(fmi2Component c, const fmi2ValueReference vr[], size_t n, const fmi2Integer v[])
{
    WHEEL_OR_ERROR(c)
    return (fmi2Status)set_seed(w, "fmi2SetInteger", vr, n, v);
}

FMI2_Export fmi2Status fmi2GetBoolean(fmi2Component c, const fmi2ValueReference vr[], size_t n, fmi2Boolean v[])
{
    WHEEL_OR_ERROR(c)
    return (fmi2Status)get_bools(w, "fmi2GetBoolean", vr, n, v, 1);
}

FMI2_Export fmi2Status fmi2SetBoolean(fmi2Component c, const fmi2ValueReference vr[], size_t n, const fmi2Boolean v[])
{
    WHEEL_OR_ERROR(c)
    return (fmi2Status)set_bools(w, "fmi2SetBoolean", vr, n, v, 1);
}

FMI2_Export fmi2Status fmi2GetString(fmi2Component c, const fmi2ValueReference vr[], size_t n, fmi2String v[])
{
    WHEEL_OR_ERROR(c)
    return (fmi2Status)get_strings(w, "fmi2GetString", vr, n, v);
}

FMI2_Export fmi2Status fmi2SetString(fmi2Component c, const fmi2ValueReference vr[], size_t n, const fmi2String v[])
{
    WHEEL_OR_ERROR(c)
    return (fmi2Status)set_strings(w, "fmi2SetString", vr, n, v);
}

FMI2_Export fmi2Status fmi2DoStep(fmi2Component c, fmi2Real t, fmi2Real h, fmi2Boolean noSetPrior)
{
    (void)noSetPrior;
    WHEEL_OR_ERROR(c)
    if (!allowed(w, IN(ST_STEP), "fmi2DoStep"))
        return fmi2Error;
    return (fmi2Status)do_step(w, t, h);
}

FMI2_Export fmi2Status fmi2CancelStep(fmi2Component c)
{
    WHEEL_OR_ERROR(c)
    return (fmi2Status)fail(w, "fmi2CancelStep: illegal call sequence: steps are synchronous, no step is in "
                               "progress to cancel");
}

FMI2_Export fmi2Status fmi2GetStatus(fmi2Component c, const fmi2StatusKind k, fmi2Status *v)
{
    (void)k, (void)v;
    WHEEL_OR_ERROR(c)
    return (fmi2Status)fail(w, "fmi2GetStatus: not supported (steps are synchronous)");
}
FMI2_Export fmi2Status fmi2GetRealStatus(fmi2Component c, const fmi2StatusKind k, fmi2Real *v)
{
    WHEEL_OR_ERROR(c)
    if (!allowed(w, IN(ST_STEP) | IN(ST_TERMINATED), "fmi2GetRealStatus"))
        return fmi2Error;
    if (k == fmi2LastSuccessfulTime && v) {
        *v = w->mu.t_host;
        return fmi2OK;
    }
    return (fmi2Status)fail(w, "fmi2GetRealStatus: status kind %d not supported", (int)k);
}
FMI2_Export fmi2Status fmi2GetIntegerStatus(fmi2Component c, const fmi2StatusKind k, fmi2Integer *v)
{
    (void)k, (void)v;
    WHEEL_OR_ERROR(c)
    return (fmi2Status)fail(w, "fmi2GetIntegerStatus: not supported");
}
FMI2_Export fmi2Status fmi2GetBooleanStatus(fmi2Component c, const fmi2StatusKind k, fmi2Boolean *v)
{
    (void)k, (void)v;
    WHEEL_OR_ERROR(c)
    return (fmi2Status)fail(w, "fmi2GetBooleanStatus: not supported");
}
FMI2_Export fmi2Status fmi2GetStringStatus(fmi2Component c, const fmi2StatusKind k, fmi2String *v)
{
    (void)k, (void)v;
    WHEEL_OR_ERROR(c)
    return (fmi2Status)fail(w, "fmi2GetStringStatus: not supported");
}
FMI2_Export fmi2Status fmi2SetRealInputDerivatives(fmi2Component c, const fmi2ValueReference vr[], size_t n,
                                                   const fmi2Integer order[], const fmi2Real v[])
{
    (void)vr, (void)n, (void)order, (void)v;
    WHEEL_OR_ERROR(c)
    return (fmi2Status)fail(w, "fmi2SetRealInputDerivatives: not supported (canInterpolateInputs = false)");
}
FMI2_Export fmi2Status fmi2GetRealOutputDerivatives(fmi2Component c, const fmi2ValueReference vr[], size_t n,
                                                    const fmi2Integer order[], fmi2Real v[])
{
    (void)vr, (void)n, (void)order, (void)v;
    WHEEL_OR_ERROR(c)
    return (fmi2Status)fail(w, "fmi2GetRealOutputDerivatives: not supported (maxOutputDerivativeOrder = 0)");
}
FMI2_Export fmi2Status fmi2GetDirectionalDerivative(fmi2Component c, const fmi2ValueReference u[], size_t nu,
                                                    const fmi2ValueReference z[], size_t nz, const fmi2Real dv[],
                                                    fmi2Real dz[])
{
    (void)u, (void)nu, (void)z, (void)nz, (void)dv, (void)dz;
    WHEEL_OR_ERROR(c)
    return (fmi2Status)fail(w, "fmi2GetDirectionalDerivative: not supported");
}

/* ------------------------------------------------------------------ FMU state (rwadist_wheel_instance.h) */
FMI2_Export fmi2Status fmi2GetFMUstate(fmi2Component c, fmi2FMUstate *s)
{
    WHEEL_OR_ERROR(c)
    return (fmi2Status)get_state(w, "fmi2GetFMUstate", s);
}

FMI2_Export fmi2Status fmi2SetFMUstate(fmi2Component c, fmi2FMUstate s)
{
    WHEEL_OR_ERROR(c)
    return (fmi2Status)set_state(w, "fmi2SetFMUstate", s);
}

FMI2_Export fmi2Status fmi2FreeFMUstate(fmi2Component c, fmi2FMUstate *s)
{
    (void)c;
    if (s) {
        free(*s);
        *s = NULL;
    }
    return fmi2OK;
}

FMI2_Export fmi2Status fmi2SerializedFMUstateSize(fmi2Component c, fmi2FMUstate s, size_t *size)
{
    WHEEL_OR_ERROR(c)
    if (!s || !size)
        return (fmi2Status)fail(w, "fmi2SerializedFMUstateSize: no state or no size pointer given");
    *size = ((const Blob *)s)->size;
    return fmi2OK;
}

FMI2_Export fmi2Status fmi2SerializeFMUstate(fmi2Component c, fmi2FMUstate s, fmi2Byte buf[], size_t size)
{
    WHEEL_OR_ERROR(c)
    return (fmi2Status)serialize_state(w, "fmi2SerializeFMUstate", s, buf, size);
}

FMI2_Export fmi2Status fmi2DeSerializeFMUstate(fmi2Component c, const fmi2Byte buf[], size_t size, fmi2FMUstate *s)
{
    WHEEL_OR_ERROR(c)
    return (fmi2Status)deserialize_state(w, "fmi2DeSerializeFMUstate", buf, size, s);
}
