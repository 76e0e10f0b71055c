/* The interior point's vector steps over the bounded entries of x (slewbench, ocp.nlp.interior_point).
 *
 * The bounded entries are one vector of nb: entry k bounds x[index[k]] from below (side[k] = +1,
 * s_k = x[index[k]] - bound[k]) or from above (side[k] = -1, s_k = bound[k] - x[index[k]]), with
 * multiplier z_k > 0. These loops replace a dozen NumPy calls an iteration (each one's fixed cost
 * is the vector's). Compiled at first use (ocp.native.load_library), loaded with ctypes.
 */
#include <math.h>

/* s = side (x[index] - bound); returns min s (+inf without bounds) and, where every s > 0,
 * *log_sum = sum log s. */
double sb_ip_slacks(int nb, const int *index, const double *side, const double *bound, const double *x,
                    double *s, double *log_sum)
{
    int k;
    double least = INFINITY, total = 0.0;
    for (k = 0; k < nb; k++) {
        s[k] = side[k] * (x[index[k]] - bound[k]);
        if (!(s[k] >= least)) least = s[k];  /* (a NaN is the least) */
    }
    if (least > 0.0)
        for (k = 0; k < nb; k++) total += log(s[k]);
    *log_sum = total;
    return least;
}

/* At (s, z): sigma = P (z / s) and barrier = P (side / s) (n, P scattering entry k to index[k]);
 * out[0] = |gradient_lag - P (side z)|_inf (the dual infeasibility), out[1] = max s z,
 * out[2] = sum z. */
void sb_ip_barrier(int n, int nb, const int *index, const double *side, const double *s, const double *z,
                   const double *gradient_lag, double *sigma, double *barrier, double *work, double *out)
{
    int i, k;
    double dual = 0.0, comp = 0.0, total = 0.0, a;
    for (i = 0; i < n; i++) { sigma[i] = 0.0; barrier[i] = 0.0; work[i] = gradient_lag[i]; }
    for (k = 0; k < nb; k++) {
        i = index[k];
        sigma[i] += z[k] / s[k];
        barrier[i] += side[k] / s[k];
        work[i] -= side[k] * z[k];
        a = s[k] * z[k];
        if (a > comp) comp = a;
        total += z[k];
    }
    for (i = 0; i < n; i++) {
        a = fabs(work[i]);
        if (!(a <= dual)) dual = a;  /* (a NaN propagates) */
    }
    out[0] = dual; out[1] = comp; out[2] = total;
}

/* max |s z - mu| (the complementarity of the barrier problem). */
double sb_ip_complementarity(int nb, const double *s, const double *z, double mu)
{
    int k;
    double worst = 0.0, a;
    for (k = 0; k < nb; k++) {
        a = fabs(s[k] * z[k] - mu);
        if (a > worst) worst = a;
    }
    return worst;
}

/* The step's consequences: dz = mu / s - z - z ds / s (ds = side dx[index]); out[0] the largest
 * alpha <= 1 with s + alpha ds >= (1 - tau) s, out[1] the same for z and dz, out[2] =
 * max_i |dx_i| / (1 + |x_i|) (IPOPT's tiny-step measure). */
void sb_ip_step(int n, int nb, const int *index, const double *side, const double *s, const double *z,
                const double *dx, const double *x, double mu, double tau, double *dz, double *out)
{
    int i, k;
    double ratio, fastest = 0.0, fastest_z = 0.0, relative = 0.0, a;
    for (k = 0; k < nb; k++) {
        ratio = side[k] * dx[index[k]] / s[k];
        dz[k] = mu / s[k] - z[k] - z[k] * ratio;
        if (-ratio > fastest) fastest = -ratio;
        a = -dz[k] / z[k];
        if (a > fastest_z) fastest_z = a;
    }
    for (i = 0; i < n; i++) {
        a = fabs(dx[i]) / (1.0 + fabs(x[i]));
        if (!(a <= relative)) relative = a;
    }
    out[0] = fastest <= tau ? 1.0 : tau / fastest;
    out[1] = fastest_z <= tau ? 1.0 : tau / fastest_z;
    out[2] = relative;
}

/* z = min(max(z + alpha_z dz, mu / (kappa s)), kappa mu / s): the step, then IPOPT's safeguard. */
void sb_ip_update(int nb, double *z, const double *dz, double alpha_z, double mu, const double *s, double kappa)
{
    int k;
    double v, low, high;
    for (k = 0; k < nb; k++) {
        v = z[k] + alpha_z * dz[k];
        low = mu / (kappa * s[k]);
        high = kappa * mu / s[k];
        z[k] = v < low ? low : (v > high ? high : v);
    }
}
