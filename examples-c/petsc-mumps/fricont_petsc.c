/* A distributed host: PETSc assembles the problem over MPI ranks, MUMPS computes the
 * condensed operators as a Schur complement, and fricont traces on rank 0.
 *
 * The body is a plane-strain Q1 rectangle (NX x NY elements on (0, 4) x (0, 1), E = 1,
 * nu = 0.3), clamped on the left, resting on a rigid foundation along the bottom (p = NX
 * contact nodes, outward normal -y, tangent +x, friction F = 0.4); f0 presses the top
 * down, f1 shears the top and lifts the right side (as examples-c/q1_rectangle.c).
 *
 * Every rank assembles its share of the elements into one distributed matrix
 *
 *         [ A   B^T  Fl ]        B  = [N; T]          (2p x n)
 *     K = [ B   0    0  ]        Fl = [f0 f1]          (n x 2)
 *         [ Fl^T 0   0  ]
 *
 * and MUMPS factors it (symmetric indefinite LDL^T) with the last 2p + 2 unknowns as the
 * Schur block: S = -[B; Fl^T] A^-1 [B^T Fl], so W = -S[0:2p, 0:2p] and
 * q_j = -S[0:2p, 2p + j]. A is never gathered on one rank. fricont gets only W, q0, q1
 * (fricont_problem_new_condensed) and traces alpha in [0, 1] on rank 0.
 *
 * Pitfalls (PETSc 3.18, MUMPS 5.5, as in Debian 12):
 *  - the Schur index set is given on rank 0 only (MUMPS centralises the complement there;
 *    PETSc refuses a distributed one);
 *  - PETSc cannot solve with a parallel Schur complement, which is why the load columns
 *    are bordered into K instead of solved for afterwards;
 *  - check MatFactorGetError and INFOG(1) after the factorisation: MUMPS can fail (for
 *    example INFOG(1) = -38 with parallel analysis, ICNTL(28) = 2) while PETSc returns a
 *    zero Schur complement without an error;
 *  - Debian's MUMPS silently falls back to the PORD ordering when Scotch or METIS is
 *    requested (harmless here).
 *
 * As a check, rank 0 also assembles A, N, T itself (sequentially, with the same element
 * routine), traces with the ordinary constructor fricont_problem_new, and compares the
 * events: same count, nodes, classes and fold flags, alpha to 1e-10 relative. Exit status
 * 0 when they agree.
 *
 * build:  mpicc -O2 $(pkg-config --cflags petsc) -I include \
 *             examples-c/petsc-mumps/fricont_petsc.c $(pkg-config --libs petsc) \
 *             -L target/release -Wl,-rpath,$PWD/target/release -lfricont -lm -o fricont_petsc
 * run:    mpirun -np 2 ./fricont_petsc [-nx 64] [-ny 8]
 */
#include <math.h>
#include <petscmat.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>

#include "fricont.h"

#define LX 4.0
#define LY 1.0
#define E_MOD 1.0
#define NU 0.3
#define FRICTION 0.4

typedef struct {
    PetscInt nx, ny, n, p;
} mesh;

/* dof of (node column i, node row j, direction d), -1 on the clamped side */
static PetscInt dof(const mesh *m, PetscInt i, PetscInt j, PetscInt d) {
    return i == 0 ? -1 : 2 * (j * m->nx + (i - 1)) + d;
}

/* 8x8 stiffness of a hx-by-hy Q1 element, plane strain, 2x2 Gauss points. Local node
 * order (0,0), (1,0), (1,1), (0,1); dofs (ux, uy) per node. */
static void element_stiffness(double hx, double hy, double ke[8][8]) {
    double c = E_MOD / ((1 + NU) * (1 - 2 * NU));
    double D[3][3] = {{c * (1 - NU), c * NU, 0}, {c * NU, c * (1 - NU), 0}, {0, 0, c * (1 - 2 * NU) / 2}};
    double xi_n[4] = {-1, 1, 1, -1}, eta_n[4] = {-1, -1, 1, 1}, g = 0.5773502691896257;
    for (int r = 0; r < 8; r++)
        for (int s = 0; s < 8; s++) ke[r][s] = 0;
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
        double w = hx * hy / 4;
        for (int r = 0; r < 8; r++)
            for (int s = 0; s < 8; s++)
                for (int k = 0; k < 3; k++)
                    for (int l = 0; l < 3; l++) ke[r][s] += B[k][r] * D[k][l] * B[l][s] * w;
    }
}

/* Adds the stiffness of the element columns ex in [ex0, ex1) to M (rows and columns 0..n). */
static PetscErrorCode add_stiffness(const mesh *m, PetscInt ex0, PetscInt ex1, Mat M) {
    double ke[8][8];
    element_stiffness(LX / m->nx, LY / m->ny, ke);
    PetscFunctionBeginUser;
    for (PetscInt ey = 0; ey < m->ny; ey++)
        for (PetscInt ex = ex0; ex < ex1; ex++) {
            PetscInt ni[4] = {ex, ex + 1, ex + 1, ex}, nj[4] = {ey, ey, ey + 1, ey + 1}, d[8];
            PetscScalar v[64];
            for (int k = 0; k < 8; k++) d[k] = dof(m, ni[k / 2], nj[k / 2], k % 2);
            for (int r = 0; r < 8; r++)
                for (int s = 0; s < 8; s++) v[r * 8 + s] = ke[r][s];
            /* negative indices (clamped dofs) are ignored by MatSetValues */
            PetscCall(MatSetValues(M, 8, d, 8, d, v, ADD_VALUES));
        }
    PetscFunctionReturn(0);
}

/* The load vectors (consistent nodal forces of uniform tractions), n entries each. */
static void loads(const mesh *m, double *f0, double *f1) {
    double hx = LX / m->nx, hy = LY / m->ny;
    for (PetscInt k = 0; k < m->n; k++) f0[k] = f1[k] = 0;
    for (PetscInt i = 1; i <= m->nx; i++) {
        double w = (i == m->nx ? 0.5 : 1.0) * hx;
        f0[dof(m, i, m->ny, 1)] += -0.02 * w;
        f1[dof(m, i, m->ny, 0)] += 0.01 * w;
    }
    for (PetscInt j = 0; j <= m->ny; j++) {
        double w = (j == 0 || j == m->ny ? 0.5 : 1.0) * hy;
        f1[dof(m, m->nx, j, 1)] += 0.03 * w;
    }
}

/* Contact node k (0-based, bottom node column k + 1): N row -e_y, T row +e_x. */
static PetscInt contact_dof(const mesh *m, PetscInt k, PetscInt d) { return dof(m, k + 1, 0, d); }

/* Traces alpha in [0, 1] and copies the events; returns their number, or -1. */
static int64_t trace(fricont_problem *prob, const double *f0, const double *f1, int64_t len,
                     fricont_event **events) {
    fricont_path *path = NULL;
    fricont_status st = fricont_problem_set_friction(prob, FRICTION);
    if (st == FRICONT_OK) st = fricont_path_new_affine(prob, f0, f1, len, &path);
    if (st == FRICONT_OK) st = fricont_path_set_window(path, 0.0, 1.0);
    if (st == FRICONT_OK) st = fricont_path_start(path, 0.0, NULL, 0);
    if (st == FRICONT_OK) st = fricont_path_run(path);
    int32_t reason = -1;
    if (st == FRICONT_END) fricont_path_end_reason(path, &reason);
    if (st != FRICONT_END || reason != FRICONT_END_WINDOW) {
        char msg[512];
        fricont_last_error_message(msg, sizeof msg);
        fprintf(stderr, "fricont: %s (end reason %d): %s\n", fricont_status_str(st), reason, msg);
        fricont_path_free(path);
        return -1;
    }
    int64_t count = 0;
    fricont_path_event_count(path, &count);
    *events = malloc(sizeof(fricont_event) * (size_t)(count > 0 ? count : 1));
    for (int64_t k = 0; k < count; k++) fricont_path_event(path, k, &(*events)[k]);
    fricont_path_free(path);
    return count;
}

/* The reference: A, N, T assembled sequentially on this rank, fricont_problem_new. */
static PetscErrorCode reference_events(const mesh *m, const double *f0, const double *f1, int64_t *count,
                                       fricont_event **events) {
    Mat A;
    PetscInt nrow;
    const PetscInt *ia, *ja;
    const PetscScalar *va;
    PetscBool done;
    PetscFunctionBeginUser;
    PetscCall(MatCreateSeqAIJ(PETSC_COMM_SELF, m->n, m->n, 18, NULL, &A));
    PetscCall(add_stiffness(m, 0, m->nx, A));
    PetscCall(MatAssemblyBegin(A, MAT_FINAL_ASSEMBLY));
    PetscCall(MatAssemblyEnd(A, MAT_FINAL_ASSEMBLY));
    PetscCall(MatGetRowIJ(A, 0, PETSC_FALSE, PETSC_FALSE, &nrow, &ia, &ja, &done));
    PetscCheck(done, PETSC_COMM_SELF, PETSC_ERR_SUP, "MatGetRowIJ");
    PetscCall(MatSeqAIJGetArrayRead(A, &va));
    int64_t nnz = ia[nrow];
    int64_t *rp = malloc(sizeof(int64_t) * (size_t)(nrow + 1)), *ci = malloc(sizeof(int64_t) * (size_t)nnz);
    for (PetscInt i = 0; i <= nrow; i++) rp[i] = ia[i];
    for (int64_t k = 0; k < nnz; k++) ci[k] = ja[k];
    int64_t *nrp = malloc(sizeof(int64_t) * (size_t)(m->p + 1)), *nci = malloc(sizeof(int64_t) * (size_t)m->p),
            *tci = malloc(sizeof(int64_t) * (size_t)m->p);
    double *nv = malloc(sizeof(double) * (size_t)m->p), *tv = malloc(sizeof(double) * (size_t)m->p);
    for (PetscInt k = 0; k < m->p; k++) {
        nrp[k] = k;
        nci[k] = contact_dof(m, k, 1);
        nv[k] = -1.0;
        tci[k] = contact_dof(m, k, 0);
        tv[k] = 1.0;
    }
    nrp[m->p] = m->p;
    fricont_csr ac = {m->n, m->n, nnz, rp, ci, va, 0};
    fricont_csr nc = {m->p, m->n, m->p, nrp, nci, nv, 0}, tc = {m->p, m->n, m->p, nrp, tci, tv, 0};
    fricont_problem *prob = NULL;
    *count = -1;
    if (fricont_problem_new(&ac, FRICONT_STORAGE_FULL, &nc, &tc, &prob) == FRICONT_OK)
        *count = trace(prob, f0, f1, m->n, events);
    fricont_problem_free(prob);
    PetscCall(MatSeqAIJRestoreArrayRead(A, &va));
    PetscCall(MatRestoreRowIJ(A, 0, PETSC_FALSE, PETSC_FALSE, &nrow, &ia, &ja, &done));
    PetscCall(MatDestroy(&A));
    free(rp);
    free(ci);
    free(nrp);
    free(nci);
    free(tci);
    free(nv);
    free(tv);
    PetscFunctionReturn(0);
}

int main(int argc, char **argv) {
    mesh m = {64, 8, 0, 0};
    PetscMPIInt rank, size;
    int ok = 0;
    PetscCall(PetscInitialize(&argc, &argv, NULL, NULL));
    PetscCall(PetscOptionsGetInt(NULL, NULL, "-nx", &m.nx, NULL));
    PetscCall(PetscOptionsGetInt(NULL, NULL, "-ny", &m.ny, NULL));
    PetscCallMPI(MPI_Comm_rank(PETSC_COMM_WORLD, &rank));
    PetscCallMPI(MPI_Comm_size(PETSC_COMM_WORLD, &size));
    m.n = 2 * m.nx * (m.ny + 1);
    m.p = m.nx;
    const PetscInt n = m.n, p = m.p, ns = 2 * p + 2, N = n + ns;

    /* K, distributed by rows; each rank assembles the element columns of its share */
    Mat K;
    PetscCall(MatCreate(PETSC_COMM_WORLD, &K));
    PetscCall(MatSetSizes(K, PETSC_DECIDE, PETSC_DECIDE, N, N));
    PetscCall(MatSetType(K, MATAIJ));
    PetscCall(MatSeqAIJSetPreallocation(K, 24, NULL));
    PetscCall(MatMPIAIJSetPreallocation(K, 24, NULL, 24, NULL));
    PetscCall(MatSetOption(K, MAT_NEW_NONZERO_ALLOCATION_ERR, PETSC_FALSE));
    PetscInt ex0 = m.nx * rank / size, ex1 = m.nx * (rank + 1) / size;
    PetscCall(add_stiffness(&m, ex0, ex1, K));
    double *f0 = malloc(sizeof(double) * (size_t)n), *f1 = malloc(sizeof(double) * (size_t)n);
    loads(&m, f0, f1);
    if (rank == 0) {
        /* B, the load columns and explicit zeros on the Schur block's diagonal */
        for (PetscInt k = 0; k < p; k++) {
            PetscInt rows[2] = {n + k, n + p + k}, cols[2] = {contact_dof(&m, k, 1), contact_dof(&m, k, 0)};
            PetscScalar vals[2] = {-1.0, 1.0};
            for (int r = 0; r < 2; r++) {
                PetscCall(MatSetValue(K, rows[r], cols[r], vals[r], ADD_VALUES));
                PetscCall(MatSetValue(K, cols[r], rows[r], vals[r], ADD_VALUES));
            }
        }
        for (PetscInt i = 0; i < n; i++)
            for (int j = 0; j < 2; j++) {
                double v = j ? f1[i] : f0[i];
                if (v == 0) continue;
                PetscCall(MatSetValue(K, i, n + 2 * p + j, v, ADD_VALUES));
                PetscCall(MatSetValue(K, n + 2 * p + j, i, v, ADD_VALUES));
            }
        for (PetscInt i = n; i < N; i++) PetscCall(MatSetValue(K, i, i, 0.0, ADD_VALUES));
    }
    PetscCall(MatAssemblyBegin(K, MAT_FINAL_ASSEMBLY));
    PetscCall(MatAssemblyEnd(K, MAT_FINAL_ASSEMBLY));
    PetscCall(MatSetOption(K, MAT_SYMMETRIC, PETSC_TRUE));
    PetscCall(MatSetOption(K, MAT_SYMMETRY_ETERNAL, PETSC_TRUE));

    /* MUMPS: LDL^T of K with the last 2p + 2 unknowns as the Schur block (on rank 0 only) */
    Mat F, S;
    IS is;
    MatFactorInfo info;
    MatFactorError ferr;
    MatFactorSchurStatus status;
    PetscInt infog1 = 0;
    PetscCall(MatGetFactor(K, MATSOLVERMUMPS, MAT_FACTOR_CHOLESKY, &F));
    PetscCall(ISCreateStride(PETSC_COMM_SELF, rank == 0 ? ns : 0, n, 1, &is));
    PetscCall(MatFactorSetSchurIS(F, is));
    PetscCall(MatFactorInfoInitialize(&info));
    PetscCall(MatCholeskyFactorSymbolic(F, K, NULL, &info));
    PetscCall(MatCholeskyFactorNumeric(F, K, &info));
    PetscCall(MatFactorGetError(F, &ferr));
    PetscCall(MatMumpsGetInfog(F, 1, &infog1));
    if (ferr != MAT_FACTOR_NOERROR || infog1 < 0) {
        PetscCall(PetscPrintf(PETSC_COMM_WORLD, "MUMPS failed: MatFactorError %d, INFOG(1) = %d\n", (int)ferr,
                              (int)infog1));
        PetscCall(PetscFinalize());
        return 1;
    }
    PetscCall(MatFactorCreateSchurComplement(F, &S, &status));

    if (rank == 0) {
        /* S is a sequential dense (2p + 2)^2 matrix here. MUMPS may fill only one triangle
         * of a symmetric complement: mirror the one that holds the diagonal's neighbours. */
        const PetscScalar *s;
        PetscInt lda;
        PetscCall(MatDenseGetLDA(S, &lda));
        PetscCall(MatDenseGetArrayRead(S, &s));
        double lower = 0, upper = 0;
        for (PetscInt j = 0; j < ns; j++)
            for (PetscInt i = j + 1; i < ns; i++) {
                lower += fabs(s[i + j * lda]);
                upper += fabs(s[j + i * lda]);
            }
        const int64_t m2 = 2 * p;
        double *w = malloc(sizeof(double) * (size_t)(m2 * m2)), *q0 = malloc(sizeof(double) * (size_t)m2),
               *q1 = malloc(sizeof(double) * (size_t)m2);
#define SIJ(i, j)                                                                                        \
    (upper == 0 ? s[((i) > (j) ? (i) : (j)) + ((i) > (j) ? (j) : (i)) * lda]                               \
                : lower == 0 ? s[((i) < (j) ? (i) : (j)) + ((i) < (j) ? (j) : (i)) * lda] : s[(i) + (j) * lda])
        for (int64_t j = 0; j < m2; j++)
            for (int64_t i = 0; i < m2; i++) w[i + j * m2] = -SIJ(i, j);
        for (int64_t i = 0; i < m2; i++) {
            q0[i] = -SIJ(i, m2);
            q1[i] = -SIJ(i, m2 + 1);
        }
#undef SIJ
        PetscCall(MatDenseRestoreArrayRead(S, &s));

        fricont_problem *prob = NULL;
        fricont_event *ev = NULL, *ref = NULL;
        int64_t count = -1, ref_count = -1;
        if (fricont_problem_new_condensed(p, w, m2, &prob) == FRICONT_OK) count = trace(prob, q0, q1, m2, &ev);
        else {
            char msg[512];
            fricont_last_error_message(msg, sizeof msg);
            fprintf(stderr, "fricont_problem_new_condensed: %s\n", msg);
        }
        fricont_problem_free(prob);
        PetscCall(reference_events(&m, f0, f1, &ref_count, &ref));

        printf("Q1 rectangle %gx%g, %dx%d elements, n = %d dofs, p = %d contact nodes, F = %g, %d MPI rank(s)\n",
               LX, LY, (int)m.nx, (int)m.ny, (int)n, (int)p, FRICTION, (int)size);
        printf("W and q by the MUMPS Schur complement; events traced by fricont on rank 0:\n\n");
        printf("  #  alpha              node  from   -> to     fold\n");
        for (int64_t k = 0; k < count; k++)
            printf("%3lld  %-17.14g  %4lld  %-6s -> %-6s %s\n", (long long)k + 1, ev[k].alpha,
                   (long long)ev[k].node + 1, fricont_class_name(ev[k].from), fricont_class_name(ev[k].to),
                   ev[k].fold ? "yes" : "");
        ok = count > 0 && count == ref_count;
        double worst = 0;
        for (int64_t k = 0; ok && k < count; k++) {
            double d = fabs(ev[k].alpha - ref[k].alpha) / fmax(1.0, fabs(ref[k].alpha));
            worst = fmax(worst, d);
            ok = d <= 1e-10 && ev[k].node == ref[k].node && ev[k].from == ref[k].from && ev[k].to == ref[k].to &&
                 ev[k].fold == ref[k].fold;
        }
        printf("\nfricont_problem_new (A, N, T on one rank): %lld events; condensed route: %lld events; "
               "largest relative difference in alpha %.2e: %s\n",
               (long long)ref_count, (long long)count, worst, ok ? "agree" : "DIFFER");
        free(ev);
        free(ref);
        free(w);
        free(q0);
        free(q1);
    }
    PetscCallMPI(MPI_Bcast(&ok, 1, MPI_INT, 0, PETSC_COMM_WORLD));
    PetscCall(MatDestroy(&S));
    PetscCall(ISDestroy(&is));
    PetscCall(MatDestroy(&F));
    PetscCall(MatDestroy(&K));
    free(f0);
    free(f1);
    PetscCall(PetscFinalize());
    return ok ? 0 : 1;
}
