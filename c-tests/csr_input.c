/* CSR input on a problem directory (the sample case by default), through the C API:
 *  - int32_t indices (fricont_csr_i32, fricont_problem_new_i32) give the events of the
 *    same matrices with int64_t indices, bit for bit (full storage 0-based, lower storage
 *    1-based);
 *  - duplicate entries are summed: A, N and T with every entry given as two parts (the
 *    rows' entries in reverse order) give, with either index width, the events of the
 *    matrices whose entries are the sums of the parts, bit for bit.
 * usage: csr_input [DIR] */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "common.h"

typedef struct {
    int64_t count;
    double *alpha;
    int64_t *node;
    int32_t *from, *to, *flags;
    fricont_status status;
} events;

/* Traces a problem (friction and gap of the case set here) over the case's window;
 * frees the problem. */
static events trace(const case_data *c, fricont_problem *p, fricont_status made) {
    events e = {0, NULL, NULL, NULL, NULL, NULL, made};
    if (made != FRICONT_OK) return e;
    fricont_path *path = NULL;
    fricont_status st = set_case_settings(c, p);
    if (st == FRICONT_OK) st = fricont_path_new_affine(p, c->f0, c->f1, c->n, &path);
    if (st == FRICONT_OK) st = fricont_path_set_window(path, c->alpha_start, c->alpha_end);
    if (st == FRICONT_OK) st = fricont_path_start(path, c->alpha_start, NULL, 0);
    if (st == FRICONT_OK) st = fricont_path_run(path);
    e.status = st;
    if (path) {
        fricont_path_event_count(path, &e.count);
        size_t m = (size_t)e.count + 1;
        e.alpha = malloc(sizeof(double) * m);
        e.node = malloc(sizeof(int64_t) * m);
        e.from = malloc(sizeof(int32_t) * m);
        e.to = malloc(sizeof(int32_t) * m);
        e.flags = malloc(sizeof(int32_t) * m);
        for (int64_t k = 0; k < e.count; k++) {
            fricont_event ev;
            fricont_path_event(path, k, &ev);
            e.alpha[k] = ev.alpha;
            e.node[k] = ev.node;
            e.from[k] = ev.from;
            e.to[k] = ev.to;
            e.flags[k] = ev.fold + 2 * ev.bifurcation;
        }
    }
    fricont_path_free(path);
    fricont_problem_free(p);
    return e;
}

static void free_events(events *e) {
    free(e->alpha);
    free(e->node);
    free(e->from);
    free(e->to);
    free(e->flags);
}

/* The same events, alpha bit for bit. */
static void same(const char *what, const events *a, const events *b) {
    CHECK(a->status == FRICONT_END && b->status == FRICONT_END, "%s: statuses %s, %s", what,
          fricont_status_str(a->status), fricont_status_str(b->status));
    CHECK(a->count == b->count && a->count > 0, "%s: %lld vs %lld events", what, (long long)a->count,
          (long long)b->count);
    for (int64_t k = 0; k < a->count && k < b->count; k++)
        CHECK(memcmp(&a->alpha[k], &b->alpha[k], sizeof(double)) == 0 && a->node[k] == b->node[k] &&
                  a->from[k] == b->from[k] && a->to[k] == b->to[k] && a->flags[k] == b->flags[k],
              "%s: event %lld: %.17g node %lld vs %.17g node %lld", what, (long long)k, a->alpha[k],
              (long long)a->node[k] + 1, b->alpha[k], (long long)b->node[k] + 1);
}

/* int32_t copies of a CSR's index arrays (what a caller with 32-bit indices holds). */
typedef struct {
    int32_t *row_ptr, *col_idx;
} idx32;

static idx32 to32(const csr *m) {
    idx32 r = {malloc(sizeof(int32_t) * (size_t)(m->nrows + 1)), malloc(sizeof(int32_t) * (size_t)(m->nnz + 1))};
    for (int64_t i = 0; i <= m->nrows; i++) r.row_ptr[i] = (int32_t)m->row_ptr[i];
    for (int64_t k = 0; k < m->nnz; k++) r.col_idx[k] = (int32_t)m->col_idx[k];
    return r;
}

static fricont_csr_i32 view32(const csr *m, const idx32 *x) {
    fricont_csr_i32 v = {m->nrows, m->ncols, m->nnz, x->row_ptr, x->col_idx, m->values, m->base};
    return v;
}

static void free32(idx32 *x) {
    free(x->row_ptr);
    free(x->col_idx);
}

/* The two parts of a value, and their sum as the library forms it (part a first). */
static double part_a(double v) { return 0.375 * v; }
static double part_b(double v) { return v - 0.375 * v; }

/* `dup`: every entry of `m` as two (part a of the row's entries in reverse order, then
 * part b in order); `sum`: `m` with each value replaced by part a + part b. */
static void split(const csr *m, csr *dup, csr *sum) {
    *dup = *m;
    *sum = *m;
    dup->nnz = 2 * m->nnz;
    dup->row_ptr = malloc(sizeof(int64_t) * (size_t)(m->nrows + 1));
    dup->col_idx = malloc(sizeof(int64_t) * (size_t)(dup->nnz + 1));
    dup->values = malloc(sizeof(double) * (size_t)(dup->nnz + 1));
    sum->row_ptr = malloc(sizeof(int64_t) * (size_t)(m->nrows + 1));
    sum->col_idx = malloc(sizeof(int64_t) * (size_t)(m->nnz + 1));
    sum->values = malloc(sizeof(double) * (size_t)(m->nnz + 1));
    memcpy(sum->row_ptr, m->row_ptr, sizeof(int64_t) * (size_t)(m->nrows + 1));
    memcpy(sum->col_idx, m->col_idx, sizeof(int64_t) * (size_t)m->nnz);
    int64_t b = m->base, q = 0;
    dup->row_ptr[0] = b;
    for (int64_t i = 0; i < m->nrows; i++) {
        int64_t lo = m->row_ptr[i] - b, hi = m->row_ptr[i + 1] - b;
        for (int64_t k = hi - 1; k >= lo; k--) {
            dup->col_idx[q] = m->col_idx[k];
            dup->values[q++] = part_a(m->values[k]);
        }
        for (int64_t k = lo; k < hi; k++) {
            dup->col_idx[q] = m->col_idx[k];
            dup->values[q++] = part_b(m->values[k]);
            sum->values[k] = part_a(m->values[k]) + part_b(m->values[k]);
        }
        dup->row_ptr[i + 1] = q + b;
    }
}

static events trace64(const case_data *c, const csr *a, int32_t storage, const csr *n, const csr *t) {
    fricont_csr av = csr_view(a), nv = csr_view(n), tv = csr_view(t);
    fricont_problem *p = NULL;
    fricont_status st = fricont_problem_new(&av, storage, &nv, &tv, &p);
    return trace(c, p, st);
}

static events trace32(const case_data *c, const csr *a, int32_t storage, const csr *n, const csr *t) {
    idx32 ai = to32(a), ni = to32(n), ti = to32(t);
    fricont_csr_i32 av = view32(a, &ai), nv = view32(n, &ni), tv = view32(t, &ti);
    fricont_problem *p = NULL;
    fricont_status st = fricont_problem_new_i32(&av, storage, &nv, &tv, &p);
    free32(&ai);
    free32(&ni);
    free32(&ti);
    return trace(c, p, st);
}

int main(int argc, char **argv) {
    const char *dir = argc > 1 ? argv[1] : "tests/data/sample-rect30";
    case_data c;
    if (read_case(dir, &c)) {
        fprintf(stderr, "cannot read %s\n", dir);
        return 2;
    }
    struct {
        int32_t storage;
        enum which_part part;
        int64_t base;
        const char *name;
    } forms[2] = {{FRICONT_STORAGE_FULL, PART_FULL, 0, "full, 0-based"},
                  {FRICONT_STORAGE_LOWER, PART_LOWER, 1, "lower, 1-based"}};
    for (int f = 0; f < 2; f++) {
        csr a = csr_from_triplets(&c.a, forms[f].part, forms[f].base);
        csr n = csr_from_triplets(&c.nm, PART_FULL, forms[f].base);
        csr t = csr_from_triplets(&c.tm, PART_FULL, forms[f].base);
        char what[128];
        events e64 = trace64(&c, &a, forms[f].storage, &n, &t);
        events e32 = trace32(&c, &a, forms[f].storage, &n, &t);
        snprintf(what, sizeof what, "int32 vs int64 indices (%s)", forms[f].name);
        same(what, &e64, &e32);

        csr ad, as, nd, ns, td, ts;
        split(&a, &ad, &as);
        split(&n, &nd, &ns);
        split(&t, &td, &ts);
        events sum = trace64(&c, &as, forms[f].storage, &ns, &ts);
        events d64 = trace64(&c, &ad, forms[f].storage, &nd, &td);
        events d32 = trace32(&c, &ad, forms[f].storage, &nd, &td);
        snprintf(what, sizeof what, "duplicates summed, int64 (%s)", forms[f].name);
        same(what, &sum, &d64);
        snprintf(what, sizeof what, "duplicates summed, int32 (%s)", forms[f].name);
        same(what, &sum, &d32);
        printf("%s (%s): %lld events, %lld entries of A given as %lld\n", dir, forms[f].name,
               (long long)e64.count, (long long)a.nnz, (long long)ad.nnz);
        free_events(&e64);
        free_events(&e32);
        free_events(&sum);
        free_events(&d64);
        free_events(&d32);
        csr *all[9] = {&a, &n, &t, &ad, &as, &nd, &ns, &td, &ts};
        for (int k = 0; k < 9; k++) free_csr(all[k]);
    }
    free_case(&c);
    return finish("csr_input");
}
