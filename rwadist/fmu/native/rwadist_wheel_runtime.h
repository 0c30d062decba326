/* rwadist wheel FMU in C: the model runtime (WheelRuntime of rwadist/fmu/runtime.py): instance data, model set-up
 * from the compiled model (wheel_model.h) and the parameters, input checks, ripple, floors, one step.
 * Independent of the FMI version: statuses are RwStatus (the values of fmi2Status and fmi3Status) and messages
 * go to the logger the wrapper installs.  Included once per FMU, through rwadist_wheel_instance.h, by
 * rwadist_wheel_fmu.c (FMI 2.0) or rwadist_wheel_fmi3.c (FMI 3.0). */
#ifndef RWADIST_WHEEL_RUNTIME_H
#define RWADIST_WHEEL_RUNTIME_H
#include <complex.h>
#include <math.h>
#include <stdarg.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "rwadist_kernel.h"
#include "rwadist_rng.h"
#include "wheel_model.h"

#define RW_TWO_PI (2.0 * 3.14159265358979311600)
#define FLOOR_RESYNC 1000
#define FLOOR_MAX_COMPONENTS 2000000
#define FLOOR_DEFAULT_SEED 20251122u
#define RIPPLE_STEPS_PER_PERIOD 20
#define STATE_MAGIC 0x52574653u /* "RWFS" */

/* the values of fmi2Status and fmi3Status (OK .. Fatal) */
typedef enum { RW_OK = 0, RW_WARNING = 1, RW_DISCARD = 2, RW_ERROR = 3, RW_FATAL = 4 } RwStatus;
/* the wrapper's logger: one plain message (no format), the instance's environment */
typedef void (*RwLogger)(void *env, RwStatus status, const char *category, const char *message);

/* the effect switches (value references VR_SWITCH ..): each turns its element's ripples and floors off */
#define N_SWITCH 2
#if RW_N_SWITCHES != N_SWITCH
#error "wheel_model.h names another number of effect switches than the FMU has (rwadist.fmu.runtime.SWITCH_SLOTS)"
#endif

/* parameters: everything the host sets before initialisation (also saved with a state) */
typedef struct {
    double floor_res, max_accel, max_step, dcm[9], pos[3];
    int use_accel, seed, imbalance, harmonics, modes, start_steady, sw[N_SWITCH];
} Params;

/* everything a step changes (the FMU state besides the arrays) */
typedef struct {
    double speed, accel;             /* inputs */
    double t_host;                   /* host time of the next step's start */
    double t_start;                  /* host start time t0 (SetupExperiment / EnterInitializationMode) */
    double t;                        /* model time since t0 (as runtime.py's self.t) */
    double prev_start, prev_alpha, prev_end_w, prev_end_h;
    int has_prev;                    /* a step has been taken (prev_* valid) */
    int started;
    int floor_count;
    double y[12];
} Mutable;

typedef struct {
    RwLogger logger;                 /* the FMI wrapper's adapter to the host's logger (may be NULL) */
    void *log_env;                   /* its argument */
    int fmi;                         /* FMI version of the wrapper: 2 or 3 */
    int mode;                        /* state of the FMI state machine (ST_* of rwadist_fmi_rules.h) */
    Params par;
    Mutable mu;
    /* built at initialisation */
    int n;                           /* kernel components */
    double *cfg, *st, kout[12];
    int has_ripple, n_ripple;        /* the ripples on (their switches on) */
    double ripple[RW_N_RIPPLES_ALLOC][5]; /* ΔΩ_ref, Ω_ref, q, 2π f_r, θ */
    const char *ripple_switch;       /* the switch that turns them off (for the step-size message), or NULL */
    double ripple_f_max;
    int n_floor;                     /* sinusoids */
    int n_seg;                       /* floor segments */
    double complex *floor_A, *floor_Z, *floor_rot;
    double *floor_w;
    double floor_rot_h;
    int *seg_start, *seg_chan;
    double *seg_ref, *seg_half_p;
    double floor_f_max;
    int floor_warned;
    int logging_on;                  /* loggingOn / SetDebugLogging: OK-status messages */
} Wheel;

/* ------------------------------------------------------------------ logging */
static void logf_(Wheel *w, RwStatus status, const char *category, const char *fmt, ...)
{
    char buf[1024];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(buf, sizeof buf, fmt, ap);
    va_end(ap);
    if (status == RW_OK && !(w && w->logging_on))
        return;
    if (w && w->logger)
        w->logger(w->log_env, status, category, buf);
}

static RwStatus fail(Wheel *w, const char *fmt, ...)
{
    char buf[1024];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(buf, sizeof buf, fmt, ap);
    va_end(ap);
    logf_(w, RW_ERROR, "logStatusError", "rwadist wheel: %s", buf);
    return RW_ERROR;
}

/* ------------------------------------------------------------------ model set-up */
static void free_model(Wheel *w)
{
    free(w->cfg);
    free(w->st);
    free(w->floor_A);
    free(w->floor_Z);
    free(w->floor_rot);
    free(w->floor_w);
    free(w->seg_start);
    free(w->seg_chan);
    free(w->seg_ref);
    free(w->seg_half_p);
    w->cfg = w->st = NULL;
    w->floor_A = w->floor_Z = w->floor_rot = NULL;
    w->floor_w = w->seg_ref = w->seg_half_p = NULL;
    w->seg_start = w->seg_chan = NULL;
    w->n = w->n_floor = w->n_seg = 0;
}

/* components of one line: (σ, coef) as runtime.components */
static int line_components(const RwLine *ln, double phase, int sigma[2], double complex coef[2])
{
    if (ln->dir >= 2 || ln->sense == 0) {
        sigma[0] = 1;
        coef[0] = CMPLX(cos(phase), sin(phase));
        return 1;
    }
    if (ln->sense == 1) {
        sigma[0] = -1;
        coef[0] = CMPLX(cos(-phase), sin(-phase));
        return 1;
    }
    /* planar: along x (sense 2) or along y (sense 3, the y load of an empirical planar line) */
    const double angle = ln->sense == 3 ? 0.5 * 3.14159265358979311600 : 0.0;
    sigma[0] = 1;
    sigma[1] = -1;
    coef[0] = 0.5 * CMPLX(cos(angle + phase), sin(angle + phase));
    coef[1] = 0.5 * CMPLX(cos(angle - phase), sin(angle - phase));
    return 2;
}

/* numpy.interp at x of knots (xp, fp), 0 outside */
static double interp0(double x, const double *xp, const double *fp, int n)
{
    if (x < xp[0] || x > xp[n - 1])
        return 0.0;
    if (x == xp[n - 1])
        return fp[n - 1];
    int lo = 0, hi = n - 1;
    while (hi - lo > 1) {
        int mid = (lo + hi) / 2;
        if (xp[mid] <= x)
            lo = mid;
        else
            hi = mid;
    }
    if (xp[lo] == x)
        return fp[lo];
    const double slope = (fp[lo + 1] - fp[lo]) / (xp[lo + 1] - xp[lo]);
    return slope * (x - xp[lo]) + fp[lo];
}

static int rotation_ok(Wheel *w, const double *R)
{
    double err = 0.0;
    for (int i = 0; i < 9; i++)
        if (!isfinite(R[i])) {
            fail(w, "initialisation failed: mounting DCM has non-finite entries");
            return 0;
        }
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++) {
            double s = 0.0;
            for (int k = 0; k < 3; k++)
                s += R[3 * k + i] * R[3 * k + j];
            err = fmax(err, fabs(s - (i == j)));
        }
    const double det = R[0] * (R[4] * R[8] - R[5] * R[7]) - R[1] * (R[3] * R[8] - R[5] * R[6]) +
                       R[2] * (R[3] * R[7] - R[4] * R[6]);
    if (err > 1e-6 || det <= 0) {
        fail(w, "initialisation failed: mounting DCM is not a proper rotation (max |R^T R - I| = %.3g, det = %.6g)",
             err, det);
        return 0;
    }
    return 1;
}

/* build the kernel configuration, ripple and floors from the compiled model and the parameters
 * (WheelRuntime.__init__); 0 with a logged error on a bad parameter */
static int build_model(Wheel *w)
{
    const Params *p = &w->par;
    free_model(w);
    if (p->seed < -1)
        return !fail(w, "initialisation failed: seed must be >= 0, or -1 for the model file's phases; got %d",
                     p->seed);
    if (!(isfinite(p->max_accel) && p->max_accel > 0))
        return !fail(w, "initialisation failed: max_acceleration must be finite and > 0, got %g", p->max_accel);
    if (!(isfinite(p->max_step) && p->max_step > 0))
        return !fail(w, "initialisation failed: max_step_size must be finite and > 0, got %g", p->max_step);
    if (!(isfinite(p->floor_res) && p->floor_res > 0))
        return !fail(w, "initialisation failed: floor_resolution must be finite and > 0, got %g Hz", p->floor_res);
    if (p->modes && !RW_SUSPENSION)
        return !fail(w, "initialisation failed: modes: on, but the model has no suspension (analytical: missing -- "
                        "an empirical fit, harmonics only); it runs hard-mounted: set modes = false");
    if (!rotation_ok(w, p->dcm))
        return 0;
    for (int i = 0; i < 3; i++)
        if (!isfinite(p->pos[i]))
            return !fail(w, "initialisation failed: interface position r is not finite");

    /* line phases: default_rng(seed).uniform(0, 2π, n_lines) over every line */
    double phase[RW_N_LINES_ALLOC];
    rw_pcg64 g;
    if (p->seed >= 0)
        rw_rng_seed(&g, (uint32_t)p->seed, -1);
    for (int i = 0; i < RW_N_LINES; i++)
        phase[i] = p->seed >= 0 ? rw_uniform(&g, 0.0, RW_TWO_PI) : 0.0;

    int n = 0, n_res = 0;
    for (int i = 0; i < RW_N_LINES; i++) {
        const RwLine *ln = &RW_LINES[i];
        if ((ln->imbalance && !p->imbalance) || (!ln->imbalance && !p->harmonics))
            continue;
        int k = 0;
        for (int r = 0; r < RW_N_RES; r++)
            k += (RW_RES[r].dirmask >> ln->dir) & 1;
        const int nc = (ln->dir < 2 && ln->sense >= 2) ? 2 : 1;
        n += nc;
        n_res += nc * k;
    }
    w->n = n;
    w->cfg = calloc((size_t)(C_COMP + C_STRIDE * n + C_RES * n_res) + 1, sizeof(double));
    w->st = calloc((size_t)(2 + 2 * n + 12), sizeof(double));
    if (!w->cfg || !w->st)
        return !fail(w, "initialisation failed: out of memory");
    double complex *S0 = (double complex *)(w->st + 2);
    for (int i = 0; i < n; i++)      /* e^{i·0}: rotor angle and time start at 0 (runtime.reset) */
        S0[i] = 1.0;
    double *cfg = w->cfg;
    cfg[C_N] = n;
    cfg[C_MODES] = p->modes ? 1.0 : 0.0;
    for (int i = 0; i < 10; i++)
        cfg[C_M + i] = RW_PARAMS[i];
    for (int i = 0; i < 4; i++) {
        cfg[C_LAMR + i] = RW_LAM[i];
        cfg[C_LAMZ + i] = RW_LAM[4 + i];
    }
    for (int i = 0; i < 9; i++)
        cfg[C_R + i] = p->dcm[i];
    for (int i = 0; i < 3; i++)
        cfg[C_POS + i] = p->pos[i];
    size_t res_at = (size_t)(C_COMP + C_STRIDE * n);
    int c = 0;
    for (int i = 0; i < RW_N_LINES; i++) {
        const RwLine *ln = &RW_LINES[i];
        if ((ln->imbalance && !p->imbalance) || (!ln->imbalance && !p->harmonics))
            continue;
        int sigma[2];
        double complex coef[2];
        const int nc = line_components(ln, phase[i], sigma, coef);
        for (int j = 0; j < nc; j++, c++) {
            double *comp = cfg + C_COMP + C_STRIDE * c;
            const double complex cC = coef[j] * ln->C;
            const double complex cCi = CMPLX(cimag(coef[j]), -creal(coef[j])) * ln->C * (ln->imbalance ? 1.0 : 0.0);
            comp[0] = sigma[j] * ln->h;
            comp[1] = ln->dir;
            comp[2] = ln->has_law ? 0.0 : creal(cC);
            comp[3] = ln->has_law ? 0.0 : cimag(cC);
            comp[4] = creal(cCi);
            comp[5] = cimag(cCi);
            comp[8] = 1.0;
            if (ln->has_law) {
                const double complex ls = coef[j] * ln->a_ref;
                comp[6] = creal(ls);
                comp[7] = cimag(ls);
                comp[8] = ln->w_ref;
                comp[9] = ln->p;
            }
            comp[10] = sigma[j] * 2.0 * 3.14159265358979311600 * ln->f_off;
            int k = 0;
            comp[12] = 0.0;
            for (int r = 0; r < RW_N_RES; r++) {
                if (!((RW_RES[r].dirmask >> ln->dir) & 1))
                    continue;
                if (k == 0)
                    comp[12] = (double)res_at;
                cfg[res_at++] = 2.0 * 3.14159265358979311600 * RW_RES[r].f_hz;
                cfg[res_at++] = 2.0 * RW_RES[r].g * RW_RES[r].zeta;
                cfg[res_at++] = 2.0 * RW_RES[r].zeta;
                k++;
            }
            comp[11] = k;
        }
    }

    /* speed ripples whose switch is on (as runtime.py: θ from default_rng((seed, 1)), one per ripple on) */
    w->n_ripple = 0;
    w->ripple_f_max = 0.0;
    w->ripple_switch = NULL;
    if (p->seed >= 0)
        rw_rng_seed(&g, (uint32_t)p->seed, 1);
    for (int i = 0; i < RW_N_RIPPLES; i++) {
        const int sw = RW_RIPPLE_SWITCH[i];
        if (sw >= 0 && !p->sw[sw])
            continue;
        double *q = w->ripple[w->n_ripple++];
        q[0] = RW_RIPPLES[i][0];
        q[1] = RW_RIPPLES[i][1];
        q[2] = RW_RIPPLES[i][2];
        q[3] = 2.0 * 3.14159265358979311600 * RW_RIPPLES[i][3];
        q[4] = p->seed >= 0 ? rw_uniform(&g, 0.0, RW_TWO_PI) : 0.0;
        /* as runtime.py: the largest ripple rate in rad/s sets the step-size check */
        w->ripple_f_max = fmax(w->ripple_f_max, RW_RIPPLES[i][3]);
        if (sw >= 0 && !w->ripple_switch)
            w->ripple_switch = RW_SWITCH_NAMES[sw];
    }
    w->has_ripple = w->n_ripple > 0;

    /* broadband floors whose switch is on: multisine at floor_resolution, phases from
       default_rng((seed or default, 2)) */
    w->floor_f_max = 0.0;
    int any_floor = 0;
    for (int f = 0; f < RW_N_FLOORS; f++)
        any_floor |= RW_FLOORS[f].sw < 0 || p->sw[RW_FLOORS[f].sw];
    if (any_floor) {
        const double df = p->floor_res;
        long n_max = 0;
        for (int f = 0; f < RW_N_FLOORS; f++) {
            const RwFloor *fl = &RW_FLOORS[f];
            if (fl->sw >= 0 && !p->sw[fl->sw])
                continue;
            const long k0 = (long)fmax(1.0, ceil(RW_FLOOR_F[fl->at] / df)), k1 = (long)floor(RW_FLOOR_F[fl->at + fl->n - 1] / df);
            n_max += k1 >= k0 ? k1 - k0 + 1 : 0;
        }
        if (n_max > FLOOR_MAX_COMPONENTS)
            return !fail(w, "initialisation failed: broadband floors need %ld sinusoids at floor_resolution = %g Hz "
                            "(limit %d); use a coarser floor_resolution", n_max, df, FLOOR_MAX_COMPONENTS);
        w->floor_A = malloc(sizeof(double complex) * (size_t)(n_max + 1));
        w->floor_Z = malloc(sizeof(double complex) * (size_t)(n_max + 1));
        w->floor_rot = malloc(sizeof(double complex) * (size_t)(n_max + 1));
        w->floor_w = malloc(sizeof(double) * (size_t)(n_max + 1));
        w->seg_start = malloc(sizeof(int) * (RW_N_FLOORS + 1));
        w->seg_chan = malloc(sizeof(int) * (RW_N_FLOORS + 1));
        w->seg_ref = malloc(sizeof(double) * (RW_N_FLOORS + 1));
        w->seg_half_p = malloc(sizeof(double) * (RW_N_FLOORS + 1));
        if (!w->floor_A || !w->floor_Z || !w->floor_rot || !w->floor_w || !w->seg_start || !w->seg_chan ||
            !w->seg_ref || !w->seg_half_p)
            return !fail(w, "initialisation failed: out of memory for %ld floor sinusoids", n_max);
        int m = 0;
        for (int f = 0; f < RW_N_FLOORS; f++) {
            const RwFloor *fl = &RW_FLOORS[f];
            if (fl->sw >= 0 && !p->sw[fl->sw])
                continue;
            const double *xp = RW_FLOOR_F + fl->at, *fp = RW_FLOOR_PSD + fl->at;
            const long k0 = (long)fmax(1.0, ceil(xp[0] / df)), k1 = (long)floor(xp[fl->n - 1] / df);
            const int start = m;
            int any_psd = 0;
            for (int i = 0; i < fl->n; i++)
                any_psd |= fp[i] > 0;
            for (long k = k0; k <= k1; k++) {
                const double S = interp0((double)k * df, xp, fp, fl->n);
                if (S > 0) {
                    w->floor_A[m] = sqrt(2.0 * S * df);
                    w->floor_w[m] = 2.0 * 3.14159265358979311600 * df * (double)k;
                    m++;
                }
            }
            if (m == start) {
                if (any_psd)
                    return !fail(w, "initialisation failed: a broadband floor of channel %d (%g-%g Hz) has no "
                                    "sinusoid at floor_resolution = %g Hz; use a finer floor_resolution",
                                 fl->channel, xp[0], xp[fl->n - 1], df);
                continue;
            }
            w->seg_start[w->n_seg] = start;
            w->seg_chan[w->n_seg] = fl->channel;
            w->seg_ref[w->n_seg] = fl->w_ref;
            w->seg_half_p[w->n_seg] = 0.5 * fl->p;
            w->n_seg++;
        }
        w->seg_start[w->n_seg] = m;
        w->n_floor = m;
        rw_rng_seed(&g, p->seed >= 0 ? (uint32_t)p->seed : FLOOR_DEFAULT_SEED, 2);
        for (int i = 0; i < m; i++) {
            const double ph = rw_uniform(&g, 0.0, RW_TWO_PI);
            w->floor_A[i] = creal(w->floor_A[i]) * CMPLX(cos(ph), sin(ph));
            w->floor_f_max = fmax(w->floor_f_max, w->floor_w[i] / RW_TWO_PI);
        }
        w->floor_rot_h = -1.0;
    }
    return 1;
}

/* ------------------------------------------------------------------ runtime pieces */
static double ripple_at(const Wheel *w, double omega, double t)
{
    double r = 0.0;
    for (int i = 0; i < w->n_ripple; i++) {
        const double *q = w->ripple[i];
        r += (q[2] != 0.0 ? q[0] * pow(fabs(omega) / q[1], q[2]) : q[0]) * sin(q[3] * t + q[4]);
    }
    return r;
}

static double ripple_rate(const Wheel *w, double omega, double t)
{
    double r = 0.0;
    for (int i = 0; i < w->n_ripple; i++) {
        const double *q = w->ripple[i];
        r += (q[2] != 0.0 ? q[0] * pow(fabs(omega) / q[1], q[2]) : q[0]) * q[3] * cos(q[3] * t + q[4]);
    }
    return r;
}

/* component amplitude coef·C·(Ω² − iΩ̇·[imbalance]) (+ law) × resonance gains (runtime._amp) */
static double complex amp(const Wheel *w, int i, double om, double wdot)
{
    const double *c = w->cfg + C_COMP + C_STRIDE * i;
    double complex a = CMPLX(c[2], c[3]) * (om * om) + CMPLX(c[4], c[5]) * wdot;
    if (c[6] != 0.0 || c[7] != 0.0)
        a += CMPLX(c[6], c[7]) * pow(fabs(om) / c[8], c[9]);
    const int nres = (int)c[11];
    if (nres > 0) {
        const double *rt = w->cfg + (size_t)c[12];
        double complex G = 1.0;
        for (int k = 0; k < nres; k++, rt += C_RES) {
            const double r = (c[0] * om + c[10]) / rt[0], base = 1.0 - r * r;
            G *= CMPLX(base, rt[1] * r) / CMPLX(base, rt[2] * r);
        }
        a *= G;
    }
    return a;
}

/* closed-form steady state at speed w0 into the modal states (runtime._steady_init) */
static void steady_init(Wheel *w, double w0, double wdot0)
{
    const double *cfg = w->cfg;
    const int n = w->n;
    const double m = cfg[C_M], I_rr = cfg[C_IRR], I_zz = cfg[C_IZZ];
    const double sub[3][4] = {{m, cfg[C_CR], cfg[C_KR], 0.0}, {I_rr, cfg[C_CROCK], cfg[C_KROCK], I_zz},
                              {m, cfg[C_CZ], cfg[C_KZ], 0.0}};
    double complex q[3] = {0, 0, 0}, qd[3] = {0, 0, 0};
    for (int i = 0; i < n; i++) {
        const double *c = cfg + C_COMP + C_STRIDE * i;
        const int d = (int)c[1];
        if (d > 2)
            continue;
        const double nu = c[0] * w0 + c[10];
        const double complex G = 1.0 / CMPLX(sub[d][2] - sub[d][0] * nu * nu + sub[d][3] * w0 * nu, sub[d][1] * nu);
        const double complex a = amp(w, i, w0, wdot0);
        q[d] += G * a;
        qd[d] += CMPLX(0.0, nu) * G * a;
    }
    double complex *S = (double complex *)(w->st + 2);
    double complex *eta_r = S + n, *eta_z = S + n + 2, *x_rock = S + n + 4;
    const double complex l1 = CMPLX(cfg[C_LAMR], cfg[C_LAMR + 1]), l2 = CMPLX(cfg[C_LAMR + 2], cfg[C_LAMR + 3]);
    eta_r[0] = (qd[0] - l2 * q[0]) / (l1 - l2);
    eta_r[1] = (l1 * q[0] - qd[0]) / (l1 - l2);
    const double complex z1 = CMPLX(cfg[C_LAMZ], cfg[C_LAMZ + 1]), z2 = CMPLX(cfg[C_LAMZ + 2], cfg[C_LAMZ + 3]);
    eta_z[0] = (qd[2] - z2 * q[2]) / (z1 - z2);
    eta_z[1] = (z1 * q[2] - qd[2]) / (z1 - z2);
    x_rock[0] = q[1];
    x_rock[1] = qd[1];
}

/* floor loads at input speed om, time t: phasors advanced by `advance` (> 0) or set from t (runtime.floor_now).
 * The phasors Z and rotations e^{iω h} are stored split (all real parts, then all imaginary parts, in the
 * buffers floor_Z and floor_rot) so the rotation and the sum run as one pass of 2-wide vector arithmetic:
 * the same products as C's complex multiply (without its NaN branch) and the same four partial sums
 * (i mod 4 from each segment's start) as before, so the values are unchanged bit for bit. */
typedef double rw_v2d __attribute__((vector_size(16), aligned(8), may_alias));   /* unaligned, aliases double */

static void floor_now(Wheel *w, double om, double t, double advance, double out[6])
{
    for (int k = 0; k < 6; k++)
        out[k] = 0.0;
    if (!w->n_floor)
        return;
    const int nf = w->n_floor;
    double *zr = (double *)w->floor_Z, *zi = zr + nf;
    int rotate = 0;
    if (advance <= 0 || w->mu.floor_count >= FLOOR_RESYNC) {
        for (int i = 0; i < nf; i++) {
            const double complex z = w->floor_A[i] * CMPLX(cos(w->floor_w[i] * t), sin(w->floor_w[i] * t));
            zr[i] = creal(z);
            zi[i] = cimag(z);
        }
        w->mu.floor_count = 0;
    } else {
        if (advance != w->floor_rot_h) {
            double *rr = (double *)w->floor_rot, *ri = rr + nf;
            for (int i = 0; i < nf; i++) {
                rr[i] = cos(w->floor_w[i] * advance);
                ri[i] = sin(w->floor_w[i] * advance);
            }
            w->floor_rot_h = advance;
        }
        rotate = 1;
        w->mu.floor_count++;
    }
    const double *rr = (const double *)w->floor_rot, *ri = rr + nf;
    for (int s = 0; s < w->n_seg; s++) {
        /* four partial sums: independent additions the CPU overlaps (the order differs from numpy's
         * pairwise sum only in rounding) */
        rw_v2d acc01 = {0.0, 0.0}, acc23 = {0.0, 0.0};
        int i = w->seg_start[s];
        const int end = w->seg_start[s + 1];
        if (rotate) {
            for (; i + 3 < end; i += 4) {
                const rw_v2d a_r = *(const rw_v2d *)(zr + i), a_i = *(const rw_v2d *)(zi + i);
                const rw_v2d b_r = *(const rw_v2d *)(zr + i + 2), b_i = *(const rw_v2d *)(zi + i + 2);
                const rw_v2d ra_r = *(const rw_v2d *)(rr + i), ra_i = *(const rw_v2d *)(ri + i);
                const rw_v2d rb_r = *(const rw_v2d *)(rr + i + 2), rb_i = *(const rw_v2d *)(ri + i + 2);
                const rw_v2d na_r = a_r * ra_r - a_i * ra_i, na_i = a_r * ra_i + a_i * ra_r;
                const rw_v2d nb_r = b_r * rb_r - b_i * rb_i, nb_i = b_r * rb_i + b_i * rb_r;
                *(rw_v2d *)(zr + i) = na_r;
                *(rw_v2d *)(zi + i) = na_i;
                *(rw_v2d *)(zr + i + 2) = nb_r;
                *(rw_v2d *)(zi + i + 2) = nb_i;
                acc01 += na_r;
                acc23 += nb_r;
            }
            for (; i < end; i++) {
                const double nr = zr[i] * rr[i] - zi[i] * ri[i], ni = zr[i] * ri[i] + zi[i] * rr[i];
                zr[i] = nr;
                zi[i] = ni;
                acc01[0] += nr;
            }
        } else {
            for (; i + 3 < end; i += 4) {
                acc01 += *(const rw_v2d *)(zr + i);
                acc23 += *(const rw_v2d *)(zr + i + 2);
            }
            for (; i < end; i++)
                acc01[0] += zr[i];
        }
        const double sum = (acc01[0] + acc01[1]) + (acc23[0] + acc23[1]);
        out[w->seg_chan[s]] += pow(fabs(om) / w->seg_ref[s], w->seg_half_p[s]) * sum;
    }
}

static void frame12(const double o[6], const double *R, const double *r, double y[12])
{
    for (int k = 0; k < 6; k++)
        y[k] = o[k];
    const double fx = R[0] * o[0] + R[1] * o[1] + R[2] * o[2];
    const double fy = R[3] * o[0] + R[4] * o[1] + R[5] * o[2];
    const double fz = R[6] * o[0] + R[7] * o[1] + R[8] * o[2];
    y[6] = fx;
    y[7] = fy;
    y[8] = fz;
    y[9] = R[0] * o[3] + R[1] * o[4] + R[2] * o[5] + r[1] * fz - r[2] * fy;
    y[10] = R[3] * o[3] + R[4] * o[4] + R[5] * o[5] + r[2] * fx - r[0] * fz;
    y[11] = R[6] * o[3] + R[7] * o[4] + R[8] * o[5] + r[0] * fy - r[1] * fx;
}

/* outputs at the current state for the input speed (runtime.outputs_now, at the end of initialisation) */
static void outputs_now(Wheel *w, double w_in, double alpha)
{
    double om = w_in;
    if (w->has_ripple) {
        om += ripple_at(w, w_in, w->mu.t);
        alpha += ripple_rate(w, w_in, w->mu.t);
    }
    const double *cfg = w->cfg;
    if (!w->mu.started && w->par.start_steady && RW_SUSPENSION)
        steady_init(w, om, alpha);
    double complex loads[4] = {0, 0, 0, 0};
    const double phi = w->st[0];
    for (int i = 0; i < w->n; i++) {
        const double *c = cfg + C_COMP + C_STRIDE * i;
        loads[(int)c[1]] += amp(w, i, om, alpha) * cexp(CMPLX(0.0, c[0] * phi + c[10] * w->mu.t));
    }
    double complex F, Tc;
    double Fz;
    if (w->par.modes) {
        const int n = w->n;
        const double complex *S = (const double complex *)(w->st + 2);
        const double complex *eta_r = S + n, *eta_z = S + n + 2, *x_rock = S + n + 4;
        const double complex l1 = CMPLX(cfg[C_LAMR], cfg[C_LAMR + 1]), l2 = CMPLX(cfg[C_LAMR + 2], cfg[C_LAMR + 3]);
        const double complex z1 = CMPLX(cfg[C_LAMZ], cfg[C_LAMZ + 1]), z2 = CMPLX(cfg[C_LAMZ + 2], cfg[C_LAMZ + 3]);
        F = cfg[C_KR] * (eta_r[0] + eta_r[1]) + cfg[C_CR] * (l1 * eta_r[0] + l2 * eta_r[1]);
        Fz = creal(cfg[C_KZ] * (eta_z[0] + eta_z[1]) + cfg[C_CZ] * (z1 * eta_z[0] + z2 * eta_z[1]));
        Tc = cfg[C_KROCK] * x_rock[0] + cfg[C_CROCK] * x_rock[1];
    } else {
        F = loads[0];
        Fz = creal(loads[2]);
        Tc = loads[1];
    }
    const double complex Tint = Tc + I * cfg[C_HEIGHT] * F;
    double o[6] = {creal(F), cimag(F), Fz, creal(Tint), cimag(Tint), creal(loads[3])};
    if (w->n_floor) {
        double fl[6];
        floor_now(w, w_in, w->mu.t, -1.0, fl);
        for (int k = 0; k < 6; k++)
            o[k] += fl[k];
    }
    frame12(o, w->par.dcm, w->par.pos, w->mu.y);
}

/* one communication step (runtime.step12); RW_ERROR with the state untouched on bad input */
static RwStatus step(Wheel *w, double t_host, double h)
{
    Mutable *mu = &w->mu;
    const Params *p = &w->par;
    double omega = mu->speed;
    double alpha = mu->accel;
    const int have_alpha = p->use_accel;
    if (!isfinite(h) || h <= 0)
        return fail(w, "step at t = %.9g s rejected: communication step size %g s is not a positive finite number",
                    t_host, h);
    if (h > p->max_step * (1 + 1e-12))
        return fail(w, "step at t = %.9g s rejected: communication step size %.6g s exceeds max_step_size = %.6g s",
                    t_host, h, p->max_step);
    if (h < 1e-9)
        return fail(w, "step at t = %.9g s rejected: communication step size %.3g s is below the 1 ns the FMU "
                       "resolves", t_host, h);
    if (w->has_ripple && h * w->ripple_f_max * RIPPLE_STEPS_PER_PERIOD > 1 + 1e-12)
        return fail(w, "step at t = %.9g s rejected: communication step size %.6g s does not resolve the speed "
                       "ripple of %.6g Hz (%d steps per period); use smaller steps%s%s%s",
                    t_host, h, w->ripple_f_max, RIPPLE_STEPS_PER_PERIOD, w->ripple_switch ? " or " : "",
                    w->ripple_switch ? w->ripple_switch : "", w->ripple_switch ? " = false" : "");
    if (!isfinite(omega))
        return fail(w, "step at t = %.9g s rejected: wheel_speed is not finite: %g rad/s", t_host, omega);
    if (have_alpha && !isfinite(alpha))
        return fail(w, "step at t = %.9g s rejected: wheel_acceleration is not finite: %g rad/s2", t_host, alpha);
    if (have_alpha && fabs(alpha) > p->max_accel)
        return fail(w, "step at t = %.9g s rejected: wheel_acceleration %.6g rad/s2 exceeds max_acceleration = "
                       "%.6g rad/s2", t_host, alpha, p->max_accel);
    if (mu->has_prev && fabs(omega - mu->prev_end_w) / mu->prev_end_h > p->max_accel)
        return fail(w, "step at t = %.9g s rejected: wheel_speed jumps from %.6g to %.6g rad/s over one step "
                       "(%.6g s): |dOmega/dt| = %.3g rad/s2 > max_acceleration = %.6g rad/s2", t_host,
                    mu->prev_end_w, omega, mu->prev_end_h, fabs(omega - mu->prev_end_w) / mu->prev_end_h,
                    p->max_accel);
    if (!have_alpha) {
        if (!mu->has_prev)
            alpha = 0.0;
        else {
            alpha = (omega - mu->prev_start) / mu->prev_end_h;
            if (fabs(alpha) > p->max_accel)
                return fail(w, "step at t = %.9g s rejected: derived wheel acceleration %.6g rad/s2 exceeds "
                               "max_acceleration = %.6g rad/s2", t_host, alpha, p->max_accel);
        }
    }
    /* the model's clock is the host's: time since t0 from the communication point, not the sum of the steps
     * (which drifts from it by rounding), as runtime.py's step12(..., t) */
    mu->t = t_host - mu->t_start;
    w->st[1] = mu->t;
    const double w_in = omega, w1_in = omega + alpha * h, t_end = mu->t + h;
    if (w->has_ripple) {
        const double r0 = ripple_at(w, omega, mu->t);
        alpha = alpha + (ripple_at(w, w1_in, t_end) - r0) / h;
        omega = omega + r0;
    }
    const double wd0 = mu->has_prev ? 0.5 * (mu->prev_alpha + alpha) : alpha;
    if (!mu->started) {
        if (p->start_steady && RW_SUSPENSION)
            steady_init(w, omega, wd0);
        mu->started = 1;
    }
    rwadist_kernel_step_impl(w->cfg, w->st, w->kout, omega, wd0, alpha, h);
    mu->prev_start = w_in;
    mu->prev_alpha = alpha;
    mu->prev_end_w = w1_in;
    mu->prev_end_h = h;
    mu->has_prev = 1;
    mu->t = t_end;
    if (w->n_floor) {
        double o[6], fl[6];
        floor_now(w, w1_in, t_end, h, fl);
        for (int k = 0; k < 6; k++)
            o[k] = w->kout[k] + fl[k];
        frame12(o, p->dcm, p->pos, mu->y);
        if (!w->floor_warned && w->floor_f_max * 2 * h > 1) {
            w->floor_warned = 1;
            logf_(w, RW_WARNING, "logStatusWarning", "rwadist wheel: the broadband floors reach %g Hz, above the "
                  "%g Hz a %g-s step samples; that content folds back", w->floor_f_max, 0.5 / h, h);
        }
    } else {
        memcpy(mu->y, w->kout, sizeof mu->y);
    }
    for (int k = 0; k < 12; k++)
        if (!isfinite(mu->y[k]))
            return fail(w, "step at t = %.9g s produced a non-finite output (%s)", t_host, k < 6 ? "wheel frame" :
                        "spacecraft frame");
    return RW_OK;
}

#endif
