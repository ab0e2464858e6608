/* A FEM user's program: plane-strain elasticity on a rectangle with Q1 elements, the left
 * side clamped, the bottom resting on a rigid foundation with Coulomb friction; a
 * pressure on the top, and a load growing with alpha that shears the top and lifts the
 * right side. Assemble A, N, T in CSR, hand them to fricont, trace alpha from 0 to 1 and
 * print every transition (contact nodes numbered from 1, left to right).
 *
 * build:  cc -std=c99 -O2 -I include examples-c/q1_rectangle.c -L target/release \
 *            -Wl,-rpath,$PWD/target/release -lfricont -lm -o q1_rectangle
 * run:    ./q1_rectangle            (print the transition table)
 *         ./q1_rectangle --write DIR  (also write the problem in the exchange format) */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fricont.h"

#define NX 16 /* elements along x */
#define NY 4  /* elements along y */
#define LX 4.0
#define LY 1.0
#define E_MOD 1.0
#define NU 0.3
#define FRICTION 0.4

/* dof number of (node column i, node row j, direction d), or -1 on the clamped side */
static int dof(int i, int j, int d) { return i == 0 ? -1 : 2 * (j * NX + (i - 1)) + d; }

/* 8x8 stiffness of a hx-by-hy Q1 element, plane strain, 2x2 Gauss points. Local node
 * order (0,0), (1,0), (1,1), (0,1); dofs (ux, uy) per node. */
static void element_stiffness(double hx, double hy, double ke[8][8]) {
    double c = E_MOD / ((1 + NU) * (1 - 2 * NU));
    double D[3][3] = {{c * (1 - NU), c * NU, 0}, {c * NU, c * (1 - NU), 0}, {0, 0, c * (1 - 2 * NU) / 2}};
    double xi_n[4] = {-1, 1, 1, -1}, eta_n[4] = {-1, -1, 1, 1}, g = 0.5773502691896257;
    memset(ke, 0, sizeof(double) * 64);
    for (int gp = 0; gp < 4; gp++) {
        double xi = xi_n[gp] * g, eta = eta_n[gp] * g, B[3][8] = {{0}};
        for (int a = 0; a < 4; a++) {
            double dx = xi_n[a] * (1 + eta_n[a] * eta) / 4 * 2 / hx;
            double dy = eta_n[a] * (1 + xi_n[a] * xi) / 4 * 2 / hy;
            B[0][2 * a] = dx;
            B[1][2 * a + 1] = dy;
            B[2][2 * a] = dy;
            B[2][2 * a + 1] = dx;
        }
        double w = hx * hy / 4; /* Jacobian determinant, Gauss weights 1 */
        for (int r = 0; r < 8; r++)
            for (int s = 0; s < 8; s++)
                for (int k = 0; k < 3; k++)
                    for (int l = 0; l < 3; l++) ke[r][s] += B[k][r] * D[k][l] * B[l][s] * w;
    }
}

/* Dense lower triangle to CSR (0-based): fine for a small example; a real code assembles
 * the CSR arrays directly. */
static fricont_csr dense_to_csr(const double *m, int nrows, int ncols, int lower_only) {
    int64_t *rp = malloc(sizeof(int64_t) * (size_t)(nrows + 1)), nnz = 0;
    for (int i = 0; i < nrows; i++)
        for (int j = 0; j < (lower_only ? i + 1 : ncols); j++) nnz += m[i * ncols + j] != 0;
    int64_t *ci = malloc(sizeof(int64_t) * (size_t)nnz);
    double *v = malloc(sizeof(double) * (size_t)nnz);
    nnz = 0;
    for (int i = 0; i < nrows; i++) {
        rp[i] = nnz;
        for (int j = 0; j < (lower_only ? i + 1 : ncols); j++)
            if (m[i * ncols + j] != 0) {
                ci[nnz] = j;
                v[nnz++] = m[i * ncols + j];
            }
    }
    rp[nrows] = nnz;
    fricont_csr out = {nrows, ncols, nnz, rp, ci, v, 0};
    return out;
}

static void free_csr(fricont_csr *m) {
    free((void *)m->row_ptr);
    free((void *)m->col_idx);
    free((void *)m->values);
}

static void write_mtx(const char *dir, const char *name, const double *m, int nr, int nc) {
    char path[1024];
    snprintf(path, sizeof path, "%s/%s", dir, name);
    FILE *f = fopen(path, "w");
    if (!f) return;
    int nnz = 0;
    for (int k = 0; k < nr * nc; k++) nnz += m[k] != 0;
    fprintf(f, "%%%%MatrixMarket matrix coordinate real general\n%d %d %d\n", nr, nc, nnz);
    for (int i = 0; i < nr; i++)
        for (int j = 0; j < nc; j++)
            if (m[i * nc + j] != 0) fprintf(f, "%d %d %.17g\n", i + 1, j + 1, m[i * nc + j]);
    fclose(f);
}

static void write_vec(const char *dir, const char *name, const double *v, int n) {
    char path[1024];
    snprintf(path, sizeof path, "%s/%s", dir, name);
    FILE *f = fopen(path, "w");
    if (!f) return;
    for (int i = 0; i < n; i++) fprintf(f, "%.17g\n", v[i]);
    fclose(f);
}

static int check(fricont_status st, const char *what) {
    if (st >= 0) return 0;
    char msg[512];
    fricont_last_error_message(msg, sizeof msg);
    fprintf(stderr, "%s: %s\n  %s\n", what, fricont_status_str(st), msg);
    return 1;
}

int main(int argc, char **argv) {
    const int n = 2 * NX * (NY + 1), p = NX;
    const double hx = LX / NX, hy = LY / NY;
    double *a = calloc((size_t)n * n, sizeof(double));
    double *nm = calloc((size_t)p * n, sizeof(double)), *tm = calloc((size_t)p * n, sizeof(double));
    double *f0 = calloc((size_t)n, sizeof(double)), *f1 = calloc((size_t)n, sizeof(double));

    /* stiffness */
    double ke[8][8];
    element_stiffness(hx, hy, ke);
    for (int ey = 0; ey < NY; ey++)
        for (int ex = 0; ex < NX; ex++) {
            int ni[4] = {ex, ex + 1, ex + 1, ex}, nj[4] = {ey, ey, ey + 1, ey + 1}, d[8];
            for (int k = 0; k < 8; k++) d[k] = dof(ni[k / 2], nj[k / 2], k % 2);
            for (int r = 0; r < 8; r++)
                for (int s = 0; s < 8; s++)
                    if (d[r] >= 0 && d[s] >= 0) a[d[r] * n + d[s]] += ke[r][s];
        }
    /* contact: bottom nodes i = 1..NX; outward normal -y, tangent +x */
    for (int k = 0; k < p; k++) {
        nm[k * n + dof(k + 1, 0, 1)] = -1.0;
        tm[k * n + dof(k + 1, 0, 0)] = 1.0;
    }
    /* loads (consistent nodal forces of uniform tractions): f0 presses the top down;
     * f1 shears the top to the right and lifts the right side. */
    for (int i = 1; i <= NX; i++) {
        double w = (i == NX ? 0.5 : 1.0) * hx;
        f0[dof(i, NY, 1)] += -0.02 * w;
        f1[dof(i, NY, 0)] += 0.01 * w;
    }
    for (int j = 0; j <= NY; j++) {
        double w = (j == 0 || j == NY ? 0.5 : 1.0) * hy;
        f1[dof(NX, j, 1)] += 0.03 * w;
    }

    if (argc == 3 && strcmp(argv[1], "--write") == 0) {
        write_mtx(argv[2], "A.mtx", a, n, n);
        write_mtx(argv[2], "N.mtx", nm, p, n);
        write_mtx(argv[2], "T.mtx", tm, p, n);
        write_vec(argv[2], "f0.txt", f0, n);
        write_vec(argv[2], "f1.txt", f1, n);
        char path[1024];
        snprintf(path, sizeof path, "%s/meta.json", argv[2]);
        FILE *f = fopen(path, "w");
        if (f) {
            fprintf(f, "{\"n\": %d, \"p\": %d, \"F\": %g, \"alpha_start\": 0, \"alpha_end\": 1,\n"
                       " \"mesh\": \"Q1 %dx%d elements on (0,%g)x(0,%g), left clamped, bottom contact\"}\n",
                    n, p, FRICTION, NX, NY, LX, LY);
            fclose(f);
        }
    }

    /* hand the problem to fricont: A as its lower triangle, N and T in full */
    fricont_csr ac = dense_to_csr(a, n, n, 1), nc = dense_to_csr(nm, p, n, 0), tc = dense_to_csr(tm, p, n, 0);
    fricont_problem *problem = NULL;
    fricont_path *path = NULL;
    int err = check(fricont_problem_new(&ac, FRICONT_STORAGE_LOWER, &nc, &tc, &problem), "problem");
    free_csr(&ac);
    free_csr(&nc);
    free_csr(&tc);
    err = err || check(fricont_problem_set_friction(problem, FRICTION), "friction");
    err = err || check(fricont_path_new_affine(problem, f0, f1, n, &path), "path");
    err = err || check(fricont_path_set_window(path, 0.0, 1.0), "window");
    err = err || check(fricont_path_start(path, 0.0, NULL, 0), "start");
    if (!err) {
        int32_t *cls = malloc(sizeof(int32_t) * (size_t)p);
        fricont_state s = {0, 0, NULL, 0, NULL, 0, NULL, 0, cls, p};
        fricont_path_start_state(path, &s);
        printf("Q1 rectangle %gx%g, %dx%d elements, n = %d dofs, p = %d contact nodes, F = %g\n", LX, LY, NX, NY,
               n, p, FRICTION);
        printf("start at alpha = 0:");
        for (int k = 0; k < p; k++) printf(" %s", fricont_class_name(cls[k]));
        printf("\n\n  #  alpha              node  from   -> to     fold\n");
        fricont_status st;
        while ((st = fricont_path_step(path)) > 0 && st != FRICONT_END) {
        }
        err = check(st, "step");
        int64_t count = 0;
        fricont_path_event_count(path, &count);
        for (int64_t k = 0; k < count; k++) {
            fricont_event ev;
            fricont_path_event(path, k, &ev);
            printf("%3lld  %-17.14g  %4lld  %-6s -> %-6s %s\n", (long long)k + 1, ev.alpha, (long long)ev.node + 1,
                   fricont_class_name(ev.from), fricont_class_name(ev.to), ev.fold ? "yes" : "");
        }
        fricont_path_current(path, &s);
        printf("\nend at alpha = %g:", s.alpha);
        for (int k = 0; k < p; k++) printf(" %s", fricont_class_name(cls[k]));
        printf("\n");
        free(cls);
    }
    fricont_path_free(path);
    fricont_problem_free(problem);
    free(a);
    free(nm);
    free(tm);
    free(f0);
    free(f1);
    return err;
}
