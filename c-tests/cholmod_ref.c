/* Independent reference check of fricont against CHOLMOD.
 *
 * Reads a problem in the exchange format itself, factors A with CHOLMOD, forms
 * W = B A^-1 B^T and q(alpha) = B A^-1 f(alpha) itself, then traces the path with fricont
 * (only through include/fricont.h) and checks, at the start point, at every event, at the
 * ends and middle of every traced piece and at alpha sampled along the window:
 *  - lambda = (lambda_n, lambda_t) equals the solution of the piece equations (SPEC §3) of
 *    the reported classes, solved here by dense LU with W and q: 1e-10 relative;
 *  - u equals A^-1 (f + B^T lambda) solved here by CHOLMOD: 1e-10 relative;
 *  - every node's class satisfies its equations and guards (within 1e-9 of the scale);
 *  - at an event, lambda also solves the equations of the piece before (the transition
 *    point lies on both pieces: this pins alpha down);
 *  - ||H(u, lambda, alpha)||_inf <= 1e-12 relative, H computed here from A, N, T, f, g, F, r.
 * Because each piece is a straight segment for an affine load and its guards are affine
 * in alpha, guards that hold at both ends of every piece hold along the whole path: no
 * transition was skipped.
 *
 * With --via condensed, fricont gets only the W and q formed here by CHOLMOD
 * (fricont_problem_new_condensed): states have no u, and the u and H checks are skipped
 * (lambda is still checked against the piece equations solved here). With --via solve,
 * fricont gets N, T and a solve callback that applies A^-1 with CHOLMOD's factor
 * (fricont_problem_new_solve, blocks of at most 16 columns): every check applies.
 *
 * usage: cholmod_ref DIR [--base 0|1] [--storage full|lower|upper] [--F value] [--r value]
 *                        [--events FILE] [--via ann|condensed|solve] [--threads N]
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include <cholmod.h>

#include "common.h"

#define REL_TOL 1e-10
#define GUARD_TOL 1e-9
#define H_TOL 1e-12

typedef struct {
    case_data c;
    int64_t n, p, m; /* m = 2p */
    cholmod_common cm;
    cholmod_factor *L;
    csr a;     /* full A, 0-based */
    csr b;     /* B = [N; T], 0-based */
    double *w; /* m x m, row-major */
    double *q0, *q1;
    double *g; /* (gap, 0): m values */
    double rs; /* 2p / trace W: force per length */
    double r;  /* the library's r */
} ref_t;

static double inf_norm(const double *x, int64_t n) {
    double s = 0;
    for (int64_t i = 0; i < n; i++) s = fmax(s, fabs(x[i]));
    return s;
}

/* x := A^-1 x with CHOLMOD (n values). */
static void chol_solve(ref_t *R, double *x) {
    cholmod_dense *rhs = cholmod_allocate_dense((size_t)R->n, 1, (size_t)R->n, CHOLMOD_REAL, &R->cm);
    memcpy(rhs->x, x, sizeof(double) * (size_t)R->n);
    cholmod_dense *sol = cholmod_solve(CHOLMOD_A, R->L, rhs, &R->cm);
    memcpy(x, sol->x, sizeof(double) * (size_t)R->n);
    cholmod_free_dense(&sol, &R->cm);
    cholmod_free_dense(&rhs, &R->cm);
}

/* The host's solve given to fricont_problem_new_solve: a block of columns by CHOLMOD. */
static int chol_block(void *user, int64_t n, int64_t ncols, double *x, int64_t ldx) {
    ref_t *R = user;
    if (n != R->n || ncols < 1 || ncols > 16 || ldx < n) return -1;
    cholmod_dense *rhs = cholmod_allocate_dense((size_t)n, (size_t)ncols, (size_t)n, CHOLMOD_REAL, &R->cm);
    if (!rhs) return -2;
    double *rx = rhs->x;
    for (int64_t j = 0; j < ncols; j++) memcpy(rx + j * n, x + j * ldx, sizeof(double) * (size_t)n);
    cholmod_dense *sol = cholmod_solve(CHOLMOD_A, R->L, rhs, &R->cm);
    cholmod_free_dense(&rhs, &R->cm);
    if (!sol) return -3;
    double *sx = sol->x;
    for (int64_t j = 0; j < ncols; j++) memcpy(x + j * ldx, sx + j * n, sizeof(double) * (size_t)n);
    cholmod_free_dense(&sol, &R->cm);
    return 0;
}

static void csr_mul(const csr *m, const double *x, double *y) {
    for (int64_t i = 0; i < m->nrows; i++) {
        double s = 0;
        for (int64_t k = m->row_ptr[i]; k < m->row_ptr[i + 1]; k++) s += m->values[k] * x[m->col_idx[k]];
        y[i] = s;
    }
}

static int setup(ref_t *R) {
    case_data *c = &R->c;
    R->n = c->n;
    R->p = c->p;
    R->m = 2 * c->p;
    int64_t n = R->n, m = R->m, p = R->p;
    cholmod_start(&R->cm);
    /* A, lower triangle, symmetric (stype -1) */
    cholmod_triplet *t = cholmod_allocate_triplet((size_t)n, (size_t)n, (size_t)c->a.nnz, -1, CHOLMOD_REAL, &R->cm);
    int *ti = t->i, *tj = t->j;
    double *tx = t->x;
    size_t k = 0;
    for (int64_t e = 0; e < c->a.nnz; e++) {
        int64_t i = c->a.row[e], j = c->a.col[e];
        if (!c->a.symmetric && i < j) continue; /* general file: the lower triangle suffices */
        if (i < j) { int64_t s = i; i = j; j = s; }
        ti[k] = (int)i;
        tj[k] = (int)j;
        tx[k] = c->a.val[e];
        k++;
    }
    t->nnz = k;
    cholmod_sparse *as = cholmod_triplet_to_sparse(t, k, &R->cm);
    cholmod_free_triplet(&t, &R->cm);
    R->L = cholmod_analyze(as, &R->cm);
    cholmod_factorize(as, R->L, &R->cm);
    cholmod_free_sparse(&as, &R->cm);
    if (R->cm.status != CHOLMOD_OK || R->L->minor != (size_t)n) {
        fprintf(stderr, "CHOLMOD: A is not positive definite\n");
        return -1;
    }
    R->a = csr_from_triplets(&c->a, PART_FULL, 0);
    /* B = [N; T] */
    triplets bt;
    bt.nrows = m;
    bt.ncols = n;
    bt.nnz = c->nm.nnz + c->tm.nnz;
    bt.symmetric = 0;
    bt.row = malloc(sizeof(int64_t) * (size_t)bt.nnz);
    bt.col = malloc(sizeof(int64_t) * (size_t)bt.nnz);
    bt.val = malloc(sizeof(double) * (size_t)bt.nnz);
    for (int64_t e = 0; e < c->nm.nnz; e++) {
        bt.row[e] = c->nm.row[e];
        bt.col[e] = c->nm.col[e];
        bt.val[e] = c->nm.val[e];
    }
    for (int64_t e = 0; e < c->tm.nnz; e++) {
        bt.row[c->nm.nnz + e] = p + c->tm.row[e];
        bt.col[c->nm.nnz + e] = c->tm.col[e];
        bt.val[c->nm.nnz + e] = c->tm.val[e];
    }
    R->b = csr_from_triplets(&bt, PART_FULL, 0);
    free(bt.row);
    free(bt.col);
    free(bt.val);
    /* X = A^-1 B^T (n x m), W = B X */
    cholmod_dense *rhs = cholmod_zeros((size_t)n, (size_t)m, CHOLMOD_REAL, &R->cm);
    double *rx = rhs->x;
    for (int64_t i = 0; i < m; i++)
        for (int64_t e = R->b.row_ptr[i]; e < R->b.row_ptr[i + 1]; e++)
            rx[i * n + R->b.col_idx[e]] = R->b.values[e];
    cholmod_dense *x = cholmod_solve(CHOLMOD_A, R->L, rhs, &R->cm);
    R->w = malloc(sizeof(double) * (size_t)(m * m));
    double *xx = x->x;
    for (int64_t l = 0; l < m; l++) {
        double *col = malloc(sizeof(double) * (size_t)m);
        csr_mul(&R->b, xx + l * n, col);
        for (int64_t i = 0; i < m; i++) R->w[i * m + l] = col[i];
        free(col);
    }
    cholmod_free_dense(&x, &R->cm);
    cholmod_free_dense(&rhs, &R->cm);
    double tr = 0;
    for (int64_t i = 0; i < m; i++) tr += R->w[i * m + i];
    R->rs = (double)m / tr;
    R->q0 = malloc(sizeof(double) * (size_t)m);
    R->q1 = malloc(sizeof(double) * (size_t)m);
    double *tmp = malloc(sizeof(double) * (size_t)n);
    memcpy(tmp, c->f0, sizeof(double) * (size_t)n);
    chol_solve(R, tmp);
    csr_mul(&R->b, tmp, R->q0);
    memcpy(tmp, c->f1, sizeof(double) * (size_t)n);
    chol_solve(R, tmp);
    csr_mul(&R->b, tmp, R->q1);
    free(tmp);
    R->g = calloc((size_t)m, sizeof(double));
    if (c->gap)
        for (int64_t i = 0; i < p; i++) R->g[i] = c->gap[i];
    return 0;
}

static void teardown(ref_t *R) {
    cholmod_free_factor(&R->L, &R->cm);
    cholmod_finish(&R->cm);
    free_csr(&R->a);
    free_csr(&R->b);
    free(R->w);
    free(R->q0);
    free(R->q1);
    free(R->g);
}

/* d0(alpha) = q(alpha) - (g, 0): d = d0 + W lambda. */
static void d0_at(const ref_t *R, double alpha, double *d0) {
    for (int64_t i = 0; i < R->m; i++) d0[i] = R->q0[i] + alpha * R->q1[i] - R->g[i];
}

/* Solves the piece equations of `cls` at alpha by LU with partial pivoting. Returns 0, or
 * 1 when the system is (numerically) singular: a vertical piece. */
static int piece_solve(const ref_t *R, const int32_t *cls, double alpha, double *lam) {
    int64_t m = R->m, p = R->p;
    double *M = calloc((size_t)(m * m), sizeof(double));
    double *rhs = calloc((size_t)m, sizeof(double));
    double *d0 = malloc(sizeof(double) * (size_t)m);
    d0_at(R, alpha, d0);
    for (int64_t i = 0; i < p; i++) {
        double F = R->c.friction[i];
        int64_t rn = i, rt = p + i;
        if (cls[i] == FRICONT_OPEN) {
            M[rn * m + i] = 1;
            M[rt * m + p + i] = 1;
            continue;
        }
        for (int64_t l = 0; l < m; l++) M[rn * m + l] = R->rs * R->w[i * m + l];
        rhs[rn] = -R->rs * d0[i];
        if (cls[i] == FRICONT_STICK) {
            for (int64_t l = 0; l < m; l++) M[rt * m + l] = R->rs * R->w[(p + i) * m + l];
            rhs[rt] = -R->rs * d0[p + i];
        } else {
            double s = cls[i] == FRICONT_SLIP_PLUS ? 1.0 : -1.0;
            M[rt * m + p + i] = 1;
            M[rt * m + i] = -s * F;
        }
    }
    double maxpiv = 0, minpiv = INFINITY;
    for (int64_t k = 0; k < m; k++) {
        int64_t piv = k;
        for (int64_t i = k + 1; i < m; i++)
            if (fabs(M[i * m + k]) > fabs(M[piv * m + k])) piv = i;
        if (piv != k) {
            for (int64_t l = 0; l < m; l++) {
                double s = M[k * m + l];
                M[k * m + l] = M[piv * m + l];
                M[piv * m + l] = s;
            }
            double s = rhs[k];
            rhs[k] = rhs[piv];
            rhs[piv] = s;
        }
        double d = M[k * m + k];
        maxpiv = fmax(maxpiv, fabs(d));
        minpiv = fmin(minpiv, fabs(d));
        if (d == 0) continue;
        for (int64_t i = k + 1; i < m; i++) {
            double f = M[i * m + k] / d;
            if (f == 0) continue;
            for (int64_t l = k; l < m; l++) M[i * m + l] -= f * M[k * m + l];
            rhs[i] -= f * rhs[k];
        }
    }
    int singular = minpiv <= 1e-12 * maxpiv;
    if (!singular) {
        for (int64_t k = m - 1; k >= 0; k--) {
            double s = rhs[k];
            for (int64_t l = k + 1; l < m; l++) s -= M[k * m + l] * lam[l];
            lam[k] = s / M[k * m + k];
        }
    }
    free(M);
    free(rhs);
    free(d0);
    return singular;
}

/* Force scale of a point: max(|lambda|, rs |q(alpha) - (g,0)|). */
static double force_scale(const ref_t *R, double alpha, const double *lam) {
    double *d0 = malloc(sizeof(double) * (size_t)R->m);
    d0_at(R, alpha, d0);
    double s = fmax(inf_norm(lam, R->m), R->rs * inf_norm(d0, R->m));
    free(d0);
    return fmax(s, 1e-300);
}

/* Guards (SPEC §3, non-strict with tolerance) of `cls` at lambda; d = d0 + W lambda. */
static void check_guards(const ref_t *R, const char *what, const int32_t *cls, double alpha,
                         const double *lam) {
    int64_t m = R->m, p = R->p;
    double *d = malloc(sizeof(double) * (size_t)m);
    d0_at(R, alpha, d);
    for (int64_t i = 0; i < m; i++)
        for (int64_t l = 0; l < m; l++) d[i] += R->w[i * m + l] * lam[l];
    double tf = GUARD_TOL * force_scale(R, alpha, lam), td = tf / R->rs;
    int bad = 0;
    for (int64_t i = 0; i < p && !bad; i++) {
        double ln = lam[i], lt = lam[p + i], F = R->c.friction[i];
        switch (cls[i]) {
        case FRICONT_OPEN: bad = !(d[i] <= td); break;
        case FRICONT_STICK: bad = !(ln <= tf && fabs(lt) <= -F * ln + tf); break;
        case FRICONT_SLIP_PLUS: bad = !(ln <= tf && d[p + i] >= -td); break;
        case FRICONT_SLIP_MINUS: bad = !(ln <= tf && d[p + i] <= td); break;
        default: bad = 1;
        }
        CHECK(!bad, "%s: node %lld (1-based) violates the guards of class %s (lambda_n %g, lambda_t %g, d_n %g, d_t %g)",
              what, (long long)i + 1, fricont_class_name(cls[i]), ln, lt, d[i], d[p + i]);
    }
    if (!bad) CHECK(1, "guards");
    free(d);
}

/* ||H||_inf relative, computed from the library's u, lambda. */
static double h_residual(const ref_t *R, double alpha, const double *u, const double *lam) {
    int64_t n = R->n, m = R->m, p = R->p;
    double *au = malloc(sizeof(double) * (size_t)n), *scale1 = calloc((size_t)n, sizeof(double));
    double *bu = malloc(sizeof(double) * (size_t)m), *absbu = calloc((size_t)m, sizeof(double));
    csr_mul(&R->a, u, au);
    double h = 0, s = 0;
    for (int64_t i = 0; i < n; i++) {
        for (int64_t k = R->a.row_ptr[i]; k < R->a.row_ptr[i + 1]; k++)
            scale1[i] += fabs(R->a.values[k] * u[R->a.col_idx[k]]);
        double f = R->c.f0[i] + alpha * R->c.f1[i];
        au[i] -= f;
        scale1[i] += fabs(f);
    }
    for (int64_t r = 0; r < m; r++)
        for (int64_t k = R->b.row_ptr[r]; k < R->b.row_ptr[r + 1]; k++) {
            au[R->b.col_idx[k]] -= R->b.values[k] * lam[r];
            scale1[R->b.col_idx[k]] += fabs(R->b.values[k] * lam[r]);
            absbu[r] += fabs(R->b.values[k] * u[R->b.col_idx[k]]);
        }
    for (int64_t i = 0; i < n; i++) {
        h = fmax(h, fabs(au[i]));
        s = fmax(s, scale1[i]);
    }
    csr_mul(&R->b, u, bu);
    double r = R->r;
    for (int64_t i = 0; i < p; i++) {
        double ln = lam[i], lt = lam[p + i], F = R->c.friction[i];
        double h2 = ln - fmin(ln - r * (bu[i] - R->g[i]), 0.0);
        double b = fmax(-F * ln, 0.0);
        double y = lt - r * bu[p + i];
        double h3 = lt - fmin(fmax(y, -b), b);
        h = fmax(h, fmax(fabs(h2), fabs(h3)));
        s = fmax(s, fmax(fabs(ln), fabs(lt)));
        s = fmax(s, r * fmax(absbu[i] + fabs(R->g[i]), absbu[p + i]));
    }
    free(au);
    free(scale1);
    free(bu);
    free(absbu);
    return h / fmax(s, 1e-300);
}

/* Checks a reported point (see the file comment). `before`: classes of the piece before
 * an event, or NULL. */
static void check_point(ref_t *R, const char *what, double alpha, const int32_t *cls,
                        const int32_t *before, const double *u, const double *ln,
                        const double *lt, double lib_residual) {
    int64_t n = R->n, m = R->m, p = R->p;
    double *lam = malloc(sizeof(double) * (size_t)m), *lref = malloc(sizeof(double) * (size_t)m);
    memcpy(lam, ln, sizeof(double) * (size_t)p);
    memcpy(lam + p, lt, sizeof(double) * (size_t)p);
    int singular = piece_solve(R, cls, alpha, lref);
    double sc = force_scale(R, alpha, singular ? lam : lref);
    if (!singular) {
        double e = 0;
        for (int64_t i = 0; i < m; i++) e = fmax(e, fabs(lam[i] - lref[i]));
        CHECK(e <= REL_TOL * sc, "%s (alpha %.15g): lambda differs from the piece solution by %g (scale %g)",
              what, alpha, e / sc, sc);
        check_guards(R, what, cls, alpha, lref);
    } else {
        check_guards(R, what, cls, alpha, lam);
    }
    if (before) {
        double *lb = malloc(sizeof(double) * (size_t)m);
        if (!piece_solve(R, before, alpha, lb)) {
            double e = 0;
            for (int64_t i = 0; i < m; i++) e = fmax(e, fabs(lam[i] - lb[i]));
            CHECK(e <= REL_TOL * sc, "%s (alpha %.15g): not on the piece before the event (lambda differs by %g relative)",
                  what, alpha, e / sc);
            check_guards(R, what, before, alpha, lb);
        }
        free(lb);
    }
    CHECK(lib_residual <= H_TOL, "%s: the library reports residual %g", what, lib_residual);
    if (!u) { /* condensed input: no displacement */
        free(lam);
        free(lref);
        return;
    }
    /* u = A^-1 (f + B^T lambda) by CHOLMOD from the reference lambda */
    const double *lu = singular ? lam : lref;
    double *uref = malloc(sizeof(double) * (size_t)n);
    for (int64_t i = 0; i < n; i++) uref[i] = R->c.f0[i] + alpha * R->c.f1[i];
    for (int64_t r = 0; r < m; r++)
        for (int64_t k = R->b.row_ptr[r]; k < R->b.row_ptr[r + 1]; k++)
            uref[R->b.col_idx[k]] += R->b.values[k] * lu[r];
    chol_solve(R, uref);
    double e = 0, us = fmax(inf_norm(uref, n), 1e-300);
    for (int64_t i = 0; i < n; i++) e = fmax(e, fabs(u[i] - uref[i]));
    CHECK(e <= REL_TOL * us, "%s (alpha %.15g): u differs from CHOLMOD's by %g relative", what, alpha, e / us);
    double h = h_residual(R, alpha, u, lam);
    CHECK(h <= H_TOL, "%s (alpha %.15g): ||H|| = %g relative > %g", what, alpha, h, H_TOL);
    free(uref);
    free(lam);
    free(lref);
}

int main(int argc, char **argv) {
    if (argc < 2) {
        fprintf(stderr, "usage: %s DIR [--base 0|1] [--storage full|lower|upper] [--F value] [--r value] [--events FILE]\n", argv[0]);
        return 2;
    }
    const char *dir = argv[1], *events_file = NULL, *via = "ann";
    int64_t base = 0;
    int32_t storage = FRICONT_STORAGE_FULL;
    double F = -1, r = -1;
    int64_t threads = 0;
    for (int i = 2; i + 1 < argc; i += 2) {
        if (!strcmp(argv[i], "--base")) base = atoi(argv[i + 1]);
        else if (!strcmp(argv[i], "--storage"))
            storage = !strcmp(argv[i + 1], "lower")   ? FRICONT_STORAGE_LOWER
                      : !strcmp(argv[i + 1], "upper") ? FRICONT_STORAGE_UPPER
                                                      : FRICONT_STORAGE_FULL;
        else if (!strcmp(argv[i], "--F")) F = atof(argv[i + 1]);
        else if (!strcmp(argv[i], "--r")) r = atof(argv[i + 1]);
        else if (!strcmp(argv[i], "--events")) events_file = argv[i + 1];
        else if (!strcmp(argv[i], "--via")) via = argv[i + 1];
        else if (!strcmp(argv[i], "--threads")) threads = atoi(argv[i + 1]);
    }
    ref_t R;
    memset(&R, 0, sizeof R);
    if (read_case(dir, &R.c)) {
        fprintf(stderr, "cannot read the case in %s\n", dir);
        return 2;
    }
    if (F >= 0)
        for (int64_t i = 0; i < R.c.p; i++) R.c.friction[i] = F;
    if (setup(&R)) return 2;
    int64_t n = R.n, p = R.p;

    int condensed = !strcmp(via, "condensed"), hosted = !strcmp(via, "solve");
    fricont_problem *prob = NULL;
    fricont_status st;
    if (condensed) {
        /* W here is row-major; fricont reads column-major, i.e. W^T (it symmetrises) */
        st = fricont_problem_new_condensed(p, R.w, R.m, &prob);
        if (st == FRICONT_OK) st = set_case_settings(&R.c, prob);
    } else if (hosted) {
        csr nm = csr_from_triplets(&R.c.nm, PART_FULL, base), tm = csr_from_triplets(&R.c.tm, PART_FULL, base);
        fricont_csr nv = csr_view(&nm), tv = csr_view(&tm);
        st = fricont_problem_new_solve(n, chol_block, &R, NULL, 16, &nv, &tv, &prob);
        free_csr(&nm);
        free_csr(&tm);
        if (st == FRICONT_OK) st = set_case_settings(&R.c, prob);
    } else {
        st = problem_from_case(&R.c, storage, base, &prob);
    }
    CHECK(st == FRICONT_OK, "problem (via %s): %s", via, fricont_status_str(st));
    if (r > 0) CHECK(fricont_problem_set_r(prob, r) == FRICONT_OK, "set_r");
    if (threads > 0) CHECK(fricont_problem_set_threads(prob, threads) == FRICONT_OK, "set_threads");
    double r0 = 0;
    CHECK(fricont_problem_r(prob, &R.r, &r0) == FRICONT_OK, "problem_r");
    /* (condensed input equilibrates W by its own diagonal, so its default r differs) */
    if (!condensed)
        CHECK(fabs(r0 - R.rs) <= 1e-10 * R.rs, "default r %.17g differs from 2p/trace(W) = %.17g", r0, R.rs);
    fricont_path *path = NULL;
    st = condensed ? fricont_path_new_affine(prob, R.q0, R.q1, R.m, &path)
                   : fricont_path_new_affine(prob, R.c.f0, R.c.f1, n, &path);
    CHECK(st == FRICONT_OK, "path: %s", fricont_status_str(st));
    fricont_problem_free(prob);
    CHECK(fricont_path_set_window(path, R.c.alpha_start, R.c.alpha_end) == FRICONT_OK, "window");
    st = fricont_path_start(path, R.c.alpha_start, NULL, 0);
    if (st != FRICONT_OK) {
        char msg[512];
        fricont_path_error_message(path, msg, sizeof msg);
        CHECK(0, "start: %s: %s", fricont_status_str(st), msg);
        fricont_path_free(path);
        teardown(&R);
        free_case(&R.c);
        return finish("cholmod_ref");
    }
    double *u = malloc(sizeof(double) * (size_t)n), *ln = malloc(sizeof(double) * (size_t)p),
           *lt = malloc(sizeof(double) * (size_t)p);
    int32_t *cls = malloc(sizeof(int32_t) * (size_t)p), *prev = malloc(sizeof(int32_t) * (size_t)p);
    fricont_state s = {0, 0, condensed ? NULL : u, condensed ? 0 : n, ln, p, lt, p, cls, p};
    CHECK(fricont_path_start_state(path, &s) == FRICONT_OK, "start_state");
    check_point(&R, "start", s.alpha, cls, NULL, s.u, ln, lt, s.residual);

    st = fricont_path_run(path);
    CHECK(st == FRICONT_END, "run: %s", fricont_status_str(st));
    int32_t reason = -1;
    fricont_path_end_reason(path, &reason);
    CHECK(reason == FRICONT_END_WINDOW, "end reason %d", reason);
    int32_t route = -1;
    CHECK(fricont_path_start_route(path, &route) == FRICONT_OK && route == FRICONT_START_SOLVED,
          "start route %d (the fixed-alpha solver starts every case this test traces)", route);
    int64_t ne = 0, np = 0;
    fricont_path_event_count(path, &ne);
    fricont_path_piece_count(path, &np);
    FILE *ef = events_file ? fopen(events_file, "w") : NULL;
    /* events: on the piece after (reported classes) and the piece before */
    int64_t t_prev = -1;
    for (int64_t k = 0; k < ne; k++) {
        fricont_event ev;
        CHECK(fricont_path_event(path, k, &ev) == FRICONT_OK, "event %lld", (long long)k);
        CHECK(ev.index == k, "event index");
        CHECK(ev.transition + 1 < np, "event %lld: transition %lld but %lld pieces", (long long)k,
              (long long)ev.transition, (long long)np);
        if (ef)
            fprintf(ef, "%.17g %lld %s %s %d %d\n", ev.alpha, (long long)ev.node + 1,
                    fricont_class_name(ev.from), fricont_class_name(ev.to), ev.fold, ev.bifurcation);
        fricont_path_piece(path, ev.transition, NULL, prev, p);
        CHECK(fricont_path_event_state(path, k, &s) == FRICONT_OK, "event_state");
        CHECK(s.alpha == ev.alpha, "event alpha");
        CHECK(prev[ev.node] == ev.from && cls[ev.node] == ev.to,
              "event %lld: node %lld goes %s -> %s but the pieces say %s -> %s", (long long)k,
              (long long)ev.node + 1, fricont_class_name(ev.from), fricont_class_name(ev.to),
              fricont_class_name(prev[ev.node]), fricont_class_name(cls[ev.node]));
        int32_t *after = malloc(sizeof(int32_t) * (size_t)p);
        fricont_piece pc;
        fricont_path_piece(path, ev.transition + 1, &pc, after, p);
        CHECK(memcmp(after, cls, sizeof(int32_t) * (size_t)p) == 0, "event state classes are the piece after");
        CHECK(pc.alpha_from == ev.alpha, "the piece after starts at the event");
        free(after);
        CHECK(ev.transition >= t_prev, "transitions in order");
        t_prev = ev.transition;
        char what[64];
        snprintf(what, sizeof what, "event %lld", (long long)k + 1);
        check_point(&R, what, ev.alpha, cls, prev, s.u, ln, lt, ev.residual);
    }
    if (ef) fclose(ef);
    /* pieces: guards at both ends and the middle with the reference solution */
    double amin = INFINITY, amax = -INFINITY;
    for (int64_t k = 0; k < np; k++) {
        fricont_piece pc;
        CHECK(fricont_path_piece(path, k, &pc, cls, p) == FRICONT_OK, "piece");
        amin = fmin(amin, fmin(pc.alpha_from, pc.alpha_to));
        amax = fmax(amax, fmax(pc.alpha_from, pc.alpha_to));
        if (pc.direction == 0) continue;
        double as[3] = {pc.alpha_from, 0.5 * (pc.alpha_from + pc.alpha_to), pc.alpha_to};
        for (int j = 0; j < 3; j++) {
            double *lam = malloc(sizeof(double) * (size_t)(2 * p));
            int sing = piece_solve(&R, cls, as[j], lam);
            CHECK(!sing, "piece %lld is singular at alpha %g but not vertical", (long long)k, as[j]);
            char what[64];
            snprintf(what, sizeof what, "piece %lld", (long long)k + 1);
            if (!sing) check_guards(&R, what, cls, as[j], lam);
            free(lam);
        }
    }
    CHECK(fabs(amin - fmin(R.c.alpha_start, R.c.alpha_end)) <= 1e-12 * (1 + fabs(amin)) &&
              fabs(amax - fmax(R.c.alpha_start, R.c.alpha_end)) <= 1e-12 * (1 + fabs(amax)),
          "the pieces cover [%g, %g], not the window", amin, amax);
    /* sampled alpha: every solution the library returns */
    const int K = 9;
    for (int j = 0; j < K; j++) {
        double a = R.c.alpha_start + (R.c.alpha_end - R.c.alpha_start) * (j + 0.37) / K;
        int64_t count = -1;
        CHECK(fricont_path_solutions_at(path, a, &count) == FRICONT_OK, "solutions_at");
        CHECK(count >= 1, "no solution at alpha %g inside the traced range", a);
        for (int64_t k = 0; k < count; k++) {
            fricont_solution info;
            CHECK(fricont_path_solution(path, k, &info, &s) == FRICONT_OK, "solution");
            CHECK(s.alpha == a, "solution alpha");
            char what[64];
            snprintf(what, sizeof what, "solution at sample %d", j + 1);
            check_point(&R, what, a, cls, NULL, s.u, ln, lt, s.residual);
        }
    }
    printf("%s (via %s): %lld events, %lld pieces, r = %.6g (default %.6g)\n", dir, via, (long long)ne, (long long)np, R.r, r0);
    free(u);
    free(ln);
    free(lt);
    free(cls);
    free(prev);
    fricont_path_free(path);
    teardown(&R);
    free_case(&R.c);
    return finish("cholmod_ref");
}
