/* Sparse LDL^T with static pivots, its inertia, and refined solves.
 *
 * The up-looking algorithm of T. A. Davis's LDL package (ACM TOMS 31(4), 2005, Algorithm 849):
 * the elimination tree and the column counts of L from the pattern (sb_ldl_symbolic), then each
 * row of L by a sparse triangular solve along the tree, its pattern found once (sb_ldl_rows) and
 * its values at each factorisation (sb_ldl_factor). The matrix is given
 * permuted (a fill-reducing order chosen by the caller) as its upper triangle, diagonal included
 * and last in each column, in compressed sparse columns (rows sorted).
 *
 * sb_ldl_factor scales the matrix symmetrically by s_i = 1 / sqrt(max(1, |A_ii|)) (rows of a large
 * diagonal brought to the others' size) and factorises S A S = L D L^T without numerical pivoting:
 * a pivot smaller in magnitude than pivot_tol is replaced by pivot_tol times the sign its row
 * expects (sign[], +1 or -1), a static pivot as in PARDISO, counted in *perturbed. It returns the
 * number of negative pivots: the inertia of the matrix factorised (Sylvester's law of inertia), or
 * -1 where a pivot is not a number. With expected_negative >= 0 it stops as soon as the count of
 * negative or of positive pivots exceeds what that inertia allows, and returns n + 1 + the count so
 * far (the factors then incomplete): a wrong inertia costs part of a factorisation.
 *
 * sb_ldl_solve_refined solves A x = b with those factors and refines x against S A S (the matrix
 * without the static pivots) until the backward error |r|_inf / (|SAS|_inf |x|_inf + |b|_inf) of
 * the scaled system is at most tol, or max_steps refinements; it returns that error. sb_ldl_factor
 * leaves S A S (SAx, in A's pattern) and its infinity norm (*norm) for it.
 *
 * Written for slewbench (ocp.nlp.sparse_ldl); compiled at first use, loaded with ctypes.
 */
#include <math.h>

/* The factorisation's arrays, set once by the caller (ocp.nlp.sparse_ldl.SparseLDL): passing one
 * pointer spares ctypes converting twenty arguments at every call. */
typedef struct {
    int n, nnz;
    const int *Ap, *Ai, *Lp, *Rp, *Ri, *Li, *take, *order;
    int *Lnz;
    const double *sign;
    double *Ax, *SAx, *S, *Lx, *D, *Y, *B, *R, *X;
    double norm;
    int perturbed, steps;
} sb_ldl;

void sb_ldl_symbolic(int n, const int *Ap, const int *Ai, int *Lp, int *Parent, int *Lnz, int *Flag)
{
    int i, k, p;
    for (k = 0; k < n; k++) {
        Parent[k] = -1;
        Flag[k] = k;
        Lnz[k] = 0;
        for (p = Ap[k]; p < Ap[k + 1]; p++) {
            i = Ai[p];
            if (i < k) {
                for (; Flag[i] != k; i = Parent[i]) {
                    if (Parent[i] == -1) Parent[i] = k;
                    Lnz[i]++;
                    Flag[i] = k;
                }
            }
        }
    }
    Lp[0] = 0;
    for (k = 0; k < n; k++) Lp[k + 1] = Lp[k] + Lnz[k];
}

/* The row patterns of L once (the pattern does not depend on the values): for each row k, the
 * columns i < k with L[k, i] != 0 in the order the numeric factorisation visits them (Ri[Rp[k]..]),
 * and the row indices of L by columns (Li). Work: Lnz, Flag, Pattern of n. */
void sb_ldl_rows(int n, const int *Ap, const int *Ai, const int *Lp, const int *Parent, int *Lnz,
                 int *Flag, int *Pattern, int *Rp, int *Ri, int *Li)
{
    int i, k, p, len, top, q = 0;
    for (k = 0; k < n; k++) Lnz[k] = 0;
    for (k = 0; k < n; k++) {
        top = n;
        Flag[k] = k;
        for (p = Ap[k]; p < Ap[k + 1]; p++) {
            i = Ai[p];
            for (len = 0; Flag[i] != k; i = Parent[i]) {
                Pattern[len++] = i;
                Flag[i] = k;
            }
            while (len > 0) Pattern[--top] = Pattern[--len];
        }
        Rp[k] = q;
        for (; top < n; top++) {
            i = Pattern[top];
            Ri[q++] = i;
            Li[Lp[i] + Lnz[i]] = k;
            Lnz[i]++;
        }
    }
    Rp[n] = q;
}

int sb_ldl_factor(sb_ldl *st, const double *values, double pivot_tol, int expected_negative)
{
    const int n = st->n, *Ap = st->Ap, *Ai = st->Ai, *Lp = st->Lp, *Rp = st->Rp, *Ri = st->Ri, *Li = st->Li;
    int *Lnz = st->Lnz;
    double *Ax = st->Ax, *SAx = st->SAx, *S = st->S, *Lx = st->Lx, *D = st->D, *Y = st->Y;
    double yi, l_ki, a, norm = 0.0;
    int i, k, p, p2, q, negative = 0;
    st->perturbed = 0;
    for (p = 0; p < st->nnz; p++) Ax[p] = values[st->take[p]];  /* the caller's nonzeros, permuted */
    for (k = 0; k < n; k++) {
        a = fabs(Ax[Ap[k + 1] - 1]);  /* the diagonal, last in its column */
        S[k] = a > 1.0 ? 1.0 / sqrt(a) : 1.0;
        Y[k] = 0.0;  /* the absolute row sums of S A S, for its norm */
        Lnz[k] = 0;
    }
    for (k = 0; k < n; k++)
        for (p = Ap[k]; p < Ap[k + 1]; p++) {
            i = Ai[p];
            SAx[p] = S[i] * Ax[p] * S[k];
            Y[i] += fabs(SAx[p]);
            if (i != k) Y[k] += fabs(SAx[p]);
        }
    for (k = 0; k < n; k++) {
        if (Y[k] > norm) norm = Y[k];
        Y[k] = 0.0;
    }
    st->norm = norm;
    for (k = 0; k < n; k++) {
        for (p = Ap[k]; p < Ap[k + 1]; p++) Y[Ai[p]] += SAx[p];
        D[k] = Y[k];
        Y[k] = 0.0;
        for (q = Rp[k]; q < Rp[k + 1]; q++) {
            i = Ri[q];
            yi = Y[i];
            Y[i] = 0.0;
            p2 = Lp[i] + Lnz[i];
            for (p = Lp[i]; p < p2; p++) Y[Li[p]] -= Lx[p] * yi;
            l_ki = yi / D[i];
            D[k] -= l_ki * yi;
            Lx[p] = l_ki;
            Lnz[i]++;
        }
        if (D[k] != D[k]) return -1;
        if (!(fabs(D[k]) >= pivot_tol)) {
            D[k] = st->sign[k] * pivot_tol;
            st->perturbed++;
        }
        if (D[k] < 0.0) negative++;
        /* more negative (or positive) pivots than expected: the inertia is wrong whatever follows */
        if (expected_negative >= 0 && (negative > expected_negative || k + 1 - negative > n - expected_negative))
            return negative + n + 1;
    }
    return negative;
}

static void ldl_solve(int n, double *X, const int *Lp, const int *Li, const double *Lx, const double *D)
{
    int j, p;
    for (j = 0; j < n; j++)
        for (p = Lp[j]; p < Lp[j + 1]; p++) X[Li[p]] -= Lx[p] * X[j];
    for (j = 0; j < n; j++) X[j] /= D[j];
    for (j = n - 1; j >= 0; j--)
        for (p = Lp[j]; p < Lp[j + 1]; p++) X[j] -= Lx[p] * X[Li[p]];
}

/* R = B - M X for the symmetric M from its upper triangle (SAx). */
static void residual(int n, const int *Ap, const int *Ai, const double *SAx, const double *X,
                     const double *B, double *R)
{
    int j, p, i;
    double a, xj, rj;
    for (i = 0; i < n; i++) R[i] = B[i];
    for (j = 0; j < n; j++) {
        xj = X[j];
        rj = 0.0;
        for (p = Ap[j]; p < Ap[j + 1] - 1; p++) {  /* above the diagonal */
            i = Ai[p];
            a = SAx[p];
            R[i] -= a * xj;
            rj += a * X[i];
        }
        R[j] -= rj + SAx[Ap[j + 1] - 1] * xj;  /* the diagonal, last in its column */
    }
}

static double infinity_norm(int n, const double *X)
{
    double m = 0.0;
    int i;
    for (i = 0; i < n; i++) {
        if (X[i] != X[i]) return X[i];
        if (fabs(X[i]) > m) m = fabs(X[i]);
    }
    return m;
}

/* solution = A^-1 rhs (both in the caller's order; order[i] the caller's index of row i). Work: B, R, X of n. */
double sb_ldl_solve_refined(sb_ldl *st, const double *rhs, double *solution, double tol, int max_steps)
{
    const int n = st->n, *order = st->order;
    const double *S = st->S;
    double *B = st->B, *R = st->R, *X = st->X;
    int i, k;
    double error, scale_b;
    for (i = 0; i < n; i++) { B[i] = S[i] * rhs[order[i]]; X[i] = B[i]; }
    ldl_solve(n, X, st->Lp, st->Li, st->Lx, st->D);
    scale_b = infinity_norm(n, B);
    st->steps = 0;
    for (k = 0;; k++) {
        residual(n, st->Ap, st->Ai, st->SAx, X, B, R);
        error = infinity_norm(n, R);  /* relative to |K||x| + |b|, where that is not zero (a zero b, a zero x) */
        if (st->norm * infinity_norm(n, X) + scale_b > 0.0) error /= st->norm * infinity_norm(n, X) + scale_b;
        if (!(error > tol) || k == max_steps) break;  /* (a NaN error is not refined) */
        ldl_solve(n, R, st->Lp, st->Li, st->Lx, st->D);
        for (i = 0; i < n; i++) X[i] += R[i];
        st->steps++;
    }
    for (i = 0; i < n; i++) solution[order[i]] = S[i] * X[i];
    return error;
}
