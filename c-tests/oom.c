/* Out of memory is a status, not an abort: problems whose W (2p x 2p) or whose trailing
 * block of the factor cannot be allocated return FRICONT_ERR_OUT_OF_MEMORY with the size
 * in the message; the process goes on, the handle is not poisoned (a second build gives
 * the same status), and a small problem built afterwards works.
 *
 * usage: oom P   (P contact nodes; run.sh uses P = 20000 under `ulimit -v` of 4 GiB, and
 *                 P = 200000, whose W needs 1.2 TiB, under valgrind without a limit) */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "common.h"

static char msg[1024];

static int solve_calls = 0;
static int never_solve(void *user, int64_t n, int64_t ncols, double *x, int64_t ldx) {
    (void)user, (void)n, (void)ncols, (void)x, (void)ldx;
    solve_calls++;
    return -1;
}

/* N row k = e_{2k}, T row k = e_{2k+1} (0-based), n columns. */
static void contact_rows(int64_t p, int64_t n, csr *nm, csr *tm) {
    csr *m[2] = {nm, tm};
    for (int r = 0; r < 2; r++) {
        m[r]->nrows = p;
        m[r]->ncols = n;
        m[r]->nnz = p;
        m[r]->base = 0;
        m[r]->row_ptr = malloc(sizeof(int64_t) * (size_t)(p + 1));
        m[r]->col_idx = malloc(sizeof(int64_t) * (size_t)p);
        m[r]->values = malloc(sizeof(double) * (size_t)p);
        for (int64_t k = 0; k <= p; k++) m[r]->row_ptr[k] = k;
        for (int64_t k = 0; k < p; k++) {
            m[r]->col_idx[k] = 2 * k + r;
            m[r]->values[k] = 1.0;
        }
    }
}

int main(int argc, char **argv) {
    int64_t p = argc > 1 ? atoll(argv[1]) : 20000;
    int64_t n = 5 * p;
    csr nm, tm;
    contact_rows(p, n, &nm, &tm);
    fricont_csr nv = csr_view(&nm), tv = csr_view(&tm);

    /* A host's solve: W = B A^-1 B^T by solves cannot even be allocated. */
    fricont_problem *prob = NULL;
    fricont_status st = fricont_problem_new_solve(n, never_solve, NULL, NULL, 64, &nv, &tv, &prob);
    CHECK(st == FRICONT_OK, "new_solve: %s", fricont_status_str(st));
    st = fricont_problem_build(prob);
    fricont_last_error_message(msg, sizeof msg);
    CHECK(st == FRICONT_ERR_OUT_OF_MEMORY && strstr(msg, "GiB"), "host solve, p = %lld: %s: %s", (long long)p,
          fricont_status_str(st), msg);
    printf("host's solve, p = %lld: %s\n", (long long)p, msg);
    CHECK(solve_calls == 0, "the solve was called %d times before the allocation failed", solve_calls);
    st = fricont_problem_build(prob);
    CHECK(st == FRICONT_ERR_OUT_OF_MEMORY, "second build: %s (the handle must not be poisoned)", fricont_status_str(st));
    fricont_problem_free(prob);

    /* A, N, T: A = I (n x n); the trailing block of the factor is 2p x 2p. */
    csr a = {n, n, n, 0, malloc(sizeof(int64_t) * (size_t)(n + 1)), malloc(sizeof(int64_t) * (size_t)n),
             malloc(sizeof(double) * (size_t)n)};
    for (int64_t i = 0; i <= n; i++) a.row_ptr[i] = i;
    for (int64_t i = 0; i < n; i++) {
        a.col_idx[i] = i;
        a.values[i] = 1.0;
    }
    fricont_csr av = csr_view(&a);
    st = fricont_problem_new(&av, FRICONT_STORAGE_LOWER, &nv, &tv, &prob);
    CHECK(st == FRICONT_OK, "new: %s", fricont_status_str(st));
    st = fricont_problem_build(prob);
    fricont_last_error_message(msg, sizeof msg);
    CHECK(st == FRICONT_ERR_OUT_OF_MEMORY && strstr(msg, "GiB"), "A, N, T, p = %lld: %s: %s", (long long)p,
          fricont_status_str(st), msg);
    printf("A, N, T, p = %lld: %s\n", (long long)p, msg);
    int64_t nd = 0, pd = 0;
    CHECK(fricont_problem_dims(prob, &nd, &pd) == FRICONT_OK && nd == n && pd == p, "dims after the failure");
    fricont_problem_free(prob);
    free_csr(&a);
    free_csr(&nm);
    free_csr(&tm);

    /* Life goes on: a small problem (p = 2 of the same kind) builds and traces. */
    contact_rows(2, 10, &nm, &tm);
    nv = csr_view(&nm);
    tv = csr_view(&tm);
    csr a2 = {10, 10, 10, 0, malloc(sizeof(int64_t) * 11), malloc(sizeof(int64_t) * 10), malloc(sizeof(double) * 10)};
    for (int64_t i = 0; i <= 10; i++) a2.row_ptr[i] = i;
    for (int64_t i = 0; i < 10; i++) {
        a2.col_idx[i] = i;
        a2.values[i] = 1.0;
    }
    av = csr_view(&a2);
    double f0[10] = {0}, f1[10] = {0};
    f0[0] = f0[2] = 1.0; /* pressed into contact (N row = +e_0: (N u) <= 0 ...) */
    f1[1] = f1[3] = 1.0;
    fricont_path *path = NULL;
    st = fricont_problem_new(&av, FRICONT_STORAGE_LOWER, &nv, &tv, &prob);
    if (st == FRICONT_OK) st = fricont_path_new_affine(prob, f0, f1, 10, &path);
    if (st == FRICONT_OK) st = fricont_path_set_window(path, 0.0, 1.0);
    if (st == FRICONT_OK) st = fricont_path_start(path, 0.0, NULL, 0);
    if (st == FRICONT_OK) st = fricont_path_run(path);
    CHECK(st == FRICONT_END, "a small problem after the failures: %s", fricont_status_str(st));
    fricont_path_free(path);
    fricont_problem_free(prob);
    free_csr(&a2);
    free_csr(&nm);
    free_csr(&tm);
    return finish("oom");
}
