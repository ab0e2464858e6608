/* Every status code the C API can return, provoked on purpose (plus the outcomes on small
 * problems solved by hand). Each error must come back with its documented code and a
 * specific message, never a crash. Run under valgrind by run.sh.
 *
 * Not provoked here: FRICONT_BIFURCATION (several continuing pieces of which exactly one
 * preserves the orientation: index theory makes this rare, and 100000 random
 * mirror-symmetric pairs gave only stops, FRICONT_END_BIFURCATION, tested below),
 * FRICONT_ERR_SOLVE_FAILED and FRICONT_ERR_NUMERICAL
 * (no input is known to make the core fail that way), FRICONT_ERR_PANIC and
 * FRICONT_ERR_POISONED (no panic is reachable; the boundary is tested in Rust,
 * src/ffi/tests.rs). Their strings are checked. */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#ifdef __linux__
#include <dirent.h>
#endif

#include "common.h"

static char msg[1024];

/* The thread-local message of the last failing call. */
static const char *last(void) {
    fricont_last_error_message(msg, sizeof msg);
    return msg;
}

/* Expects status `want` with a message containing `needle`. */
#define EXPECT(call, want, needle)                                                               \
    do {                                                                                         \
        fricont_status got_ = (call);                                                            \
        CHECK(got_ == (want), "%s returned %d (%s), expected %s; message: %s", #call, (int)got_, \
              fricont_status_str(got_), #want, last());                                          \
        if ((want) < 0)                                                                          \
            CHECK(strstr(last(), (needle)) != NULL, "%s: message \"%s\" lacks \"%s\"", #call,    \
                  msg, (needle));                                                                \
    } while (0)

/* ---- the block on a foundation (src/ffi/tests.rs derives it by hand) ----
 * n = 2, A = diag(2, 1), N = [1 0], T = [0 1], F = 1/2, f(alpha) = (1, 0) + alpha (0, 1):
 * stick with lambda = (-1, -alpha) up to alpha = 1/2, then slip+ (u_2 = alpha - 1/2). */
static int64_t a_rp[] = {0, 1, 2}, a_ci[] = {0, 1};
static double a_v[] = {2.0, 1.0};
static int64_t n_rp[] = {0, 1}, n_ci[] = {0};
static double n_v[] = {1.0};
static int64_t t_rp[] = {0, 1}, t_ci[] = {1};
static double t_v[] = {1.0};
static double f0[] = {1.0, 0.0}, f1[] = {0.0, 1.0};

static fricont_csr mk(int64_t nr, int64_t nc, int64_t nnz, int64_t *rp, int64_t *ci, double *v,
                      int64_t base) {
    fricont_csr m = {nr, nc, nnz, rp, ci, v, base};
    return m;
}

static fricont_problem *block(void) {
    fricont_csr a = mk(2, 2, 2, a_rp, a_ci, a_v, 0), n = mk(1, 2, 1, n_rp, n_ci, n_v, 0),
                t = mk(1, 2, 1, t_rp, t_ci, t_v, 0);
    fricont_problem *p = NULL;
    EXPECT(fricont_problem_new(&a, FRICONT_STORAGE_FULL, &n, &t, &p), FRICONT_OK, "");
    EXPECT(fricont_problem_set_friction(p, 0.5), FRICONT_OK, "");
    return p;
}

static void test_csr_errors(void) {
    fricont_csr a = mk(2, 2, 2, a_rp, a_ci, a_v, 0), n = mk(1, 2, 1, n_rp, n_ci, n_v, 0),
                t = mk(1, 2, 1, t_rp, t_ci, t_v, 0);
    fricont_problem *p = (fricont_problem *)&a; /* must be overwritten with NULL */
    EXPECT(fricont_problem_new(NULL, 0, &n, &t, &p), FRICONT_ERR_NULL, "A is NULL");
    CHECK(p == NULL, "out is cleared on failure");
    EXPECT(fricont_problem_new(&a, 0, &n, &t, NULL), FRICONT_ERR_NULL, "out");
    fricont_csr b = a;
    b.row_ptr = NULL;
    EXPECT(fricont_problem_new(&b, 0, &n, &t, &p), FRICONT_ERR_NULL, "A.row_ptr");
    b = a;
    b.values = NULL;
    EXPECT(fricont_problem_new(&b, 0, &n, &t, &p), FRICONT_ERR_NULL, "A.values");
    b = a;
    b.nrows = -1;
    EXPECT(fricont_problem_new(&b, 0, &n, &t, &p), FRICONT_ERR_LENGTH, "A.nrows");
    /* row pointer not monotone */
    int64_t rp_dec[] = {0, 2, 1};
    b = a;
    b.row_ptr = rp_dec;
    EXPECT(fricont_problem_new(&b, 0, &n, &t, &p), FRICONT_ERR_CSR, "decreases");
    /* row pointer not ending at nnz */
    int64_t rp_short[] = {0, 1, 1};
    b = a;
    b.row_ptr = rp_short;
    EXPECT(fricont_problem_new(&b, 0, &n, &t, &p), FRICONT_ERR_CSR, "row_ptr");
    /* column out of range */
    int64_t ci_out[] = {0, 2};
    b = a;
    b.col_idx = ci_out;
    EXPECT(fricont_problem_new(&b, 0, &n, &t, &p), FRICONT_ERR_CSR, "column index 2");
    int64_t ci_neg[] = {-1, 1};
    b = a;
    b.col_idx = ci_neg;
    EXPECT(fricont_problem_new(&b, 0, &n, &t, &p), FRICONT_ERR_CSR, "column index -1");
    /* duplicate entries are summed: A(0, 0) = 1.5 + 0.5 gives A = diag(2, 1), the block's
     * A, so the default r is the block's (W = diag(1/2, 1), r0 = 2p / trace W = 2 / 1.5) */
    int64_t rp_dup[] = {0, 2, 3}, ci_dup[] = {0, 0, 1};
    double v_dup[] = {1.5, 0.5, 1.0};
    b = mk(2, 2, 3, rp_dup, ci_dup, v_dup, 0);
    EXPECT(fricont_problem_new(&b, 0, &n, &t, &p), FRICONT_OK, "");
    double r_dup = 0, r0_dup = 0;
    EXPECT(fricont_problem_r(p, &r_dup, &r0_dup), FRICONT_OK, "");
    CHECK(fabs(r0_dup - 2.0 / 1.5) <= 1e-15, "duplicates summed: r0 = %.17g", r0_dup);
    fricont_problem_free(p);
    /* a sum of duplicates that overflows */
    double v_big[] = {1e308, 1e308, 1.0};
    b = mk(2, 2, 3, rp_dup, ci_dup, v_big, 0);
    EXPECT(fricont_problem_new(&b, 0, &n, &t, &p), FRICONT_ERR_NONFINITE, "sum to inf");
    /* extreme int64 values: errors, never an overflow in the library's index arithmetic
     * (checked in debug builds too by tests/core_errors.rs) */
    int64_t rp_min[] = {0, INT64_MIN, 2}, rp_max[] = {0, 1, INT64_MAX};
    b = a;
    b.row_ptr = rp_min;
    EXPECT(fricont_problem_new(&b, 0, &n, &t, &p), FRICONT_ERR_CSR, "decreases");
    b.row_ptr = rp_max;
    EXPECT(fricont_problem_new(&b, 0, &n, &t, &p), FRICONT_ERR_CSR, "outside");
    int64_t ci_max[] = {0, INT64_MAX}, ci_min[] = {INT64_MIN, 1};
    b = a;
    b.col_idx = ci_max;
    EXPECT(fricont_problem_new(&b, 0, &n, &t, &p), FRICONT_ERR_CSR, "column index");
    b.col_idx = ci_min;
    b.index_base = 1;
    int64_t rp_one[] = {1, 2, 3};
    b.row_ptr = rp_one;
    EXPECT(fricont_problem_new(&b, 0, &n, &t, &p), FRICONT_ERR_CSR, "column index");
    int64_t rp_first_max[] = {INT64_MAX, INT64_MAX, INT64_MAX};
    b = a;
    b.row_ptr = rp_first_max;
    b.index_base = 1;
    EXPECT(fricont_problem_new(&b, 0, &n, &t, &p), FRICONT_ERR_CSR, "row_ptr[0]");
    b = a;
    b.index_base = INT64_MIN;
    EXPECT(fricont_problem_new(&b, 0, &n, &t, &p), FRICONT_ERR_CSR, "index_base");
    b = a;
    b.nrows = INT64_MAX;
    EXPECT(fricont_problem_new(&b, 0, &n, &t, &p), FRICONT_ERR_LENGTH, "not a valid length");
    b = a;
    b.nnz = INT64_MAX;
    EXPECT(fricont_problem_new(&b, 0, &n, &t, &p), FRICONT_ERR_LENGTH, "not a valid length");
    b = a;
    b.ncols = INT64_MIN;
    EXPECT(fricont_problem_new(&b, 0, &n, &t, &p), FRICONT_ERR_LENGTH, "not a valid length");
    /* index base 2 */
    b = a;
    b.index_base = 2;
    EXPECT(fricont_problem_new(&b, 0, &n, &t, &p), FRICONT_ERR_CSR, "index_base is 2");
    /* a 0-based matrix declared 1-based */
    b = a;
    b.index_base = 1;
    EXPECT(fricont_problem_new(&b, 0, &n, &t, &p), FRICONT_ERR_CSR, "row_ptr[0]");
    /* NaN in A */
    double v_nan[] = {2.0, NAN};
    b = a;
    b.values = v_nan;
    EXPECT(fricont_problem_new(&b, 0, &n, &t, &p), FRICONT_ERR_NONFINITE, "NaN");
    double v_inf[] = {INFINITY, 1.0};
    b = a;
    b.values = v_inf;
    EXPECT(fricont_problem_new(&b, 0, &n, &t, &p), FRICONT_ERR_NONFINITE, "inf");
    /* dimensions */
    fricont_csr t3 = mk(1, 3, 1, t_rp, t_ci, t_v, 0);
    EXPECT(fricont_problem_new(&a, 0, &n, &t3, &p), FRICONT_ERR_LENGTH, "T is 1x3");
    int64_t rp_rect[] = {0, 1};
    fricont_csr arect = mk(1, 2, 1, rp_rect, a_ci, a_v, 0);
    EXPECT(fricont_problem_new(&arect, 0, &n, &t, &p), FRICONT_ERR_LENGTH, "square");
    int64_t rp_none[] = {0};
    fricont_csr n0 = mk(0, 2, 0, rp_none, NULL, NULL, 0);
    EXPECT(fricont_problem_new(&a, 0, &n0, &n0, &p), FRICONT_ERR_LENGTH, "at least one contact node");
    /* storage */
    EXPECT(fricont_problem_new(&a, 7, &n, &t, &p), FRICONT_ERR_RANGE, "a_storage = 7");
    /* an entry in the wrong triangle: detected when built */
    int64_t rp_up[] = {0, 2, 3}, ci_up[] = {0, 1, 1};
    double v_up[] = {2.0, 0.1, 1.0};
    b = mk(2, 2, 3, rp_up, ci_up, v_up, 0);
    EXPECT(fricont_problem_new(&b, FRICONT_STORAGE_LOWER, &n, &t, &p), FRICONT_OK, "");
    EXPECT(fricont_problem_build(p), FRICONT_ERR_CSR, "other triangle");
    fricont_problem_free(p);
    /* the same matrix as upper storage is fine */
    EXPECT(fricont_problem_new(&b, FRICONT_STORAGE_UPPER, &n, &t, &p), FRICONT_OK, "");
    EXPECT(fricont_problem_build(p), FRICONT_OK, "");
    fricont_problem_free(p);
    /* not symmetric in full storage */
    EXPECT(fricont_problem_new(&b, FRICONT_STORAGE_FULL, &n, &t, &p), FRICONT_OK, "");
    EXPECT(fricont_problem_build(p), FRICONT_ERR_NOT_SYMMETRIC, "differ");
    fricont_problem_free(p);
    /* not positive definite */
    double v_neg[] = {2.0, -1.0};
    b = a;
    b.values = v_neg;
    EXPECT(fricont_problem_new(&b, 0, &n, &t, &p), FRICONT_OK, "");
    fricont_status st_spd = fricont_problem_build(p);
    EXPECT(st_spd, FRICONT_ERR_NOT_SPD, "pivot");
    CHECK(fricont_problem_error_message(p, NULL, 0) > 10, "the message is on the handle too");
    if (st_spd == FRICONT_ERR_PANIC) /* a bug, but then the handle must be poisoned */
        EXPECT(fricont_problem_set_friction(p, 0.1), FRICONT_ERR_POISONED, "poisoned");
    fricont_problem_free(p);
    /* rank-deficient B: T = N */
    EXPECT(fricont_problem_new(&a, 0, &n, &n, &p), FRICONT_OK, "");
    EXPECT(fricont_problem_build(p), FRICONT_ERR_RANK_DEFICIENT, "rank");
    fricont_problem_free(p);
    /* 2p > n: two contact nodes on two dofs */
    int64_t rp2[] = {0, 1, 2}, ci2[] = {0, 1};
    double v2[] = {1.0, 1.0};
    fricont_csr n2 = mk(2, 2, 2, rp2, ci2, v2, 0);
    EXPECT(fricont_problem_new(&a, 0, &n2, &n2, &p), FRICONT_OK, "");
    EXPECT(fricont_problem_build(p), FRICONT_ERR_LENGTH, "2p = 4 exceeds n = 2");
    fricont_problem_free(p);
}

static void test_problem_setters(void) {
    fricont_problem *p = block();
    EXPECT(fricont_problem_set_friction(NULL, 0.1), FRICONT_ERR_NULL, "problem");
    EXPECT(fricont_problem_set_friction(p, -0.1), FRICONT_ERR_RANGE, "F = -0.1");
    EXPECT(fricont_problem_set_friction(p, NAN), FRICONT_ERR_RANGE, "F = NaN");
    double fr[] = {0.5, 0.5};
    EXPECT(fricont_problem_set_friction_nodes(p, fr, 2), FRICONT_ERR_LENGTH, "expected p = 1");
    EXPECT(fricont_problem_set_friction_nodes(p, NULL, 1), FRICONT_ERR_NULL, "friction");
    double frneg[] = {-2.0};
    EXPECT(fricont_problem_set_friction_nodes(p, frneg, 1), FRICONT_ERR_RANGE, "node 1");
    EXPECT(fricont_problem_set_friction_nodes(p, fr, -1), FRICONT_ERR_LENGTH, "len = -1");
    EXPECT(fricont_problem_set_r(p, 0.0), FRICONT_ERR_RANGE, "r = 0");
    EXPECT(fricont_problem_set_r(p, -1.0), FRICONT_ERR_RANGE, "r = -1");
    EXPECT(fricont_problem_set_r(p, INFINITY), FRICONT_ERR_RANGE, "r = inf");
    EXPECT(fricont_problem_set_threads(NULL, 2), FRICONT_ERR_NULL, "problem");
    EXPECT(fricont_problem_set_threads(p, 0), FRICONT_ERR_RANGE, "threads = 0");
    EXPECT(fricont_problem_set_threads(p, -3), FRICONT_ERR_RANGE, "threads = -3");
    EXPECT(fricont_problem_set_threads(p, 1025), FRICONT_ERR_RANGE, "threads = 1025");
    EXPECT(fricont_problem_set_threads(p, 1), FRICONT_OK, "");
    double g2[] = {0.0, 0.0}, gnan[] = {NAN};
    EXPECT(fricont_problem_set_gap(p, g2, 2), FRICONT_ERR_LENGTH, "gap has 2 values");
    EXPECT(fricont_problem_set_gap(p, gnan, 1), FRICONT_ERR_NONFINITE, "gap[0]");
    EXPECT(fricont_problem_set_gap(p, NULL, 0), FRICONT_OK, "");
    int64_t n = -1, pp = -1;
    EXPECT(fricont_problem_dims(p, &n, &pp), FRICONT_OK, "");
    CHECK(n == 2 && pp == 1, "dims %lld %lld", (long long)n, (long long)pp);
    EXPECT(fricont_problem_dims(NULL, &n, &pp), FRICONT_ERR_NULL, "problem");
    /* r: default 2p / trace W = 2 / (1/2 + 1) */
    double r = 0, r0 = 0;
    EXPECT(fricont_problem_r(p, &r, &r0), FRICONT_OK, "");
    CHECK(fabs(r0 - 4.0 / 3.0) < 1e-15 && r == r0, "default r %.17g", r0);
    EXPECT(fricont_problem_set_r(p, 3.0), FRICONT_OK, "");
    EXPECT(fricont_problem_r(p, &r, &r0), FRICONT_OK, "");
    CHECK(r == 3.0 && fabs(r0 - 4.0 / 3.0) < 1e-15, "r after set_r %g", r);
    /* r far from the default: refused, the setting unchanged */
    EXPECT(fricont_problem_set_r(p, 1e300), FRICONT_ERR_RANGE, "outside [1e-6, 1e6]");
    EXPECT(fricont_problem_set_r(p, 1e-300), FRICONT_ERR_RANGE, "outside [1e-6, 1e6]");
    EXPECT(fricont_problem_r(p, &r, &r0), FRICONT_OK, "");
    CHECK(r == 3.0, "r after refused set_r %g", r);
    /* snprintf semantics of the messages */
    EXPECT(fricont_problem_set_friction(p, -7.0), FRICONT_ERR_RANGE, "F = -7");
    size_t full = fricont_problem_error_message(p, NULL, 0);
    char small[8];
    memset(small, 'x', sizeof small);
    size_t got = fricont_problem_error_message(p, small, sizeof small);
    CHECK(got == full && full > sizeof small, "length %zu vs %zu", got, full);
    CHECK(strlen(small) == sizeof small - 1, "cut to len - 1 bytes and a NUL");
    CHECK(fricont_problem_error_message(NULL, small, sizeof small) == 0, "NULL handle: 0");
    CHECK(fricont_last_error_message(NULL, 0) == full, "the thread-local copy");
    fricont_problem_free(p);
    fricont_problem_free(NULL); /* no-op */
}

/* Callback state: counts calls and finalizations; fails on request. */
typedef struct {
    int fail_above_set;
    double fail_above;
    int32_t code;
    int write_nan;
    int calls, finalized;
} cb_data;

static int32_t load_cb(double alpha, double *f, int64_t n, void *ud) {
    cb_data *d = ud;
    d->calls++;
    if (d->fail_above_set && alpha > d->fail_above) return d->code;
    for (int64_t i = 0; i < n; i++) f[i] = f0[i] + alpha * f1[i];
    if (d->write_nan && alpha > d->fail_above) f[0] = NAN;
    return 0;
}

static int32_t dload_cb(double alpha, double *f, int64_t n, void *ud) {
    (void)alpha;
    (void)ud;
    for (int64_t i = 0; i < n; i++) f[i] = f1[i];
    return 0;
}

static int32_t weights_cb(double alpha, double *phi, double *dphi, int64_t k, void *ud) {
    cb_data *d = ud;
    d->calls++;
    if (k != 2) return 99;
    if (d->fail_above_set && alpha > d->fail_above) return d->code;
    phi[0] = 1.0;
    phi[1] = alpha;
    dphi[0] = 0.0;
    dphi[1] = 1.0;
    return 0;
}

static void finalize_cb(void *ud) { ((cb_data *)ud)->finalized++; }

static void test_path_construction(void) {
    fricont_problem *p = block();
    fricont_path *path = (fricont_path *)p;
    EXPECT(fricont_path_new_affine(NULL, f0, f1, 2, &path), FRICONT_ERR_NULL, "problem");
    CHECK(path == NULL, "out cleared");
    EXPECT(fricont_path_new_affine(p, f0, f1, 2, NULL), FRICONT_ERR_NULL, "out");
    EXPECT(fricont_path_new_affine(p, NULL, f1, 2, &path), FRICONT_ERR_NULL, "f0");
    /* (arrays of 3: the library may read n entries before it compares n with the
     * problem's; AddressSanitizer holds the test to that contract) */
    double f0_3[] = {1.0, 0.0, 0.0}, f1_3[] = {0.0, 1.0, 0.0};
    EXPECT(fricont_path_new_affine(p, f0_3, f1_3, 3, &path), FRICONT_ERR_LENGTH, "n = 2");
    EXPECT(fricont_path_new_affine(p, f0, f1, -2, &path), FRICONT_ERR_LENGTH, "n = -2");
    double fnan[] = {0.0, NAN};
    EXPECT(fricont_path_new_affine(p, f0, fnan, 2, &path), FRICONT_ERR_NONFINITE, "f1");
    /* a build error surfaces at path creation, on the problem and thread-locally */
    double v_neg[] = {2.0, -1.0};
    fricont_csr a = mk(2, 2, 2, a_rp, a_ci, v_neg, 0), n = mk(1, 2, 1, n_rp, n_ci, n_v, 0),
                t = mk(1, 2, 1, t_rp, t_ci, t_v, 0);
    fricont_problem *bad = NULL;
    EXPECT(fricont_problem_new(&a, 0, &n, &t, &bad), FRICONT_OK, "");
    EXPECT(fricont_path_new_affine(bad, f0, f1, 2, &path), FRICONT_ERR_NOT_SPD, "positive definite");
    fricont_problem_free(bad);
    /* basis and general: the finalizer runs exactly once, also on failure */
    cb_data d = {0, 0, 0, 0, 0, 0};
    double vecs[] = {1.0, 0.0, 0.0, 1.0};
    EXPECT(fricont_path_new_basis(p, vecs, 2, 0, weights_cb, &d, finalize_cb, &path), FRICONT_ERR_LENGTH, "k = 0");
    CHECK(d.finalized == 1, "finalizer after a failed basis creation: %d", d.finalized);
    EXPECT(fricont_path_new_basis(p, vecs, 2, 2, NULL, &d, finalize_cb, &path), FRICONT_ERR_NULL, "weights");
    CHECK(d.finalized == 2, "finalizer after NULL weights");
    EXPECT(fricont_path_new_basis(p, NULL, 2, 2, weights_cb, &d, finalize_cb, &path), FRICONT_ERR_NULL, "vectors");
    EXPECT(fricont_path_new_general(p, 2, NULL, NULL, &d, finalize_cb, &path), FRICONT_ERR_NULL, "f (the load callback)");
    EXPECT(fricont_path_new_general(NULL, 2, load_cb, NULL, &d, finalize_cb, &path), FRICONT_ERR_NULL, "problem");
    EXPECT(fricont_path_new_general(p, 5, load_cb, NULL, &d, finalize_cb, &path), FRICONT_ERR_LENGTH, "n = 2");
    CHECK(d.finalized == 6, "finalizer once per failed creation: %d", d.finalized);
    EXPECT(fricont_path_new_general(p, 2, load_cb, dload_cb, &d, finalize_cb, &path), FRICONT_OK, "");
    CHECK(d.calls == 0 && d.finalized == 6, "no callback at creation");
    fricont_path_free(path);
    CHECK(d.finalized == 7, "finalizer at free");
    fricont_path_free(NULL);
    fricont_problem_free(p);
}

static void test_misuse_and_queries(void) {
    fricont_problem *p = block();
    fricont_path *path = NULL;
    EXPECT(fricont_path_new_affine(p, f0, f1, 2, &path), FRICONT_OK, "");
    int64_t count = -1;
    int32_t reason = -1;
    fricont_event ev;
    EXPECT(fricont_path_step(path), FRICONT_ERR_ORDER, "not been started");
    EXPECT(fricont_path_run(path), FRICONT_ERR_ORDER, "not been started");
    EXPECT(fricont_path_event_count(path, &count), FRICONT_ERR_ORDER, "not been started");
    EXPECT(fricont_path_event(path, 0, &ev), FRICONT_ERR_ORDER, "not been started");
    EXPECT(fricont_path_end_reason(path, &reason), FRICONT_ERR_ORDER, "not been started");
    EXPECT(fricont_path_start_state(path, NULL), FRICONT_ERR_ORDER, "not been started");
    EXPECT(fricont_path_solutions_at(path, 0.0, &count), FRICONT_ERR_ORDER, "not been started");
    EXPECT(fricont_path_start(path, 0.0, NULL, 0), FRICONT_ERR_ORDER, "fricont_path_set_window");
    EXPECT(fricont_path_set_window(path, 1.0, 1.0), FRICONT_ERR_RANGE, "distinct");
    EXPECT(fricont_path_set_window(path, 0.0, NAN), FRICONT_ERR_RANGE, "finite");
    EXPECT(fricont_path_set_max_steps(path, 0), FRICONT_ERR_RANGE, "max_steps = 0");
    EXPECT(fricont_path_set_zero_tol(path, 0.1), FRICONT_ERR_RANGE, "zero_tol");
    EXPECT(fricont_path_set_zero_tol(path, 0.0), FRICONT_ERR_RANGE, "zero_tol");
    EXPECT(fricont_path_set_window(NULL, 0.0, 1.0), FRICONT_ERR_NULL, "path");
    EXPECT(fricont_path_set_window(path, 0.0, 2.0), FRICONT_OK, "");
    EXPECT(fricont_path_set_max_steps(path, 100), FRICONT_OK, "");
    EXPECT(fricont_path_set_zero_tol(path, 1e-10), FRICONT_OK, "");
    double guess1[] = {-1.0}, guess2[] = {-1.0, NAN};
    EXPECT(fricont_path_start(path, 0.0, guess1, 1), FRICONT_ERR_LENGTH, "expected 2p = 2");
    EXPECT(fricont_path_start(path, 0.0, guess2, 2), FRICONT_ERR_NONFINITE, "guess[1]");
    EXPECT(fricont_path_start(path, NAN, NULL, 0), FRICONT_ERR_RANGE, "not finite");
    EXPECT(fricont_path_start(path, 5.0, NULL, 0), FRICONT_ERR_RANGE, "window");
    EXPECT(fricont_path_start(NULL, 0.0, NULL, 0), FRICONT_ERR_NULL, "path");
    double guess[] = {-1.0, 0.0};
    EXPECT(fricont_path_start(path, 0.0, guess, 2), FRICONT_OK, "");
    EXPECT(fricont_path_set_window(path, 0.0, 3.0), FRICONT_ERR_ORDER, "before the first");
    EXPECT(fricont_path_set_max_steps(path, 3), FRICONT_ERR_ORDER, "before the first");
    EXPECT(fricont_path_end_reason(path, &reason), FRICONT_OK, "");
    CHECK(reason == FRICONT_END_NONE, "not ended yet");
    EXPECT(fricont_path_choose_branch(path, 0), FRICONT_ERR_ORDER, "no bifurcation pending");
    EXPECT(fricont_path_branch_count(path, &count), FRICONT_OK, "");
    CHECK(count == 0, "no branches");
    EXPECT(fricont_path_branch(path, 0, NULL, NULL, 0), FRICONT_ERR_RANGE, "branch index 0");
    /* outcomes: one transition at alpha = 1/2 (stick -> slip+), then the window */
    EXPECT(fricont_path_step(path), FRICONT_TRANSITION, "");
    EXPECT(fricont_path_event_count(path, &count), FRICONT_OK, "");
    CHECK(count == 1, "one event");
    EXPECT(fricont_path_event(path, 0, &ev), FRICONT_OK, "");
    CHECK(fabs(ev.alpha - 0.5) < 1e-14 && ev.node == 0 && ev.from == FRICONT_STICK &&
              ev.to == FRICONT_SLIP_PLUS && !ev.fold && !ev.bifurcation,
          "event %.17g %lld %d %d", ev.alpha, (long long)ev.node, ev.from, ev.to);
    EXPECT(fricont_path_event(path, 1, &ev), FRICONT_ERR_RANGE, "event index 1");
    EXPECT(fricont_path_event(path, -1, &ev), FRICONT_ERR_RANGE, "event index -1");
    EXPECT(fricont_path_event(path, 0, NULL), FRICONT_ERR_NULL, "out");
    EXPECT(fricont_path_event_count(path, NULL), FRICONT_ERR_NULL, "count");
    EXPECT(fricont_path_step(path), FRICONT_END, "");
    EXPECT(fricont_path_step(path), FRICONT_END, ""); /* again */
    EXPECT(fricont_path_end_reason(path, &reason), FRICONT_OK, "");
    CHECK(reason == FRICONT_END_WINDOW, "window");
    EXPECT(fricont_path_end_reason(path, NULL), FRICONT_ERR_NULL, "reason");
    /* buffers */
    double u[2] = {7, 7}, ln[1], lt[1];
    int32_t cl[1];
    fricont_state s = {0, 0, u, 1, ln, 1, lt, 1, cl, 1};
    EXPECT(fricont_path_current(path, &s), FRICONT_ERR_LENGTH, "needs 2");
    CHECK(u[0] == 7 && u[1] == 7, "nothing written on a length error");
    s.u_len = 2;
    s.classes_len = 0;
    EXPECT(fricont_path_event_state(path, 0, &s), FRICONT_ERR_LENGTH, "classes");
    s.classes = NULL; /* skipped */
    EXPECT(fricont_path_event_state(path, 0, &s), FRICONT_OK, "");
    CHECK(fabs(ln[0] + 1) < 1e-14 && fabs(lt[0] + 0.5) < 1e-14 && fabs(u[1]) < 1e-14,
          "state at the event");
    EXPECT(fricont_path_current(path, &s), FRICONT_OK, "");
    CHECK(fabs(u[1] - 1.5) < 1e-14 && s.alpha == 2.0, "current u %g alpha %g", u[1], s.alpha);
    int64_t np = 0;
    fricont_piece pc;
    EXPECT(fricont_path_piece_count(path, &np), FRICONT_OK, "");
    CHECK(np == 2, "two pieces");
    EXPECT(fricont_path_piece(path, 1, &pc, cl, 1), FRICONT_OK, "");
    CHECK(pc.alpha_from == ev.alpha && pc.alpha_to == 2.0 && pc.direction == 1 && cl[0] == FRICONT_SLIP_PLUS,
          "piece 1");
    EXPECT(fricont_path_piece(path, 2, &pc, NULL, 0), FRICONT_ERR_RANGE, "piece index 2");
    EXPECT(fricont_path_piece(path, 0, &pc, cl, 0), FRICONT_ERR_LENGTH, "classes");
    /* solutions */
    EXPECT(fricont_path_solutions_at(path, 0.25, NULL), FRICONT_ERR_NULL, "count");
    EXPECT(fricont_path_solutions_at(path, INFINITY, &count), FRICONT_ERR_RANGE, "not finite");
    EXPECT(fricont_path_solutions_at(path, 0.25, &count), FRICONT_OK, "");
    CHECK(count == 1, "one solution at 0.25");
    fricont_solution info;
    EXPECT(fricont_path_solution(path, 0, &info, &s), FRICONT_OK, "");
    CHECK(info.piece == 0 && !info.continuum && fabs(lt[0] + 0.25) < 1e-14, "solution at 0.25");
    EXPECT(fricont_path_solution(path, 1, &info, &s), FRICONT_ERR_RANGE, "solution index 1");
    EXPECT(fricont_path_solutions_at(path, 7.0, &count), FRICONT_OK, "");
    CHECK(count == 0, "no solution outside the traced range");
    /* restart clears */
    EXPECT(fricont_path_start(path, 1.0, NULL, 0), FRICONT_OK, "");
    EXPECT(fricont_path_event_count(path, &count), FRICONT_OK, "");
    CHECK(count == 0, "restart clears the events");
    /* step limit */
    fricont_path *p2 = NULL;
    EXPECT(fricont_path_new_affine(p, f0, f1, 2, &p2), FRICONT_OK, "");
    fricont_path_set_window(p2, 0.0, 2.0);
    fricont_path_set_max_steps(p2, 1);
    EXPECT(fricont_path_start(p2, 0.0, NULL, 0), FRICONT_OK, "");
    EXPECT(fricont_path_step(p2), FRICONT_TRANSITION, "");
    EXPECT(fricont_path_step(p2), FRICONT_END, "");
    fricont_path_end_reason(p2, &reason);
    CHECK(reason == FRICONT_END_MAX_STEPS, "max steps: %d", reason);
    fricont_path_free(p2);
    fricont_path_free(path);
    fricont_problem_free(p);
}

static void test_callback_failures(void) {
    fricont_problem *p = block();
    fricont_path *path = NULL;
    int32_t code = -1, reason = -1;
    /* general callback failing with 7 beyond alpha = 0.3 */
    cb_data d = {1, 0.3, 7, 0, 0, 0};
    EXPECT(fricont_path_new_general(p, 2, load_cb, dload_cb, &d, finalize_cb, &path), FRICONT_OK, "");
    fricont_path_set_window(path, 0.0, 2.0);
    EXPECT(fricont_path_callback_code(path, &code), FRICONT_OK, "");
    CHECK(code == 0, "no failure yet");
    EXPECT(fricont_path_start(path, 0.0, NULL, 0), FRICONT_OK, "");
    EXPECT(fricont_path_run(path), FRICONT_ERR_CALLBACK, "returned 7");
    CHECK(fricont_path_error_message(path, msg, sizeof msg) > 0 && strstr(msg, "code 7"), "path message: %s", msg);
    EXPECT(fricont_path_callback_code(path, &code), FRICONT_OK, "");
    CHECK(code == 7, "callback code %d", code);
    EXPECT(fricont_path_callback_code(path, NULL), FRICONT_ERR_NULL, "code");
    EXPECT(fricont_path_end_reason(path, &reason), FRICONT_OK, "");
    CHECK(reason == FRICONT_END_FAILED, "failed: %d", reason);
    EXPECT(fricont_path_step(path), FRICONT_END, "");
    fricont_path_free(path);
    CHECK(d.finalized == 1, "finalized");
    /* NaN written by the callback */
    cb_data dn = {0, 0.3, 0, 1, 0, 0};
    EXPECT(fricont_path_new_general(p, 2, load_cb, NULL, &dn, NULL, &path), FRICONT_OK, "");
    fricont_path_set_window(path, 0.0, 2.0);
    EXPECT(fricont_path_start(path, 0.0, NULL, 0), FRICONT_OK, "");
    EXPECT(fricont_path_run(path), FRICONT_ERR_CALLBACK_VALUE, "NaN");
    fricont_path_callback_code(path, &code);
    CHECK(code == 0, "code 0 for a NaN");
    fricont_path_free(path);
    /* failure at the start */
    cb_data d0 = {1, -1.0, -3, 0, 0, 0};
    EXPECT(fricont_path_new_general(p, 2, load_cb, NULL, &d0, NULL, &path), FRICONT_OK, "");
    fricont_path_set_window(path, 0.0, 2.0);
    EXPECT(fricont_path_start(path, 0.0, NULL, 0), FRICONT_ERR_CALLBACK, "returned -3");
    EXPECT(fricont_path_step(path), FRICONT_ERR_ORDER, "not been started");
    fricont_path_free(path);
    /* basis weights failing */
    cb_data dw = {1, 0.7, 11, 0, 0, 0};
    double vecs[] = {1.0, 0.0, 0.0, 1.0}; /* f = 1 * f0 + alpha * f1 */
    EXPECT(fricont_path_new_basis(p, vecs, 2, 2, weights_cb, &dw, finalize_cb, &path), FRICONT_OK, "");
    fricont_path_set_window(path, 0.0, 2.0);
    EXPECT(fricont_path_start(path, 0.0, NULL, 0), FRICONT_OK, "");
    EXPECT(fricont_path_step(path), FRICONT_TRANSITION, ""); /* alpha = 1/2 */
    fricont_event ev;
    fricont_path_event(path, 0, &ev);
    CHECK(fabs(ev.alpha - 0.5) < 1e-12, "basis load event at %.17g", ev.alpha);
    EXPECT(fricont_path_step(path), FRICONT_ERR_CALLBACK, "returned 11");
    fricont_path_callback_code(path, &code);
    CHECK(code == 11, "basis callback code %d", code);
    fricont_path_free(path);
    CHECK(dw.finalized == 1, "basis finalized");
    fricont_problem_free(p);
}

/* The fold problem of tests/core_hand.rs (two_folds_three_solutions), derived by hand
 * there: n = 3, A = diag(1, 1, 4), N = [1 0 0], T = [-1 1 0], F = 2,
 * f0 = (0, 1, 0.7), f1 = (1, -1.5, -0.3). From alpha = -3 (open) the path turns back at
 * alpha = 0 (open -> slip+, fold) and at alpha = -2 (slip+ -> stick, fold), then goes up to
 * alpha = 1.2 (stick -> slip-). At alpha = -1 there are three solutions: lambda = (0, 0),
 * (-1, -2), (-1.5, -2.5). Given here 1-based and in upper storage. */
static void test_fold(void) {
    int64_t arp[] = {1, 2, 3, 4}, aci[] = {1, 2, 3};
    double av[] = {1.0, 1.0, 4.0};
    int64_t nrp[] = {1, 2}, nci[] = {1};
    double nv[] = {1.0};
    int64_t trp[] = {1, 3}, tci[] = {1, 2};
    double tv[] = {-1.0, 1.0};
    fricont_csr a = mk(3, 3, 3, arp, aci, av, 1), n = mk(1, 3, 1, nrp, nci, nv, 1),
                t = mk(1, 3, 2, trp, tci, tv, 1);
    fricont_problem *p = NULL;
    EXPECT(fricont_problem_new(&a, FRICONT_STORAGE_UPPER, &n, &t, &p), FRICONT_OK, "");
    double F[] = {2.0};
    EXPECT(fricont_problem_set_friction_nodes(p, F, 1), FRICONT_OK, "");
    double g0[] = {0.0, 1.0, 0.7}, g1[] = {1.0, -1.5, -0.3};
    fricont_path *path = NULL;
    EXPECT(fricont_path_new_affine(p, g0, g1, 3, &path), FRICONT_OK, "");
    fricont_problem_free(p);
    fricont_path_set_window(path, -3.0, 3.0);
    EXPECT(fricont_path_start(path, -3.0, NULL, 0), FRICONT_OK, "");
    EXPECT(fricont_path_step(path), FRICONT_FOLD, "");
    EXPECT(fricont_path_step(path), FRICONT_FOLD, "");
    EXPECT(fricont_path_step(path), FRICONT_TRANSITION, "");
    EXPECT(fricont_path_step(path), FRICONT_END, "");
    double want[3][4] = {{0.0, FRICONT_OPEN, FRICONT_SLIP_PLUS, 1},
                         {-2.0, FRICONT_SLIP_PLUS, FRICONT_STICK, 1},
                         {1.2, FRICONT_STICK, FRICONT_SLIP_MINUS, 0}};
    for (int k = 0; k < 3; k++) {
        fricont_event ev;
        EXPECT(fricont_path_event(path, k, &ev), FRICONT_OK, "");
        CHECK(fabs(ev.alpha - want[k][0]) <= 1e-12 && ev.from == (int32_t)want[k][1] &&
                  ev.to == (int32_t)want[k][2] && ev.fold == (want[k][3] != 0),
              "fold problem event %d: %.17g %s -> %s fold %d", k, ev.alpha,
              fricont_class_name(ev.from), fricont_class_name(ev.to), ev.fold);
    }
    int64_t count = 0;
    EXPECT(fricont_path_solutions_at(path, -1.0, &count), FRICONT_OK, "");
    CHECK(count == 3, "three solutions between the folds, got %lld", (long long)count);
    double sols[3][2] = {{0, 0}, {-1, -2}, {-1.5, -2.5}};
    int found[3] = {0, 0, 0};
    for (int64_t k = 0; k < count && k < 3; k++) {
        double ln, lt;
        fricont_state s = {0, 0, NULL, 0, &ln, 1, &lt, 1, NULL, 0};
        EXPECT(fricont_path_solution(path, k, NULL, &s), FRICONT_OK, "");
        for (int j = 0; j < 3; j++)
            if (fabs(ln - sols[j][0]) < 1e-12 && fabs(lt - sols[j][1]) < 1e-12) found[j]++;
    }
    CHECK(found[0] == 1 && found[1] == 1 && found[2] == 1, "the three hand solutions");
    fricont_path_free(path);
}

static void test_strings(void) {
    const int32_t all[] = {FRICONT_OK, FRICONT_TRANSITION, FRICONT_FOLD, FRICONT_BIFURCATION,
                           FRICONT_END, FRICONT_ERR_NULL, FRICONT_ERR_LENGTH, FRICONT_ERR_RANGE,
                           FRICONT_ERR_ORDER, FRICONT_ERR_CSR, FRICONT_ERR_NONFINITE,
                           FRICONT_ERR_NOT_SYMMETRIC, FRICONT_ERR_NOT_SPD,
                           FRICONT_ERR_RANK_DEFICIENT, FRICONT_ERR_SOLVE_FAILED,
                           FRICONT_ERR_NUMERICAL, FRICONT_ERR_CALLBACK,
                           FRICONT_ERR_CALLBACK_VALUE, FRICONT_ERR_PANIC, FRICONT_ERR_POISONED};
    for (size_t i = 0; i < sizeof all / sizeof all[0]; i++) {
        const char *s = fricont_status_str(all[i]);
        CHECK(strncmp(s, "FRICONT_", 8) == 0 && strchr(s, ':'), "status string %s", s);
        for (size_t j = 0; j < i; j++) CHECK(all[i] != all[j] && s != fricont_status_str(all[j]), "distinct");
    }
    CHECK(strcmp(fricont_status_str(-999), "unknown fricont status code") == 0, "unknown");
    CHECK(strcmp(fricont_class_name(FRICONT_SLIP_MINUS), "slip-") == 0, "slip-");
    CHECK(strcmp(fricont_class_name(42), "unknown") == 0, "unknown class");
    CHECK(strcmp(fricont_end_reason_name(FRICONT_END_NONE), "none") == 0, "none");
    CHECK(strcmp(fricont_end_reason_name(FRICONT_END_CLOSED_LOOP), "closed_loop") == 0, "loop");
    CHECK(strcmp(fricont_end_reason_name(FRICONT_END_STOPPED), "stopped") == 0, "stopped");
    CHECK(strcmp(fricont_end_reason_name(7), "unknown") == 0, "unknown end reason");
    CHECK(strcmp(fricont_start_route_name(FRICONT_START_SOLVED), "solved") == 0, "solved");
    CHECK(strcmp(fricont_start_route_name(FRICONT_START_ZERO_LOAD), "zero_load") == 0, "zero");
    CHECK(strcmp(fricont_start_route_name(-1), "unknown") == 0, "unknown start route");
}

/* A mirror-symmetric pair of nodes (found by a search over such pairs, checked here
 * independently): n = 5 dofs (a1, b1, a2, b2, c), A = I, N1 = a1 - 1.5 c, T1 = b1 - 2 c,
 * N2 = a2 + 1.5 c, T2 = -b2 + 2 c, F = 1.5, f(alpha) = (alpha - 0.5, -1 - alpha,
 * alpha - 0.5, 1 + alpha, 0): the mirror a1 <-> a2, b1 <-> -b2, c <-> -c maps the problem
 * to itself. Both nodes are open until q_n = alpha - 0.5 reaches 0 at alpha = 1/2 for
 * both at once. There the library must stop with FRICONT_END_BIFURCATION and list
 * candidate branches that (checked here with W = B B^T and q = B f solved by hand-written
 * elimination) pass through the point, enter their own region in their direction, and
 * come in mirror pairs. Choosing each orientation-preserving branch continues the path on
 * that branch. */
static void solve4(double M[4][4], double *x) {
    for (int k = 0; k < 4; k++) {
        int piv = k;
        for (int i = k + 1; i < 4; i++)
            if (fabs(M[i][k]) > fabs(M[piv][k])) piv = i;
        for (int l = 0; l < 4; l++) {
            double t = M[k][l];
            M[k][l] = M[piv][l];
            M[piv][l] = t;
        }
        double t = x[k];
        x[k] = x[piv];
        x[piv] = t;
        for (int i = k + 1; i < 4; i++) {
            double f = M[i][k] / M[k][k];
            for (int l = k; l < 4; l++) M[i][l] -= f * M[k][l];
            x[i] -= f * x[k];
        }
    }
    for (int k = 3; k >= 0; k--) {
        for (int l = k + 1; l < 4; l++) x[k] -= M[k][l] * x[l];
        x[k] /= M[k][k];
    }
}

/* B rows (nu1, nu2, t1, t2) over (a1, b1, a2, b2, c) and the load */
static const double mir_b[4][5] = {{1, 0, 0, 0, -1.5}, {0, 0, 1, 0, 1.5}, {0, 1, 0, 0, -2}, {0, 0, 0, -1, 2}};
static const double mir_f0[5] = {-0.5, -1, -0.5, 1, 0}, mir_f1[5] = {1, -1, 1, 1, 0};
#define MIR_F 1.5

/* lambda (nu1, nu2, t1, t2) on the piece of classes c at alpha; returns the guard margin
 * (> 0: strictly inside the piece's region). */
static double mirror_piece(const int32_t c[2], double alpha, double lam[4]) {
    double W[4][4], q[4], M[4][4] = {{0}};
    for (int i = 0; i < 4; i++) {
        q[i] = 0;
        for (int k = 0; k < 5; k++) q[i] += mir_b[i][k] * (mir_f0[k] + alpha * mir_f1[k]);
        for (int j = 0; j < 4; j++) {
            W[i][j] = 0;
            for (int k = 0; k < 5; k++) W[i][j] += mir_b[i][k] * mir_b[j][k];
        }
    }
    for (int i = 0; i < 2; i++) {
        int rn = i, rt = 2 + i;
        lam[rn] = 0;
        lam[rt] = 0;
        if (c[i] == FRICONT_OPEN) {
            M[rn][i] = 1;
            M[rt][2 + i] = 1;
            continue;
        }
        for (int j = 0; j < 4; j++) M[rn][j] = W[i][j];
        lam[rn] = -q[i];
        if (c[i] == FRICONT_STICK) {
            for (int j = 0; j < 4; j++) M[rt][j] = W[2 + i][j];
            lam[rt] = -q[2 + i];
        } else {
            M[rt][2 + i] = 1;
            M[rt][i] = c[i] == FRICONT_SLIP_PLUS ? -MIR_F : MIR_F;
        }
    }
    solve4(M, lam);
    double margin = INFINITY;
    for (int i = 0; i < 2; i++) {
        double dn = q[i], dt = q[2 + i];
        for (int j = 0; j < 4; j++) {
            dn += W[i][j] * lam[j];
            dt += W[2 + i][j] * lam[j];
        }
        double ln = lam[i], lt = lam[2 + i], g;
        switch (c[i]) {
        case FRICONT_OPEN: g = -dn; break;
        case FRICONT_STICK: g = fmin(-ln, fmin(lt - MIR_F * ln, -MIR_F * ln - lt)); break;
        case FRICONT_SLIP_PLUS: g = fmin(-ln, dt); break;
        default: g = fmin(-ln, -dt);
        }
        margin = fmin(margin, g);
    }
    return margin;
}

static fricont_path *mirror_path(void) {
    int64_t arp[] = {0, 1, 2, 3, 4, 5}, aci[] = {0, 1, 2, 3, 4};
    double av[] = {1, 1, 1, 1, 1};
    int64_t nrp[] = {0, 2, 4}, nci[] = {0, 4, 2, 4}, trp[] = {0, 2, 4}, tci[] = {1, 4, 3, 4};
    double nv[] = {1, -1.5, 1, 1.5}, tv[] = {1, -2, -1, 2};
    fricont_csr a = mk(5, 5, 5, arp, aci, av, 0), n = mk(2, 5, 4, nrp, nci, nv, 0), t = mk(2, 5, 4, trp, tci, tv, 0);
    fricont_problem *p = NULL;
    fricont_path *path = NULL;
    EXPECT(fricont_problem_new(&a, FRICONT_STORAGE_FULL, &n, &t, &p), FRICONT_OK, "");
    EXPECT(fricont_problem_set_friction(p, MIR_F), FRICONT_OK, "");
    EXPECT(fricont_path_new_affine(p, mir_f0, mir_f1, 5, &path), FRICONT_OK, "");
    fricont_problem_free(p);
    fricont_path_set_window(path, -3.0, 3.0);
    EXPECT(fricont_path_start(path, -3.0, NULL, 0), FRICONT_OK, "");
    return path;
}

static void test_bifurcation(void) {
    fricont_path *path = mirror_path();
    int32_t reason = -1;
    EXPECT(fricont_path_step(path), FRICONT_END, "");
    EXPECT(fricont_path_end_reason(path, &reason), FRICONT_OK, "");
    CHECK(reason == FRICONT_END_BIFURCATION, "end reason %d, expected FRICONT_END_BIFURCATION", reason);
    fricont_state s = {0, 0, NULL, 0, NULL, 0, NULL, 0, NULL, 0};
    EXPECT(fricont_path_current(path, &s), FRICONT_OK, "");
    CHECK(fabs(s.alpha - 0.5) < 1e-14, "stopped at alpha %.17g, expected 1/2", s.alpha);
    int64_t nb = 0;
    EXPECT(fricont_path_branch_count(path, &nb), FRICONT_OK, "");
    CHECK(nb >= 2, "%lld branches", (long long)nb);
    int32_t cls[8][2];
    fricont_branch br[8];
    int preserving = 0;
    for (int64_t k = 0; k < nb && k < 8; k++) {
        EXPECT(fricont_path_branch(path, k, &br[k], cls[k], 2), FRICONT_OK, "");
        double lam[4];
        double at = mirror_piece(cls[k], 0.5, lam);
        CHECK(fabs(lam[0]) + fabs(lam[1]) + fabs(lam[2]) + fabs(lam[3]) < 1e-12 && at > -1e-12,
              "branch %lld (%s, %s) does not pass through the point", (long long)k,
              fricont_class_name(cls[k][0]), fricont_class_name(cls[k][1]));
        CHECK(br[k].direction != 0, "a vertical branch");
        double inside = mirror_piece(cls[k], 0.5 + 1e-3 * br[k].direction, lam);
        CHECK(inside > 0, "branch %lld (%s, %s) does not enter its region in direction %d (margin %g)",
              (long long)k, fricont_class_name(cls[k][0]), fricont_class_name(cls[k][1]), br[k].direction, inside);
        preserving += br[k].orientation_preserving;
        int mirrored = 0;
        for (int64_t j = 0; j < nb && j < 8; j++) {
            int32_t cj[2];
            fricont_path_branch(path, j, NULL, cj, 2);
            mirrored += cj[0] == cls[k][1] && cj[1] == cls[k][0];
        }
        CHECK(mirrored == 1, "the mirror image of branch %lld is listed once (%d)", (long long)k, mirrored);
    }
    CHECK(preserving != 1, "stopped although exactly one branch preserves the orientation");
    EXPECT(fricont_path_choose_branch(path, nb), FRICONT_ERR_RANGE, "branch index");
    fricont_path_free(path);
    /* each branch, chosen on a fresh path, is followed */
    for (int64_t k = 0; k < nb && k < 8; k++) {
        path = mirror_path();
        EXPECT(fricont_path_step(path), FRICONT_END, "");
        EXPECT(fricont_path_choose_branch(path, k), FRICONT_OK, "");
        fricont_status st = fricont_path_step(path);
        CHECK(st > 0, "step after choosing branch %lld: %s", (long long)k, fricont_status_str(st));
        int64_t np = 0;
        fricont_path_piece_count(path, &np);
        int32_t c[2] = {-1, -1};
        fricont_piece pc;
        fricont_path_piece(path, 1, &pc, c, 2);
        CHECK(np >= 2 && c[0] == cls[k][0] && c[1] == cls[k][1] && pc.direction == br[k].direction &&
                  fabs(pc.alpha_from - 0.5) < 1e-14,
              "branch %lld: the second piece is (%s, %s) direction %d", (long long)k, fricont_class_name(c[0]),
              fricont_class_name(c[1]), pc.direction);
        double lam[4];
        CHECK(mirror_piece(c, 0.5 * (pc.alpha_from + pc.alpha_to), lam) > 0, "branch %lld: the piece is valid", (long long)k);
        fricont_path_free(path);
    }
}

/* ---- condensed input and a host's solve, on the block above ----
 * W = B A^-1 B^T = diag(1/2, 1), q(alpha) = B A^-1 f(alpha) = (1/2, alpha): the same path,
 * stick with lambda = (-1, -alpha) up to alpha = 1/2, then slip+ with u_2 = alpha - 1/2. */
typedef struct {
    int calls, fail_from, fail_code, fail_times, finalized;
} solve_data;

static void solve_finalize(void *user) { ((solve_data *)user)->finalized++; }

/* A^-1 = diag(1/2, 1); fails with fail_code on calls fail_from .. fail_from + fail_times - 1
 * (after scribbling over x, which fricont must restore before a retry). */
static int diag_solve(void *user, int64_t n, int64_t ncols, double *x, int64_t ldx) {
    solve_data *d = user;
    d->calls++;
    if (n != 2 || ldx < n || ncols < 1) return -99;
    if (d->fail_from > 0 && d->calls >= d->fail_from && d->calls < d->fail_from + d->fail_times) {
        x[0] = 1e300;
        return d->fail_code;
    }
    for (int64_t j = 0; j < ncols; j++) x[j * ldx] *= 0.5;
    return 0;
}

static void test_host_input(void) {
    double w[4] = {0.5, 0.0, 0.0, 1.0}, q0[2] = {0.5, 0.0}, q1[2] = {0.0, 1.0}, q3[3] = {0, 0, 0};
    fricont_problem *p = NULL;
    fricont_path *path = NULL;
    /* constructor errors */
    EXPECT(fricont_problem_new_condensed(1, NULL, 2, &p), FRICONT_ERR_NULL, "w");
    EXPECT(fricont_problem_new_condensed(0, w, 2, &p), FRICONT_ERR_LENGTH, "p = 0");
    EXPECT(fricont_problem_new_condensed(1, w, 1, &p), FRICONT_ERR_LENGTH, "ldw");
    EXPECT(fricont_problem_new_condensed(-1, w, 2, &p), FRICONT_ERR_LENGTH, "p = -1");
    EXPECT(fricont_problem_new_condensed(1, w, 2, NULL), FRICONT_ERR_NULL, "out");
    /* bad W, found at the build */
    double bad[3][4] = {{0.5, 0.1, 0.0, 1.0}, {0.5, 1.0, 1.0, 1.0}, {0.5, 0.0, 0.0, NAN}};
    fricont_status want[3] = {FRICONT_ERR_NOT_SYMMETRIC, FRICONT_ERR_NOT_SPD, FRICONT_ERR_NONFINITE};
    const char *needle[3] = {"W is not symmetric", "row 2", "W(2, 2)"};
    for (int k = 0; k < 3; k++) {
        EXPECT(fricont_problem_new_condensed(1, bad[k], 2, &p), FRICONT_OK, "");
        EXPECT(fricont_problem_build(p), want[k], needle[k]);
        fricont_problem_free(p);
    }
    /* the hand-derived path from condensed data */
    EXPECT(fricont_problem_new_condensed(1, w, 2, &p), FRICONT_OK, "");
    EXPECT(fricont_problem_set_friction(p, 0.5), FRICONT_OK, "");
    int64_t n = -1, np = -1;
    EXPECT(fricont_problem_dims(p, &n, &np), FRICONT_OK, "");
    CHECK(n == 0 && np == 1, "condensed dims n = %lld, p = %lld", (long long)n, (long long)np);
    EXPECT(fricont_path_new_affine(p, q3, q3, 3, &path), FRICONT_ERR_LENGTH, "2p = 2");
    EXPECT(fricont_path_new_affine(p, q0, q1, 2, &path), FRICONT_OK, "");
    EXPECT(fricont_path_set_window(path, 0.0, 1.0), FRICONT_OK, "");
    EXPECT(fricont_path_start(path, 0.0, NULL, 0), FRICONT_OK, "");
    EXPECT(fricont_path_run(path), FRICONT_END, "");
    int64_t ne = 0;
    EXPECT(fricont_path_event_count(path, &ne), FRICONT_OK, "");
    fricont_event ev;
    EXPECT(fricont_path_event(path, 0, &ev), FRICONT_OK, "");
    CHECK(ne == 1 && fabs(ev.alpha - 0.5) <= 1e-15 && ev.from == FRICONT_STICK && ev.to == FRICONT_SLIP_PLUS,
          "condensed: %lld events, first at %.17g", (long long)ne, ev.alpha);
    double u[2], ln[1], lt[1];
    int32_t cl[1];
    fricont_state s = {0, 0, u, 2, ln, 1, lt, 1, cl, 1};
    EXPECT(fricont_path_event_state(path, 0, &s), FRICONT_ERR_UNAVAILABLE, "u = NULL");
    s.u = NULL;
    s.u_len = 0;
    EXPECT(fricont_path_event_state(path, 0, &s), FRICONT_OK, "");
    CHECK(fabs(ln[0] + 1) <= 1e-15 && fabs(lt[0] + 0.5) <= 1e-15 && s.residual <= 1e-15,
          "condensed event: lambda (%g, %g), residual %g", ln[0], lt[0], s.residual);
    fricont_path_free(path);
    fricont_problem_free(p);

    /* a host's solve */
    fricont_csr nm = mk(1, 2, 1, n_rp, n_ci, n_v, 0), tm = mk(1, 2, 1, t_rp, t_ci, t_v, 0);
    solve_data sd = {0, 0, 0, 0, 0};
    EXPECT(fricont_problem_new_solve(2, NULL, &sd, solve_finalize, 1, &nm, &tm, &p), FRICONT_ERR_NULL, "solve");
    CHECK(sd.finalized == 1, "a failing constructor finalizes the user data at once (%d)", sd.finalized);
    sd.finalized = 0;
    EXPECT(fricont_problem_new_solve(1, diag_solve, &sd, NULL, 1, &nm, &tm, &p), FRICONT_ERR_LENGTH, "N is 1x2");
    EXPECT(fricont_problem_new_solve(2, diag_solve, &sd, NULL, 0, &nm, &tm, &p), FRICONT_ERR_LENGTH, "max_block");
    EXPECT(fricont_problem_new_solve(2, diag_solve, &sd, NULL, 1, NULL, &tm, &p), FRICONT_ERR_NULL, "N");
    /* 2p > n: two contact nodes on two dofs, refused at once (the header's LENGTH) */
    int64_t rp22[] = {0, 1, 2}, ci22[] = {0, 1};
    double v22[] = {1.0, 1.0};
    fricont_csr n22 = mk(2, 2, 2, rp22, ci22, v22, 0);
    EXPECT(fricont_problem_new_solve(2, diag_solve, &sd, NULL, 1, &n22, &n22, &p), FRICONT_ERR_LENGTH,
           "2p = 4 exceeds n = 2");
    /* fatal, recoverable twice, recoverable once (then fine) */
    int codes[3] = {-3, 5, 5}, times[3] = {1, 2, 1};
    fricont_status wants[3] = {FRICONT_ERR_SOLVE_CALLBACK, FRICONT_ERR_SOLVE_CALLBACK, FRICONT_OK};
    const char *needles[3] = {"code -3", "code 5", ""};
    for (int k = 0; k < 3; k++) {
        solve_data f = {0, 1, codes[k], times[k], 0};
        EXPECT(fricont_problem_new_solve(2, diag_solve, &f, NULL, 1, &nm, &tm, &p), FRICONT_OK, "");
        EXPECT(fricont_problem_build(p), wants[k], needles[k]);
        if (wants[k] == FRICONT_OK) {
            double r = 0, r0 = 0;
            EXPECT(fricont_problem_r(p, &r, &r0), FRICONT_OK, "");
            /* W = diag(1/2, 1) after the retry: r0 = 2p / trace W = 2 / 1.5 */
            CHECK(fabs(r0 - 2.0 / 1.5) <= 1e-15, "retried solve: r0 = %.17g", r0);
        }
        fricont_problem_free(p);
    }
    EXPECT(fricont_problem_new_solve(2, diag_solve, &sd, solve_finalize, 1, &nm, &tm, &p), FRICONT_OK, "");
    EXPECT(fricont_problem_set_friction(p, 0.5), FRICONT_OK, "");
    EXPECT(fricont_path_new_affine(p, f0, f1, 2, &path), FRICONT_OK, "");
    CHECK(sd.calls == 2, "W by 2 one-column solves, got %d calls", sd.calls);
    EXPECT(fricont_path_set_window(path, 0.0, 1.0), FRICONT_OK, "");
    EXPECT(fricont_path_start(path, 0.0, NULL, 0), FRICONT_OK, "");
    EXPECT(fricont_path_run(path), FRICONT_END, "");
    EXPECT(fricont_path_event(path, 0, &ev), FRICONT_OK, "");
    CHECK(fabs(ev.alpha - 0.5) <= 1e-15, "host solve: event at %.17g", ev.alpha);
    int64_t count = 0;
    EXPECT(fricont_path_solutions_at(path, 0.75, &count), FRICONT_OK, "");
    s.u = u;
    s.u_len = 2;
    EXPECT(fricont_path_solution(path, 0, NULL, &s), FRICONT_OK, "");
    CHECK(count == 1 && fabs(u[0]) <= 1e-15 && fabs(u[1] - 0.25) <= 1e-15 && cl[0] == FRICONT_SLIP_PLUS,
          "host solve at alpha 0.75: u = (%g, %g), class %d", u[0], u[1], cl[0]);
    /* the solve fails later, for u at an event */
    sd.fail_from = sd.calls + 1;
    sd.fail_code = -4;
    sd.fail_times = 1000;
    EXPECT(fricont_path_event_state(path, 0, &s), FRICONT_ERR_SOLVE_CALLBACK, "code -4");
    int32_t code = 0;
    EXPECT(fricont_path_callback_code(path, &code), FRICONT_OK, "");
    CHECK(code == -4, "callback code %d after a failing solve", code);
    /* the path still needs the solve after the problem handle is gone */
    fricont_problem_free(p);
    CHECK(sd.finalized == 0, "user data finalized while a path uses the solve");
    fricont_path_free(path);
    CHECK(sd.finalized == 1, "user data finalized %d times after the last free", sd.finalized);
}

/* CSR with int32_t indices (fricont_csr_i32, the _i32 constructors): the block problem
 * gives the hand-derived event, and bad input gives the statuses of the int64 API. */
static fricont_csr_i32 mk32(int64_t nr, int64_t nc, int64_t nnz, int32_t *rp, int32_t *ci, double *v,
                            int64_t base) {
    fricont_csr_i32 m = {nr, nc, nnz, rp, ci, v, base};
    return m;
}

static void block_event_at_half(fricont_problem *p, const char *what) {
    fricont_path *path = NULL;
    EXPECT(fricont_problem_set_friction(p, 0.5), FRICONT_OK, "");
    EXPECT(fricont_path_new_affine(p, f0, f1, 2, &path), FRICONT_OK, "");
    EXPECT(fricont_path_set_window(path, 0.0, 1.0), FRICONT_OK, "");
    EXPECT(fricont_path_start(path, 0.0, NULL, 0), FRICONT_OK, "");
    EXPECT(fricont_path_run(path), FRICONT_END, "");
    int64_t ne = 0;
    fricont_event ev = {0};
    EXPECT(fricont_path_event_count(path, &ne), FRICONT_OK, "");
    EXPECT(fricont_path_event(path, 0, &ev), FRICONT_OK, "");
    CHECK(ne == 1 && fabs(ev.alpha - 0.5) <= 1e-15 && ev.node == 0 && ev.from == FRICONT_STICK &&
              ev.to == FRICONT_SLIP_PLUS,
          "%s: %lld events, the first at %.17g", what, (long long)ne, ev.alpha);
    fricont_path_free(path);
}

static void test_csr_i32(void) {
    int32_t a_rp32[] = {0, 1, 2}, a_ci32[] = {0, 1}, n_rp32[] = {0, 1}, n_ci32[] = {0}, t_rp32[] = {0, 1},
            t_ci32[] = {1};
    fricont_csr_i32 a = mk32(2, 2, 2, a_rp32, a_ci32, a_v, 0), n = mk32(1, 2, 1, n_rp32, n_ci32, n_v, 0),
                    t = mk32(1, 2, 1, t_rp32, t_ci32, t_v, 0);
    fricont_problem *p = NULL;
    EXPECT(fricont_problem_new_i32(&a, FRICONT_STORAGE_FULL, &n, &t, &p), FRICONT_OK, "");
    block_event_at_half(p, "int32 CSR");
    fricont_problem_free(p);
    /* 1-based, lower storage, with a duplicate in A (2 = 1.25 + 0.75) */
    int32_t a_rp1[] = {1, 3, 4}, a_ci1[] = {1, 1, 2}, n_rp1[] = {1, 2}, n_ci1[] = {1}, t_rp1[] = {1, 2},
            t_ci1[] = {2};
    double a_v1[] = {1.25, 0.75, 1.0};
    fricont_csr_i32 a1 = mk32(2, 2, 3, a_rp1, a_ci1, a_v1, 1), n1 = mk32(1, 2, 1, n_rp1, n_ci1, n_v, 1),
                    t1 = mk32(1, 2, 1, t_rp1, t_ci1, t_v, 1);
    EXPECT(fricont_problem_new_i32(&a1, FRICONT_STORAGE_LOWER, &n1, &t1, &p), FRICONT_OK, "");
    block_event_at_half(p, "int32 CSR, 1-based, lower, duplicates");
    fricont_problem_free(p);
    /* the host's solve with int32 N, T */
    solve_data sd = {0, 0, 0, 0, 0};
    EXPECT(fricont_problem_new_solve_i32(2, diag_solve, &sd, solve_finalize, 1, &n, &t, &p), FRICONT_OK, "");
    block_event_at_half(p, "int32 CSR, host's solve");
    fricont_problem_free(p);
    CHECK(sd.finalized == 1, "int32 host solve: user data finalized %d times", sd.finalized);

    /* bad input: the statuses of the int64 API */
    fricont_csr_i32 b = a;
    p = (fricont_problem *)&b; /* must be overwritten with NULL */
    EXPECT(fricont_problem_new_i32(NULL, 0, &n, &t, &p), FRICONT_ERR_NULL, "A is NULL");
    CHECK(p == NULL, "out is cleared on failure (int32)");
    b.row_ptr = NULL;
    EXPECT(fricont_problem_new_i32(&b, 0, &n, &t, &p), FRICONT_ERR_NULL, "A.row_ptr");
    int32_t rp_dec[] = {0, 2, 1}, rp_neg[] = {0, -1, 2}, rp_short[] = {0, 1, 1}, rp_base[] = {1, 2, 3};
    int32_t ci_neg[] = {-1, 1}, ci_out[] = {0, 2}, ci_min[] = {0, INT32_MIN}, ci_max[] = {INT32_MAX, 1};
    b = a;
    b.row_ptr = rp_dec;
    EXPECT(fricont_problem_new_i32(&b, 0, &n, &t, &p), FRICONT_ERR_CSR, "decreases");
    b.row_ptr = rp_neg;
    EXPECT(fricont_problem_new_i32(&b, 0, &n, &t, &p), FRICONT_ERR_CSR, "row pointer decreases");
    b.row_ptr = rp_short;
    EXPECT(fricont_problem_new_i32(&b, 0, &n, &t, &p), FRICONT_ERR_CSR, "row_ptr");
    b.row_ptr = rp_base; /* 1-based pointers declared 0-based */
    EXPECT(fricont_problem_new_i32(&b, 0, &n, &t, &p), FRICONT_ERR_CSR, "row_ptr[0] = 1");
    b = a;
    b.col_idx = ci_neg;
    EXPECT(fricont_problem_new_i32(&b, 0, &n, &t, &p), FRICONT_ERR_CSR, "column index -1");
    b.col_idx = ci_out;
    EXPECT(fricont_problem_new_i32(&b, 0, &n, &t, &p), FRICONT_ERR_CSR, "column index 2");
    b.col_idx = ci_min;
    EXPECT(fricont_problem_new_i32(&b, 0, &n, &t, &p), FRICONT_ERR_CSR, "column index -2147483648");
    b.col_idx = ci_max;
    EXPECT(fricont_problem_new_i32(&b, 0, &n, &t, &p), FRICONT_ERR_CSR, "column index 2147483647");
    b = a;
    b.index_base = 2;
    EXPECT(fricont_problem_new_i32(&b, 0, &n, &t, &p), FRICONT_ERR_CSR, "index_base is 2");
    b = a;
    b.nnz = -1;
    EXPECT(fricont_problem_new_i32(&b, 0, &n, &t, &p), FRICONT_ERR_LENGTH, "A.nnz");
    double v_nan[] = {2.0, NAN};
    b = a;
    b.values = v_nan;
    EXPECT(fricont_problem_new_i32(&b, 0, &n, &t, &p), FRICONT_ERR_NONFINITE, "NaN");
    fricont_csr_i32 t3 = mk32(1, 3, 1, t_rp32, t_ci32, t_v, 0);
    EXPECT(fricont_problem_new_i32(&a, 0, &n, &t3, &p), FRICONT_ERR_LENGTH, "T is 1x3");
    EXPECT(fricont_problem_new_i32(&a, 7, &n, &t, &p), FRICONT_ERR_RANGE, "a_storage = 7");
    /* the same through the host's solve constructor; the user data is finalized at once */
    fricont_csr_i32 bn = n;
    bn.col_idx = ci_neg;
    sd.finalized = 0;
    EXPECT(fricont_problem_new_solve_i32(2, diag_solve, &sd, solve_finalize, 1, &bn, &t, &p), FRICONT_ERR_CSR,
           "column index -1");
    CHECK(sd.finalized == 1, "a failing int32 constructor finalizes the user data (%d)", sd.finalized);
    bn = n;
    bn.row_ptr = rp_neg;
    bn.nrows = 2;
    EXPECT(fricont_problem_new_solve_i32(2, diag_solve, &sd, NULL, 1, &bn, &t, &p), FRICONT_ERR_CSR, "row pointer");
    EXPECT(fricont_problem_new_solve_i32(2, diag_solve, &sd, NULL, 1, &n, NULL, &p), FRICONT_ERR_NULL, "T");
    EXPECT(fricont_problem_new_solve_i32(2, NULL, &sd, NULL, 1, &n, &t, &p), FRICONT_ERR_NULL, "solve");
}

/* The library must not start threads in the host program (factorisations and solves run
 * on the calling thread): after everything above, this process still has one thread. */
static void test_no_threads_started(void) {
#ifdef __linux__
    DIR *d = opendir("/proc/self/task");
    if (!d) return;
    int count = 0;
    struct dirent *e;
    while ((e = readdir(d)) != NULL)
        if (e->d_name[0] != '.') count++;
    closedir(d);
    CHECK(count == 1, "the library started %d thread(s) in the host process (a thread pool?)", count - 1);
#endif
}

/* Extreme but valid scales of A: the block with A and f multiplied by s (A = diag(2s, s),
 * f = s (1, alpha)) is the same problem with lambda times s, so the event stays at
 * alpha = 1/2 with lambda = s (-1, -1/2), and u at alpha = 2 stays (0, 3/2).
 * s = 8e307: the diagonal 1.6e308 overflowed the mean (a + b)/2 of full storage;
 * s = 1e-310: subnormal entries gave "relative pivot NaN"; s = 2^-1000 is exact;
 * s = 1e-315 (29 significant bits) is refused with a range error. */
static void test_extreme_scales(void) {
    const double scales[] = {8e307, 1e-310, 9.332636185032189e-302 /* 2^-1000 */};
    for (int k = 0; k < 3; k++) {
        double sc = scales[k];
        double av[] = {2.0 * sc, sc}, g0[] = {sc, 0.0}, g1[] = {0.0, sc};
        for (int32_t storage = 0; storage < 3; storage++) {
            fricont_csr a = mk(2, 2, 2, a_rp, a_ci, av, 0), n = mk(1, 2, 1, n_rp, n_ci, n_v, 0),
                        t = mk(1, 2, 1, t_rp, t_ci, t_v, 0);
            fricont_problem *p = NULL;
            fricont_path *path = NULL;
            EXPECT(fricont_problem_new(&a, storage, &n, &t, &p), FRICONT_OK, "");
            EXPECT(fricont_problem_set_friction(p, 0.5), FRICONT_OK, "");
            fricont_status st = fricont_problem_build(p);
            CHECK(st == FRICONT_OK, "A x %g, storage %d: %s: %s", sc, storage, fricont_status_str(st), last());
            EXPECT(fricont_path_new_affine(p, g0, g1, 2, &path), FRICONT_OK, "");
            EXPECT(fricont_path_set_window(path, 0.0, 2.0), FRICONT_OK, "");
            EXPECT(fricont_path_start(path, 0.0, NULL, 0), FRICONT_OK, "");
            EXPECT(fricont_path_run(path), FRICONT_END, "");
            int64_t count = 0;
            fricont_event ev = {0};
            EXPECT(fricont_path_event_count(path, &count), FRICONT_OK, "");
            EXPECT(fricont_path_event(path, 0, &ev), FRICONT_OK, "");
            double u[2], ln[1], lt[1];
            fricont_state s = {0, 0, u, 2, ln, 1, lt, 1, NULL, 0};
            EXPECT(fricont_path_event_state(path, 0, &s), FRICONT_OK, "");
            CHECK(count == 1 && fabs(ev.alpha - 0.5) < 1e-14 && ev.from == FRICONT_STICK &&
                      ev.to == FRICONT_SLIP_PLUS && fabs(ln[0] / sc + 1) < 1e-9 &&
                      fabs(lt[0] / sc + 0.5) < 1e-9 && s.residual <= 1e-12,
                  "A x %g, storage %d: %lld events, alpha %.17g, lambda %g %g, residual %g", sc, storage,
                  (long long)count, ev.alpha, ln[0] / sc, lt[0] / sc, s.residual);
            EXPECT(fricont_path_current(path, &s), FRICONT_OK, "");
            CHECK(fabs(u[0]) < 1e-9 && fabs(u[1] - 1.5) < 1e-9 && s.alpha == 2.0,
                  "A x %g: u at alpha = 2: %g %g", sc, u[0], u[1]);
            fricont_path_free(path);
            fricont_problem_free(p);
        }
    }
    /* 1e-315: fewer than 40 significant bits */
    double avs[] = {2e-315, 1e-315};
    fricont_csr a = mk(2, 2, 2, a_rp, a_ci, avs, 0), n = mk(1, 2, 1, n_rp, n_ci, n_v, 0),
                t = mk(1, 2, 1, t_rp, t_ci, t_v, 0);
    fricont_problem *p = NULL;
    EXPECT(fricont_problem_new(&a, FRICONT_STORAGE_FULL, &n, &t, &p), FRICONT_OK, "");
    EXPECT(fricont_problem_build(p), FRICONT_ERR_RANGE, "subnormal");
    fricont_problem_free(p);
    /* a tiny A with an ordinary load pulling the block off (open): u = A^-1 f would
     * overflow. The forces trace; u is an error where it is computed (a state). */
    double atiny[] = {2e-310, 1e-310}, pull[] = {-1.0, 0.0};
    a.values = atiny;
    EXPECT(fricont_problem_new(&a, FRICONT_STORAGE_FULL, &n, &t, &p), FRICONT_OK, "");
    fricont_path *path = NULL;
    EXPECT(fricont_path_new_affine(p, pull, f1, 2, &path), FRICONT_OK, "");
    EXPECT(fricont_path_set_window(path, 0.0, 2.0), FRICONT_OK, "");
    EXPECT(fricont_path_start(path, 0.0, NULL, 0), FRICONT_OK, "");
    EXPECT(fricont_path_start_state(path, NULL), FRICONT_ERR_NUMERICAL, "overflows");
    fricont_path_free(path);
    fricont_problem_free(p);
    /* not symmetric near the largest double: the message has the caller's numbers */
    int64_t rp[] = {0, 2, 3}, ci[] = {0, 1, 1};
    double v[] = {1.6e308, 1e308, 8e307};
    fricont_csr b = mk(2, 2, 3, rp, ci, v, 0);
    EXPECT(fricont_problem_new(&b, FRICONT_STORAGE_FULL, &n, &t, &p), FRICONT_OK, "");
    EXPECT(fricont_problem_build(p), FRICONT_ERR_NOT_SYMMETRIC, "differ by 1e308");
    fricont_problem_free(p);
}

int main(void) {
    test_strings();
    test_extreme_scales();
    test_csr_errors();
    test_problem_setters();
    test_path_construction();
    test_misuse_and_queries();
    test_callback_failures();
    test_fold();
    test_bifurcation();
    test_host_input();
    test_csr_i32();
    test_no_threads_started();
    return finish("status");
}
