/* Loads and threads on a problem directory (the sample case by default):
 *  - the same affine load given as fricont_path_new_affine, as a general callback (with
 *    and without its derivative) and as a basis load with weights (1, alpha) gives the
 *    same events (alpha to 1e-9 of the window, nodes, classes, flags);
 *  - three paths traced at once from three threads (two on one shared problem handle,
 *    one on a second problem with another friction) give bit-for-bit the results of
 *    the same paths traced one after the other.
 * usage: paths [DIR] */
#include <math.h>
#include <pthread.h>
#include <stdlib.h>
#include <string.h>

#include "common.h"

typedef struct {
    int64_t count;
    double *alpha;
    int64_t *node;
    int32_t *from, *to, *fold;
    double *u_end; /* u at the end of the path */
    int32_t status;
} trace_result;

typedef struct {
    const case_data *c;
    int calls;
} load_ud;

static int32_t general_f(double alpha, double *f, int64_t n, void *ud) {
    load_ud *d = ud;
    d->calls++;
    for (int64_t i = 0; i < n; i++) f[i] = d->c->f0[i] + alpha * d->c->f1[i];
    return 0;
}

static int32_t general_df(double alpha, double *f, int64_t n, void *ud) {
    load_ud *d = ud;
    (void)alpha;
    for (int64_t i = 0; i < n; i++) f[i] = d->c->f1[i];
    return 0;
}

static int32_t weights(double alpha, double *phi, double *dphi, int64_t k, void *ud) {
    (void)ud;
    if (k != 2) return 1;
    phi[0] = 1.0;
    phi[1] = alpha;
    dphi[0] = 0.0;
    dphi[1] = 1.0;
    return 0;
}

enum load_kind { AFFINE, GENERAL_DF, GENERAL, BASIS };

typedef struct {
    fricont_problem *problem;
    const case_data *c;
    enum load_kind kind;
    trace_result out;
} job;

static void trace(job *j) {
    const case_data *c = j->c;
    fricont_path *path = NULL;
    load_ud ud = {c, 0};
    fricont_status st;
    double *vecs = NULL;
    switch (j->kind) {
    case AFFINE: st = fricont_path_new_affine(j->problem, c->f0, c->f1, c->n, &path); break;
    case GENERAL_DF:
        st = fricont_path_new_general(j->problem, c->n, general_f, general_df, &ud, NULL, &path);
        break;
    case GENERAL:
        st = fricont_path_new_general(j->problem, c->n, general_f, NULL, &ud, NULL, &path);
        break;
    default:
        vecs = malloc(sizeof(double) * (size_t)(2 * c->n));
        memcpy(vecs, c->f0, sizeof(double) * (size_t)c->n);
        memcpy(vecs + c->n, c->f1, sizeof(double) * (size_t)c->n);
        st = fricont_path_new_basis(j->problem, vecs, c->n, 2, weights, NULL, NULL, &path);
        free(vecs);
    }
    memset(&j->out, 0, sizeof j->out);
    j->out.status = st;
    if (st != FRICONT_OK) return;
    fricont_path_set_window(path, c->alpha_start, c->alpha_end);
    st = fricont_path_start(path, c->alpha_start, NULL, 0);
    if (st == FRICONT_OK) st = fricont_path_run(path);
    j->out.status = st;
    fricont_path_event_count(path, &j->out.count);
    int64_t m = j->out.count;
    j->out.alpha = malloc(sizeof(double) * (size_t)(m + 1));
    j->out.node = malloc(sizeof(int64_t) * (size_t)(m + 1));
    j->out.from = malloc(sizeof(int32_t) * (size_t)(m + 1));
    j->out.to = malloc(sizeof(int32_t) * (size_t)(m + 1));
    j->out.fold = malloc(sizeof(int32_t) * (size_t)(m + 1));
    for (int64_t k = 0; k < m; k++) {
        fricont_event ev;
        fricont_path_event(path, k, &ev);
        j->out.alpha[k] = ev.alpha;
        j->out.node[k] = ev.node;
        j->out.from[k] = ev.from;
        j->out.to[k] = ev.to;
        j->out.fold[k] = ev.fold + 2 * ev.bifurcation;
    }
    j->out.u_end = malloc(sizeof(double) * (size_t)c->n);
    fricont_state s = {0, 0, j->out.u_end, c->n, NULL, 0, NULL, 0, NULL, 0};
    fricont_path_current(path, &s);
    fricont_path_free(path);
}

static void free_result(trace_result *r) {
    free(r->alpha);
    free(r->node);
    free(r->from);
    free(r->to);
    free(r->fold);
    free(r->u_end);
}

static void *thread_main(void *arg) {
    trace((job *)arg);
    return NULL;
}

/* Same events; alpha within tol (0: bitwise, and u_end bitwise too). */
static void compare(const char *what, const trace_result *a, const trace_result *b, double tol, int64_t n) {
    CHECK(a->status == FRICONT_END && b->status == FRICONT_END, "%s: statuses %d %d", what, a->status, b->status);
    CHECK(a->count == b->count, "%s: %lld vs %lld events", what, (long long)a->count, (long long)b->count);
    for (int64_t k = 0; k < a->count && k < b->count; k++) {
        int same_alpha = tol == 0 ? a->alpha[k] == b->alpha[k] : fabs(a->alpha[k] - b->alpha[k]) <= tol;
        CHECK(same_alpha && a->node[k] == b->node[k] && a->from[k] == b->from[k] && a->to[k] == b->to[k] &&
                  a->fold[k] == b->fold[k],
              "%s: event %lld differs: %.17g node %lld vs %.17g node %lld", what, (long long)k, a->alpha[k],
              (long long)a->node[k] + 1, b->alpha[k], (long long)b->node[k] + 1);
    }
    if (tol == 0 && a->u_end && b->u_end)
        CHECK(memcmp(a->u_end, b->u_end, sizeof(double) * (size_t)n) == 0, "%s: final u differs", what);
}

int main(int argc, char **argv) {
    const char *dir = argc > 1 ? argv[1] : "tests/data/sample-rect30";
    case_data c;
    if (read_case(dir, &c)) {
        fprintf(stderr, "cannot read %s\n", dir);
        return 2;
    }
    fricont_problem *p1 = NULL, *p2 = NULL;
    CHECK(problem_from_case(&c, FRICONT_STORAGE_FULL, 0, &p1) == FRICONT_OK, "problem 1");
    CHECK(problem_from_case(&c, FRICONT_STORAGE_LOWER, 1, &p2) == FRICONT_OK, "problem 2");
    CHECK(fricont_problem_set_friction(p2, 0.6) == FRICONT_OK, "F = 0.6");
    double tol = 1e-9 * fabs(c.alpha_end - c.alpha_start);

    /* the four forms of one affine load */
    job loads[4] = {{p1, &c, AFFINE, {0}}, {p1, &c, GENERAL_DF, {0}}, {p1, &c, GENERAL, {0}}, {p1, &c, BASIS, {0}}};
    for (int k = 0; k < 4; k++) trace(&loads[k]);
    CHECK(loads[0].out.count > 0, "the affine path has events");
    compare("general load with derivative", &loads[0].out, &loads[1].out, tol, c.n);
    compare("general load, finite differences", &loads[0].out, &loads[2].out, tol, c.n);
    compare("basis load", &loads[0].out, &loads[3].out, tol, c.n);

    /* threads: sequential first, then all at once */
    job seq[3] = {{p1, &c, AFFINE, {0}}, {p2, &c, AFFINE, {0}}, {p1, &c, GENERAL_DF, {0}}};
    job par[3] = {{p1, &c, AFFINE, {0}}, {p2, &c, AFFINE, {0}}, {p1, &c, GENERAL_DF, {0}}};
    for (int k = 0; k < 3; k++) trace(&seq[k]);
    pthread_t th[3];
    for (int k = 0; k < 3; k++) CHECK(pthread_create(&th[k], NULL, thread_main, &par[k]) == 0, "pthread_create");
    for (int k = 0; k < 3; k++) pthread_join(th[k], NULL);
    compare("thread 1 (affine, shared problem)", &seq[0].out, &par[0].out, 0, c.n);
    compare("thread 2 (affine, F = 0.6)", &seq[1].out, &par[1].out, 0, c.n);
    compare("thread 3 (general callback, shared problem)", &seq[2].out, &par[2].out, 0, c.n);
    CHECK(seq[0].out.count != seq[1].out.count || memcmp(seq[0].out.alpha, seq[1].out.alpha, sizeof(double) * (size_t)seq[0].out.count) != 0,
          "the two frictions give different paths (the threads are not trivially equal)");
    printf("%s: %lld events (F from the case), %lld events (F = 0.6)\n", dir, (long long)seq[0].out.count,
           (long long)seq[1].out.count);
    for (int k = 0; k < 4; k++) free_result(&loads[k].out);
    for (int k = 0; k < 3; k++) {
        free_result(&seq[k].out);
        free_result(&par[k].out);
    }
    fricont_problem_free(p1);
    fricont_problem_free(p2);
    free_case(&c);
    return finish("paths");
}
