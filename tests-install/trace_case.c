/*
 * trace_case: trace a problem in the exchange format (SPEC §7) through the C ABI and
 * print its events in the plain text form that the binding tests compare:
 *
 *   start <alpha> <residual>
 *   event <index> <transition> <alpha> <node> <from> <to> <fold> <bifurcation>
 *   end <reason> <number of pieces>
 *
 * index, transition and node count from 1 (as reports do); alpha is printed with 17
 * significant digits; from/to are class names; fold/bifurcation are 0 or 1.
 *
 * It is the C program that the install tests build against an installed copy
 * (pkg-config and CMake), and the C reference of the Fortran, Octave and C++ tests.
 *
 * Usage: trace_case CASE_DIR
 */
#include <fricont.h>

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static void die(const char *what, const char *detail) {
    fprintf(stderr, "trace_case: %s%s%s\n", what, detail ? ": " : "", detail ? detail : "");
    exit(2);
}

static void check(fricont_status st, const char *what) {
    if (st < 0) {
        char msg[512];
        fricont_last_error_message(msg, sizeof msg);
        fprintf(stderr, "trace_case: %s failed: %s (%s)\n", what, fricont_status_str(st), msg);
        exit(1);
    }
}

static FILE *open_in(const char *dir, const char *name, int required) {
    char path[4096];
    snprintf(path, sizeof path, "%s/%s", dir, name);
    FILE *fp = fopen(path, "r");
    if (!fp && required) die("cannot open", path);
    return fp;
}

/* A Matrix Market coordinate real matrix converted to 0-based CSR. A "symmetric" file
 * keeps its stored triangle (the caller passes the matching storage code). */
typedef struct {
    int64_t nrows, ncols, nnz;
    int64_t *row_ptr, *col_idx;
    double *values;
    int symmetric;
} csr;

static csr read_mtx(const char *dir, const char *name) {
    FILE *fp = open_in(dir, name, 1);
    char line[1024];
    csr m = {0};
    if (!fgets(line, sizeof line, fp) || strncmp(line, "%%MatrixMarket", 14) != 0)
        die("not a Matrix Market file", name);
    if (!strstr(line, "coordinate") || !strstr(line, "real")) die("not coordinate real", name);
    m.symmetric = strstr(line, "symmetric") != NULL;
    do {
        if (!fgets(line, sizeof line, fp)) die("no size line", name);
    } while (line[0] == '%');
    long long r, c, z;
    if (sscanf(line, "%lld %lld %lld", &r, &c, &z) != 3) die("bad size line", name);
    m.nrows = r; m.ncols = c; m.nnz = z;
    int64_t *ri = malloc(sizeof(int64_t) * (size_t)(z + 1));
    int64_t *ci = malloc(sizeof(int64_t) * (size_t)(z + 1));
    double *v = malloc(sizeof(double) * (size_t)(z + 1));
    m.row_ptr = calloc((size_t)r + 1, sizeof(int64_t));
    m.col_idx = malloc(sizeof(int64_t) * (size_t)(z + 1));
    m.values = malloc(sizeof(double) * (size_t)(z + 1));
    if (!ri || !ci || !v || !m.row_ptr || !m.col_idx || !m.values) die("out of memory", name);
    for (int64_t k = 0; k < z; k++) {
        long long i, j;
        if (fscanf(fp, "%lld %lld %lf", &i, &j, &v[k]) != 3) die("short entry list", name);
        if (i < 1 || i > r || j < 1 || j > c) die("entry out of range", name);
        ri[k] = i - 1; ci[k] = j - 1;
        m.row_ptr[ri[k] + 1]++;
    }
    fclose(fp);
    for (int64_t i = 0; i < r; i++) m.row_ptr[i + 1] += m.row_ptr[i];
    int64_t *next = malloc(sizeof(int64_t) * (size_t)(r + 1));
    if (!next) die("out of memory", name);
    memcpy(next, m.row_ptr, sizeof(int64_t) * (size_t)(r + 1));
    for (int64_t k = 0; k < z; k++) {
        int64_t pos = next[ri[k]]++;
        m.col_idx[pos] = ci[k];
        m.values[pos] = v[k];
    }
    free(next); free(ri); free(ci); free(v);
    return m;
}

static double *read_vec(const char *dir, const char *name, int64_t len, int required) {
    FILE *fp = open_in(dir, name, required);
    if (!fp) return NULL;
    double *x = malloc(sizeof(double) * (size_t)len);
    if (!x) die("out of memory", name);
    for (int64_t i = 0; i < len; i++)
        if (fscanf(fp, "%lf", &x[i]) != 1) die("too few numbers in", name);
    fclose(fp);
    return x;
}

/* meta.json: only the keys we need, found by name (the files are written by our tools). */
static char *read_text(const char *dir, const char *name) {
    FILE *fp = open_in(dir, name, 1);
    static char buf[1 << 16];
    size_t len = fread(buf, 1, sizeof buf - 1, fp);
    buf[len] = 0;
    fclose(fp);
    return buf;
}

static const char *json_value(const char *text, const char *key) {
    char pat[64];
    snprintf(pat, sizeof pat, "\"%s\"", key);
    const char *at = strstr(text, pat);
    if (!at) die("meta.json lacks key", key);
    at = strchr(at + strlen(pat), ':');
    if (!at) die("meta.json: no value for", key);
    at++;
    while (*at == ' ' || *at == '\t' || *at == '\n' || *at == '\r') at++;
    return at;
}

static double json_number(const char *text, const char *key) {
    const char *at = json_value(text, key);
    char *end;
    errno = 0;
    double x = strtod(at, &end);
    if (end == at || errno) die("meta.json: not a number:", key);
    return x;
}

int main(int argc, char **argv) {
    if (argc != 2) die("usage: trace_case CASE_DIR", NULL);
    const char *dir = argv[1];
    char *meta = read_text(dir, "meta.json");
    double a0 = json_number(meta, "alpha_start");
    double a1 = json_number(meta, "alpha_end");

    csr a = read_mtx(dir, "A.mtx"), nm = read_mtx(dir, "N.mtx"), tm = read_mtx(dir, "T.mtx");
    int64_t n = a.nrows, p = nm.nrows;
    fricont_csr ca = {a.nrows, a.ncols, a.nnz, a.row_ptr, a.col_idx, a.values, 0};
    fricont_csr cn = {nm.nrows, nm.ncols, nm.nnz, nm.row_ptr, nm.col_idx, nm.values, 0};
    fricont_csr ct = {tm.nrows, tm.ncols, tm.nnz, tm.row_ptr, tm.col_idx, tm.values, 0};
    fricont_problem *prob = NULL;
    /* A symmetric Matrix Market file stores the lower triangle. */
    check(fricont_problem_new(&ca, a.symmetric ? FRICONT_STORAGE_LOWER : FRICONT_STORAGE_FULL,
                              &cn, &ct, &prob),
          "fricont_problem_new");

    const char *fv = json_value(meta, "F");
    if (*fv == '[') {
        double *f = malloc(sizeof(double) * (size_t)p);
        if (!f) die("out of memory", NULL);
        const char *at = fv + 1;
        for (int64_t i = 0; i < p; i++) {
            char *end;
            f[i] = strtod(at, &end);
            if (end == at) die("meta.json: short F array", NULL);
            at = end;
            while (*at == ',' || *at == ' ' || *at == '\n') at++;
        }
        check(fricont_problem_set_friction_nodes(prob, f, p), "set_friction_nodes");
        free(f);
    } else {
        check(fricont_problem_set_friction(prob, json_number(meta, "F")), "set_friction");
    }
    double *gap = read_vec(dir, "gap.txt", p, 0);
    if (gap) check(fricont_problem_set_gap(prob, gap, p), "set_gap");

    double *f0 = read_vec(dir, "f0.txt", n, 1), *f1 = read_vec(dir, "f1.txt", n, 1);
    fricont_path *path = NULL;
    check(fricont_path_new_affine(prob, f0, f1, n, &path), "fricont_path_new_affine");
    fricont_problem_free(prob);
    check(fricont_path_set_window(path, a0, a1), "set_window");
    check(fricont_path_start(path, a0, NULL, 0), "fricont_path_start");
    check(fricont_path_run(path), "fricont_path_run");

    fricont_state st;
    memset(&st, 0, sizeof st);
    check(fricont_path_start_state(path, &st), "start_state");
    printf("start %.17g %.3e\n", st.alpha, st.residual);
    int64_t count = 0, pieces = 0;
    check(fricont_path_event_count(path, &count), "event_count");
    for (int64_t k = 0; k < count; k++) {
        fricont_event e;
        check(fricont_path_event(path, k, &e), "event");
        printf("event %lld %lld %.17g %lld %s %s %d %d\n", (long long)e.index + 1,
               (long long)e.transition + 1, e.alpha, (long long)e.node + 1,
               fricont_class_name(e.from), fricont_class_name(e.to), e.fold ? 1 : 0,
               e.bifurcation ? 1 : 0);
    }
    int32_t reason = 0;
    check(fricont_path_end_reason(path, &reason), "end_reason");
    check(fricont_path_piece_count(path, &pieces), "piece_count");
    static const char *names[] = {"none", "window", "max_steps", "closed_loop", "bifurcation",
                                  "failed"};
    printf("end %s %lld\n", reason >= 0 && reason <= 5 ? names[reason] : "unknown",
           (long long)pieces);
    fricont_path_free(path);
    free(f0); free(f1); free(gap);
    free(a.row_ptr); free(a.col_idx); free(a.values);
    free(nm.row_ptr); free(nm.col_idx); free(nm.values);
    free(tm.row_ptr); free(tm.col_idx); free(tm.values);
    return 0;
}
