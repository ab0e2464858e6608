"""A scikit-fem user's script: a plane-strain block on a rigid foundation, traced by fricont.

The body is the rectangle [0, 3] x [0, 1] (E = 1, nu = 0.3, bilinear quadrilaterals), the
left side is clamped, the bottom nodes (except the clamped corner) touch a rigid
foundation with friction F = 0.4, the top is pressed down by a uniform traction and, as
alpha grows, sheared to the right and pulled up at the right end. fricont traces the path
for alpha in [0, 1], prints every transition point and draws the path (normal and
tangential contact force of a few nodes against alpha) and the contact forces at the end
of the window into a PNG.

    python skfem_block.py [OUTDIR]          # writes OUTDIR/skfem_block.png (default .)
    python skfem_block.py OUTDIR --export   # also writes the problem in the exchange
                                            # format to OUTDIR/problem (for `fricont trace`)
"""

import json
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import scipy.io  # noqa: E402
import scipy.sparse as sp  # noqa: E402
from skfem import (  # noqa: E402
    Basis,
    ElementQuad1,
    ElementVector,
    FacetBasis,
    LinearForm,
    MeshQuad,
    asm,
)
from skfem.models.elasticity import lame_parameters, linear_elasticity  # noqa: E402

import fricont  # noqa: E402


def assemble(nx=24, ny=8, friction=0.4):
    """A, N, T, f0, f1 of the block (free dofs only) and the x of the contact nodes."""
    mesh = MeshQuad.init_tensor(np.linspace(0.0, 3.0, nx + 1), np.linspace(0.0, 1.0, ny + 1))
    e = ElementVector(ElementQuad1())
    basis = Basis(mesh, e)
    K = asm(linear_elasticity(*lame_parameters(1.0, 0.3)), basis)

    def boundary_load(facets, tx, ty):
        fb = FacetBasis(mesh, e, facets=facets)

        @LinearForm
        def traction(v, w):
            return tx * v.value[0] + ty * v.value[1]

        return asm(traction, fb)

    top = mesh.facets_satisfying(lambda x: np.isclose(x[1], 1.0))
    right = mesh.facets_satisfying(lambda x: np.isclose(x[0], 3.0))
    f0 = boundary_load(top, 0.0, -0.02)  # pressure on the top
    f1 = boundary_load(top, 0.01, 0.0) + boundary_load(right, 0.0, 0.01)  # shear, lift

    clamped = basis.get_dofs(lambda x: np.isclose(x[0], 0.0)).all()
    free = basis.complement_dofs(clamped)
    index = -np.ones(basis.N, dtype=np.int64)
    index[free] = np.arange(free.size)
    A = K[free][:, free].tocsr()

    # Contact nodes: the bottom nodes that are not clamped, left to right.
    nodes = [j for j in np.argsort(mesh.p[0]) if np.isclose(mesh.p[1, j], 0.0) and mesh.p[0, j] > 0]
    p, n = len(nodes), free.size
    rows = np.arange(p)
    ux = index[basis.nodal_dofs[0, nodes]]
    uy = index[basis.nodal_dofs[1, nodes]]
    N = sp.csr_array((-np.ones(p), (rows, uy)), shape=(p, n))  # N u = -u_y <= 0: no penetration
    T = sp.csr_array((np.ones(p), (rows, ux)), shape=(p, n))  # T u = u_x
    return A, N, T, f0[free], f1[free], mesh.p[0, nodes], friction


def export(directory, A, N, T, f0, f1, friction, window):
    """The problem in fricont's exchange format (docs/exchange-format.md)."""
    os.makedirs(directory, exist_ok=True)
    scipy.io.mmwrite(os.path.join(directory, "A.mtx"), sp.coo_matrix(A), symmetry="general")
    scipy.io.mmwrite(os.path.join(directory, "N.mtx"), sp.coo_matrix(N))
    scipy.io.mmwrite(os.path.join(directory, "T.mtx"), sp.coo_matrix(T))
    np.savetxt(os.path.join(directory, "f0.txt"), f0, fmt="%.17g")
    np.savetxt(os.path.join(directory, "f1.txt"), f1, fmt="%.17g")
    meta = {"n": A.shape[0], "p": N.shape[0], "F": friction,
            "alpha_start": window[0], "alpha_end": window[1], "source": "skfem_block.py"}
    with open(os.path.join(directory, "meta.json"), "w") as fh:
        json.dump(meta, fh, indent=1)


def main(argv):
    out = argv[1] if len(argv) > 1 and not argv[1].startswith("--") else "."
    os.makedirs(out, exist_ok=True)
    A, N, T, f0, f1, x, friction = assemble()
    window = (0.0, 1.0)
    if "--export" in argv:
        export(os.path.join(out, "problem"), A, N, T, f0, f1, friction, window)

    prob = fricont.Problem(A, N, T, friction=friction)
    path = prob.trace(f0, f1, window=window)
    print(f"n = {prob.n}, p = {prob.p}: {len(path.events)} events, end {path.end_reason}")
    for e in path.events:
        print(f"alpha = {e.alpha:.14g}  node {e.node + 1:3d}  {e.from_class} -> {e.to_class}"
              + ("  fold" if e.fold else ""))

    fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(11, 4.2), constrained_layout=True)
    shown = sorted({e.node for e in path.events})[:6] or [0]
    colors = plt.cm.viridis(np.linspace(0.0, 0.9, len(shown)))
    for c, i in zip(colors, shown):
        a = [pc.alpha_from for pc in path.pieces] + [path.pieces[-1].alpha_to]
        ln = [pc.lambda_from[i] for pc in path.pieces] + [path.pieces[-1].lambda_to[i]]
        lt = [pc.lambda_from[prob.p + i] for pc in path.pieces] + [path.pieces[-1].lambda_to[prob.p + i]]
        ax1.plot(a, ln, "-", color=c, label=f"node {i + 1}: λν")
        ax1.plot(a, lt, "--", color=c, label=f"node {i + 1}: λt")
    for e in path.events:
        ax1.axvline(e.alpha, color="0.85", lw=0.6, zorder=0)
    ax1.set_xlabel("α")
    ax1.set_ylabel("contact force (λν ≤ 0 compressive)")
    ax1.set_title("the path: contact forces of the nodes that change class")
    ax1.legend(fontsize=8, ncol=2, loc="best")
    end = path.solutions_at(window[1])[0]
    ax2.plot(x, end.lambda_n, "o-", label="λν")
    ax2.plot(x, end.lambda_t, "s--", label="λt")
    ax2.plot(x, -friction * end.lambda_n, ":", color="0.4", label="±F|λν|")
    ax2.plot(x, friction * end.lambda_n, ":", color="0.4")
    ax2.set_xlabel("x of the contact node")
    ax2.set_title(f"contact forces at α = {window[1]:g}")
    ax2.legend(fontsize=8)
    png = os.path.join(out, "skfem_block.png")
    fig.savefig(png, dpi=120)
    print(f"wrote {png}")
    return path


if __name__ == "__main__":
    main(sys.argv)
