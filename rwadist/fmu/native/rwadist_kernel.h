/* The step kernel of the rwadist wheel FMU: WheelRuntime.step of rwadist/fmu/runtime.py in C (same equations,
 * same order of operations where it matters; tested against it and against
 * rwadist.extended.simulate_time).  Shared by the pythonfmu FMU's native layer (rwadist_fmu_native.c)
 * and the pure-C FMU (rwadist_wheel_fmu.c).  Memory layouts are defined in runtime.py (KernelLayout). */
#ifndef RWADIST_KERNEL_H
#define RWADIST_KERNEL_H
#include <complex.h>
#include <float.h>
#include <math.h>
#include <stddef.h>

#ifndef CMPLX /* C11; a C99 compiler gets the same value for finite parts */
#define CMPLX(x, y) ((double complex)((double)(x)) + _Complex_I * (double)(y))
#endif

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

/* (b + i·p)/(b + i·q) in real arithmetic (the complex division of C calls a slow, scaling
 * library routine; these values are moderate) */
static inline double complex rw_ratio(double b, double p, double q)
{
    const double den = b * b + q * q;
    return CMPLX((b * b + p * q) / den, (p * b - b * q) / den);
}

/* sin and cos of one argument together, inline: Cody-Waite reduction by π/2 in three parts and the
 * fdlibm kernels (__kernel_sin, __kernel_cos minimax polynomials on [-π/4, π/4]); within ~1 ulp of libm
 * for |x| < 2^19·π/2 (checked against libm: tests/test_fmu_native.py); larger |x| go to libm. */
static inline void rw_sincos(double x, double *s, double *c)
{
    const double ax = fabs(x);
    if (!(ax < 823550.0)) {                 /* 2^19·π/2: q·PIO2_1 stays exact; NaN/inf to libm as well */
        *s = sin(x);
        *c = cos(x);
        return;
    }
#if defined(FLT_EVAL_METHOD) && FLT_EVAL_METHOD == 0
    /* round to nearest (even) by the 1.5·2^52 shift: nearbyint's value, without its library call */
    const double q = (x * 6.36619772367581382433e-01 + 6755399441055744.0) - 6755399441055744.0;   /* 2/π */
#else /* extended-precision evaluation (x87) would break the shift */
    const double q = nearbyint(x * 6.36619772367581382433e-01);
#endif
    const double r = ((x - q * 1.57079632673412561417e+00) - q * 6.07710050630396597660e-11) -
                     q * 2.02226624871116645580e-21;
    const double z = r * r;
    const double sr = r + r * z * (-1.66666666666666324348e-01 + z * (8.33333333332248946124e-03 +
                      z * (-1.98412698298579493134e-04 + z * (2.75573137070700676789e-06 +
                      z * (-2.50507602534068634195e-08 + z * 1.58969099521155010221e-10)))));
    const double cr = 1.0 - 0.5 * z + z * z * (4.16666666666666019037e-02 + z * (-1.38888888888741095749e-03 +
                      z * (2.48015872894767294178e-05 + z * (-2.75573143513906633035e-07 +
                      z * (2.08757232129817482790e-09 + z * -1.13596475577881948265e-11)))));
    switch ((long)q & 3) {
    case 0: *s = sr; *c = cr; break;
    case 1: *s = cr; *c = -sr; break;
    case 2: *s = -sr; *c = -cr; break;
    default: *s = -cr; *c = sr; break;
    }
}

/* 1/z in real arithmetic (C's complex division calls a slow, scaling library routine; these values are
 * moderate: eigenvalues of the suspension modes and their differences) */
static inline double complex rw_cinv(double complex z)
{
    const double den = creal(z) * creal(z) + cimag(z) * cimag(z);
    return CMPLX(creal(z) / den, -cimag(z) / den);
}

/* e^z with rw_sincos (within ~1 ulp of cexp for the moderate λh of the suspension modes) */
static inline double complex rw_cexp(double complex z)
{
    double s, c;
    rw_sincos(cimag(z), &s, &c);
    const double e = exp(creal(z));
    return CMPLX(e * c, e * s);
}

/* principal square root in real arithmetic (csqrt's branch cut; without its scaling and hypot: the
 * discriminants of the suspension modes are moderate) */
static inline double complex rw_csqrt(double complex z)
{
    const double a = creal(z), b = cimag(z);
    if (a == 0.0 && b == 0.0)
        return CMPLX(0.0, b);
    const double t = sqrt(0.5 * (fabs(a) + sqrt(a * a + b * b)));
    return a >= 0 ? CMPLX(t, b / (2.0 * t)) : CMPLX(fabs(b) / (2.0 * t), copysign(t, b));
}

static void quad_roots(double m, double complex c, double k, double complex *l1, double complex *l2)
{
    double complex disc = rw_csqrt(c * c - 4.0 * m * k);
    double sgn = creal(conj(c) * disc) >= 0 ? 1.0 : -1.0;
    double complex q = -0.5 * (c + sgn * disc);
    *l1 = q / m;
    *l2 = k * rw_cinv(q);
}

static void rwadist_kernel_step_impl(const double *cfg, double *st, double *out, double omega, double wd0, double alpha,
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
    double complex lk[2] = {0, 0}, Xp[3][2], lamh[3][2];   /* per subsystem: e^{λh}, λh */
    if (modes) {
        const double w_mid = 0.5 * (omega + w1);
        quad_roots(cfg[C_IRR], CMPLX(cfg[C_CROCK], -cfg[C_IZZ] * w_mid), cfg[C_KROCK], &lk[0], &lk[1]);
        for (int j = 0; j < 2; j++) {
            Xp[0][j] = rw_cexp(lam_r[j] * h);
            Xp[1][j] = rw_cexp(lk[j] * h);
            Xp[2][j] = rw_cexp(lam_z[j] * h);
            lamh[0][j] = lam_r[j] * h;
            lamh[1][j] = lk[j] * h;
            lamh[2][j] = lam_z[j] * h;
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
                g0 *= rw_ratio(b0, rt[1] * r0, rt[2] * r0);
                g1 *= rw_ratio(b1, rt[1] * r1, rt[2] * r1);
            }
            a0 *= g0;
            a1 *= g1;
        }
        const double arg = sh * phi1 + woff * t1;
        double s_arg, c_arg;
        rw_sincos(arg, &s_arg, &c_arg);
        const double complex S1 = CMPLX(c_arg, s_arg);
        loads1[d] += a1 * S1;
        if (modes && d != 3) {
            const int sub = d == 0 ? 0 : (d == 2 ? 2 : 1);
            const double complex *X = Xp[sub];
            const double wz = sh * dphi + woff * h;
            for (int j = 0; j < 2; j++) {
                const double complex z = CMPLX(-creal(lamh[sub][j]), wz - cimag(lamh[sub][j]));
                const double complex XS0 = X[j] * S[i];
                double complex t0, t1;
                const double zz = creal(z) * creal(z) + cimag(z) * cimag(z);
                if (zz < SMALL_Z * SMALL_Z) {
                    t0 = XS0 * (1 + z * (1.0 / 2 + z * (1.0 / 6 + z * (1.0 / 24 + z / 120))));
                    t1 = XS0 * (1.0 / 2 + z * (1.0 / 3 + z * (1.0 / 8 + z * (1.0 / 30 + z / 144))));
                } else {
                    const double inv = 1.0 / zz;
                    const double complex iz = CMPLX(creal(z) * inv, -cimag(z) * inv);   /* 1/z */
                    t0 = (S1 - XS0) * iz;
                    t1 = (S1 - t0) * iz;
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
        const double complex ir = rw_cinv(m * (lam_r[0] - lam_r[1])), iz = rw_cinv(m * (lam_z[0] - lam_z[1]));
        eta_r[0] = Xp[0][0] * eta_r[0] + W[0][0] * ir;
        eta_r[1] = Xp[0][1] * eta_r[1] - W[0][1] * ir;
        eta_z[0] = Xp[2][0] * eta_z[0] + W[2][0] * iz;
        eta_z[1] = Xp[2][1] * eta_z[1] - W[2][1] * iz;
        const double complex dl = lk[0] - lk[1], idl = rw_cinv(dl), e1 = Xp[1][0], e2 = Xp[1][1];
        const double complex q = x_rock[0], qd = x_rock[1];
        const double kI = k_rock / I_rr;
        const double complex P00 = (e1 * (-lk[1]) - e2 * (-lk[0])) * idl, P01 = (e1 - e2) * idl;
        const double complex P10 = (-kI) * (e1 - e2) * idl, P11 = (e1 * lk[0] - e2 * lk[1]) * idl;
        const double complex w1r = W[1][0] * idl / I_rr, w2r = -W[1][1] * idl / I_rr;
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
#endif
