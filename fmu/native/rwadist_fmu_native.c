/* Native layer of the rwadist wheel FMU (Linux): an FMI 2.0 status adapter in front of
 * pythonfmu's library, and the step kernel of fmu/runtime.py in C.
 *
 * Why: pythonfmu 0.7 reports a do_step that returns False as fmi2Discard and any Python
 * exception as fmi2Fatal; the FMI way to refuse bad input is fmi2Error.  The Python slave calls
 * rwadist_fmu_flag_error() (through ctypes, on the calling thread) when it refuses an input; the
 * adapter then returns fmi2Error from the FMI call in progress.  Every fmi2 function is forwarded
 * to pythonfmu's library, shipped beside this one as <modelIdentifier>_pythonfmu.so.
 *
 * rwadist_kernel_step() is WheelRuntime.step of fmu/runtime.py (same equations, same order of
 * operations where it matters; tested against it and against rwadist.extended.simulate_time).
 * Memory layouts are defined in runtime.py (KernelLayout). */
#define _GNU_SOURCE
#include <complex.h>
#include <dlfcn.h>
#include <math.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
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

EXPORT const char *fmi2GetTypesPlatform(void) { return "default"; }
EXPORT const char *fmi2GetVersion(void) { return "2.0"; }

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
    error_flag = 0;
    return fn(instanceName, fmuType, guid, resourceLocation, functions, visible, loggingOn);
}

EXPORT void fmi2FreeInstance(fmi2Component c)
{
    static void (*fn)(fmi2Component);
    if (!fn)
        fn = (void (*)(fmi2Component))sym("fmi2FreeInstance");
    if (fn)
        fn(c);
}

FORWARD(fmi2Status, fmi2SetDebugLogging, (fmi2Component c, fmi2Boolean on, size_t n, const fmi2String cat[]),
        (c, on, n, cat), fmi2Error, adapt)
FORWARD(fmi2Status, fmi2SetupExperiment,
        (fmi2Component c, fmi2Boolean tolDef, fmi2Real tol, fmi2Real t0, fmi2Boolean stopDef, fmi2Real stop),
        (c, tolDef, tol, t0, stopDef, stop), fmi2Error, adapt)
FORWARD(fmi2Status, fmi2EnterInitializationMode, (fmi2Component c), (c), fmi2Error, adapt)
FORWARD(fmi2Status, fmi2ExitInitializationMode, (fmi2Component c), (c), fmi2Error, adapt)
FORWARD(fmi2Status, fmi2Terminate, (fmi2Component c), (c), fmi2Error, adapt)
FORWARD(fmi2Status, fmi2Reset, (fmi2Component c), (c), fmi2Error, adapt)
FORWARD(fmi2Status, fmi2GetReal, (fmi2Component c, const fmi2ValueReference vr[], size_t n, fmi2Real v[]),
        (c, vr, n, v), fmi2Error, adapt)
FORWARD(fmi2Status, fmi2GetInteger, (fmi2Component c, const fmi2ValueReference vr[], size_t n, fmi2Integer v[]),
        (c, vr, n, v), fmi2Error, adapt)
FORWARD(fmi2Status, fmi2GetBoolean, (fmi2Component c, const fmi2ValueReference vr[], size_t n, fmi2Boolean v[]),
        (c, vr, n, v), fmi2Error, adapt)
FORWARD(fmi2Status, fmi2GetString, (fmi2Component c, const fmi2ValueReference vr[], size_t n, fmi2String v[]),
        (c, vr, n, v), fmi2Error, adapt)
FORWARD(fmi2Status, fmi2SetReal, (fmi2Component c, const fmi2ValueReference vr[], size_t n, const fmi2Real v[]),
        (c, vr, n, v), fmi2Error, adapt)
FORWARD(fmi2Status, fmi2SetInteger,
        (fmi2Component c, const fmi2ValueReference vr[], size_t n, const fmi2Integer v[]), (c, vr, n, v), fmi2Error,
        adapt)
FORWARD(fmi2Status, fmi2SetBoolean,
        (fmi2Component c, const fmi2ValueReference vr[], size_t n, const fmi2Boolean v[]), (c, vr, n, v), fmi2Error,
        adapt)
FORWARD(fmi2Status, fmi2SetString, (fmi2Component c, const fmi2ValueReference vr[], size_t n, const fmi2String v[]),
        (c, vr, n, v), fmi2Error, adapt)
FORWARD(fmi2Status, fmi2GetFMUstate, (fmi2Component c, fmi2FMUstate *s), (c, s), fmi2Error, adapt)
FORWARD(fmi2Status, fmi2SetFMUstate, (fmi2Component c, fmi2FMUstate s), (c, s), fmi2Error, adapt)
FORWARD(fmi2Status, fmi2FreeFMUstate, (fmi2Component c, fmi2FMUstate *s), (c, s), fmi2Error, adapt)
FORWARD(fmi2Status, fmi2SerializedFMUstateSize, (fmi2Component c, fmi2FMUstate s, size_t *n), (c, s, n), fmi2Error,
        adapt)
FORWARD(fmi2Status, fmi2SerializeFMUstate, (fmi2Component c, fmi2FMUstate s, fmi2Byte b[], size_t n),
        (c, s, b, n), fmi2Error, adapt)
FORWARD(fmi2Status, fmi2DeSerializeFMUstate, (fmi2Component c, const fmi2Byte b[], size_t n, fmi2FMUstate *s),
        (c, b, n, s), fmi2Error, adapt)
FORWARD(fmi2Status, fmi2GetDirectionalDerivative,
        (fmi2Component c, const fmi2ValueReference u[], size_t nu, const fmi2ValueReference z[], size_t nz,
         const fmi2Real dv[], fmi2Real dz[]),
        (c, u, nu, z, nz, dv, dz), fmi2Error, adapt)
FORWARD(fmi2Status, fmi2SetRealInputDerivatives,
        (fmi2Component c, const fmi2ValueReference vr[], size_t n, const fmi2Integer order[], const fmi2Real v[]),
        (c, vr, n, order, v), fmi2Error, adapt)
FORWARD(fmi2Status, fmi2GetRealOutputDerivatives,
        (fmi2Component c, const fmi2ValueReference vr[], size_t n, const fmi2Integer order[], fmi2Real v[]),
        (c, vr, n, order, v), fmi2Error, adapt)
/* a refused step: the slave flags it and returns False, which pythonfmu reports as Discard */
FORWARD(fmi2Status, fmi2DoStep, (fmi2Component c, fmi2Real t, fmi2Real h, fmi2Boolean noPrior), (c, t, h, noPrior),
        fmi2Error, adapt)
FORWARD(fmi2Status, fmi2CancelStep, (fmi2Component c), (c), fmi2Error, adapt)
FORWARD(fmi2Status, fmi2GetStatus, (fmi2Component c, const fmi2StatusKind k, fmi2Status *v), (c, k, v), fmi2Error,
        adapt)
FORWARD(fmi2Status, fmi2GetRealStatus, (fmi2Component c, const fmi2StatusKind k, fmi2Real *v), (c, k, v), fmi2Error,
        adapt)
FORWARD(fmi2Status, fmi2GetIntegerStatus, (fmi2Component c, const fmi2StatusKind k, fmi2Integer *v), (c, k, v),
        fmi2Error, adapt)
FORWARD(fmi2Status, fmi2GetBooleanStatus, (fmi2Component c, const fmi2StatusKind k, fmi2Boolean *v), (c, k, v),
        fmi2Error, adapt)
FORWARD(fmi2Status, fmi2GetStringStatus, (fmi2Component c, const fmi2StatusKind k, fmi2String *v), (c, k, v),
        fmi2Error, adapt)

/* ------------------------------------------------------------------ step kernel
 * cfg (read only): [0] n components, [1] modes on, [2..11] mass, c_r, k_r, I_rr, c_rock, k_rock, I_zz,
 * c_z, k_z, height, [12..15] λ_r (2 complex), [16..19] λ_z, [20..28] R (row major), [29..31] r,
 * then per component 13 doubles: σh, direction index, coef·C (complex), −i·coef·C·[imbalance] (complex),
 * coef·A_ref (complex, 0 without an amplitude law), Ω_ref, p: amplitude += coef·A_ref·(|Ω|/Ω_ref)^p,
 * ω_off (rad/s, a sideband's fixed phase rate), number of wheel-mode resonances, cfg index of their
 * entries; then the resonance table, 3 doubles per entry: 2π f_r, 2·g·ζ, 2·ζ.  The amplitude is
 * multiplied by H = (1 − r² + 2j·g·ζ·r)/(1 − r² + 2j·ζ·r), r = (σhΩ + ω_off)/(2π f_r), of each
 * resonance at both step ends (quasi-static).
 * st (state): [0] rotor angle φ, [1] time since t0, then S = e^{i(σhφ + ω_off t)} (n complex), η_r (2),
 * η_z (2), x_rock = (q, q̇) (2), complex.  out: 12 outputs (wheel frame, spacecraft frame). */
enum { C_N, C_MODES, C_M, C_CR, C_KR, C_IRR, C_CROCK, C_KROCK, C_IZZ, C_CZ, C_KZ, C_HEIGHT, C_LAMR = 12,
       C_LAMZ = 16, C_R = 20, C_POS = 29, C_COMP = 32, C_STRIDE = 13, C_RES = 3 };
#define SMALL_Z 1e-3

static void quad_roots(double m, double complex c, double k, double complex *l1, double complex *l2)
{
    double complex disc = csqrt(c * c - 4.0 * m * k);
    double sgn = creal(conj(c) * disc) >= 0 ? 1.0 : -1.0;
    double complex q = -0.5 * (c + sgn * disc);
    *l1 = q / m;
    *l2 = k / q;
}

EXPORT void rwadist_kernel_step(const double *cfg, double *st, double *out, double omega, double wd0, double alpha,
                                double h)
{
    const int n = (int)cfg[C_N];
    double complex *S = (double complex *)(st + 2);
    double complex *eta_r = S + n, *eta_z = S + n + 2, *x_rock = S + n + 4;
    const double complex lam_r[2] = {CMPLX(cfg[C_LAMR], cfg[C_LAMR + 1]), CMPLX(cfg[C_LAMR + 2], cfg[C_LAMR + 3])};
    const double complex lam_z[2] = {CMPLX(cfg[C_LAMZ], cfg[C_LAMZ + 1]), CMPLX(cfg[C_LAMZ + 2], cfg[C_LAMZ + 3])};
    const double w1 = omega + alpha * h;
    const double dphi = 0.5 * (omega + w1) * h;
    const double phi1 = st[0] + dphi;
    const double t1 = st[1] + h;
    const int modes = cfg[C_MODES] != 0.0;
    double complex loads1[4] = {0, 0, 0, 0};
    double complex W[4][2] = {{0, 0}, {0, 0}, {0, 0}, {0, 0}};
    double complex lk[2] = {0, 0}, Xp[3][2];
    if (modes) {
        const double w_mid = 0.5 * (omega + w1);
        quad_roots(cfg[C_IRR], CMPLX(cfg[C_CROCK], -cfg[C_IZZ] * w_mid), cfg[C_KROCK], &lk[0], &lk[1]);
        for (int j = 0; j < 2; j++) {
            Xp[0][j] = cexp(lam_r[j] * h);
            Xp[1][j] = cexp(lk[j] * h);
            Xp[2][j] = cexp(lam_z[j] * h);
        }
    }
    for (int i = 0; i < n; i++) {
        const double *c = cfg + C_COMP + C_STRIDE * i;
        const double sh = c[0];
        const int d = (int)c[1];
        const double complex cC = CMPLX(c[2], c[3]), cCi = CMPLX(c[4], c[5]);
        double complex a0 = cC * (omega * omega) + cCi * wd0;
        double complex a1 = cC * (w1 * w1) + cCi * alpha;
        if (c[6] != 0.0 || c[7] != 0.0) {
            const double complex ls = CMPLX(c[6], c[7]);
            a0 += ls * pow(fabs(omega) / c[8], c[9]);
            a1 += ls * pow(fabs(w1) / c[8], c[9]);
        }
        const double woff = c[10];
        const int nres = (int)c[11];
        if (nres > 0) {
            const double *rt = cfg + (size_t)c[12];
            double complex g0 = 1.0, g1 = 1.0;
            for (int k = 0; k < nres; k++, rt += C_RES) {
                const double r0 = (sh * omega + woff) / rt[0], r1 = (sh * w1 + woff) / rt[0];
                const double b0 = 1.0 - r0 * r0, b1 = 1.0 - r1 * r1;
                g0 *= CMPLX(b0, rt[1] * r0) / CMPLX(b0, rt[2] * r0);
                g1 *= CMPLX(b1, rt[1] * r1) / CMPLX(b1, rt[2] * r1);
            }
            a0 *= g0;
            a1 *= g1;
        }
        const double complex S1 = cexp(CMPLX(0.0, sh * phi1 + woff * t1));
        loads1[d] += a1 * S1;
        if (modes && d != 3) {
            const double complex *lam = d == 0 ? lam_r : (d == 2 ? lam_z : lk);
            const double complex *X = Xp[d == 0 ? 0 : (d == 2 ? 2 : 1)];
            for (int j = 0; j < 2; j++) {
                const double complex z = CMPLX(0.0, sh * dphi + woff * h) - lam[j] * h;
                const double complex XS0 = X[j] * S[i];
                double complex t0, t1;
                if (cabs(z) < SMALL_Z) {
                    t0 = XS0 * (1 + z * (1.0 / 2 + z * (1.0 / 6 + z * (1.0 / 24 + z / 120))));
                    t1 = XS0 * (1.0 / 2 + z * (1.0 / 3 + z * (1.0 / 8 + z * (1.0 / 30 + z / 144))));
                } else {
                    t0 = (S1 - XS0) / z;
                    t1 = (S1 - t0) / z;
                }
                W[d][j] += a0 * t0 + (a1 - a0) * t1;
            }
        }
        S[i] = S1;
    }
    const double m = cfg[C_M], c_r = cfg[C_CR], k_r = cfg[C_KR], I_rr = cfg[C_IRR], c_rock = cfg[C_CROCK],
                 k_rock = cfg[C_KROCK], c_z = cfg[C_CZ], k_z = cfg[C_KZ];
    double complex F, Tc;
    double Fz;
    if (modes) {
        for (int d = 0; d < 3; d++)
            for (int j = 0; j < 2; j++)
                W[d][j] *= h;
        eta_r[0] = Xp[0][0] * eta_r[0] + W[0][0] / (m * (lam_r[0] - lam_r[1]));
        eta_r[1] = Xp[0][1] * eta_r[1] + W[0][1] / (m * (lam_r[1] - lam_r[0]));
        eta_z[0] = Xp[2][0] * eta_z[0] + W[2][0] / (m * (lam_z[0] - lam_z[1]));
        eta_z[1] = Xp[2][1] * eta_z[1] + W[2][1] / (m * (lam_z[1] - lam_z[0]));
        const double complex dl = lk[0] - lk[1], e1 = Xp[1][0], e2 = Xp[1][1];
        const double complex q = x_rock[0], qd = x_rock[1];
        const double kI = k_rock / I_rr;
        const double complex P00 = (e1 * (-lk[1]) - e2 * (-lk[0])) / dl, P01 = (e1 - e2) / dl;
        const double complex P10 = (-kI) * (e1 - e2) / dl, P11 = (e1 * lk[0] - e2 * lk[1]) / dl;
        const double complex w1r = W[1][0] / (I_rr * dl), w2r = W[1][1] / (-I_rr * dl);
        x_rock[0] = P00 * q + P01 * qd + w1r + w2r;
        x_rock[1] = P10 * q + P11 * qd + lk[0] * w1r + lk[1] * w2r;
        const double complex qr = eta_r[0] + eta_r[1], qdr = lam_r[0] * eta_r[0] + lam_r[1] * eta_r[1];
        F = k_r * qr + c_r * qdr;
        const double complex qz = eta_z[0] + eta_z[1], qdz = lam_z[0] * eta_z[0] + lam_z[1] * eta_z[1];
        Fz = creal(k_z * qz + c_z * qdz);
        Tc = k_rock * x_rock[0] + c_rock * x_rock[1];
    } else {
        F = loads1[0];
        Fz = creal(loads1[2]);
        Tc = loads1[1];
    }
    st[0] = phi1;
    st[1] = t1;
    const double complex Tint = Tc + I * cfg[C_HEIGHT] * F;
    const double o[6] = {creal(F), cimag(F), Fz, creal(Tint), cimag(Tint), creal(loads1[3])};
    const double *R = cfg + C_R, *r = cfg + C_POS;
    for (int k = 0; k < 6; k++)
        out[k] = o[k];
    for (int a = 0; a < 3; a++) {
        out[6 + a] = R[3 * a] * o[0] + R[3 * a + 1] * o[1] + R[3 * a + 2] * o[2];
        out[9 + a] = R[3 * a] * o[3] + R[3 * a + 1] * o[4] + R[3 * a + 2] * o[5];
    }
    /* T_sc += r × F_sc */
    out[9] += r[1] * out[8] - r[2] * out[7];
    out[10] += r[2] * out[6] - r[0] * out[8];
    out[11] += r[0] * out[7] - r[1] * out[6];
}
