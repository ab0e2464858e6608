/* Branches at the start point through the C ABI, on tests/data/vertex-start: two nodes
 * (A, N, T of tests/common's random_case(196)) made degenerate: zero gaps, a homogeneous
 * load f = alpha f1, node 1's friction at W_nn / |W_nt| (its slip piece singular), the
 * start at alpha = 0 where both nodes are at the zero-force vertex. The brute force of
 * tests/common (every class vector solved with nalgebra) finds three solution curves
 * leaving that point toward alpha_end = -1, with the classes (open, slip+),
 * (slip-, slip+) and (stick, slip-) (tests/core_vertex_start.rs checks the same in Rust).
 * Checked here:
 *  - fricont_path_branch_count is 3 directly after the start, and the branches' classes
 *    are those three, each moving alpha toward alpha_end (direction -1);
 *  - fricont_path_choose_branch(k) directly after a start restarts on branch k: the path
 *    then runs to FRICONT_END_WINDOW on one piece with branch k's classes;
 *  - branch index 3 is FRICONT_ERR_RANGE; after a step there are no branches and
 *    choosing one is FRICONT_ERR_ORDER.
 * usage: start_branches DIR */
#include <stdlib.h>
#include <string.h>

#include "common.h"

static const int32_t expected[3][2] = {
    {FRICONT_OPEN, FRICONT_SLIP_PLUS},
    {FRICONT_SLIP_MINUS, FRICONT_SLIP_PLUS},
    {FRICONT_STICK, FRICONT_SLIP_MINUS},
};

static int find_expected(const int32_t cl[2]) {
    for (int k = 0; k < 3; k++)
        if (cl[0] == expected[k][0] && cl[1] == expected[k][1]) return k;
    return -1;
}

int main(int argc, char **argv) {
    if (argc < 2) {
        fprintf(stderr, "usage: %s DIR\n", argv[0]);
        return 2;
    }
    case_data c;
    if (read_case(argv[1], &c) != 0) return 2;
    CHECK(c.p == 2, "p = %lld", (long long)c.p);
    fricont_problem *prob = NULL;
    fricont_status st = problem_from_case(&c, FRICONT_STORAGE_FULL, 0, &prob);
    CHECK(st == FRICONT_OK, "problem: %d", (int)st);
    fricont_path *path = NULL;
    st = fricont_path_new_affine(prob, c.f0, c.f1, c.n, &path);
    CHECK(st == FRICONT_OK, "path: %d", (int)st);
    CHECK(fricont_path_set_window(path, c.alpha_start, c.alpha_end) == FRICONT_OK, "window");
    CHECK(fricont_path_start(path, c.alpha_start, NULL, 0) == FRICONT_OK, "start");
    int64_t count = -1;
    CHECK(fricont_path_branch_count(path, &count) == FRICONT_OK && count == 3,
          "branches at the start: %lld, expected 3", (long long)count);
    int seen[3] = {0, 0, 0};
    int32_t branch_classes[3][2];
    for (int64_t k = 0; k < count && k < 3; k++) {
        fricont_branch b;
        int32_t cl[2] = {-1, -1};
        CHECK(fricont_path_branch(path, k, &b, cl, 2) == FRICONT_OK, "branch %lld", (long long)k);
        int e = find_expected(cl);
        CHECK(e >= 0, "branch %lld has classes (%d, %d), not one of the brute force's",
              (long long)k, cl[0], cl[1]);
        if (e >= 0) seen[e]++;
        CHECK(b.direction == -1, "branch %lld direction %d", (long long)k, b.direction);
        memcpy(branch_classes[k], cl, sizeof cl);
    }
    CHECK(seen[0] == 1 && seen[1] == 1 && seen[2] == 1, "each brute-force curve once");
    CHECK(fricont_path_choose_branch(path, 3) == FRICONT_ERR_RANGE, "branch 3 out of range");
    for (int64_t k = 0; k < count && k < 3; k++) {
        CHECK(fricont_path_start(path, c.alpha_start, NULL, 0) == FRICONT_OK, "restart");
        CHECK(fricont_path_choose_branch(path, k) == FRICONT_OK, "choose %lld", (long long)k);
        CHECK(fricont_path_run(path) == FRICONT_END, "run on branch %lld", (long long)k);
        int32_t reason = -1;
        fricont_path_end_reason(path, &reason);
        CHECK(reason == FRICONT_END_WINDOW, "branch %lld ends with %d", (long long)k, reason);
        int64_t pieces = -1;
        fricont_path_piece_count(path, &pieces);
        CHECK(pieces == 1, "branch %lld: %lld pieces", (long long)k, (long long)pieces);
        int32_t cl[2] = {-1, -1};
        fricont_piece pc;
        CHECK(fricont_path_piece(path, 0, &pc, cl, 2) == FRICONT_OK &&
                  cl[0] == branch_classes[k][0] && cl[1] == branch_classes[k][1],
              "branch %lld traced (%d, %d)", (long long)k, cl[0], cl[1]);
    }
    /* after a step the start's branches are gone */
    CHECK(fricont_path_start(path, c.alpha_start, NULL, 0) == FRICONT_OK, "restart");
    CHECK(fricont_path_step(path) == FRICONT_END, "step to the window's end (one piece)");
    CHECK(fricont_path_branch_count(path, &count) == FRICONT_OK && count == 0,
          "branches after a step: %lld", (long long)count);
    CHECK(fricont_path_choose_branch(path, 0) == FRICONT_ERR_ORDER, "choose after a step");
    fricont_path_free(path);
    fricont_problem_free(prob);
    free_case(&c);
    return finish("start_branches");
}
