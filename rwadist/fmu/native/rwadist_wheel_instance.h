/* rwadist wheel FMU in C: the FMI wrapper layer common to FMI 2.0 (rwadist_wheel_fmu.c) and FMI 3.0
 * (rwadist_wheel_fmi3.c): every FMI call's work, version-neutral -- the state machine of rwadist_fmi_rules.h (the
 * standards' tables: which call each state allows, where an error leads), parameter defaults, variables by value
 * reference, one step, the FMU state (get/set, serialize).  The API files only adapt types and names.  The physics is
 * rwadist_wheel_runtime.h; nothing here computes a load.
 *
 * Every call is admitted by its row of the table (admit) and ends through finish: a call not allowed in the
 * instance's state is answered with Error and a logged message naming the call, the state, the states it is allowed
 * in and what to call next; any Error (refused call, bad value, failed initialisation or step) then moves the
 * instance as its FMI version says (FMI 2.0: to the error state, from terminated nowhere; FMI 3.0: to Terminated).
 * From there the getters (values for debugging), Reset, the FMU-state functions (a state stored before the error
 * restores the run) and FreeInstance lead on. */
#ifndef RWADIST_WHEEL_INSTANCE_H
#define RWADIST_WHEEL_INSTANCE_H
#include "rwadist_fmi_rules.h"
#include "rwadist_wheel_runtime.h"

/* the status of a call, after FMI's transition on Error */
static RwStatus finish(Wheel *w, RwStatus s)
{
    if (s >= RW_ERROR)
        w->mode = rw_error_state(w->fmi, w->mode);
    return s;
}

/* Error, logged (printf format), after FMI's transition */
#define REFUSE(w, ...) finish((w), fail((w), __VA_ARGS__))

/* 1 when `call` (the FMI function fn) is allowed in w's state; else it is refused (logged, transition made), 0 */
static int admit(Wheel *w, RwCall call, const char *fn)
{
    if (rw_allowed(w->fmi, w->mode, call))
        return 1;
    char message[768];
    rw_refusal(message, sizeof message, w->fmi, call, w->mode, fn);
    REFUSE(w, "%s", message);
    return 0;
}

static RwStatus unsupported(Wheel *w, const char *fn, const char *why)
{
    return REFUSE(w, "%s: not supported (%s)", fn, why);
}

static void set_defaults(Wheel *w)
{
    Params *p = &w->par;
    memset(p, 0, sizeof *p);
    p->floor_res = 0.1;
    p->max_accel = 500.0;
    p->max_step = 0.01;
    p->dcm[0] = p->dcm[4] = p->dcm[8] = 1.0;
    p->seed = -1;
    p->imbalance = p->harmonics = 1;
    for (int i = 0; i < N_SWITCH; i++)
        p->sw[i] = 1;
    p->modes = RW_MODES_DEFAULT;
    memset(&w->mu, 0, sizeof w->mu);
}

/* a new instance (after the wrapper installed its logger) */
static void instantiated(Wheel *w, int fmi, int logging_on)
{
    w->fmi = fmi;
    w->logging_on = logging_on;
    w->mode = ST_INSTANTIATED;
    set_defaults(w);
    logf_(w, RW_OK, "logAll", "rwadist wheel (native C FMU, FMI %d.0): %s", fmi, RW_PHYSICS);
}

/* ------------------------------------------------------------------ the run: set-up, initialisation, steps */
/* start time, stop time, tolerance (fmi2SetupExperiment; the arguments of fmi3EnterInitializationMode) */
static RwStatus setup_experiment(Wheel *w, const char *fn, int tol_def, double tol, double t0, int stop_def,
                                 double stop)
{
    if (!admit(w, RW_SETUP_EXPERIMENT, fn))
        return RW_ERROR;
    if (!isfinite(t0))
        return REFUSE(w, "%s: start time %g is not finite: give the run's start time in s", fn, t0);
    if (stop_def && !(stop >= t0))
        return REFUSE(w, "%s: stop time %g s is before the start time %g s: give a stop time after the start, or "
                         "none", fn, stop, t0);
    if (tol_def && !(tol > 0 && isfinite(tol)))
        return REFUSE(w, "%s: tolerance %g is not a positive number: give one > 0, or none", fn, tol);
    w->mu.t_host = t0;
    return RW_OK;
}

static RwStatus enter_initialization(Wheel *w, const char *fn)
{
    if (!admit(w, RW_ENTER_INIT, fn))
        return RW_ERROR;
    w->mode = ST_INIT;
    return RW_OK;
}

/* leave initialization mode: build the model from the parameters, outputs at the initial inputs */
static RwStatus exit_initialization(Wheel *w, const char *fn)
{
    if (!admit(w, RW_EXIT_INIT, fn))
        return RW_ERROR;
    const double t_host = w->mu.t_host, speed = w->mu.speed, accel = w->mu.accel;
    memset(&w->mu, 0, sizeof w->mu);
    w->mu.t_host = t_host;
    w->mu.t_start = t_host;
    w->mu.speed = speed;
    w->mu.accel = accel;
    w->floor_warned = 0;
    if (!build_model(w))
        return finish(w, RW_ERROR);
    if (RW_MODES_ASSUMED && w->par.modes)
        logf_(w, RW_WARNING, "logStatusWarning", "rwadist wheel: the suspension modes of this wheel are ASSUMED "
              "(datasheet wheel, not measured); the outputs with modes = true are built on assumed values "
              "(modes = false: hard-mounted, as the datasheet states)");
    w->mode = ST_STEP;
    if (isfinite(speed)) {
        const double a = w->par.use_accel ? accel : 0.0;
        outputs_now(w, speed, isfinite(a) ? a : 0.0);
        for (int k = 0; k < 12; k++)
            if (!isfinite(w->mu.y[k])) {
                memset(w->mu.y, 0, sizeof w->mu.y);
                return REFUSE(w, "initialisation failed: the outputs at the initial wheel_speed = %g rad/s are not "
                                 "finite", speed);
            }
    }
    return RW_OK;
}

/* one communication step at host time t */
static RwStatus do_step(Wheel *w, const char *fn, double t, double h)
{
    if (!admit(w, RW_DO_STEP, fn))
        return RW_ERROR;
    if (!isfinite(t) || fabs(t - w->mu.t_host) > 1e-9 * fmax(1.0, fabs(t)))
        return REFUSE(w, "step rejected: communication point %.12g s does not continue the last step (expected "
                         "%.12g s)", t, w->mu.t_host);
    Mutable saved = w->mu;
    const RwStatus s = step(w, t, h);
    if (s != RW_OK) {
        /* the state stays at the last good step (st and floor phasors are written only on success, except
         * a non-finite output: roll the scalars back; the kernel state then holds the bad step) */
        if (w->mu.t != saved.t)
            w->mu = saved;
        return finish(w, s);
    }
    w->mu.t_host = t + h;
    return RW_OK;
}

static RwStatus terminate(Wheel *w, const char *fn)
{
    if (!admit(w, RW_TERMINATE, fn))
        return RW_ERROR;
    w->mode = ST_TERMINATED;
    return RW_OK;
}

static RwStatus reset(Wheel *w, const char *fn)
{
    if (!admit(w, RW_RESET, fn))
        return RW_ERROR;
    free_model(w);
    set_defaults(w);
    w->mode = ST_INSTANTIATED;
    return RW_OK;
}

/* ------------------------------------------------------------------ variables by value reference */
/* where value reference vr is kept (double for Real, int for Integer and Boolean; NULL: model_file, kept nowhere) */
static void *slot(Wheel *w, unsigned vr)
{
    switch (vr) {
    case VR_SPEED: return &w->mu.speed;
    case VR_ACCEL: return &w->mu.accel;
    case VR_USE_ACCEL: return &w->par.use_accel;
    case VR_SEED: return &w->par.seed;
    case VR_IMBALANCE: return &w->par.imbalance;
    case VR_HARMONICS: return &w->par.harmonics;
    case VR_MODES: return &w->par.modes;
    case VR_START_STEADY: return &w->par.start_steady;
    case VR_FLOOR_RES: return &w->par.floor_res;
    case VR_MAX_ACCEL: return &w->par.max_accel;
    case VR_MAX_STEP: return &w->par.max_step;
    case VR_TIME: return &w->mu.t_host;
    default: break;
    }
    if (vr >= VR_SWITCH && vr < VR_SWITCH + N_SWITCH)
        return &w->par.sw[vr - VR_SWITCH];
    if (vr >= VR_DCM && vr < VR_DCM + 9)
        return &w->par.dcm[vr - VR_DCM];
    if (vr >= VR_POS && vr < VR_POS + 3)
        return &w->par.pos[vr - VR_POS];
    if (vr >= VR_OUT && vr < VR_OUT + 12)
        return &w->mu.y[vr - VR_OUT];
    return NULL;
}

/* n value references and nv values given (every variable is a scalar: nv == n), NULL arrays only when n == 0 */
static int arrays_ok(Wheel *w, const char *fn, size_t n, size_t nv, const void *vr, const void *v)
{
    if (nv != n)
        REFUSE(w, "%s: %zu values for %zu value references: every variable of this FMU is a scalar, give one value "
                  "each", fn, nv, n);
    else if (n && (!vr || !v))
        REFUSE(w, "%s: %zu values asked with a NULL %s array", fn, n, vr ? "value" : "value reference");
    else
        return 1;
    return 0;
}

static const char *type_name(const Wheel *w, RwType type) { return RW_TYPE_NAMES[w->fmi == 3][type]; }

/* fmiXGet{type}: values of n variables into v (Boolean: int for FMI 2.0, one byte for FMI 3.0) */
static RwStatus get_vars(Wheel *w, const char *fn, RwType type, const unsigned vr[], size_t n, void *v, size_t nv)
{
    if (!admit(w, RW_GET, fn) || !arrays_ok(w, fn, n, nv, vr, v))
        return RW_ERROR;
    for (size_t i = 0; i < n; i++) {
        if (rw_variable(w->fmi, vr[i], NULL) != type)
            return REFUSE(w, "%s: value reference %u is not a%s %s variable of this FMU", fn, vr[i],
                          type == RW_INTEGER ? "n" : "", type_name(w, type));
        const void *s = slot(w, vr[i]);
        if (type == RW_REAL)
            ((double *)v)[i] = *(const double *)s;
        else if (type == RW_INTEGER)
            ((int *)v)[i] = *(const int *)s;
        else if (type == RW_BOOLEAN && w->fmi == 2)
            ((int *)v)[i] = *(const int *)s != 0;
        else if (type == RW_BOOLEAN)
            ((unsigned char *)v)[i] = *(const int *)s != 0;
        else
            ((const char **)v)[i] = "";
    }
    return RW_OK;
}

#if N_SWITCH != N_SWITCH_VR
#error "the model's effect switches (N_SWITCH) do not fill the FMU's switch value references (N_SWITCH_VR)"
#endif

/* the name of value reference vr <= N_VR: an effect switch by the name its element gives it */
static const char *var_name(unsigned vr)
{
    return vr >= VR_SWITCH && vr < VR_SWITCH + N_SWITCH ? RW_SWITCH_NAMES[vr - VR_SWITCH] : RW_VAR_NAMES[vr];
}

/* whether the n references of a set are all settable variables of `type`; *parameters: one is a parameter */
static int settable(Wheel *w, const char *fn, RwType type, const unsigned vr[], size_t n, const void *v,
                    int *parameters)
{
    *parameters = 0;
    for (size_t i = 0; i < n; i++) {
        RwCausality c;
        const char *why = rw_not_settable(w->fmi, vr[i], type);
        if (why) {
            REFUSE(w, "%s: value reference %u%s%s%s %s (this call sets %s variables)", fn, vr[i],
                   vr[i] <= N_VR ? " (" : "", vr[i] <= N_VR ? var_name(vr[i]) : "", vr[i] <= N_VR ? ")" : "",
                   why, type_name(w, type));
            return 0;
        }
        rw_variable(w->fmi, vr[i], &c);
        *parameters |= c == RW_PARAMETER;
        if (type == RW_STRING && ((const char *const *)v)[i] && ((const char *const *)v)[i][0]) {
            REFUSE(w, "%s: model_file = '%s': the native FMU carries its model compiled in; build another FMU from "
                      "that model file (rwadist fmu build --native FILE)", fn, ((const char *const *)v)[i]);
            return 0;
        }
    }
    return 1;
}

/* fmiXSet{type}: n values from v; nothing is written when a reference or the state refuses the call */
static RwStatus set_vars(Wheel *w, const char *fn, RwType type, const unsigned vr[], size_t n, const void *v,
                         size_t nv)
{
    int parameters;
    if (!arrays_ok(w, fn, n, nv, vr, v) || !settable(w, fn, type, vr, n, v, &parameters) ||
        !admit(w, parameters ? RW_SET_PARAMETER : RW_SET_INPUT, fn))
        return RW_ERROR;
    for (size_t i = 0; i < n; i++) {
        void *s = slot(w, vr[i]);
        if (type == RW_REAL)
            *(double *)s = ((const double *)v)[i];
        else if (type == RW_INTEGER)
            *(int *)s = ((const int *)v)[i];
        else if (type == RW_BOOLEAN)
            *(int *)s = w->fmi == 2 ? ((const int *)v)[i] != 0 : ((const unsigned char *)v)[i] != 0;
    }
    return RW_OK;
}

/* fmiXGet/Set of a type this FMU has no variable of: every value reference is refused */
static RwStatus no_variable(Wheel *w, const char *fn, int set, size_t n, const unsigned vr[])
{
    if (!admit(w, set ? RW_SET_INPUT : RW_GET, fn))
        return RW_ERROR;
    if (!n)
        return RW_OK;
    return REFUSE(w, "%s: value reference %u: this FMU has no variable of this type", fn, vr ? vr[0] : 0u);
}

/* ------------------------------------------------------------------ FMU state
 * Layout (native byte order): header {magic, version, sizeof(Params), sizeof(Mutable), n, n_floor, mode,
 * floor_warned, built}, Params, Mutable, the kernel state (2 + 2n + 12 doubles), the floor phasors (n_floor complex).
 * `built`: the model was built (after initialisation; its kernel state follows), whatever the state. */
#define STATE_VERSION 2
typedef struct {
    uint32_t magic, version, size_par, size_mu;
    int32_t n, n_floor, mode, floor_warned, built;
} StateHeader;

typedef struct {
    size_t size;
    char data[];
} Blob;

/* doubles of the kernel state of n lines; in size_t: a stored header's n may be anything (no int overflow) */
static size_t kernel_doubles(int32_t n) { return (size_t)2 + 2 * (size_t)(uint32_t)n + 12; }

static size_t state_size(int32_t n, int32_t n_floor)
{
    return sizeof(StateHeader) + sizeof(Params) + sizeof(Mutable) + sizeof(double) * kernel_doubles(n) +
           sizeof(double complex) * (size_t)(uint32_t)n_floor;
}

static void write_state(const Wheel *w, char *buf)
{
    StateHeader hd = {STATE_MAGIC, STATE_VERSION, sizeof(Params), sizeof(Mutable), w->n, w->n_floor, w->mode,
                      w->floor_warned, w->cfg != NULL};
    char *p = buf;
    memcpy(p, &hd, sizeof hd), p += sizeof hd;
    memcpy(p, &w->par, sizeof w->par), p += sizeof w->par;
    memcpy(p, &w->mu, sizeof w->mu), p += sizeof w->mu;
    if (w->st)
        memcpy(p, w->st, sizeof(double) * kernel_doubles(w->n));
    else
        memset(p, 0, sizeof(double) * kernel_doubles(w->n));
    p += sizeof(double) * kernel_doubles(w->n);
    if (w->n_floor)
        memcpy(p, w->floor_Z, sizeof(double complex) * (size_t)w->n_floor);
}

/* 1 when buf holds a state of this FMU's layout (header checked against its size) */
static int state_header_ok(const char *buf, size_t size, StateHeader *hd)
{
    if (size < sizeof *hd)
        return 0;
    memcpy(hd, buf, sizeof *hd);
    return hd->magic == STATE_MAGIC && hd->version == STATE_VERSION && hd->size_par == sizeof(Params) &&
           hd->size_mu == sizeof(Mutable) && hd->n >= 0 && hd->n_floor >= 0 && rw_state_ok(hd->mode) &&
           (hd->built == 0 || hd->built == 1) && size == state_size(hd->n, hd->n_floor);
}

static RwStatus read_state(Wheel *w, const char *buf, size_t size, const char *fn)
{
    StateHeader hd;
    if (!state_header_ok(buf, size, &hd))
        return fail(w, "%s: not a state of this FMU (wrong magic, version or size): give a state this FMU stored", fn);
    Params par;
    memcpy(&par, buf + sizeof hd, sizeof par);
    /* a state with a built model carries the kernel state: the state's parameters rebuild the model when they
     * differ from the instance's; a state from before initialisation carries parameters and inputs only */
    if (hd.built && (memcmp(&par, &w->par, sizeof par) != 0 || !w->cfg)) {
        const Params old = w->par;
        w->par = par;
        if (!build_model(w)) {
            w->par = old;
            free_model(w);
            return fail(w, "%s: the state's parameters do not build the model", fn);
        }
    }
    if (hd.built && (hd.n != w->n || hd.n_floor != w->n_floor))
        return fail(w, "%s: the state's model size does not match this FMU", fn);
    if (!hd.built)
        free_model(w);
    w->par = par;
    const char *p = buf + sizeof hd + sizeof par;
    memcpy(&w->mu, p, sizeof w->mu), p += sizeof w->mu;
    if (hd.built) {
        memcpy(w->st, p, sizeof(double) * kernel_doubles(w->n));
        p += sizeof(double) * kernel_doubles(w->n);
        if (w->n_floor)
            memcpy(w->floor_Z, p, sizeof(double complex) * (size_t)w->n_floor);
        w->floor_rot_h = -1.0;      /* the rotations are recomputed for the next step size */
    }
    w->mode = hd.mode;
    w->floor_warned = hd.floor_warned;
    return RW_OK;
}

/* GetFMUstate: a new blob, or the host's previous one (*s) reused when its size fits */
static RwStatus get_state(Wheel *w, const char *fn, void **s)
{
    if (!admit(w, RW_FMU_STATE, fn))
        return RW_ERROR;
    if (!s)
        return REFUSE(w, "%s: NULL state pointer", fn);
    const size_t size = state_size(w->n, w->n_floor);
    Blob *b = *s ? (Blob *)*s : NULL;
    if (b && b->size != size) {
        free(b);
        b = NULL;
    }
    if (!b) {
        b = malloc(sizeof(Blob) + size);
        if (!b)
            return REFUSE(w, "%s: out of memory", fn);
        b->size = size;
    }
    write_state(w, b->data);
    *s = b;
    return RW_OK;
}

/* SetFMUstate: allowed in every state (the run it was stored from goes on from where it was stored) */
static RwStatus set_state(Wheel *w, const char *fn, const void *s)
{
    if (!admit(w, RW_FMU_STATE, fn))
        return RW_ERROR;
    if (!s)
        return REFUSE(w, "%s: no state given: give a state from GetFMUstate or DeserializeFMUstate", fn);
    const Blob *b = (const Blob *)s;
    return finish(w, read_state(w, b->data, b->size, fn));
}

static RwStatus free_state(Wheel *w, const char *fn, void **s)
{
    if (!admit(w, RW_FMU_STATE, fn))
        return RW_ERROR;
    if (s) {
        free(*s);
        *s = NULL;
    }
    return RW_OK;
}

static RwStatus serialized_size(Wheel *w, const char *fn, const void *s, size_t *size)
{
    if (!admit(w, RW_FMU_STATE, fn))
        return RW_ERROR;
    if (!s || !size)
        return REFUSE(w, "%s: no state or no size pointer given", fn);
    *size = ((const Blob *)s)->size;
    return RW_OK;
}

static RwStatus serialize_state(Wheel *w, const char *fn, const void *s, char *buf, size_t size)
{
    if (!admit(w, RW_FMU_STATE, fn))
        return RW_ERROR;
    if (!s || (size && !buf))
        return REFUSE(w, "%s: no state or no buffer given", fn);
    const Blob *b = (const Blob *)s;
    if (size < b->size)
        return REFUSE(w, "%s: buffer of %zu bytes is smaller than the state (%zu): ask SerializedFMUstateSize first",
                      fn, size, b->size);
    memcpy(buf, b->data, b->size);
    return RW_OK;
}

static RwStatus deserialize_state(Wheel *w, const char *fn, const char *buf, size_t size, void **s)
{
    StateHeader hd;
    if (!admit(w, RW_FMU_STATE, fn))
        return RW_ERROR;
    if (!s || (size && !buf))
        return REFUSE(w, "%s: no buffer or no state pointer given", fn);
    if (!state_header_ok(buf, size, &hd))
        return REFUSE(w, "%s: %zu bytes are not a state of this FMU (wrong magic, version or size)", fn, size);
    Blob *b = malloc(sizeof(Blob) + size);
    if (!b)
        return REFUSE(w, "%s: out of memory", fn);
    b->size = size;
    memcpy(b->data, buf, size);
    *s = b;
    return RW_OK;
}

#endif
