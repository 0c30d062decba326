/* rwadist speed command: the speed inputs of a wheel-assembly SSP (rwadist/fmu/ssp.py), an FMI 2.0 co-simulation FMU in C.
 *
 * One input per independently driven wheel, `speed_<wheel>` (rad/s, its commanded speed), and one output each,
 * `wheel_speed_<wheel>`, that the SSP connects to the wheel FMUs' `wheel_speed` (a tied wheel through an
 * ssc:LinearTransformation whose factor is its tie ratio).  The outputs hold the inputs set before the last step
 * (a zero-order hold; at the end of initialisation, the initial inputs).  Why a component: SSP hosts such as
 * libcosim connect element to element only, so the assembly's inputs are this component's.  The state machine is
 * the wheel FMU's (rwadist_fmi_rules.h): a call out of order or with a bad value is fmi2Error, logged, and moves the
 * instance to FMI 2.0's error state; it has no FMU state (canGetAndSetFMUstate = false).
 *
 * speed_command.h (written by rwadist/fmu/ssp.py) defines RW_GUID, RW_N_SPEEDS and RW_START[RW_N_SPEEDS] (the inputs' start
 * values, rad/s).  Value references: inputs 0 .. N-1, outputs N .. 2N-1. */
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fmi2Functions.h"
#include "rwadist_fmi_rules.h"
#include "speed_command.h"

typedef struct {
    int mode;
    fmi2CallbackFunctions cb;
    char name[128];
    double u[RW_N_SPEEDS], y[RW_N_SPEEDS], t;
} Command;

/* fmi2Error with a message logged (the message is the format: '%' from the arguments replaced), and FMI 2.0's
 * transition to the error state */
static fmi2Status refuse(Command *c, const char *fmt, ...)
{
    char message[768];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(message, sizeof message, fmt, ap);
    va_end(ap);
    for (char *p = message; *p; p++)
        if (*p == '%')
            *p = '?';
    if (c->cb.logger)
        c->cb.logger(c->cb.componentEnvironment, c->name, fmi2Error, "logStatusError", message);
    c->mode = rw_error_state(2, c->mode);
    return fmi2Error;
}

static int admit(Command *c, RwCall call, const char *fn)
{
    if (rw_allowed(2, c->mode, call))
        return 1;
    char message[700];
    rw_refusal(message, sizeof message, 2, call, c->mode, fn);
    refuse(c, "rwadist speed command: %s", message);
    return 0;
}

#define COMMAND_OR_ERROR(c)                                                                                       \
    Command *c = (Command *)(instance);                                                                           \
    if (!c)                                                                                                       \
        return fmi2Error;

static void start_values(Command *c)
{
    for (int k = 0; k < RW_N_SPEEDS; k++)
        c->u[k] = c->y[k] = RW_START[k];
    c->t = 0.0;
}

FMI2_Export const char *fmi2GetTypesPlatform(void) { return fmi2TypesPlatform; }
FMI2_Export const char *fmi2GetVersion(void) { return fmi2Version; }

FMI2_Export fmi2Component fmi2Instantiate(fmi2String name, fmi2Type type, fmi2String guid, fmi2String resources,
                                          const fmi2CallbackFunctions *functions, fmi2Boolean visible,
                                          fmi2Boolean loggingOn)
{
    (void)resources, (void)visible, (void)loggingOn;
    if (!functions)
        return NULL;
    Command tmp;
    memset(&tmp, 0, sizeof tmp);
    tmp.cb = *functions;
    snprintf(tmp.name, sizeof tmp.name, "%s", name ? name : "speed_command");
    if (type != fmi2CoSimulation || !guid || strcmp(guid, RW_GUID) != 0) {
        refuse(&tmp, "rwadist speed command: fmi2Instantiate: %s", type != fmi2CoSimulation ?
               "co-simulation only: instantiate it with fmi2CoSimulation" :
               "the GUID is not this FMU's: the host read another FMU's model description; load this FMU's");
        return NULL;
    }
    Command *c = malloc(sizeof *c);
    if (!c)
        return NULL;
    *c = tmp;
    c->mode = ST_INSTANTIATED;
    start_values(c);
    return c;
}

FMI2_Export void fmi2FreeInstance(fmi2Component instance) { free(instance); }

FMI2_Export fmi2Status fmi2SetDebugLogging(fmi2Component instance, fmi2Boolean on, size_t n, const fmi2String cat[])
{
    (void)on, (void)n, (void)cat;
    COMMAND_OR_ERROR(c)
    return fmi2OK;
}

FMI2_Export fmi2Status fmi2SetupExperiment(fmi2Component instance, fmi2Boolean tolDef, fmi2Real tol, fmi2Real t0,
                                           fmi2Boolean stopDef, fmi2Real stop)
{
    (void)tolDef, (void)tol;
    COMMAND_OR_ERROR(c)
    if (!admit(c, RW_SETUP_EXPERIMENT, "fmi2SetupExperiment"))
        return fmi2Error;
    if (!isfinite(t0) || (stopDef && !(stop >= t0)))
        return refuse(c, "rwadist speed command: fmi2SetupExperiment: start time %g s, stop time %g s: give a finite "
                         "start and a stop after it, or none", t0, stop);
    c->t = t0;
    return fmi2OK;
}

FMI2_Export fmi2Status fmi2EnterInitializationMode(fmi2Component instance)
{
    COMMAND_OR_ERROR(c)
    if (!admit(c, RW_ENTER_INIT, "fmi2EnterInitializationMode"))
        return fmi2Error;
    c->mode = ST_INIT;
    return fmi2OK;
}

FMI2_Export fmi2Status fmi2ExitInitializationMode(fmi2Component instance)
{
    COMMAND_OR_ERROR(c)
    if (!admit(c, RW_EXIT_INIT, "fmi2ExitInitializationMode"))
        return fmi2Error;
    memcpy(c->y, c->u, sizeof c->y);
    c->mode = ST_STEP;
    return fmi2OK;
}

FMI2_Export fmi2Status fmi2DoStep(fmi2Component instance, fmi2Real t, fmi2Real h, fmi2Boolean noSetPrior)
{
    (void)noSetPrior;
    COMMAND_OR_ERROR(c)
    if (!admit(c, RW_DO_STEP, "fmi2DoStep"))
        return fmi2Error;
    if (!isfinite(t) || fabs(t - c->t) > 1e-9 * fmax(1.0, fabs(t)) || !(h > 0 && isfinite(h)))
        return refuse(c, "rwadist speed command: step rejected: communication point %.12g s and step %g s do not "
                         "continue the last step (expected %.12g s and a step > 0)", t, h, c->t);
    for (int k = 0; k < RW_N_SPEEDS; k++)
        if (!isfinite(c->u[k]))
            return refuse(c, "rwadist speed command: step at t = %.9g s rejected: input %d is not finite: give "
                             "every wheel a speed in rad/s", t, k);
    memcpy(c->y, c->u, sizeof c->y);
    c->t = t + h;
    return fmi2OK;
}

FMI2_Export fmi2Status fmi2Terminate(fmi2Component instance)
{
    COMMAND_OR_ERROR(c)
    if (!admit(c, RW_TERMINATE, "fmi2Terminate"))
        return fmi2Error;
    c->mode = ST_TERMINATED;
    return fmi2OK;
}

FMI2_Export fmi2Status fmi2Reset(fmi2Component instance)
{
    COMMAND_OR_ERROR(c)
    c->mode = ST_INSTANTIATED;
    start_values(c);
    return fmi2OK;
}

FMI2_Export fmi2Status fmi2GetReal(fmi2Component instance, const fmi2ValueReference vr[], size_t n, fmi2Real v[])
{
    COMMAND_OR_ERROR(c)
    if (!admit(c, RW_GET, "fmi2GetReal"))
        return fmi2Error;
    if (n && (!vr || !v))
        return refuse(c, "rwadist speed command: fmi2GetReal: NULL arrays for %zu values", n);
    for (size_t i = 0; i < n; i++) {
        if (vr[i] >= 2 * RW_N_SPEEDS)
            return refuse(c, "rwadist speed command: fmi2GetReal: value reference %u is no variable of this FMU "
                             "(0 .. %d)", vr[i], 2 * RW_N_SPEEDS - 1);
        v[i] = vr[i] < RW_N_SPEEDS ? c->u[vr[i]] : c->y[vr[i] - RW_N_SPEEDS];
    }
    return fmi2OK;
}

FMI2_Export fmi2Status fmi2SetReal(fmi2Component instance, const fmi2ValueReference vr[], size_t n,
                                   const fmi2Real v[])
{
    COMMAND_OR_ERROR(c)
    if (n && (!vr || !v))
        return refuse(c, "rwadist speed command: fmi2SetReal: NULL arrays for %zu values", n);
    for (size_t i = 0; i < n; i++)
        if (vr[i] >= RW_N_SPEEDS)
            return refuse(c, "rwadist speed command: fmi2SetReal: value reference %u is %s", vr[i],
                          vr[i] < 2 * RW_N_SPEEDS ? "an output: outputs are read, not set" : "no variable of this FMU");
    if (!admit(c, RW_SET_INPUT, "fmi2SetReal"))
        return fmi2Error;
    for (size_t i = 0; i < n; i++)
        c->u[vr[i]] = v[i];
    return fmi2OK;
}

FMI2_Export fmi2Status fmi2GetRealStatus(fmi2Component instance, const fmi2StatusKind k, fmi2Real *v)
{
    COMMAND_OR_ERROR(c)
    if (!admit(c, RW_GET_STATUS, "fmi2GetRealStatus"))
        return fmi2Error;
    if (k != fmi2LastSuccessfulTime || !v)
        return refuse(c, "rwadist speed command: fmi2GetRealStatus: ask fmi2LastSuccessfulTime");
    *v = c->t;
    return fmi2OK;
}

/* ------------------------------------------------------------------ no variables of these types; not supported.
 * These functions ignore their arguments by design (no unused-parameter warnings for them). */
#if defined(__GNUC__)
#pragma GCC diagnostic ignored "-Wunused-parameter"
#endif
/* the getters and setters of a type without variables: nothing to do for none, fmi2Error for any */
#define NO_VARIABLES(T)                                                                                           \
    FMI2_Export fmi2Status fmi2Get##T(fmi2Component instance, const fmi2ValueReference vr[], size_t n, fmi2##T v[]) \
    {                                                                                                             \
        COMMAND_OR_ERROR(c)                                                                                       \
        if (!admit(c, RW_GET, "fmi2Get" #T))                                                                      \
            return fmi2Error;                                                                                     \
        return n ? refuse(c, "rwadist speed command: fmi2Get" #T ": this FMU has no " #T " variable") : fmi2OK;   \
    }                                                                                                             \
    FMI2_Export fmi2Status fmi2Set##T(fmi2Component instance, const fmi2ValueReference vr[], size_t n,           \
                                      const fmi2##T v[])                                                          \
    {                                                                                                             \
        COMMAND_OR_ERROR(c)                                                                                       \
        if (!admit(c, RW_SET_INPUT, "fmi2Set" #T))                                                                \
            return fmi2Error;                                                                                     \
        return n ? refuse(c, "rwadist speed command: fmi2Set" #T ": this FMU has no " #T " variable") : fmi2OK;   \
    }
NO_VARIABLES(Integer)
NO_VARIABLES(Boolean)
NO_VARIABLES(String)

#define UNSUPPORTED(NAME, WHY, ...)                                                                               \
    FMI2_Export fmi2Status NAME(fmi2Component instance, __VA_ARGS__)                                              \
    {                                                                                                             \
        COMMAND_OR_ERROR(c)                                                                                       \
        return refuse(c, "rwadist speed command: " #NAME ": not supported (" WHY ")");                            \
    }
#define NO_STATE "canGetAndSetFMUstate = false: restart the run with fmi2Reset"
UNSUPPORTED(fmi2GetFMUstate, NO_STATE, fmi2FMUstate *s)
UNSUPPORTED(fmi2SetFMUstate, NO_STATE, fmi2FMUstate s)
UNSUPPORTED(fmi2SerializedFMUstateSize, NO_STATE, fmi2FMUstate s, size_t *size)
UNSUPPORTED(fmi2SerializeFMUstate, NO_STATE, fmi2FMUstate s, fmi2Byte b[], size_t size)
UNSUPPORTED(fmi2DeSerializeFMUstate, NO_STATE, const fmi2Byte b[], size_t size, fmi2FMUstate *s)
UNSUPPORTED(fmi2GetStatus, "steps are synchronous", const fmi2StatusKind k, fmi2Status *v)
UNSUPPORTED(fmi2GetIntegerStatus, "steps are synchronous", const fmi2StatusKind k, fmi2Integer *v)
UNSUPPORTED(fmi2GetBooleanStatus, "steps are synchronous", const fmi2StatusKind k, fmi2Boolean *v)
UNSUPPORTED(fmi2GetStringStatus, "steps are synchronous", const fmi2StatusKind k, fmi2String *v)
UNSUPPORTED(fmi2SetRealInputDerivatives, "canInterpolateInputs = false", const fmi2ValueReference vr[], size_t n,
            const fmi2Integer order[], const fmi2Real v[])
UNSUPPORTED(fmi2GetRealOutputDerivatives, "maxOutputDerivativeOrder = 0", const fmi2ValueReference vr[], size_t n,
            const fmi2Integer order[], fmi2Real v[])
UNSUPPORTED(fmi2GetDirectionalDerivative, "providesDirectionalDerivative = false", const fmi2ValueReference u[],
            size_t nu, const fmi2ValueReference z[], size_t nz, const fmi2Real dv[], fmi2Real dz[])

FMI2_Export fmi2Status fmi2FreeFMUstate(fmi2Component instance, fmi2FMUstate *s)
{
    COMMAND_OR_ERROR(c)
    return s && *s ? refuse(c, "rwadist speed command: fmi2FreeFMUstate: not a state of this FMU (it hands out none)")
                   : fmi2OK;
}

FMI2_Export fmi2Status fmi2CancelStep(fmi2Component instance)
{
    COMMAND_OR_ERROR(c)
    return refuse(c, "rwadist speed command: fmi2CancelStep: illegal call sequence: steps are synchronous");
}
