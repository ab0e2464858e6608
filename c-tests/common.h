/* Shared helpers of the C tests: a minimal reader of the exchange format (Matrix Market
 * coordinate files, one-number-a-line text files, the few keys of meta.json the tests
 * need), CSR assembly with int64_t indices, and pass/fail counting. */
#ifndef FRICONT_CTESTS_COMMON_H
#define FRICONT_CTESTS_COMMON_H

#include <stdint.h>
#include <stdio.h>

#include "fricont.h"

/* A sparse matrix as 0-based triplets (duplicates summed when converted). */
typedef struct {
    int64_t nrows, ncols, nnz;
    int64_t *row, *col;
    double *val;
    int symmetric; /* Matrix Market "symmetric": only one triangle stored */
} triplets;

/* A problem in the exchange format. */
typedef struct {
    int64_t n, p;
    triplets a, nm, tm;
    double *f0, *f1, *gap; /* gap NULL when absent */
    double *friction;      /* p values (a scalar F is broadcast) */
    double alpha_start, alpha_end;
} case_data;

/* A CSR matrix owning its arrays, with a chosen index base. */
typedef struct {
    int64_t nrows, ncols, nnz, base;
    int64_t *row_ptr, *col_idx;
    double *values;
} csr;

enum which_part { PART_FULL, PART_LOWER, PART_UPPER };

int read_case(const char *dir, case_data *c);
void free_case(case_data *c);
/* CSR of the triplets (expanded to both triangles when symmetric, then restricted to
 * `part`), duplicates summed, sorted columns, index base `base`. */
csr csr_from_triplets(const triplets *t, enum which_part part, int64_t base);
void free_csr(csr *m);
fricont_csr csr_view(const csr *m);
/* A problem handle for a case: A in the given storage and index base, friction and gap
 * from the case. Returns the status of the first failing call. */
fricont_status problem_from_case(const case_data *c, int32_t storage, int64_t base,
                                 fricont_problem **out);
/* Sets a case's friction and gap on a problem handle (any constructor). */
fricont_status set_case_settings(const case_data *c, fricont_problem *p);

/* Pass/fail bookkeeping. */
extern long g_passed, g_failed;
#define CHECK(cond, ...)                                                                   \
    do {                                                                                   \
        if (cond) {                                                                        \
            g_passed++;                                                                    \
        } else {                                                                           \
            g_failed++;                                                                    \
            fprintf(stderr, "FAIL %s:%d: ", __FILE__, __LINE__);                           \
            fprintf(stderr, __VA_ARGS__);                                                  \
            fprintf(stderr, "\n");                                                         \
        }                                                                                  \
    } while (0)
/* Prints "<name>: N passed, M failed" and returns the exit code. */
int finish(const char *name);

#endif
