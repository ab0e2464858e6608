/* Times CHOLMOD on a problem directory's A.mtx: reading the Matrix Market file, the
 * symbolic analysis (fill-reducing ordering) and the numeric Cholesky factorisation, in
 * one run, for comparison with fricont's set-up (cli/benches/setup.rs).
 *
 *   cc -O2 -I/usr/include/suitesparse benches-c/cholmod_setup_time.c -lcholmod -o cholmod_setup_time
 *   ./cholmod_setup_time DIR            # prints read_s, analyse_s, factorise_s, nnz(L)
 */
#include <stdio.h>
#include <stdlib.h>
#include <time.h>
#include <cholmod.h>

static double now(void) {
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

int main(int argc, char **argv) {
    if (argc < 2) {
        fprintf(stderr, "usage: %s DIR (a problem directory with A.mtx)\n", argv[0]);
        return 2;
    }
    char path[4096];
    snprintf(path, sizeof path, "%s/A.mtx", argv[1]);
    FILE *f = fopen(path, "r");
    if (!f) {
        perror(path);
        return 2;
    }
    cholmod_common c;
    cholmod_l_start(&c);
    double t0 = now();
    cholmod_sparse *a = cholmod_l_read_sparse(f, &c);
    double t1 = now();
    fclose(f);
    if (!a) {
        fprintf(stderr, "%s: CHOLMOD cannot read it (status %d)\n", path, c.status);
        return 1;
    }
    /* A general (unsymmetric-stored) matrix: use its lower triangle as symmetric. */
    if (a->stype == 0) {
        cholmod_sparse *l = cholmod_l_copy(a, -1, 1, &c);
        cholmod_l_free_sparse(&a, &c);
        a = l;
    }
    double t2 = now();
    cholmod_factor *lf = cholmod_l_analyze(a, &c);
    double t3 = now();
    int ok = cholmod_l_factorize(a, lf, &c);
    double t4 = now();
    if (!ok || c.status != CHOLMOD_OK) {
        fprintf(stderr, "CHOLMOD factorisation failed (status %d)\n", c.status);
        return 1;
    }
    printf("n = %ld, nnz(A) stored = %ld, nnz(L) = %.0f\n", (long)a->nrow,
           (long)cholmod_l_nnz(a, &c), c.lnz);
    printf("cholmod read_s %.3f analyse_s %.3f factorise_s %.3f (analyse+factorise %.3f)\n",
           t1 - t0, t3 - t2, t4 - t3, t4 - t2);
    cholmod_l_free_factor(&lf, &c);
    cholmod_l_free_sparse(&a, &c);
    cholmod_l_finish(&c);
    return 0;
}
