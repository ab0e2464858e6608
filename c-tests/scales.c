/* Extreme but valid scales of A through the C API, on a problem directory (the sample):
 * A and the load multiplied by one factor s are the same contact problem (u unchanged,
 * lambda times s), so every storage of A and both index bases must give the events of
 * the unscaled problem:
 *  - s = 2^-900, 2^1020 (exact): alpha to 1e-10 relative, the same nodes and classes,
 *    lambda = s times the unscaled one, every event's residual <= 1e-10;
 *  - s = 4e307 (entries of 9.2e307: their mean (a + b)/2 overflows);
 *  - s = 1e-310 (every entry of A subnormal): against the same rounded numbers times
 *    2^1030 (exact, normal), alpha to 1e-10; against the unscaled data to 5e-10 (the
 *    scaling itself rounds f1's entries ~6e-315 to ~30 bits, 4e-10 relative);
 *  - s = 1e-315 (29 significant bits): FRICONT_ERR_RANGE naming the subnormal entry;
 *  - A x 1e-310 with the unscaled load: u overflows, FRICONT_ERR_NUMERICAL at the start;
 *  - a non-symmetric A x 4e307 in full storage: FRICONT_ERR_NOT_SYMMETRIC whose message
 *    gives the caller's numbers (not the internally scaled ones).
 * usage: scales DIR */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "common.h"

typedef struct {
    int64_t count;
    double *alpha, *lam; /* lam: 2p values per event (lambda_n, lambda_t) */
    int64_t *node;
    int32_t *from, *to;
    double max_residual;
} events;

static void free_events(events *e) {
    free(e->alpha);
    free(e->lam);
    free(e->node);
    free(e->from);
    free(e->to);
}

/* s * 2^e, exact when the result is normal (2^e itself may not be a double). */
static double mul_pow2(double x, int e) {
    while (e > 1000) {
        x *= ldexp(1.0, 1000);
        e -= 1000;
    }
    while (e < -1000) {
        x *= ldexp(1.0, -1000);
        e += 1000;
    }
    return x * ldexp(1.0, e);
}

typedef double (*map_fn)(double v, const void *arg);
static double by_factor(double v, const void *arg) { return v * *(const double *)arg; }
static double by_pow2(double v, const void *arg) { return mul_pow2(v, *(const int *)arg); }
/* v * 1e-310, then times 2^1030 */
static double sub_back(double v, const void *arg) {
    (void)arg;
    return mul_pow2(v * 1e-310, 1030);
}
static double ident(double v, const void *arg) {
    (void)arg;
    return v;
}

static char msg[1024];

/* A problem of the case with A's values and the load mapped by `fa`, `ff`. Returns the
 * status of the first failing call (the problem's message in `msg`). */
static fricont_status trace(const case_data *c, int32_t storage, int64_t base, map_fn fa,
                            map_fn ff, const void *arg, events *out) {
    memset(out, 0, sizeof *out);
    case_data s = *c;
    triplets a = c->a;
    a.val = malloc(sizeof(double) * (size_t)(a.nnz + 1));
    for (int64_t k = 0; k < a.nnz; k++) a.val[k] = fa(c->a.val[k], arg);
    s.a = a;
    double *f0 = malloc(sizeof(double) * (size_t)c->n), *f1 = malloc(sizeof(double) * (size_t)c->n);
    for (int64_t i = 0; i < c->n; i++) {
        f0[i] = ff(c->f0[i], arg);
        f1[i] = ff(c->f1[i], arg);
    }
    fricont_problem *pb = NULL;
    fricont_path *path = NULL;
    fricont_status st = problem_from_case(&s, storage, base, &pb);
    free(a.val);
    if (st == FRICONT_OK) st = fricont_problem_build(pb);
    if (st != FRICONT_OK) {
        fricont_last_error_message(msg, sizeof msg);
        goto done;
    }
    st = fricont_path_new_affine(pb, f0, f1, c->n, &path);
    if (st == FRICONT_OK) st = fricont_path_set_window(path, c->alpha_start, c->alpha_end);
    if (st == FRICONT_OK) st = fricont_path_start(path, c->alpha_start, NULL, 0);
    if (st == FRICONT_OK) {
        st = fricont_path_run(path);
        if (st == FRICONT_END) st = FRICONT_OK;
    }
    if (st != FRICONT_OK) {
        if (path) fricont_path_error_message(path, msg, sizeof msg);
        goto done;
    }
    /* the start state: u by one back-solve (an error where u overflows) */
    st = fricont_path_start_state(path, NULL);
    if (st != FRICONT_OK) {
        fricont_last_error_message(msg, sizeof msg);
        goto done;
    }
    int64_t ne = 0, p = c->p;
    fricont_path_event_count(path, &ne);
    out->count = ne;
    out->alpha = malloc(sizeof(double) * (size_t)(ne + 1));
    out->lam = malloc(sizeof(double) * (size_t)(2 * p * ne + 1));
    out->node = malloc(sizeof(int64_t) * (size_t)(ne + 1));
    out->from = malloc(sizeof(int32_t) * (size_t)(ne + 1));
    out->to = malloc(sizeof(int32_t) * (size_t)(ne + 1));
    double *u = malloc(sizeof(double) * (size_t)c->n);
    for (int64_t k = 0; k < ne; k++) {
        fricont_event ev;
        CHECK(fricont_path_event(path, k, &ev) == FRICONT_OK, "event %lld", (long long)k);
        out->alpha[k] = ev.alpha;
        out->node[k] = ev.node;
        out->from[k] = ev.from;
        out->to[k] = ev.to;
        fricont_state sk = {0};
        sk.u = u;
        sk.u_len = c->n;
        sk.lambda_n = out->lam + 2 * p * k;
        sk.lambda_n_len = p;
        sk.lambda_t = out->lam + 2 * p * k + p;
        sk.lambda_t_len = p;
        CHECK(fricont_path_event_state(path, k, &sk) == FRICONT_OK, "event_state %lld", (long long)k);
        if (sk.residual > out->max_residual || sk.residual != sk.residual)
            out->max_residual = sk.residual;
    }
    free(u);
done:
    fricont_path_free(path);
    fricont_problem_free(pb);
    free(f0);
    free(f1);
    return st;
}

/* y against x: alpha to tol relative (of max(1, |alpha|)), the same node changes, lambda
 * of y mapped by `back` equal to x's to tol_lam of the largest |lambda| of the event, and
 * every residual of y <= 1e-10. */
static void compare(const char *ctx, const events *x, const events *y, int64_t p, map_fn back,
                    const void *arg, double tol, double tol_lam) {
    CHECK(x->count >= 20 && x->count == y->count, "%s: %lld events, unscaled %lld", ctx,
          (long long)y->count, (long long)x->count);
    int64_t n = x->count < y->count ? x->count : y->count;
    int bad = 0;
    for (int64_t k = 0; k < n && bad < 3; k++) {
        double a = x->alpha[k], b = y->alpha[k];
        double sc = fmax(1.0, fmax(fabs(a), fabs(b)));
        int ok = fabs(a - b) <= tol * sc && x->node[k] == y->node[k] && x->from[k] == y->from[k] &&
                 x->to[k] == y->to[k];
        double lmax = 0, dl = 0;
        for (int64_t i = 0; i < 2 * p; i++) lmax = fmax(lmax, fabs(x->lam[2 * p * k + i]));
        for (int64_t i = 0; i < 2 * p; i++)
            dl = fmax(dl, fabs(back(y->lam[2 * p * k + i], arg) - x->lam[2 * p * k + i]));
        ok = ok && dl <= tol_lam * lmax;
        CHECK(ok, "%s: event %lld: alpha %.14e node %lld vs %.14e node %lld; lambda off by %.3e of %.3e",
              ctx, (long long)k + 1, b, (long long)y->node[k] + 1, a, (long long)x->node[k] + 1, dl,
              lmax);
        bad += !ok;
    }
    CHECK(y->max_residual <= 1e-10, "%s: largest event residual %.3e", ctx, y->max_residual);
}

static double div_factor(double v, const void *arg) { return v / *(const double *)arg; }
static double div_pow2(double v, const void *arg) { return mul_pow2(v, -*(const int *)arg); }

int main(int argc, char **argv) {
    if (argc < 2) {
        fprintf(stderr, "usage: scales DIR\n");
        return 2;
    }
    case_data c;
    if (read_case(argv[1], &c) != 0) {
        fprintf(stderr, "cannot read the case in %s\n", argv[1]);
        return 2;
    }
    const int32_t storages[] = {FRICONT_STORAGE_FULL, FRICONT_STORAGE_LOWER, FRICONT_STORAGE_UPPER};
    const char *names[] = {"full", "lower", "upper"};
    for (int si = 0; si < 3; si++) {
        int32_t storage = storages[si];
        int64_t base = si == 1; /* lower storage with 1-based indices */
        char ctx[160];
        events x, y;
        fricont_status st = trace(&c, storage, base, ident, ident, NULL, &x);
        CHECK(st == FRICONT_OK, "%s: unscaled: %s: %s", names[si], fricont_status_str(st), msg);
        /* exact power-of-two scalings */
        const int ks[] = {-900, 1020};
        for (int ki = 0; ki < 2; ki++) {
            snprintf(ctx, sizeof ctx, "%s, A and f x 2^%d", names[si], ks[ki]);
            st = trace(&c, storage, base, by_pow2, by_pow2, &ks[ki], &y);
            CHECK(st == FRICONT_OK, "%s: %s: %s", ctx, fricont_status_str(st), msg);
            compare(ctx, &x, &y, c.p, div_pow2, &ks[ki], 1e-10, 1e-9);
            free_events(&y);
        }
        /* 4e307 */
        double s = 4e307;
        snprintf(ctx, sizeof ctx, "%s, A and f x 4e307", names[si]);
        st = trace(&c, storage, base, by_factor, by_factor, &s, &y);
        CHECK(st == FRICONT_OK, "%s: %s: %s", ctx, fricont_status_str(st), msg);
        compare(ctx, &x, &y, c.p, div_factor, &s, 1e-10, 1e-9);
        free_events(&y);
        /* 1e-310: against the same rounded numbers brought back by 2^1030, and the
         * unscaled data */
        s = 1e-310;
        events z;
        snprintf(ctx, sizeof ctx, "%s, A and f x 1e-310", names[si]);
        st = trace(&c, storage, base, by_factor, by_factor, &s, &y);
        CHECK(st == FRICONT_OK, "%s: %s: %s", ctx, fricont_status_str(st), msg);
        st = trace(&c, storage, base, sub_back, sub_back, NULL, &z);
        CHECK(st == FRICONT_OK, "%s (x 2^1030): %s: %s", ctx, fricont_status_str(st), msg);
        const int e1030 = -1030;
        /* lambda of the subnormal problem is itself subnormal (~31 bits) */
        compare(ctx, &z, &y, c.p, div_pow2, &e1030, 1e-10, 1e-8);
        snprintf(ctx, sizeof ctx, "%s, A and f x 1e-310 vs unscaled", names[si]);
        compare(ctx, &x, &y, c.p, div_factor, &s, 5e-10, 1e-8);
        free_events(&y);
        free_events(&z);
        /* 1e-315: 29 significant bits, refused */
        s = 1e-315;
        st = trace(&c, storage, base, by_factor, by_factor, &s, &y);
        CHECK(st == FRICONT_ERR_RANGE && strstr(msg, "subnormal") && strstr(msg, "power of two"),
              "%s, A x 1e-315: %s: %s", names[si], fricont_status_str(st), msg);
        free_events(&y);
        /* a tiny A with the unscaled load: u overflows */
        s = 1e-310;
        st = trace(&c, storage, base, by_factor, ident, &s, &y);
        CHECK(st == FRICONT_ERR_NUMERICAL && strstr(msg, "overflows"),
              "%s, A x 1e-310, f unscaled: %s: %s", names[si], fricont_status_str(st), msg);
        free_events(&y);
        free_events(&x);
    }
    /* A x 4e307 in full storage with entry (1, 2) perturbed in one triangle by 1e-6
     * max|A|: the message gives the caller's numbers. */
    {
        case_data s = c;
        triplets a = c.a;
        a.val = malloc(sizeof(double) * (size_t)(a.nnz + 1));
        double amax = 0;
        int64_t kmax = -1;
        for (int64_t k = 0; k < a.nnz; k++) {
            amax = fmax(amax, fabs(c.a.val[k]));
            if (c.a.row[k] == 0 && c.a.col[k] != 0 &&
                (kmax < 0 || fabs(c.a.val[k]) > fabs(c.a.val[kmax])))
                kmax = k;
        }
        for (int64_t k = 0; k < a.nnz; k++) a.val[k] = c.a.val[k];
        a.val[kmax] += 1e-6 * amax;
        for (int64_t k = 0; k < a.nnz; k++) a.val[k] *= 4e307;
        s.a = a;
        fricont_problem *pb = NULL;
        fricont_status st = problem_from_case(&s, FRICONT_STORAGE_FULL, 0, &pb);
        CHECK(st == FRICONT_OK, "asymmetric: %s", fricont_status_str(st));
        st = fricont_problem_build(pb);
        fricont_problem_error_message(pb, msg, sizeof msg);
        const char *d = strstr(msg, "differ by "), *t = strstr(msg, "max|A| = ");
        double dv = d ? strtod(d + 10, NULL) : 0, tv = t ? strtod(t + 9, NULL) : 0;
        double want = 1e-6 * amax * 4e307;
        CHECK(st == FRICONT_ERR_NOT_SYMMETRIC && fabs(dv - want) <= 1e-9 * want &&
                  fabs(tv - 1e-10 * amax * 4e307) <= 1e-12 * tv,
              "asymmetric A x 4e307: %s: %s (expected a difference of %.6e)", fricont_status_str(st),
              msg, want);
        fricont_problem_free(pb);
        free(a.val);
    }
    free_case(&c);
    return finish("scales");
}
