/* Extended precision through the C API (fricont_problem_set_extended_precision,
 * fricont_problem_extended_precision):
 *  - modes other than 0, 1, 2 are FRICONT_ERR_RANGE naming the value, the setting
 *    unchanged;
 *  - the sample (W well conditioned, but small enough for auto to refine it): auto and
 *    on refine it (extended 1, condition estimate between 10 and 1e7), off does not, and
 *    the traced events of on and off agree;
 *  - a tiny ill-conditioned problem (A = diag(2, 1, 1), N = [1 0 0], T = [1 1e-5 0]:
 *    W = [[1/2, 1/2], [1/2, 1/2 + 1e-10]], condition number 2e10): auto refines;
 *  - a host's solve with on: the build fails with FRICONT_ERR_RANGE ("host"); with auto it
 *    builds, not extended;
 *  - condensed data: on makes it extended, auto with a well-conditioned W does not.
 * usage: extended_precision DIR (the sample) */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "common.h"

static const char *last(void) {
    static char buf[1024];
    fricont_last_error_message(buf, sizeof buf);
    return buf;
}

static int extended(fricont_problem *p, double *cond) {
    int32_t e = -1;
    fricont_status st = fricont_problem_extended_precision(p, &e, cond);
    CHECK(st == FRICONT_OK, "fricont_problem_extended_precision: %s", last());
    return e;
}

/* Events of the sample's path on a built problem: count and alphas (caller frees). */
static int64_t trace(const case_data *c, fricont_problem *p, double **alpha) {
    fricont_path *path = NULL;
    CHECK(fricont_path_new_affine(p, c->f0, c->f1, c->n, &path) == FRICONT_OK, "path: %s", last());
    CHECK(fricont_path_set_window(path, c->alpha_start, c->alpha_end) == FRICONT_OK, "window");
    CHECK(fricont_path_start(path, c->alpha_start, NULL, 0) == FRICONT_OK, "start: %s", last());
    CHECK(fricont_path_run(path) == FRICONT_END, "run: %s", last());
    int64_t count = 0;
    CHECK(fricont_path_event_count(path, &count) == FRICONT_OK, "event count");
    *alpha = calloc((size_t)(count > 0 ? count : 1), sizeof **alpha);
    for (int64_t k = 0; k < count; k++) {
        fricont_event ev;
        CHECK(fricont_path_event(path, k, &ev) == FRICONT_OK, "event %lld", (long long)k);
        (*alpha)[k] = ev.alpha;
    }
    fricont_path_free(path);
    return count;
}

static int half_solve(void *user, int64_t n, int64_t ncols, double *x, int64_t ldx) {
    (void)user;
    for (int64_t j = 0; j < ncols; j++) x[j * ldx] *= 0.5; /* A = diag(2, 1, ...) */
    (void)n;
    return 0;
}

int main(int argc, char **argv) {
    if (argc < 2) {
        fprintf(stderr, "usage: extended_precision DIR\n");
        return 2;
    }
    case_data c;
    if (read_case(argv[1], &c) != 0) {
        fprintf(stderr, "cannot read %s\n", argv[1]);
        return 2;
    }
    fricont_problem *p = NULL;
    CHECK(problem_from_case(&c, FRICONT_STORAGE_LOWER, 0, &p) == FRICONT_OK, "sample: %s", last());

    /* bad modes */
    CHECK(fricont_problem_set_extended_precision(NULL, 0) == FRICONT_ERR_NULL, "NULL handle");
    int32_t bad[] = {3, -1, 1000};
    for (int k = 0; k < 3; k++) {
        char want[64];
        snprintf(want, sizeof want, "mode = %d", (int)bad[k]);
        CHECK(fricont_problem_set_extended_precision(p, bad[k]) == FRICONT_ERR_RANGE, "mode %d accepted",
              (int)bad[k]);
        CHECK(strstr(last(), want) != NULL, "message \"%s\" lacks \"%s\"", last(), want);
    }

    /* the sample: auto (default) and on refine (it is small), off does not */
    double cond = 0.0;
    CHECK(extended(p, &cond) == 1, "sample, auto: not extended");
    CHECK(cond > 10.0 && cond < 1e7, "sample: condition estimate %g", cond);
    double *a_off = NULL, *a_on = NULL;
    CHECK(fricont_problem_set_extended_precision(p, 2) == FRICONT_OK, "off: %s", last());
    CHECK(extended(p, NULL) == 0, "sample, off: extended");
    int64_t n_off = trace(&c, p, &a_off);
    CHECK(fricont_problem_set_extended_precision(p, 1) == FRICONT_OK, "on: %s", last());
    double cond_on = 0.0;
    CHECK(extended(p, &cond_on) == 1, "sample, on: not extended");
    CHECK(cond_on == cond, "the condition estimate does not depend on the mode (%g, %g)", cond_on, cond);
    int64_t n_on = trace(&c, p, &a_on);
    CHECK(n_on == n_off && n_on > 10, "events: on %lld, off %lld", (long long)n_on, (long long)n_off);
    for (int64_t k = 0; k < n_on && k < n_off; k++)
        CHECK(fabs(a_on[k] - a_off[k]) <= 1e-10 * fmax(1.0, fabs(a_off[k])), "event %lld: %.17g against %.17g",
              (long long)k, a_on[k], a_off[k]);
    free(a_off);
    free(a_on);
    fricont_problem_free(p);

    /* a tiny ill-conditioned W: auto refines */
    int64_t a_rp[] = {0, 1, 2, 3}, a_ci[] = {0, 1, 2};
    double a_v[] = {2.0, 1.0, 1.0};
    int64_t n_rp[] = {0, 1}, n_ci[] = {0}, t_rp[] = {0, 2}, t_ci[] = {0, 1};
    double n_v[] = {1.0}, t_v[] = {1.0, 1e-5};
    fricont_csr a = {3, 3, 3, a_rp, a_ci, a_v, 0};
    fricont_csr nm = {1, 3, 1, n_rp, n_ci, n_v, 0}, tm = {1, 3, 2, t_rp, t_ci, t_v, 0};
    CHECK(fricont_problem_new(&a, FRICONT_STORAGE_LOWER, &nm, &tm, &p) == FRICONT_OK, "tiny: %s", last());
    CHECK(extended(p, &cond) == 1, "tiny, auto: not extended");
    CHECK(cond > 1e9 && cond < 1e11, "tiny: condition estimate %g (2e10 expected)", cond);
    fricont_problem_free(p);

    /* a host's solve cannot be refined */
    CHECK(fricont_problem_new_solve(3, half_solve, NULL, NULL, 4, &nm, &tm, &p) == FRICONT_OK, "host: %s", last());
    CHECK(fricont_problem_set_extended_precision(p, 1) == FRICONT_OK, "host, on: %s", last());
    CHECK(fricont_problem_build(p) == FRICONT_ERR_RANGE, "host, on: build");
    CHECK(strstr(last(), "host") != NULL, "host, on: message \"%s\"", last());
    CHECK(fricont_problem_set_extended_precision(p, 0) == FRICONT_OK, "host, auto: %s", last());
    CHECK(fricont_problem_build(p) == FRICONT_OK, "host, auto: %s", last());
    CHECK(extended(p, NULL) == 0, "host, auto: extended");
    fricont_problem_free(p);

    /* condensed data: on is extended (the caller's W as data), auto here is not */
    double w[4] = {0.5, 0.0, 0.0, 1.0};
    for (int32_t mode = 0; mode <= 1; mode++) {
        CHECK(fricont_problem_new_condensed(1, w, 2, &p) == FRICONT_OK, "condensed: %s", last());
        CHECK(fricont_problem_set_extended_precision(p, mode) == FRICONT_OK, "condensed: %s", last());
        CHECK(extended(p, NULL) == mode, "condensed, mode %d", (int)mode);
        fricont_problem_free(p);
    }
    free_case(&c);
    return finish("extended_precision");
}
