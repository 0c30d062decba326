/* rwadist wheel FMU in C: the FMI wrapper layer common to FMI 2.0 (rwadist_wheel_fmu.c) and FMI 3.0
 * (rwadist_wheel_fmi3.c): the FMI state machine, parameter defaults, variable access by value reference and
 * the FMU state (get/set, serialize).  The physics is rwadist_wheel_runtime.h; nothing here computes a load.
 *
 * State machine (FMI 2.0 section 4.2.4, FMI 3.0 section 4.2; co-simulation without event mode): an instance is
 * INSTANTIATED, in INITIALIZATION mode, STEPPING (FMI 2.0 stepComplete, FMI 3.0 Step Mode), TERMINATED, or
 * FAILED (initialisation failed: FMI's error state).  Every entry point names the states it is allowed in; a call
 * in another state is answered with Error and a logged message naming the call, the state and what to call
 * first, and changes nothing (the instance stays in its state, so the host can go on in order).  A refused value
 * (bad input, bad parameter) leaves the instance in its state as well; only a failed initialisation moves it to
 * FAILED, from which Reset, a stored FMU state or FreeInstance lead on. */
#ifndef RWADIST_WHEEL_INSTANCE_H
#define RWADIST_WHEEL_INSTANCE_H
#include "rwadist_wheel_runtime.h"

/* Wheel.mode: the numbers are stored in a serialized FMU state, keep them */
enum { ST_INSTANTIATED = 0, ST_INIT = 1, ST_STEP = 2, ST_TERMINATED = 3, ST_FAILED = 4, N_ST = 5 };
#define IN(s) (1u << (s))
#define ANY_STATE (IN(ST_INSTANTIATED) | IN(ST_INIT) | IN(ST_STEP) | IN(ST_TERMINATED) | IN(ST_FAILED))
#define SETTABLE (IN(ST_INSTANTIATED) | IN(ST_INIT) | IN(ST_STEP))
#define READABLE (IN(ST_INIT) | IN(ST_STEP) | IN(ST_TERMINATED) | IN(ST_FAILED))

static const char *const STATE_NAMES[N_ST] = {"instantiated", "initialization mode", "stepping", "terminated",
                                             "failed (initialisation failed)"};
/* what leads out of each state */
static const char *const STATE_NEXT[N_ST] = {
    "enter initialization mode first", "exit initialization mode first", "the instance is stepping",
    "the instance is terminated: reset it (or free it) to run again",
    "initialisation failed (see the error logged then): reset the instance, set a stored FMU state, or free it"};

/* 1 when the call `fn` is allowed in the instance's state (mask of IN(state)); else a logged error, 0 */
static int allowed(Wheel *w, unsigned mask, const char *fn)
{
    if (w->mode >= 0 && w->mode < N_ST && (mask & IN(w->mode)))
        return 1;
    char states[160] = "";
    for (int s = 0; s < N_ST; s++)
        if (mask & IN(s)) {
            const size_t len = strlen(states);
            snprintf(states + len, sizeof states - len, "%s%s", len ? ", " : "", STATE_NAMES[s]);
        }
    fail(w, "%s: illegal call sequence: the instance is %s; %s is allowed when %s (%s)", fn,
         w->mode >= 0 && w->mode < N_ST ? STATE_NAMES[w->mode] : "in an unknown state", fn,
         states[0] ? states : "never", w->mode >= 0 && w->mode < N_ST ? STATE_NEXT[w->mode] : "free it");
    return 0;
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

/* leave initialization mode: build the model from the parameters, outputs at the initial inputs (both FMI
 * versions' ExitInitializationMode); RW_ERROR and the FAILED state on a bad parameter */
static RwStatus exit_initialization(Wheel *w)
{
    const double t_host = w->mu.t_host, speed = w->mu.speed, accel = w->mu.accel;
    memset(&w->mu, 0, sizeof w->mu);
    w->mu.t_host = t_host;
    w->mu.t_start = t_host;
    w->mu.speed = speed;
    w->mu.accel = accel;
    w->floor_warned = 0;
    if (!build_model(w)) {
        w->mode = ST_FAILED;
        return RW_ERROR;
    }
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
                w->mode = ST_FAILED;
                return fail(w, "initialisation failed: the outputs at the initial wheel_speed = %g rad/s are not "
                               "finite", speed);
            }
    }
    return RW_OK;
}

/* one communication step at host time t (both versions' DoStep; the state is checked by the caller) */
static RwStatus do_step(Wheel *w, double t, double h)
{
    if (!isfinite(t) || fabs(t - w->mu.t_host) > 1e-9 * fmax(1.0, fabs(t)))
        return fail(w, "step rejected: communication point %.12g s does not continue the last step (expected "
                       "%.12g s)", t, w->mu.t_host);
    Mutable saved = w->mu;
    const RwStatus s = step(w, t, h);
    if (s != RW_OK) {
        /* the state stays at the last good step (st and floor phasors are written only on success, except
         * a non-finite output: roll the scalars back; the kernel state then holds the bad step) */
        if (w->mu.t != saved.t)
            w->mu = saved;
        return s;
    }
    w->mu.t_host = t + h;
    return RW_OK;
}

/* ------------------------------------------------------------------ variables by value reference */
static int is_real_vr(unsigned vr) { return vr == VR_SPEED || vr == VR_ACCEL || (vr >= VR_FLOOR_RES && vr < N_VR); }
static int is_input_vr(unsigned vr) { return vr == VR_SPEED || vr == VR_ACCEL; }

static double *real_slot(Wheel *w, unsigned vr)
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

static int *bool_slot(Wheel *w, unsigned vr)
{
    switch (vr) {
    case VR_USE_ACCEL: return &w->par.use_accel;
    case VR_IMBALANCE: return &w->par.imbalance;
    case VR_HARMONICS: return &w->par.harmonics;
    case VR_MODES: return &w->par.modes;
    case VR_START_STEADY: return &w->par.start_steady;
    default: return vr >= VR_SWITCH && vr < VR_SWITCH + N_SWITCH ? &w->par.sw[vr - VR_SWITCH] : NULL;
    }
}

/* a value-reference array the host gave: n > 0 needs both arrays */
static int arrays_ok(Wheel *w, const char *fn, size_t n, const void *vr, const void *v)
{
    if (n && (!vr || !v)) {
        fail(w, "%s: %zu values asked with a NULL %s array", fn, n, vr ? "value" : "value reference");
        return 0;
    }
    return 1;
}

/* a fixed parameter may change in INSTANTIATED and INITIALIZATION mode only */
static int parameter_settable(Wheel *w, const char *fn, unsigned vr)
{
    if (w->mode == ST_INSTANTIATED || w->mode == ST_INIT)
        return 1;
    fail(w, "%s: value reference %u is a fixed parameter; set it before the end of initialisation (the "
            "instance is %s)", fn, vr, STATE_NAMES[w->mode]);
    return 0;
}

static RwStatus get_reals(Wheel *w, const char *fn, const unsigned vr[], size_t n, double v[])
{
    if (!allowed(w, READABLE, fn) || !arrays_ok(w, fn, n, vr, v))
        return RW_ERROR;
    for (size_t i = 0; i < n; i++) {
        double *s = is_real_vr(vr[i]) ? real_slot(w, vr[i]) : NULL;
        if (!s)
            return fail(w, "%s: value reference %u is not a Real (Float64) variable of this FMU", fn, vr[i]);
        v[i] = *s;
    }
    return RW_OK;
}

static RwStatus set_reals(Wheel *w, const char *fn, const unsigned vr[], size_t n, const double v[])
{
    if (!allowed(w, SETTABLE, fn) || !arrays_ok(w, fn, n, vr, v))
        return RW_ERROR;
    for (size_t i = 0; i < n; i++) {
        if (vr[i] >= VR_OUT && vr[i] < VR_OUT + 12)
            return fail(w, "%s: value reference %u is an output", fn, vr[i]);
        double *s = is_real_vr(vr[i]) ? real_slot(w, vr[i]) : NULL;
        if (!s)
            return fail(w, "%s: value reference %u is not a Real (Float64) variable of this FMU", fn, vr[i]);
        if (!is_input_vr(vr[i]) && !parameter_settable(w, fn, vr[i]))
            return RW_ERROR;
        *s = v[i];
    }
    return RW_OK;
}

static RwStatus get_seed(Wheel *w, const char *fn, const unsigned vr[], size_t n, int v[])
{
    if (!allowed(w, READABLE, fn) || !arrays_ok(w, fn, n, vr, v))
        return RW_ERROR;
    for (size_t i = 0; i < n; i++) {
        if (vr[i] != VR_SEED)
            return fail(w, "%s: value reference %u is not an Integer (Int32) variable of this FMU", fn, vr[i]);
        v[i] = w->par.seed;
    }
    return RW_OK;
}

static RwStatus set_seed(Wheel *w, const char *fn, const unsigned vr[], size_t n, const int v[])
{
    if (!allowed(w, SETTABLE, fn) || !arrays_ok(w, fn, n, vr, v))
        return RW_ERROR;
    for (size_t i = 0; i < n; i++) {
        if (vr[i] != VR_SEED)
            return fail(w, "%s: value reference %u is not an Integer (Int32) variable of this FMU", fn, vr[i]);
        if (!parameter_settable(w, fn, vr[i]))
            return RW_ERROR;
        w->par.seed = v[i];
    }
    return RW_OK;
}

/* Booleans as ints (fmi2Boolean) or bytes (fmi3Boolean): `wide` says which */
static RwStatus get_bools(Wheel *w, const char *fn, const unsigned vr[], size_t n, void *v, int wide)
{
    if (!allowed(w, READABLE, fn) || !arrays_ok(w, fn, n, vr, v))
        return RW_ERROR;
    for (size_t i = 0; i < n; i++) {
        int *s = bool_slot(w, vr[i]);
        if (!s)
            return fail(w, "%s: value reference %u is not a Boolean variable of this FMU", fn, vr[i]);
        if (wide)
            ((int *)v)[i] = *s != 0;
        else
            ((unsigned char *)v)[i] = *s != 0;
    }
    return RW_OK;
}

static RwStatus set_bools(Wheel *w, const char *fn, const unsigned vr[], size_t n, const void *v, int wide)
{
    if (!allowed(w, SETTABLE, fn) || !arrays_ok(w, fn, n, vr, v))
        return RW_ERROR;
    for (size_t i = 0; i < n; i++) {
        int *s = bool_slot(w, vr[i]);
        if (!s)
            return fail(w, "%s: value reference %u is not a Boolean variable of this FMU", fn, vr[i]);
        if (!parameter_settable(w, fn, vr[i]))
            return RW_ERROR;
        *s = wide ? ((const int *)v)[i] != 0 : ((const unsigned char *)v)[i] != 0;
    }
    return RW_OK;
}

static RwStatus get_strings(Wheel *w, const char *fn, const unsigned vr[], size_t n, const char *v[])
{
    if (!allowed(w, READABLE, fn) || !arrays_ok(w, fn, n, vr, v))
        return RW_ERROR;
    for (size_t i = 0; i < n; i++) {
        if (vr[i] != VR_MODEL_FILE)
            return fail(w, "%s: value reference %u is not a String variable of this FMU", fn, vr[i]);
        v[i] = "";
    }
    return RW_OK;
}

static RwStatus set_strings(Wheel *w, const char *fn, const unsigned vr[], size_t n, const char *const v[])
{
    if (!allowed(w, SETTABLE, fn) || !arrays_ok(w, fn, n, vr, v))
        return RW_ERROR;
    for (size_t i = 0; i < n; i++) {
        if (vr[i] != VR_MODEL_FILE)
            return fail(w, "%s: value reference %u is not a String variable of this FMU", fn, vr[i]);
        if (!parameter_settable(w, fn, vr[i]))
            return RW_ERROR;
        if (v[i] && v[i][0])
            return fail(w, "%s: model_file = '%s': the native FMU carries its model compiled in; build another FMU "
                           "from that model file (rwadist fmu build --native FILE)", fn, v[i]);
    }
    return RW_OK;
}

/* ------------------------------------------------------------------ FMU state
 * Layout (native byte order): header {magic, version, sizeof(Params), sizeof(Mutable), n, n_floor, mode},
 * Params, Mutable, the kernel state (2 + 2n + 12 doubles), the floor phasors (n_floor complex). */
typedef struct {
    uint32_t magic, version, size_par, size_mu;
    int32_t n, n_floor, mode, floor_warned;
} StateHeader;

typedef struct {
    size_t size;
    char data[];
} Blob;

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

/* 1 when buf holds a state of this FMU's layout (header checked against its size) */
static int state_header_ok(const char *buf, size_t size, StateHeader *hd)
{
    if (size < sizeof *hd)
        return 0;
    memcpy(hd, buf, sizeof *hd);
    return hd->magic == STATE_MAGIC && hd->version == 1 && hd->size_par == sizeof(Params) &&
           hd->size_mu == sizeof(Mutable) && hd->n >= 0 && hd->n_floor >= 0 && hd->mode >= 0 && hd->mode < N_ST &&
           size == state_size(hd->n, hd->n_floor);
}

static RwStatus read_state(Wheel *w, const char *buf, size_t size, const char *what)
{
    StateHeader hd;
    if (!state_header_ok(buf, size, &hd))
        return fail(w, "%s: not a state of this FMU (wrong magic, version or size)", what);
    Params par;
    memcpy(&par, buf + sizeof hd, sizeof par);
    /* a state taken after initialisation carries the kernel state: the state's parameters rebuild the model
     * when they differ from the instance's; a state from before carries parameters and inputs only */
    const int built = hd.mode == ST_STEP || hd.mode == ST_TERMINATED;
    if (built && (memcmp(&par, &w->par, sizeof par) != 0 || !w->cfg)) {
        const Params old = w->par;
        w->par = par;
        if (!build_model(w)) {
            w->par = old;
            if (w->mode == ST_STEP || w->mode == ST_TERMINATED)
                build_model(w);
            return fail(w, "%s: the state's parameters do not build the model", what);
        }
    }
    if (built && (hd.n != w->n || hd.n_floor != w->n_floor))
        return fail(w, "%s: the state's model size does not match this FMU", what);
    if (!built)
        free_model(w);
    w->par = par;
    const char *p = buf + sizeof hd + sizeof par;
    memcpy(&w->mu, p, sizeof w->mu), p += sizeof w->mu;
    if (built) {
        memcpy(w->st, p, sizeof(double) * (size_t)(2 + 2 * w->n + 12));
        p += sizeof(double) * (size_t)(2 + 2 * w->n + 12);
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
    if (!s)
        return fail(w, "%s: NULL state pointer", fn);
    const size_t size = state_size(w->n, w->n_floor);
    Blob *b = *s ? (Blob *)*s : NULL;
    if (b && b->size != size) {
        free(b);
        b = NULL;
    }
    if (!b) {
        b = malloc(sizeof(Blob) + size);
        if (!b)
            return fail(w, "%s: out of memory", fn);
        b->size = size;
    }
    write_state(w, b->data);
    *s = b;
    return RW_OK;
}

/* SetFMUstate: not into a terminated instance (it would step again without a reset) */
static RwStatus set_state(Wheel *w, const char *fn, const void *s)
{
    if (!allowed(w, ANY_STATE & ~IN(ST_TERMINATED), fn))
        return RW_ERROR;
    if (!s)
        return fail(w, "%s: no state given", fn);
    const Blob *b = (const Blob *)s;
    return read_state(w, b->data, b->size, fn);
}

static RwStatus serialize_state(Wheel *w, const char *fn, const void *s, char *buf, size_t size)
{
    if (!s || (size && !buf))
        return fail(w, "%s: no state or no buffer given", fn);
    const Blob *b = (const Blob *)s;
    if (size < b->size)
        return fail(w, "%s: buffer of %zu bytes is smaller than the state (%zu)", fn, size, b->size);
    memcpy(buf, b->data, b->size);
    return RW_OK;
}

static RwStatus deserialize_state(Wheel *w, const char *fn, const char *buf, size_t size, void **s)
{
    StateHeader hd;
    if (!s || (size && !buf))
        return fail(w, "%s: no buffer or no state pointer given", fn);
    if (!state_header_ok(buf, size, &hd))
        return fail(w, "%s: %zu bytes are not a state of this FMU (wrong magic, version or size)", fn, size);
    Blob *b = malloc(sizeof(Blob) + size);
    if (!b)
        return fail(w, "%s: out of memory", fn);
    b->size = size;
    memcpy(b->data, buf, size);
    *s = b;
    return RW_OK;
}

#endif
