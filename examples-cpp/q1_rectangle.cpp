// A FEM user's program in C++ (the C++ twin of examples-c/q1_rectangle.c): plane-strain
// elasticity on a 4 x 1 rectangle with 16 x 4 Q1 elements, the left side clamped, the
// bottom resting on a rigid foundation with Coulomb friction F = 0.4; a pressure on the
// top, and a load growing with alpha that shears the top and lifts the right side.
// A (lower triangle), N and T are assembled row by row into CSR vectors, handed to
// fricont through the header-only wrapper fricont.hpp (RAII handles, exceptions), and
// every transition for alpha in [0, 1] is printed (contact nodes numbered from 1, left
// to right; alpha to 14 significant digits). The output is that of the C example.
//
// Build against an installed copy (scripts/install.sh PREFIX; pkg-config's file then
// sets the run-time path too; PKG_CONFIG_PATH=PREFIX/lib/pkgconfig for a custom PREFIX):
//   c++ -std=c++17 -O2 q1_rectangle.cpp $(pkg-config --cflags --libs fricont) -o q1_rectangle_cpp
// or against the build tree (repository root, after `cargo build --release`), one line:
//   c++ -std=c++17 -O2 -I include examples-cpp/q1_rectangle.cpp -L target/release
//       -Wl,-rpath,"$PWD/target/release" -lfricont -o q1_rectangle_cpp
#include <fricont.hpp>

#include <array>
#include <cstdint>
#include <cstdio>
#include <map>
#include <string>
#include <vector>

namespace {

constexpr int NX = 16;  // elements along x
constexpr int NY = 4;   // elements along y
constexpr double LX = 4.0, LY = 1.0, E_MOD = 1.0, NU = 0.3, FRICTION = 0.4;

// dof number of (node column i, node row j, direction d), or -1 on the clamped side
int dof(int i, int j, int d) { return i == 0 ? -1 : 2 * (j * NX + (i - 1)) + d; }

using Ke = std::array<std::array<double, 8>, 8>;

// 8x8 stiffness of a hx-by-hy Q1 element, plane strain, 2x2 Gauss points. Local node
// order (0,0), (1,0), (1,1), (0,1); dofs (ux, uy) per node.
Ke element_stiffness(double hx, double hy) {
    const double c = E_MOD / ((1 + NU) * (1 - 2 * NU));
    const double D[3][3] = {{c * (1 - NU), c * NU, 0}, {c * NU, c * (1 - NU), 0}, {0, 0, c * (1 - 2 * NU) / 2}};
    const double xi_n[4] = {-1, 1, 1, -1}, eta_n[4] = {-1, -1, 1, 1}, g = 0.5773502691896257;
    Ke ke{};
    for (int gp = 0; gp < 4; gp++) {
        const double xi = xi_n[gp] * g, eta = eta_n[gp] * g;
        double B[3][8] = {};
        for (int a = 0; a < 4; a++) {
            const double dx = xi_n[a] * (1 + eta_n[a] * eta) / 4 * 2 / hx;
            const double dy = eta_n[a] * (1 + xi_n[a] * xi) / 4 * 2 / hy;
            B[0][2 * a] = dx;
            B[1][2 * a + 1] = dy;
            B[2][2 * a] = dy;
            B[2][2 * a + 1] = dx;
        }
        const double w = hx * hy / 4;  // Jacobian determinant, Gauss weights 1
        for (int r = 0; r < 8; r++)
            for (int s = 0; s < 8; s++)
                for (int k = 0; k < 3; k++)
                    for (int l = 0; l < 3; l++) ke[r][s] += B[k][r] * D[k][l] * B[l][s] * w;
    }
    return ke;
}

// A matrix assembled row by row (sorted columns), turned into the CSR vectors that
// fricont::CsrRef borrows. The vectors must outlive the CsrRef (the library copies them
// when the problem is made).
struct Csr {
    int64_t nrows, ncols;
    std::vector<int64_t> row_ptr, col_idx;
    std::vector<double> values;
    Csr(int64_t nr, int64_t nc, const std::vector<std::map<int64_t, double>> &rows) : nrows(nr), ncols(nc) {
        row_ptr.push_back(0);
        for (const auto &row : rows) {
            for (const auto &[col, v] : row)
                if (v != 0) {
                    col_idx.push_back(col);
                    values.push_back(v);
                }
            row_ptr.push_back(static_cast<int64_t>(col_idx.size()));
        }
    }
    fricont::CsrRef ref() const { return fricont::CsrRef(nrows, ncols, row_ptr, col_idx, values); }
};

std::string classes(const std::vector<fricont::Class> &cls) {
    std::string s;
    for (fricont::Class c : cls) s += " " + fricont::name(c);
    return s;
}

}  // namespace

int main() {
    const int n = 2 * NX * (NY + 1), p = NX;
    const double hx = LX / NX, hy = LY / NY;

    // Stiffness, lower triangle only (column <= row).
    std::vector<std::map<int64_t, double>> a_rows(n), n_rows(p), t_rows(p);
    const Ke ke = element_stiffness(hx, hy);
    for (int ey = 0; ey < NY; ey++)
        for (int ex = 0; ex < NX; ex++) {
            const int ni[4] = {ex, ex + 1, ex + 1, ex}, nj[4] = {ey, ey, ey + 1, ey + 1};
            int d[8];
            for (int k = 0; k < 8; k++) d[k] = dof(ni[k / 2], nj[k / 2], k % 2);
            for (int r = 0; r < 8; r++)
                for (int s = 0; s < 8; s++)
                    if (d[r] >= 0 && d[s] >= 0 && d[s] <= d[r]) a_rows[d[r]][d[s]] += ke[r][s];
        }
    // Contact: bottom nodes i = 1..NX; outward normal -y, tangent +x.
    for (int k = 0; k < p; k++) {
        n_rows[k][dof(k + 1, 0, 1)] = -1.0;
        t_rows[k][dof(k + 1, 0, 0)] = 1.0;
    }
    // Loads (consistent nodal forces of uniform tractions): f0 presses the top down;
    // f1 shears the top to the right and lifts the right side.
    std::vector<double> f0(n, 0.0), f1(n, 0.0);
    for (int i = 1; i <= NX; i++) {
        const double w = (i == NX ? 0.5 : 1.0) * hx;
        f0[dof(i, NY, 1)] += -0.02 * w;
        f1[dof(i, NY, 0)] += 0.01 * w;
    }
    for (int j = 0; j <= NY; j++) {
        const double w = (j == 0 || j == NY ? 0.5 : 1.0) * hy;
        f1[dof(NX, j, 1)] += 0.03 * w;
    }
    const Csr a(n, n, a_rows), nm(p, n, n_rows), tm(p, n, t_rows);

    try {
        fricont::Problem problem(a.ref(), fricont::Storage::Lower, nm.ref(), tm.ref());
        problem.set_friction(FRICTION);
        fricont::Path path = fricont::Path::affine(problem, f0, f1);
        path.set_window(0.0, 1.0);
        path.start(0.0);
        std::printf("Q1 rectangle %gx%g, %dx%d elements, n = %d dofs, p = %d contact nodes, F = %g\n", LX, LY, NX,
                    NY, n, p, FRICTION);
        std::printf("start at alpha = 0:%s\n", classes(path.start_state().classes).c_str());
        std::printf("\n  #  alpha              node  from   -> to     fold\n");
        path.run();
        int k = 0;
        for (const fricont::Event &e : path.events())
            std::printf("%3d  %-17.14g  %4lld  %-6s -> %-6s %s\n", ++k, e.alpha, static_cast<long long>(e.node) + 1,
                        fricont::name(e.from).c_str(), fricont::name(e.to).c_str(), e.fold ? "yes" : "");
        const fricont::State end = path.current();
        std::printf("\nend at alpha = %g:%s\n", end.alpha, classes(end.classes).c_str());
    } catch (const fricont::Error &e) {
        // The library's message names the argument and the cause; status() is the code.
        std::fprintf(stderr, "fricont error %d (%s): %s\n", e.status(), fricont_status_str(e.status()), e.what());
        return 1;
    }
    return 0;
}
