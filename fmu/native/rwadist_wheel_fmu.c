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
 * Bad input (non-finite speed, a step the model does not resolve, a time that does not continue the
 * last step, a parameter out of range) is logged and answered with fmi2Error; the state stays at the
 * last good step, so the host may go on.  FMU state: get/set and serialize/deserialize (the
 * parameters travel with the state: a state restores the run it was taken from, bit for bit). */
#include "rwadist_wheel_runtime.h"

/* ------------------------------------------------------------------ FMI 2.0 */
static void set_defaults(Wheel *w)
{
    Params *p = &w->par;
    memset(p, 0, sizeof *p);
    p->floor_res = 0.1;
    p->max_accel = 500.0;
    p->max_step = 0.01;
    p->dcm[0] = p->dcm[4] = p->dcm[8] = 1.0;
    p->seed = -1;
    p->imbalance = p->harmonics = p->speed_ripple = p->broadband = 1;
    p->modes = RW_MODES_DEFAULT;
    memset(&w->mu, 0, sizeof w->mu);
}

static Wheel *as_wheel(fmi2Component c) { return (Wheel *)c; }

FMI2_Export const char *fmi2GetTypesPlatform(void) { return fmi2TypesPlatform; }
FMI2_Export const char *fmi2GetVersion(void) { return fmi2Version; }

FMI2_Export fmi2Status fmi2SetDebugLogging(fmi2Component c, fmi2Boolean on, size_t n, const fmi2String cat[])
{
    (void)n, (void)cat;
    if (!c)
        return fmi2Error;
    as_wheel(c)->logging_on = on != fmi2False;
    return fmi2OK;
}

FMI2_Export fmi2Component fmi2Instantiate(fmi2String name, fmi2Type type, fmi2String guid, fmi2String resources,
                                          const fmi2CallbackFunctions *functions, fmi2Boolean visible,
                                          fmi2Boolean loggingOn)
{
    (void)resources, (void)visible;
    if (!functions)
        return NULL;
    Wheel tmp;
    memset(&tmp, 0, sizeof tmp);
    tmp.cb = *functions;
    snprintf(tmp.name, sizeof tmp.name, "%s", name ? name : "wheel");
    if (type != fmi2CoSimulation) {
        fail(&tmp, "fmi2Instantiate: this FMU is for co-simulation only");
        return NULL;
    }
    if (!guid || strcmp(guid, RW_GUID) != 0) {
        fail(&tmp, "fmi2Instantiate: GUID %s does not match this FMU's %s", guid ? guid : "(null)", RW_GUID);
        return NULL;
    }
    Wheel *w = calloc(1, sizeof *w);
    if (!w) {
        fail(&tmp, "fmi2Instantiate: out of memory");
        return NULL;
    }
    *w = tmp;
    w->logging_on = loggingOn != fmi2False;
    set_defaults(w);
    logf_(w, fmi2OK, "logAll", "rwadist wheel (native C FMU): %s", RW_PHYSICS);
    return w;
}

FMI2_Export void fmi2FreeInstance(fmi2Component c)
{
    Wheel *w = as_wheel(c);
    if (!w)
        return;
    free_model(w);
    free(w);
}

FMI2_Export fmi2Status fmi2SetupExperiment(fmi2Component c, fmi2Boolean tolDef, fmi2Real tol, fmi2Real t0,
                                           fmi2Boolean stopDef, fmi2Real stop)
{
    (void)tolDef, (void)tol, (void)stopDef, (void)stop;
    Wheel *w = as_wheel(c);
    if (!w)
        return fmi2Error;
    if (!isfinite(t0))
        return fail(w, "fmi2SetupExperiment: start time %g is not finite", t0);
    w->mu.t_host = t0;
    return fmi2OK;
}

FMI2_Export fmi2Status fmi2EnterInitializationMode(fmi2Component c)
{
    Wheel *w = as_wheel(c);
    if (!w)
        return fmi2Error;
    w->mode = 1;
    return fmi2OK;
}

FMI2_Export fmi2Status fmi2ExitInitializationMode(fmi2Component c)
{
    Wheel *w = as_wheel(c);
    if (!w)
        return fmi2Error;
    const double t_host = w->mu.t_host, speed = w->mu.speed, accel = w->mu.accel;
    memset(&w->mu, 0, sizeof w->mu);
    w->mu.t_host = t_host;
    w->mu.t_start = t_host;
    w->mu.speed = speed;
    w->mu.accel = accel;
    w->floor_warned = 0;
    if (!build_model(w)) {
        w->mode = 4;
        return fmi2Error;
    }
    if (RW_MODES_ASSUMED && w->par.modes)
        logf_(w, fmi2Warning, "logStatusWarning", "rwadist wheel: the suspension modes of this wheel are ASSUMED "
              "(datasheet wheel, not measured); the outputs with modes = true are built on assumed values "
              "(modes = false: hard-mounted, as the datasheet states)");
    w->mode = 2;
    if (isfinite(speed)) {
        const double a = w->par.use_accel ? accel : 0.0;
        outputs_now(w, speed, isfinite(a) ? a : 0.0);
        for (int k = 0; k < 12; k++)
            if (!isfinite(w->mu.y[k])) {
                memset(w->mu.y, 0, sizeof w->mu.y);
                w->mode = 4;
                return fail(w, "initialisation failed: the outputs at the initial wheel_speed = %g rad/s are not "
                               "finite", speed);
            }
    }
    return fmi2OK;
}

FMI2_Export fmi2Status fmi2Terminate(fmi2Component c)
{
    Wheel *w = as_wheel(c);
    if (!w)
        return fmi2Error;
    w->mode = 3;
    return fmi2OK;
}

FMI2_Export fmi2Status fmi2Reset(fmi2Component c)
{
    Wheel *w = as_wheel(c);
    if (!w)
        return fmi2Error;
    free_model(w);
    set_defaults(w);
    w->mode = 0;
    return fmi2OK;
}

static int is_real_vr(fmi2ValueReference vr) { return vr == VR_SPEED || vr == VR_ACCEL || (vr >= VR_FLOOR_RES && vr < N_VR); }

static double *real_slot(Wheel *w, fmi2ValueReference vr)
{
    switch (vr) {
    case VR_SPEED: return &w->mu.speed;
    case VR_ACCEL: return &w->mu.accel;
    case VR_FLOOR_RES: return &w->par.floor_res;
    case VR_MAX_ACCEL: return &w->par.max_accel;
    case VR_MAX_STEP: return &w->par.max_step;
    default: break;
    }
    if (vr >= VR_DCM && vr < VR_DCM + 9)
        return &w->par.dcm[vr - VR_DCM];
    if (vr >= VR_POS && vr < VR_POS + 3)
        return &w->par.pos[vr - VR_POS];
    if (vr >= VR_OUT && vr < VR_OUT + 12)
        return &w->mu.y[vr - VR_OUT];
    return NULL;
}

static int *bool_slot(Wheel *w, fmi2ValueReference vr)
{
    switch (vr) {
    case VR_USE_ACCEL: return &w->par.use_accel;
    case VR_IMBALANCE: return &w->par.imbalance;
    case VR_HARMONICS: return &w->par.harmonics;
    case VR_MODES: return &w->par.modes;
    case VR_START_STEADY: return &w->par.start_steady;
    case VR_SPEED_RIPPLE: return &w->par.speed_ripple;
    case VR_BROADBAND: return &w->par.broadband;
    default: return NULL;
    }
}

FMI2_Export fmi2Status fmi2GetReal(fmi2Component c, const fmi2ValueReference vr[], size_t n, fmi2Real v[])
{
    Wheel *w = as_wheel(c);
    if (!w)
        return fmi2Error;
    for (size_t i = 0; i < n; i++) {
        double *s = is_real_vr(vr[i]) ? real_slot(w, vr[i]) : NULL;
        if (!s)
            return fail(w, "fmi2GetReal: value reference %u is not a Real variable of this FMU", vr[i]);
        v[i] = *s;
    }
    return fmi2OK;
}

FMI2_Export fmi2Status fmi2SetReal(fmi2Component c, const fmi2ValueReference vr[], size_t n, const fmi2Real v[])
{
    Wheel *w = as_wheel(c);
    if (!w)
        return fmi2Error;
    for (size_t i = 0; i < n; i++) {
        if (vr[i] >= VR_OUT && vr[i] < VR_OUT + 12)
            return fail(w, "fmi2SetReal: value reference %u is an output", vr[i]);
        double *s = is_real_vr(vr[i]) ? real_slot(w, vr[i]) : NULL;
        if (!s)
            return fail(w, "fmi2SetReal: value reference %u is not a Real variable of this FMU", vr[i]);
        if (vr[i] != VR_SPEED && vr[i] != VR_ACCEL && w->mode >= 2)
            return fail(w, "fmi2SetReal: value reference %u is a fixed parameter; set it before initialisation", vr[i]);
        *s = v[i];
    }
    return fmi2OK;
}

FMI2_Export fmi2Status fmi2GetInteger(fmi2Component c, const fmi2ValueReference vr[], size_t n, fmi2Integer v[])
{
    Wheel *w = as_wheel(c);
    if (!w)
        return fmi2Error;
    for (size_t i = 0; i < n; i++) {
        if (vr[i] != VR_SEED)
            return fail(w, "fmi2GetInteger: value reference %u is not an Integer variable of this FMU", vr[i]);
        v[i] = w->par.seed;
    }
    return fmi2OK;
}

FMI2_Export fmi2Status fmi2SetInteger(fmi2Component c, const fmi2ValueReference vr[], size_t n, const fmi2Integer v[])
{
    Wheel *w = as_wheel(c);
    if (!w)
        return fmi2Error;
    for (size_t i = 0; i < n; i++) {
        if (vr[i] != VR_SEED)
            return fail(w, "fmi2SetInteger: value reference %u is not an Integer variable of this FMU", vr[i]);
        if (w->mode >= 2)
            return fail(w, "fmi2SetInteger: seed is a fixed parameter; set it before initialisation");
        w->par.seed = v[i];
    }
    return fmi2OK;
}

FMI2_Export fmi2Status fmi2GetBoolean(fmi2Component c, const fmi2ValueReference vr[], size_t n, fmi2Boolean v[])
{
    Wheel *w = as_wheel(c);
    if (!w)
        return fmi2Error;
    for (size_t i = 0; i < n; i++) {
        int *s = bool_slot(w, vr[i]);
        if (!s)
            return fail(w, "fmi2GetBoolean: value reference %u is not a Boolean variable of this FMU", vr[i]);
        v[i] = *s ? fmi2True : fmi2False;
    }
    return fmi2OK;
}

FMI2_Export fmi2Status fmi2SetBoolean(fmi2Component c, const fmi2ValueReference vr[], size_t n, const fmi2Boolean v[])
{
    Wheel *w = as_wheel(c);
    if (!w)
        return fmi2Error;
    for (size_t i = 0; i < n; i++) {
        int *s = bool_slot(w, vr[i]);
        if (!s)
            return fail(w, "fmi2SetBoolean: value reference %u is not a Boolean variable of this FMU", vr[i]);
        if (w->mode >= 2)
            return fail(w, "fmi2SetBoolean: value reference %u is a fixed parameter; set it before initialisation",
                        vr[i]);
        *s = v[i] != fmi2False;
    }
    return fmi2OK;
}

FMI2_Export fmi2Status fmi2GetString(fmi2Component c, const fmi2ValueReference vr[], size_t n, fmi2String v[])
{
    Wheel *w = as_wheel(c);
    if (!w)
        return fmi2Error;
    for (size_t i = 0; i < n; i++) {
        if (vr[i] != VR_MODEL_FILE)
            return fail(w, "fmi2GetString: value reference %u is not a String variable of this FMU", vr[i]);
        v[i] = "";
    }
    return fmi2OK;
}

FMI2_Export fmi2Status fmi2SetString(fmi2Component c, const fmi2ValueReference vr[], size_t n, const fmi2String v[])
{
    Wheel *w = as_wheel(c);
    if (!w)
        return fmi2Error;
    for (size_t i = 0; i < n; i++) {
        if (vr[i] != VR_MODEL_FILE)
            return fail(w, "fmi2SetString: value reference %u is not a String variable of this FMU", vr[i]);
        if (v[i] && v[i][0])
            return fail(w, "fmi2SetString: model_file = '%s': the native FMU carries its model compiled in; build "
                           "another FMU from that model file (rwadist fmu build --native FILE)", v[i]);
    }
    return fmi2OK;
}

FMI2_Export fmi2Status fmi2DoStep(fmi2Component c, fmi2Real t, fmi2Real h, fmi2Boolean noSetPrior)
{
    (void)noSetPrior;
    Wheel *w = as_wheel(c);
    if (!w)
        return fmi2Error;
    if (w->mode != 2)
        return fail(w, "cannot step: %s", w->mode == 4 ? "initialisation failed (see the error logged then)" :
                    "the FMU is not initialised (fmi2ExitInitializationMode) or is terminated");
    if (!isfinite(t) || fabs(t - w->mu.t_host) > 1e-9 * fmax(1.0, fabs(t)))
        return fail(w, "step rejected: communication point %.12g s does not continue the last step (expected "
                       "%.12g s)", t, w->mu.t_host);
    Mutable saved = w->mu;
    const fmi2Status s = step(w, t, h);
    if (s != fmi2OK) {
        /* the state stays at the last good step (st and floor phasors are written only on success, except
         * a non-finite output: roll the scalars back; the kernel state then holds the bad step) */
        if (w->mu.t != saved.t)
            w->mu = saved;
        return s;
    }
    w->mu.t_host = t + h;
    return fmi2OK;
}

FMI2_Export fmi2Status fmi2CancelStep(fmi2Component c)
{
    return c ? fail(as_wheel(c), "fmi2CancelStep: steps are synchronous, nothing to cancel") : fmi2Error;
}

FMI2_Export fmi2Status fmi2GetStatus(fmi2Component c, const fmi2StatusKind k, fmi2Status *v)
{
    (void)k, (void)v;
    return c ? fail(as_wheel(c), "fmi2GetStatus: not supported (steps are synchronous)") : fmi2Error;
}
FMI2_Export fmi2Status fmi2GetRealStatus(fmi2Component c, const fmi2StatusKind k, fmi2Real *v)
{
    if (!c)
        return fmi2Error;
    if (k == fmi2LastSuccessfulTime) {
        *v = as_wheel(c)->mu.t_host;
        return fmi2OK;
    }
    return fail(as_wheel(c), "fmi2GetRealStatus: status kind %d not supported", (int)k);
}
FMI2_Export fmi2Status fmi2GetIntegerStatus(fmi2Component c, const fmi2StatusKind k, fmi2Integer *v)
{
    (void)k, (void)v;
    return c ? fail(as_wheel(c), "fmi2GetIntegerStatus: not supported") : fmi2Error;
}
FMI2_Export fmi2Status fmi2GetBooleanStatus(fmi2Component c, const fmi2StatusKind k, fmi2Boolean *v)
{
    (void)k, (void)v;
    return c ? fail(as_wheel(c), "fmi2GetBooleanStatus: not supported") : fmi2Error;
}
FMI2_Export fmi2Status fmi2GetStringStatus(fmi2Component c, const fmi2StatusKind k, fmi2String *v)
{
    (void)k, (void)v;
    return c ? fail(as_wheel(c), "fmi2GetStringStatus: not supported") : fmi2Error;
}
FMI2_Export fmi2Status fmi2SetRealInputDerivatives(fmi2Component c, const fmi2ValueReference vr[], size_t n,
                                                   const fmi2Integer order[], const fmi2Real v[])
{
    (void)vr, (void)n, (void)order, (void)v;
    return c ? fail(as_wheel(c), "fmi2SetRealInputDerivatives: not supported (canInterpolateInputs = false)")
             : fmi2Error;
}
FMI2_Export fmi2Status fmi2GetRealOutputDerivatives(fmi2Component c, const fmi2ValueReference vr[], size_t n,
                                                    const fmi2Integer order[], fmi2Real v[])
{
    (void)vr, (void)n, (void)order, (void)v;
    return c ? fail(as_wheel(c), "fmi2GetRealOutputDerivatives: not supported (maxOutputDerivativeOrder = 0)")
             : fmi2Error;
}
FMI2_Export fmi2Status fmi2GetDirectionalDerivative(fmi2Component c, const fmi2ValueReference u[], size_t nu,
                                                    const fmi2ValueReference z[], size_t nz, const fmi2Real dv[],
                                                    fmi2Real dz[])
{
    (void)u, (void)nu, (void)z, (void)nz, (void)dv, (void)dz;
    return c ? fail(as_wheel(c), "fmi2GetDirectionalDerivative: not supported") : fmi2Error;
}

/* ------------------------------------------------------------------ FMU state
 * Layout (native byte order): header {magic, version, sizeof(Params), sizeof(Mutable), n, n_floor, mode},
 * Params, Mutable, the kernel state (2 + 2n + 12 doubles), the floor phasors (n_floor complex). */
typedef struct {
    uint32_t magic, version, size_par, size_mu;
    int32_t n, n_floor, mode, floor_warned;
} StateHeader;

static size_t state_size(int n, int n_floor)
{
    return sizeof(StateHeader) + sizeof(Params) + sizeof(Mutable) + sizeof(double) * (size_t)(2 + 2 * n + 12) +
           sizeof(double complex) * (size_t)n_floor;
}

static void write_state(const Wheel *w, char *buf)
{
    StateHeader hd = {STATE_MAGIC, 1, sizeof(Params), sizeof(Mutable), w->n, w->n_floor, w->mode, w->floor_warned};
    char *p = buf;
    memcpy(p, &hd, sizeof hd), p += sizeof hd;
    memcpy(p, &w->par, sizeof w->par), p += sizeof w->par;
    memcpy(p, &w->mu, sizeof w->mu), p += sizeof w->mu;
    if (w->st)
        memcpy(p, w->st, sizeof(double) * (size_t)(2 + 2 * w->n + 12));
    else
        memset(p, 0, sizeof(double) * (size_t)(2 + 2 * w->n + 12));
    p += sizeof(double) * (size_t)(2 + 2 * w->n + 12);
    if (w->n_floor)
        memcpy(p, w->floor_Z, sizeof(double complex) * (size_t)w->n_floor);
}

static fmi2Status read_state(Wheel *w, const char *buf, size_t size, const char *what)
{
    StateHeader hd;
    if (size < sizeof hd)
        return fail(w, "%s: %zu bytes are not an rwadist wheel FMU state", what, size);
    memcpy(&hd, buf, sizeof hd);
    if (hd.magic != STATE_MAGIC || hd.version != 1 || hd.size_par != sizeof(Params) || hd.size_mu != sizeof(Mutable) ||
        hd.n < 0 || hd.n_floor < 0 || size != state_size(hd.n, hd.n_floor))
        return fail(w, "%s: not a state of this FMU (wrong magic, version or size)", what);
    Params par;
    memcpy(&par, buf + sizeof hd, sizeof par);
    /* the state's parameters rebuild the model when they differ from the instance's */
    if (hd.mode >= 2 && hd.mode != 4 && (memcmp(&par, &w->par, sizeof par) != 0 || !w->cfg)) {
        const Params old = w->par;
        w->par = par;
        if (!build_model(w)) {
            w->par = old;
            build_model(w);
            return fail(w, "%s: the state's parameters do not build the model", what);
        }
    } else {
        w->par = par;
    }
    if (hd.mode >= 2 && hd.mode != 4 && (hd.n != w->n || hd.n_floor != w->n_floor))
        return fail(w, "%s: the state's model size does not match this FMU", what);
    const char *p = buf + sizeof hd + sizeof par;
    memcpy(&w->mu, p, sizeof w->mu), p += sizeof w->mu;
    if (w->st)
        memcpy(w->st, p, sizeof(double) * (size_t)(2 + 2 * w->n + 12));
    p += sizeof(double) * (size_t)(2 + 2 * hd.n + 12);
    if (w->n_floor)
        memcpy(w->floor_Z, p, sizeof(double complex) * (size_t)w->n_floor);
    w->mode = hd.mode;
    w->floor_warned = hd.floor_warned;
    return fmi2OK;
}

typedef struct {
    size_t size;
    char data[];
} Blob;

FMI2_Export fmi2Status fmi2GetFMUstate(fmi2Component c, fmi2FMUstate *s)
{
    Wheel *w = as_wheel(c);
    if (!w || !s)
        return fmi2Error;
    const size_t size = state_size(w->n, w->n_floor);
    Blob *b = *s ? (Blob *)*s : NULL;
    if (b && b->size != size) {
        free(b);
        b = NULL;
    }
    if (!b) {
        b = malloc(sizeof(Blob) + size);
        if (!b)
            return fail(w, "fmi2GetFMUstate: out of memory");
        b->size = size;
    }
    write_state(w, b->data);
    *s = b;
    return fmi2OK;
}

FMI2_Export fmi2Status fmi2SetFMUstate(fmi2Component c, fmi2FMUstate s)
{
    Wheel *w = as_wheel(c);
    if (!w)
        return fmi2Error;
    if (!s)
        return fail(w, "fmi2SetFMUstate: no state given");
    const Blob *b = (const Blob *)s;
    return read_state(w, b->data, b->size, "fmi2SetFMUstate");
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
    Wheel *w = as_wheel(c);
    if (!w || !s || !size)
        return fmi2Error;
    *size = ((const Blob *)s)->size;
    return fmi2OK;
}

FMI2_Export fmi2Status fmi2SerializeFMUstate(fmi2Component c, fmi2FMUstate s, fmi2Byte buf[], size_t size)
{
    Wheel *w = as_wheel(c);
    if (!w || !s)
        return fmi2Error;
    const Blob *b = (const Blob *)s;
    if (size < b->size)
        return fail(w, "fmi2SerializeFMUstate: buffer of %zu bytes is smaller than the state (%zu)", size, b->size);
    memcpy(buf, b->data, b->size);
    return fmi2OK;
}

FMI2_Export fmi2Status fmi2DeSerializeFMUstate(fmi2Component c, const fmi2Byte buf[], size_t size, fmi2FMUstate *s)
{
    Wheel *w = as_wheel(c);
    if (!w || !s)
        return fmi2Error;
    StateHeader hd;
    if (size < sizeof hd)
        return fail(w, "fmi2DeSerializeFMUstate: %zu bytes are not an rwadist wheel FMU state", size);
    memcpy(&hd, buf, sizeof hd);
    if (hd.magic != STATE_MAGIC || hd.n < 0 || hd.n_floor < 0 || size != state_size(hd.n, hd.n_floor))
        return fail(w, "fmi2DeSerializeFMUstate: not a state of this FMU (wrong magic or size)");
    Blob *b = malloc(sizeof(Blob) + size);
    if (!b)
        return fail(w, "fmi2DeSerializeFMUstate: out of memory");
    b->size = size;
    memcpy(b->data, buf, size);
    *s = b;
    return fmi2OK;
}
