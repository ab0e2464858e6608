/* The monitor, the largest alpha step and re-entrant callbacks, on a problem directory
 * (the sample case by default). Reference: the same affine path run without a monitor.
 *  - a monitor is called once per transition point with alpha, the transition count and
 *    the new events (which it reads through fricont_path_event from inside the call);
 *    returning nonzero ends the path with FRICONT_END_STOPPED, and running again continues
 *    to the reference's end with the reference's events;
 *  - its finalizer runs exactly once: when the monitor is replaced, removed, or the path
 *    freed, and when fricont_path_set_monitor fails on a NULL handle;
 *  - a load callback that calls back into its own path gets FRICONT_ERR_ORDER (not a
 *    caught panic): the path traces on, unpoisoned, to the reference's events;
 *  - fricont_path_set_max_alpha_step: range and order errors; a general load with a small
 *    largest step still gives the reference's events.
 * usage: monitor [DIR] */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "common.h"

typedef struct {
    int64_t count;
    double *alpha;
    int64_t *node;
} events;

static events collect(fricont_path *path) {
    events e = {0, NULL, NULL};
    fricont_path_event_count(path, &e.count);
    e.alpha = malloc(sizeof(double) * (size_t)(e.count + 1));
    e.node = malloc(sizeof(int64_t) * (size_t)(e.count + 1));
    for (int64_t k = 0; k < e.count; k++) {
        fricont_event ev;
        fricont_path_event(path, k, &ev);
        e.alpha[k] = ev.alpha;
        e.node[k] = ev.node;
    }
    return e;
}

static void free_events(events *e) {
    free(e->alpha);
    free(e->node);
}

static int same_events(const events *a, const events *b, double tol) {
    if (a->count != b->count) return 0;
    for (int64_t k = 0; k < a->count; k++) {
        if (fabs(a->alpha[k] - b->alpha[k]) > tol * fmax(1.0, fabs(a->alpha[k]))) return 0;
        if (a->node[k] != b->node[k]) return 0;
    }
    return 1;
}

typedef struct {
    fricont_path **path;
    int calls, stop_at, bad_reads, order_errors;
    int64_t last_transitions, last_end;
    int freed;
} monitor_ud;

static int32_t monitor(double alpha, int64_t transitions, int64_t first, int64_t end, void *ud) {
    monitor_ud *m = ud;
    m->calls++;
    if (transitions != m->last_transitions + 1 || first != m->last_end || end <= first) m->bad_reads++;
    /* the path can be read from inside the monitor */
    int64_t count = -1;
    if (fricont_path_event_count(*m->path, &count) != FRICONT_OK || count != end) m->bad_reads++;
    for (int64_t k = first; k < end; k++) {
        fricont_event ev;
        if (fricont_path_event(*m->path, k, &ev) != FRICONT_OK || ev.alpha != alpha ||
            ev.transition != transitions - 1)
            m->bad_reads++;
    }
    m->last_transitions = transitions;
    m->last_end = end;
    return transitions == m->stop_at ? 7 : 0;
}

static void free_monitor_ud(void *ud) { ((monitor_ud *)ud)->freed++; }

typedef struct {
    const case_data *c;
    fricont_path **path;
    int order_errors, other;
} load_ud;

static int32_t reentrant_load(double alpha, double *f, int64_t n, void *ud) {
    load_ud *d = ud;
    int64_t count;
    fricont_status st = fricont_path_event_count(*d->path, &count);
    if (st == FRICONT_ERR_ORDER) {
        d->order_errors++;
    } else {
        d->other++;
    }
    for (int64_t i = 0; i < n; i++) f[i] = d->c->f0[i] + alpha * d->c->f1[i];
    return 0;
}

static int32_t plain_load(double alpha, double *f, int64_t n, void *ud) {
    load_ud *d = ud;
    for (int64_t i = 0; i < n; i++) f[i] = d->c->f0[i] + alpha * d->c->f1[i];
    return 0;
}

int main(int argc, char **argv) {
    const char *dir = argc > 1 ? argv[1] : "tests/data/sample-rect30";
    case_data c;
    if (read_case(dir, &c) != 0) {
        fprintf(stderr, "cannot read %s\n", dir);
        return 1;
    }
    fricont_problem *pb = NULL;
    CHECK(problem_from_case(&c, FRICONT_STORAGE_FULL, 0, &pb) == FRICONT_OK, "problem");

    /* reference */
    fricont_path *ref = NULL;
    CHECK(fricont_path_new_affine(pb, c.f0, c.f1, c.n, &ref) == FRICONT_OK, "reference path");
    fricont_path_set_window(ref, c.alpha_start, c.alpha_end);
    fricont_path_start(ref, c.alpha_start, NULL, 0);
    CHECK(fricont_path_run(ref) == FRICONT_END, "reference run");
    int32_t ref_reason = -1;
    fricont_path_end_reason(ref, &ref_reason);
    events want = collect(ref);
    CHECK(want.count >= 4, "the reference has %lld events, need >= 4", (long long)want.count);

    /* a monitor that stops at the third transition point */
    fricont_path *path = NULL;
    monitor_ud m = {&path, 0, 3, 0, 0, 0, 0, 0};
    CHECK(fricont_path_new_affine(pb, c.f0, c.f1, c.n, &path) == FRICONT_OK, "path");
    fricont_path_set_window(path, c.alpha_start, c.alpha_end);
    CHECK(fricont_path_set_monitor(path, monitor, &m, free_monitor_ud) == FRICONT_OK, "set monitor");
    fricont_path_start(path, c.alpha_start, NULL, 0);
    CHECK(fricont_path_run(path) == FRICONT_END, "monitored run");
    int32_t reason = -1;
    fricont_path_end_reason(path, &reason);
    CHECK(reason == FRICONT_END_STOPPED, "end reason %d, expected FRICONT_END_STOPPED", reason);
    CHECK(m.calls == 3, "monitor called %d times before stopping", m.calls);
    int64_t count = -1;
    fricont_path_event_count(path, &count);
    CHECK(count == m.last_end, "%lld events after the stop, the monitor saw %lld", (long long)count,
          (long long)m.last_end);
    for (int64_t k = 0; k < count && k < want.count; k++) {
        fricont_event ev;
        fricont_path_event(path, k, &ev);
        CHECK(ev.alpha == want.alpha[k] && ev.node == want.node[k], "event %lld before the stop",
              (long long)k);
    }
    /* running again continues to the reference's end */
    CHECK(fricont_path_run(path) == FRICONT_END, "second run");
    fricont_path_end_reason(path, &reason);
    CHECK(reason == ref_reason, "end reason %d after the restart, reference %d", reason, ref_reason);
    events got = collect(path);
    CHECK(same_events(&got, &want, 0.0), "events after the restart differ from the reference");
    CHECK(m.bad_reads == 0, "%d wrong arguments or reads inside the monitor", m.bad_reads);
    free_events(&got);
    /* the finalizer: once on replacement, nothing on removal of the new (none), once on free */
    monitor_ud m2 = {&path, 0, -1, 0, 0, 0, 0, 0};
    CHECK(fricont_path_set_monitor(path, monitor, &m2, free_monitor_ud) == FRICONT_OK, "replace");
    CHECK(m.freed == 1, "finalizer of the replaced monitor ran %d times", m.freed);
    CHECK(fricont_path_set_monitor(path, NULL, NULL, NULL) == FRICONT_OK, "remove");
    CHECK(m2.freed == 1, "finalizer of the removed monitor ran %d times", m2.freed);
    monitor_ud m3 = {&path, 0, -1, 0, 0, 0, 0, 0};
    fricont_path_set_monitor(path, monitor, &m3, free_monitor_ud);
    fricont_path_free(path);
    CHECK(m3.freed == 1, "finalizer on free ran %d times", m3.freed);
    monitor_ud m4 = {NULL, 0, -1, 0, 0, 0, 0, 0};
    CHECK(fricont_path_set_monitor(NULL, monitor, &m4, free_monitor_ud) == FRICONT_ERR_NULL,
          "NULL path");
    CHECK(m4.freed == 1, "finalizer after a failed set ran %d times", m4.freed);

    /* a load callback calling back into its own path */
    fricont_path *rp = NULL;
    load_ud ld = {&c, &rp, 0, 0};
    CHECK(fricont_path_new_general(pb, c.n, reentrant_load, NULL, &ld, NULL, &rp) == FRICONT_OK,
          "general path");
    fricont_path_set_window(rp, c.alpha_start, c.alpha_end);
    CHECK(fricont_path_start(rp, c.alpha_start, NULL, 0) == FRICONT_OK, "start");
    CHECK(fricont_path_run(rp) == FRICONT_END, "re-entrant run");
    CHECK(ld.order_errors > 0 && ld.other == 0,
          "calls into the path from its load callback: %d FRICONT_ERR_ORDER, %d other", ld.order_errors,
          ld.other);
    events re = collect(rp);
    CHECK(same_events(&re, &want, 1e-9), "events with a re-entrant callback differ");
    CHECK(fricont_path_event_count(rp, &count) == FRICONT_OK, "the path is not poisoned");
    free_events(&re);
    fricont_path_free(rp);

    /* the largest alpha step */
    fricont_path *sp = NULL;
    load_ud pl = {&c, NULL, 0, 0};
    fricont_path_new_general(pb, c.n, plain_load, NULL, &pl, NULL, &sp);
    fricont_path_set_window(sp, c.alpha_start, c.alpha_end);
    CHECK(fricont_path_set_max_alpha_step(NULL, 0.1) == FRICONT_ERR_NULL, "NULL");
    CHECK(fricont_path_set_max_alpha_step(sp, 0.0) == FRICONT_ERR_RANGE, "0");
    CHECK(fricont_path_set_max_alpha_step(sp, -1.0) == FRICONT_ERR_RANGE, "-1");
    CHECK(fricont_path_set_max_alpha_step(sp, NAN) == FRICONT_ERR_RANGE, "NaN");
    CHECK(fricont_path_set_max_alpha_step(sp, INFINITY) == FRICONT_ERR_RANGE, "inf");
    double h = (c.alpha_end - c.alpha_start) / 400.0;
    CHECK(fricont_path_set_max_alpha_step(sp, fabs(h)) == FRICONT_OK, "valid step");
    fricont_path_start(sp, c.alpha_start, NULL, 0);
    CHECK(fricont_path_set_max_alpha_step(sp, 0.1) == FRICONT_ERR_ORDER, "after the start");
    CHECK(fricont_path_run(sp) == FRICONT_END, "run with a small step");
    events sm = collect(sp);
    CHECK(same_events(&sm, &want, 1e-9), "events with max_alpha_step differ from the reference");
    free_events(&sm);
    fricont_path_free(sp);

    free_events(&want);
    fricont_path_free(ref);
    fricont_problem_free(pb);
    free_case(&c);
    return finish("monitor");
}
