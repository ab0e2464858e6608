#include "common.h"

#include <ctype.h>
#include <stdlib.h>
#include <string.h>

long g_passed = 0, g_failed = 0;

int finish(const char *name) {
    printf("%s: %ld passed, %ld failed\n", name, g_passed, g_failed);
    return g_failed == 0 ? 0 : 1;
}

static char *path_join(const char *dir, const char *file) {
    size_t n = strlen(dir) + strlen(file) + 2;
    char *s = malloc(n);
    snprintf(s, n, "%s/%s", dir, file);
    return s;
}

static int read_mtx(const char *dir, const char *file, triplets *t) {
    char *path = path_join(dir, file);
    FILE *f = fopen(path, "r");
    free(path);
    if (!f) return -1;
    char line[1024];
    memset(t, 0, sizeof *t);
    if (!fgets(line, sizeof line, f) || strncmp(line, "%%MatrixMarket", 14) != 0) {
        fclose(f);
        return -1;
    }
    if (!strstr(line, "coordinate") || !strstr(line, "real")) {
        fclose(f);
        return -1;
    }
    t->symmetric = strstr(line, "symmetric") != NULL;
    do {
        if (!fgets(line, sizeof line, f)) {
            fclose(f);
            return -1;
        }
    } while (line[0] == '%');
    long long r, c, nz;
    if (sscanf(line, "%lld %lld %lld", &r, &c, &nz) != 3) {
        fclose(f);
        return -1;
    }
    t->nrows = r;
    t->ncols = c;
    t->nnz = nz;
    t->row = malloc(sizeof(int64_t) * (size_t)(nz + 1));
    t->col = malloc(sizeof(int64_t) * (size_t)(nz + 1));
    t->val = malloc(sizeof(double) * (size_t)(nz + 1));
    for (long long k = 0; k < nz; k++) {
        long long i, j;
        double v;
        if (fscanf(f, "%lld %lld %lf", &i, &j, &v) != 3) {
            fclose(f);
            return -1;
        }
        t->row[k] = i - 1;
        t->col[k] = j - 1;
        t->val[k] = v;
    }
    fclose(f);
    return 0;
}

static double *read_vec(const char *dir, const char *file, int64_t n) {
    char *path = path_join(dir, file);
    FILE *f = fopen(path, "r");
    free(path);
    if (!f) return NULL;
    double *v = malloc(sizeof(double) * (size_t)(n > 0 ? n : 1));
    for (int64_t i = 0; i < n; i++) {
        if (fscanf(f, "%lf", &v[i]) != 1) {
            free(v);
            fclose(f);
            return NULL;
        }
    }
    fclose(f);
    return v;
}

/* The text following "key": in a JSON object (no nesting needed here). */
static const char *json_value(const char *json, const char *key) {
    char pat[64];
    snprintf(pat, sizeof pat, "\"%s\"", key);
    const char *s = strstr(json, pat);
    if (!s) return NULL;
    s += strlen(pat);
    while (*s && (isspace((unsigned char)*s) || *s == ':')) s++;
    return s;
}

int read_case(const char *dir, case_data *c) {
    memset(c, 0, sizeof *c);
    char *path = path_join(dir, "meta.json");
    FILE *f = fopen(path, "r");
    free(path);
    if (!f) return -1;
    char json[1 << 16];
    size_t len = fread(json, 1, sizeof json - 1, f);
    json[len] = 0;
    fclose(f);
    const char *v;
    if (!(v = json_value(json, "n"))) return -1;
    c->n = strtoll(v, NULL, 10);
    if (!(v = json_value(json, "p"))) return -1;
    c->p = strtoll(v, NULL, 10);
    if (!(v = json_value(json, "alpha_start"))) return -1;
    c->alpha_start = strtod(v, NULL);
    if (!(v = json_value(json, "alpha_end"))) return -1;
    c->alpha_end = strtod(v, NULL);
    c->friction = malloc(sizeof(double) * (size_t)c->p);
    if (!(v = json_value(json, "F"))) return -1;
    if (*v == '[') {
        v++;
        for (int64_t i = 0; i < c->p; i++) {
            char *end;
            c->friction[i] = strtod(v, &end);
            v = end;
            while (*v == ',' || isspace((unsigned char)*v)) v++;
        }
    } else {
        double F = strtod(v, NULL);
        for (int64_t i = 0; i < c->p; i++) c->friction[i] = F;
    }
    if (read_mtx(dir, "A.mtx", &c->a) || read_mtx(dir, "N.mtx", &c->nm) ||
        read_mtx(dir, "T.mtx", &c->tm))
        return -1;
    if (c->a.nrows != c->n || c->nm.nrows != c->p || c->tm.nrows != c->p) return -1;
    c->f0 = read_vec(dir, "f0.txt", c->n);
    c->f1 = read_vec(dir, "f1.txt", c->n);
    if (!c->f0 || !c->f1) return -1;
    c->gap = read_vec(dir, "gap.txt", c->p); /* optional */
    return 0;
}

static void free_triplets(triplets *t) {
    free(t->row);
    free(t->col);
    free(t->val);
}

void free_case(case_data *c) {
    free_triplets(&c->a);
    free_triplets(&c->nm);
    free_triplets(&c->tm);
    free(c->f0);
    free(c->f1);
    free(c->gap);
    free(c->friction);
}

typedef struct {
    int64_t r, c;
    double v;
} entry;

static int cmp_entry(const void *x, const void *y) {
    const entry *a = x, *b = y;
    if (a->r != b->r) return a->r < b->r ? -1 : 1;
    if (a->c != b->c) return a->c < b->c ? -1 : 1;
    return 0;
}

csr csr_from_triplets(const triplets *t, enum which_part part, int64_t base) {
    entry *e = malloc(sizeof(entry) * (size_t)(2 * t->nnz + 1));
    int64_t m = 0;
    for (int64_t k = 0; k < t->nnz; k++) {
        int64_t i = t->row[k], j = t->col[k];
        e[m++] = (entry){i, j, t->val[k]};
        if (t->symmetric && i != j) e[m++] = (entry){j, i, t->val[k]};
    }
    qsort(e, (size_t)m, sizeof(entry), cmp_entry);
    csr out = {t->nrows, t->ncols, 0, base, NULL, NULL, NULL};
    out.row_ptr = calloc((size_t)t->nrows + 1, sizeof(int64_t));
    out.col_idx = malloc(sizeof(int64_t) * (size_t)(m + 1));
    out.values = malloc(sizeof(double) * (size_t)(m + 1));
    int64_t nz = 0;
    for (int64_t k = 0; k < m; k++) {
        if ((part == PART_LOWER && e[k].c > e[k].r) || (part == PART_UPPER && e[k].c < e[k].r))
            continue;
        if (nz > 0 && out.col_idx[nz - 1] == e[k].c + base && k > 0 && e[k - 1].r == e[k].r &&
            e[k - 1].c == e[k].c) {
            out.values[nz - 1] += e[k].v;
            continue;
        }
        out.col_idx[nz] = e[k].c + base;
        out.values[nz] = e[k].v;
        out.row_ptr[e[k].r + 1]++;
        nz++;
    }
    for (int64_t i = 0; i < t->nrows; i++) out.row_ptr[i + 1] += out.row_ptr[i];
    for (int64_t i = 0; i <= t->nrows; i++) out.row_ptr[i] += base;
    out.nnz = nz;
    free(e);
    return out;
}

void free_csr(csr *m) {
    free(m->row_ptr);
    free(m->col_idx);
    free(m->values);
}

fricont_csr csr_view(const csr *m) {
    fricont_csr v = {m->nrows, m->ncols, m->nnz, m->row_ptr, m->col_idx, m->values, m->base};
    return v;
}

fricont_status problem_from_case(const case_data *c, int32_t storage, int64_t base,
                                 fricont_problem **out) {
    enum which_part part = storage == FRICONT_STORAGE_LOWER   ? PART_LOWER
                           : storage == FRICONT_STORAGE_UPPER ? PART_UPPER
                                                              : PART_FULL;
    csr a = csr_from_triplets(&c->a, part, base);
    csr nm = csr_from_triplets(&c->nm, PART_FULL, base);
    csr tm = csr_from_triplets(&c->tm, PART_FULL, base);
    fricont_csr av = csr_view(&a), nv = csr_view(&nm), tv = csr_view(&tm);
    fricont_status st = fricont_problem_new(&av, storage, &nv, &tv, out);
    free_csr(&a);
    free_csr(&nm);
    free_csr(&tm);
    if (st != FRICONT_OK) return st;
    return set_case_settings(c, *out);
}

fricont_status set_case_settings(const case_data *c, fricont_problem *p) {
    fricont_status st = fricont_problem_set_friction_nodes(p, c->friction, c->p);
    if (st == FRICONT_OK && c->gap) st = fricont_problem_set_gap(p, c->gap, c->p);
    return st;
}
