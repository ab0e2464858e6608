//! A generator of the rectangle problem of the founding paper's case study, with
//! parameters: mesh size, side lengths, material, friction, gap and surface tractions
//! that depend affinely on the load parameter, `t(α) = t0 + α t1`.
//!
//! ## Geometry, mesh and unknowns
//!
//! The body is the rectangle `(0, lx) × (0, ly)` (length units of the user's choice),
//! meshed by `(nx − 1) × (ny − 1)` equal rectangular Q1 elements: node `(i, j)` sits at
//! `x = i·lx/(nx−1)`, `y = j·ly/(ny−1)`, `i = 0..nx`, `j = 0..ny`. The **left side**
//! `x = 0` is clamped (its `ny` nodes carry no unknowns); the **bottom side** `y = 0` rests
//! on a rigid flat foundation: its `nx − 1` free nodes are the contact nodes, numbered
//! `1..=p` from left to right in reports (`0..p` in Rust). So
//!
//! * `n = 2 (nx·ny − ny)` free dofs, `p = nx − 1` contact nodes;
//! * the dofs of free node `(i, j)` are `2k` (horizontal displacement `u_x`) and `2k + 1`
//!   (vertical `u_y`), `k = j (nx − 1) + (i − 1)`: row by row from the bottom, left to
//!   right, x before y. (The contact nodes therefore own dofs `0..2p`.)
//!
//! ## Contact matrices and signs
//!
//! The outward normal of the body on the contact side points down, `ν = (0, −1)`, and the
//! tangent is `t = (1, 0)`. Row `i` of `N` has a single `−1` on the `u_y` dof of contact
//! node `i` (so `N u = −u_y`, the displacement towards the foundation) and row `i` of `T`
//! a single `+1` on its `u_x` dof. With the initial gap `g` (default 0), non-penetration
//! reads `N u ≤ g`; `λν ≤ 0` is the (compressive) normal contact force on the body along
//! `ν`, so the foundation pushes the body up with the force `−λν`; `λt` is the tangential
//! contact force along `+x`. Forces are nodal forces (force per unit thickness times the
//! thickness), not stresses.
//!
//! ## Material and stiffness
//!
//! Isotropic linear elasticity in **plane strain** with Young's modulus `E` and Poisson's
//! ratio `ν` (stress units, the same as the tractions), per unit thickness times
//! `thickness`:
//! `D = E / ((1+ν)(1−2ν)) · [[1−ν, ν, 0], [ν, 1−ν, 0], [0, 0, (1−2ν)/2]]`. The element
//! stiffness is integrated with 2 × 2 Gauss points (exact for Q1 on rectangles). `A` is
//! assembled directly in CSR form (the mesh is structured, every row has at most 18
//! entries), so `n ≈ 10^6` takes about a second.
//!
//! ## Loads
//!
//! Each [`Traction`] is a surface force density (force per unit area = stress units,
//! like `E`) on one side of the rectangle, linear along the side, given by its
//! Cartesian components at the two ends of the side (ends ordered by increasing `x` for
//! the bottom and top sides, increasing `y` for the left and right sides). The nodal
//! forces are the **consistent** ones (exact integral of the traction times the linear
//! shape functions of each edge, [`ForceRule::Consistent`]) or, on request, the
//! trapezoidal (lumped) ones. Forces on the clamped nodes are dropped (they are taken by
//! the support). `f0` collects [`RectSpec::load0`] and `f1` collects
//! [`RectSpec::load1`], so `f(α) = f0 + α f1`.

use serde::{Deserialize, Serialize};

use crate::io::CaseData;
use crate::{Error, Result};

/// An invalid generator parameter, as the core reports invalid parameters.
fn invalid(m: String) -> Error {
    fricont::Error::InvalidParameter(m).into()
}
use fricont::problem::CsrMatrix;

/// A side of the rectangle.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Side {
    /// `y = 0` (the contact side).
    Bottom,
    /// `x = lx`.
    Right,
    /// `y = ly`.
    Top,
    /// `x = 0` (the clamped side).
    Left,
}

impl Side {
    /// Lower-case name (`"bottom"`, …).
    pub fn name(self) -> &'static str {
        match self {
            Side::Bottom => "bottom",
            Side::Right => "right",
            Side::Top => "top",
            Side::Left => "left",
        }
    }
}

/// A surface traction on one side, linear along it: the Cartesian components at the
/// first end (`start`) and at the second end (`end`) of the side, ends ordered by
/// increasing `x` (bottom, top) or `y` (left, right). Units: force per unit area (stress,
/// the units of `E`). `(0, −1)` on the top side is a downward pressure of 1.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Traction {
    /// The side.
    pub side: Side,
    /// `(t_x, t_y)` at the first end.
    pub start: [f64; 2],
    /// `(t_x, t_y)` at the second end.
    pub end: [f64; 2],
}

impl Traction {
    /// A traction with the same value along the whole side.
    pub fn uniform(side: Side, t: [f64; 2]) -> Self {
        Self {
            side,
            start: t,
            end: t,
        }
    }

    /// A traction varying linearly from `start` to `end` along the side.
    pub fn linear(side: Side, start: [f64; 2], end: [f64; 2]) -> Self {
        Self { side, start, end }
    }
}

impl std::str::FromStr for Side {
    type Err = Error;
    /// `"bottom"`, `"right"`, `"top"`, `"left"` (case-insensitive).
    fn from_str(s: &str) -> Result<Side> {
        match s.trim().to_ascii_lowercase().as_str() {
            "bottom" => Ok(Side::Bottom),
            "right" => Ok(Side::Right),
            "top" => Ok(Side::Top),
            "left" => Ok(Side::Left),
            _ => Err(invalid(format!(
                "side \"{s}\": expected bottom, right, top or left"
            ))),
        }
    }
}

impl std::str::FromStr for Traction {
    type Err = Error;
    /// Parses `SIDE:TX,TY` (uniform) or `SIDE:TX,TY:TX2,TY2` (linear from the first end
    /// of the side to the second), e.g. `top:0,-0.004:0,-0.024` or `right:0,0.01`
    /// (the command-line form of `fricont gen-rect`). Errors:
    /// [`fricont::Error::InvalidParameter`] saying what is wrong.
    fn from_str(s: &str) -> Result<Traction> {
        let bad = |m: &str| {
            invalid(format!(
                "traction \"{s}\": {m} (expected SIDE:TX,TY or SIDE:TX,TY:TX2,TY2)"
            ))
        };
        let parts: Vec<&str> = s.split(':').collect();
        if !(2..=3).contains(&parts.len()) {
            return Err(bad("wrong number of ':'-separated fields"));
        }
        let side: Side = parts[0].parse()?;
        let pair = |t: &str| -> Result<[f64; 2]> {
            let v: Vec<&str> = t.split(',').collect();
            if v.len() != 2 {
                return Err(bad("a value must be two numbers TX,TY"));
            }
            let x: f64 = v[0].trim().parse().map_err(|_| bad("not a number"))?;
            let y: f64 = v[1].trim().parse().map_err(|_| bad("not a number"))?;
            if !x.is_finite() || !y.is_finite() {
                return Err(bad("non-finite value"));
            }
            Ok([x, y])
        };
        let start = pair(parts[1])?;
        let end = if parts.len() == 3 {
            pair(parts[2])?
        } else {
            start
        };
        Ok(Traction { side, start, end })
    }
}

/// How surface tractions become nodal forces.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum ForceRule {
    /// Exact integral of the traction against the edge shape functions: on an edge of
    /// length `h` with end values `t_a`, `t_b`, the nodes get `h (2 t_a + t_b) / 6` and
    /// `h (t_a + 2 t_b) / 6`.
    Consistent,
    /// Trapezoidal rule (lumped): `h t_a / 2` and `h t_b / 2`. Same as consistent at
    /// interior nodes of a linear traction; differs at the corners.
    Trapezoid,
}

/// The parameters of the rectangle problem. `Default` is the project's reconstruction of
/// the founding paper's case study (see `docs/case-study.md`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct RectSpec {
    /// Nodes along x (≥ 2); the contact side has `nx − 1` contact nodes.
    pub nx: usize,
    /// Nodes along y (≥ 2).
    pub ny: usize,
    /// Side length along x (> 0).
    pub lx: f64,
    /// Side length along y (> 0).
    pub ly: f64,
    /// Young's modulus (> 0, stress units).
    pub e: f64,
    /// Poisson's ratio (in [0, 0.5)).
    pub nu: f64,
    /// Thickness (> 0); multiplies `A` and the nodal forces alike (plane strain per unit
    /// thickness when 1).
    pub thickness: f64,
    /// Coulomb friction coefficient of every contact node (≥ 0).
    pub friction: f64,
    /// Uniform initial gap between the bottom side and the foundation (≥ 0 usual; length
    /// units). Zero means no `gap.txt` is written.
    pub gap: f64,
    /// Tractions making up `f0` (the load at α = 0).
    pub load0: Vec<Traction>,
    /// Tractions making up `f1` (the load per unit α).
    pub load1: Vec<Traction>,
    /// Consistent or trapezoidal nodal forces.
    pub rule: ForceRule,
    /// Start of the α window.
    pub alpha_start: f64,
    /// End of the α window.
    pub alpha_end: f64,
    /// A short name of the load, written to `meta.json`.
    pub load_name: String,
}

impl Default for RectSpec {
    /// The case study (the project's reconstruction, see `docs/case-study.md`): 31 × 22
    /// nodes on `(0, 3) × (0, 2.1)` (square elements of side 0.1), `E = 1`, `ν = 0.3`,
    /// `F = 0.3`, no gap, α ∈ [−0.5, 1.5], consistent nodal forces, and the load
    /// "lift-press":
    /// * `f0`: an upward traction 0.01 on the right side (lifting the free end), and on
    ///   the top a uniform shear 0.01 towards the clamp (−x) with a downward pressure
    ///   growing linearly from 0.0112 at the clamped end to 0.0208 at the free end;
    /// * `f1`: a further pressure on the top with the same profile shape, from 0.00161 to
    ///   0.00299 (0.0023 × (0.7 → 1.3)).
    ///
    /// On [−0.5, 1.5] the contact zone grows from nodes 1–9 towards the free end; the path
    /// has 14 transition points (no contact → slip, slip → stick, stick → slip), and
    /// transition points 6, 7, 8 have the nodes and kinds the paper reports.
    fn default() -> Self {
        Self {
            nx: 31,
            ny: 22,
            lx: 3.0,
            ly: 2.1,
            e: 1.0,
            nu: 0.3,
            thickness: 1.0,
            friction: 0.3,
            gap: 0.0,
            load0: vec![
                Traction::uniform(Side::Right, [0.0, 0.01]),
                Traction::linear(Side::Top, [-0.01, -0.0112], [-0.01, -0.0208]),
            ],
            load1: vec![Traction::linear(
                Side::Top,
                [0.0, -0.00161],
                [0.0, -0.00299],
            )],
            rule: ForceRule::Consistent,
            alpha_start: -0.5,
            alpha_end: 1.5,
            load_name: "lift-press".into(),
        }
    }
}

impl RectSpec {
    /// The load of the sample case `press-shear` shipped with the project's brief, on the
    /// case-study mesh: `f0` a downward pressure on the top growing linearly from 0.004
    /// at the clamped end to 0.024 at the free end; `f1` a uniform shear 0.01 (+x) on the
    /// top and an upward traction on the right side decreasing linearly from 0.012 at the
    /// bottom to 0 at the top. With [`ForceRule::Trapezoid`] this reproduces the sample's
    /// files exactly.
    pub fn press_shear() -> Self {
        Self {
            load0: vec![Traction::linear(Side::Top, [0.0, -0.004], [0.0, -0.024])],
            load1: vec![
                Traction::uniform(Side::Top, [0.01, 0.0]),
                Traction::linear(Side::Right, [0.0, 0.012], [0.0, 0.0]),
            ],
            load_name: "press-shear".into(),
            ..Self::default()
        }
    }

    /// The high-friction variant of the case study (see `docs/case-study.md`): the same
    /// mesh and material with `F = 3` and the load "pull-shear", α ∈ [−0.5, 2.5]:
    /// * `f0`: on the top a uniform pressure 0.004 and shear 0.004 (+x); on the right side
    ///   a uniform outward pull 0.008 (+x) and upward shear 0.002;
    /// * `f1`: on the top a shear 0.0025 (+x); on the right side a pull 0.003 and upward
    ///   shear 0.002.
    ///
    /// The body is peeled off the foundation from the clamped side until only the free
    /// corner (node 30) touches and sticks; when it starts to slip, α turns back (a
    /// non-smooth fold; a single slipping corner node makes its piece singular at
    /// `F = W_νν/|W_νt| ≈ 2.32` on this mesh).
    pub fn high_friction() -> Self {
        Self {
            friction: 3.0,
            alpha_end: 2.5,
            load0: vec![
                Traction::uniform(Side::Top, [0.004, -0.004]),
                Traction::uniform(Side::Right, [0.008, 0.002]),
            ],
            load1: vec![
                Traction::uniform(Side::Top, [0.0025, 0.0]),
                Traction::uniform(Side::Right, [0.003, 0.002]),
            ],
            load_name: "pull-shear".into(),
            ..Self::default()
        }
    }
}

impl RectSpec {
    /// Number of free dofs, `2 (nx·ny − ny)`.
    pub fn n(&self) -> usize {
        2 * (self.nx * self.ny - self.ny)
    }

    /// Number of contact nodes, `nx − 1`.
    pub fn p(&self) -> usize {
        self.nx - 1
    }

    /// Element sizes `(hx, hy)`.
    pub fn h(&self) -> (f64, f64) {
        (
            self.lx / (self.nx - 1) as f64,
            self.ly / (self.ny - 1) as f64,
        )
    }

    /// x-coordinate of contact node `i` (0-based): `(i + 1) hx`.
    pub fn contact_x(&self, i: usize) -> f64 {
        (i + 1) as f64 * self.h().0
    }

    /// Checks the parameters. Errors: [`fricont::Error::InvalidParameter`] naming the field.
    pub fn validate(&self) -> Result<()> {
        let bad = |m: String| Err(invalid(m));
        if self.nx < 2 || self.ny < 2 {
            return bad(format!(
                "rectangle mesh needs nx ≥ 2 and ny ≥ 2 nodes (got {} × {})",
                self.nx, self.ny
            ));
        }
        if self
            .nx
            .checked_mul(self.ny)
            .is_none_or(|m| m > (1usize << 40))
        {
            return bad(format!("mesh {} × {} is too large", self.nx, self.ny));
        }
        for (name, v) in [
            ("lx", self.lx),
            ("ly", self.ly),
            ("e", self.e),
            ("thickness", self.thickness),
        ] {
            if !(v.is_finite() && v > 0.0) {
                return bad(format!("{name} = {v} must be finite and > 0"));
            }
        }
        if !(self.nu.is_finite() && (0.0..0.5).contains(&self.nu)) {
            return bad(format!("nu = {} must be in [0, 0.5)", self.nu));
        }
        if !(self.friction.is_finite() && self.friction >= 0.0) {
            return bad(format!(
                "friction = {} must be finite and ≥ 0",
                self.friction
            ));
        }
        if !self.gap.is_finite() {
            return bad(format!("gap = {} must be finite", self.gap));
        }
        if !self.alpha_start.is_finite()
            || !self.alpha_end.is_finite()
            || self.alpha_start == self.alpha_end
        {
            return bad(format!(
                "alpha window [{}, {}] must be finite with distinct ends",
                self.alpha_start, self.alpha_end
            ));
        }
        for (k, t) in self.load0.iter().chain(&self.load1).enumerate() {
            if !t.start.iter().chain(&t.end).all(|v| v.is_finite()) {
                return bad(format!("traction {} has a non-finite value", k + 1));
            }
        }
        Ok(())
    }

    /// A one-line description of the mesh for `meta.json`.
    pub fn mesh_description(&self) -> String {
        format!(
            "Q1 {}x{} nodes on (0,{})x(0,{}), left clamped, bottom contact",
            self.nx, self.ny, self.lx, self.ly
        )
    }
}

/// The plane-strain elasticity matrix `D` (3 × 3, Voigt order xx, yy, xy with engineering
/// shear strain) times `thickness`.
fn elasticity(e: f64, nu: f64, thickness: f64) -> [[f64; 3]; 3] {
    let c = thickness * e / ((1.0 + nu) * (1.0 - 2.0 * nu));
    [
        [c * (1.0 - nu), c * nu, 0.0],
        [c * nu, c * (1.0 - nu), 0.0],
        [0.0, 0.0, c * (1.0 - 2.0 * nu) / 2.0],
    ]
}

/// The 8 × 8 stiffness of a `hx × hy` Q1 element, plane strain, 2 × 2 Gauss points.
/// Local nodes counter-clockwise from the lower left: `(0,0), (hx,0), (hx,hy), (0,hy)`;
/// local dofs `2a` (x) and `2a+1` (y) of node `a`.
pub fn q1_element_stiffness(hx: f64, hy: f64, e: f64, nu: f64, thickness: f64) -> [[f64; 8]; 8] {
    const XI: [f64; 4] = [-1.0, 1.0, 1.0, -1.0];
    const ETA: [f64; 4] = [-1.0, -1.0, 1.0, 1.0];
    let d = elasticity(e, nu, thickness);
    let g = 1.0 / 3f64.sqrt();
    let det_j = hx * hy / 4.0;
    let mut k = [[0.0; 8]; 8];
    for &xi in &[-g, g] {
        for &eta in &[-g, g] {
            // B (3 × 8)
            let mut b = [[0.0; 8]; 3];
            for a in 0..4 {
                let dx = XI[a] * (1.0 + ETA[a] * eta) / 4.0 * (2.0 / hx);
                let dy = ETA[a] * (1.0 + XI[a] * xi) / 4.0 * (2.0 / hy);
                b[0][2 * a] = dx;
                b[1][2 * a + 1] = dy;
                b[2][2 * a] = dy;
                b[2][2 * a + 1] = dx;
            }
            // k += Bᵀ D B detJ (weights 1)
            let mut db = [[0.0; 8]; 3];
            for r in 0..3 {
                for c in 0..8 {
                    db[r][c] = (0..3).map(|s| d[r][s] * b[s][c]).sum();
                }
            }
            for r in 0..8 {
                for c in 0..8 {
                    k[r][c] += det_j * (0..3).map(|s| b[s][r] * db[s][c]).sum::<f64>();
                }
            }
        }
    }
    k
}

/// Local index of the element corner `(di, dj)` ∈ {0,1}².
fn local(di: usize, dj: usize) -> usize {
    match (di, dj) {
        (0, 0) => 0,
        (1, 0) => 1,
        (1, 1) => 2,
        _ => 3,
    }
}

/// Assembles the stiffness of the structured mesh directly in CSR form.
///
/// With `clamp_left` the nodes with `i = 0` are removed (the case's numbering); without
/// it every node is free and node `(i, j)` owns dofs `2 (j nx + i)`, `+1` (used by the
/// tests: rigid-body modes, patch test).
pub(crate) fn assemble_stiffness(
    nx: usize,
    ny: usize,
    ke: &[[f64; 8]; 8],
    clamp_left: bool,
) -> Result<CsrMatrix> {
    let i0 = usize::from(clamp_left);
    let cols = nx - i0;
    let nnodes = cols * ny;
    let ndof = 2 * nnodes;
    let node = |i: usize, j: usize| j * cols + (i - i0);
    let mut row_ptr: Vec<i64> = Vec::with_capacity(ndof + 1);
    let mut col_idx: Vec<i64> = Vec::with_capacity(18 * ndof);
    let mut values: Vec<f64> = Vec::with_capacity(18 * ndof);
    row_ptr.push(0);
    for j in 0..ny {
        for i in i0..nx {
            for c in 0..2 {
                // neighbours in increasing dof order: by row j2, then column i2
                for j2 in j.saturating_sub(1)..(j + 2).min(ny) {
                    for i2 in i.saturating_sub(1).max(i0)..(i + 2).min(nx) {
                        let mut v = [0.0; 2];
                        // elements (ei, ej) containing both nodes
                        for ej in j.max(j2).saturating_sub(1)..j.min(j2).min(ny - 2) + 1 {
                            for ei in i.max(i2).saturating_sub(1)..i.min(i2).min(nx - 2) + 1 {
                                let a = local(i - ei, j - ej);
                                let b = local(i2 - ei, j2 - ej);
                                v[0] += ke[2 * a + c][2 * b];
                                v[1] += ke[2 * a + c][2 * b + 1];
                            }
                        }
                        let k2 = node(i2, j2);
                        for (d, &vd) in v.iter().enumerate() {
                            col_idx.push((2 * k2 + d) as i64);
                            values.push(vd);
                        }
                    }
                }
                row_ptr.push(col_idx.len() as i64);
            }
        }
    }
    Ok(CsrMatrix::from_raw(
        "A", ndof, ndof, &row_ptr, &col_idx, &values, 0,
    )?)
}

/// Nodes of a side in increasing coordinate order, as `(i, j)`, and the edge length.
fn side_nodes(spec: &RectSpec, side: Side) -> (Vec<(usize, usize)>, f64) {
    let (hx, hy) = spec.h();
    match side {
        Side::Bottom => ((0..spec.nx).map(|i| (i, 0)).collect(), hx),
        Side::Top => ((0..spec.nx).map(|i| (i, spec.ny - 1)).collect(), hx),
        Side::Left => ((0..spec.ny).map(|j| (0, j)).collect(), hy),
        Side::Right => ((0..spec.ny).map(|j| (spec.nx - 1, j)).collect(), hy),
    }
}

/// Adds the nodal forces of `tractions` to `f`, where `dof(i, j)` gives the x dof of node
/// `(i, j)` or `None` for a clamped node (its force is dropped).
pub(crate) fn add_tractions(
    spec: &RectSpec,
    tractions: &[Traction],
    dof: &dyn Fn(usize, usize) -> Option<usize>,
    f: &mut [f64],
) {
    for t in tractions {
        let (nodes, h) = side_nodes(spec, t.side);
        let m = nodes.len() - 1;
        let th = spec.thickness;
        let value = |k: usize, c: usize| {
            let s = k as f64 / m as f64;
            t.start[c] * (1.0 - s) + t.end[c] * s
        };
        for e in 0..m {
            for c in 0..2 {
                let (ta, tb) = (value(e, c), value(e + 1, c));
                let (fa, fb) = match spec.rule {
                    ForceRule::Consistent => (h * (2.0 * ta + tb) / 6.0, h * (ta + 2.0 * tb) / 6.0),
                    ForceRule::Trapezoid => (h * ta / 2.0, h * tb / 2.0),
                };
                if let Some(d) = dof(nodes[e].0, nodes[e].1) {
                    f[d + c] += th * fa;
                }
                if let Some(d) = dof(nodes[e + 1].0, nodes[e + 1].1) {
                    f[d + c] += th * fb;
                }
            }
        }
    }
}

/// The x dof of node `(i, j)` in the case's numbering (left side clamped).
fn case_dof(spec: &RectSpec) -> impl Fn(usize, usize) -> Option<usize> + '_ {
    move |i, j| (i > 0).then(|| 2 * (j * (spec.nx - 1) + i - 1))
}

/// The nodal load vector of `tractions` in the case's numbering (n entries).
pub fn load_vector(spec: &RectSpec, tractions: &[Traction]) -> Vec<f64> {
    let mut f = vec![0.0; spec.n()];
    add_tractions(spec, tractions, &case_dof(spec), &mut f);
    f
}

/// Generates the rectangle problem in the exchange format (in memory).
///
/// Returns `A` (n × n, full symmetric storage, SPD because the left side is clamped),
/// `N`, `T` (p × n, see the module doc for the signs), `f0`, `f1`, the gap (only when
/// `spec.gap ≠ 0`), the friction and the α window, and a `meta.json` object with `n`,
/// `p`, `F`, `alpha_start`, `alpha_end`, `E`, `nu`, `mesh`, `load` and the whole spec
/// under `"spec"`. Errors: [`fricont::Error::InvalidParameter`] from [`RectSpec::validate`].
pub fn generate(spec: &RectSpec) -> Result<CaseData> {
    spec.validate()?;
    let (hx, hy) = spec.h();
    let ke = q1_element_stiffness(hx, hy, spec.e, spec.nu, spec.thickness);
    let a = assemble_stiffness(spec.nx, spec.ny, &ke, true)?;
    let n = spec.n();
    let p = spec.p();
    let nt: Vec<(usize, usize, f64)> = (0..p).map(|i| (i, 2 * i + 1, -1.0)).collect();
    let tt: Vec<(usize, usize, f64)> = (0..p).map(|i| (i, 2 * i, 1.0)).collect();
    let n_mat = CsrMatrix::from_triplets("N", p, n, &nt)?;
    let t_mat = CsrMatrix::from_triplets("T", p, n, &tt)?;
    let f0 = load_vector(spec, &spec.load0);
    let f1 = load_vector(spec, &spec.load1);
    let gap = (spec.gap != 0.0).then(|| vec![spec.gap; p]);
    let meta = serde_json::json!({
        "n": n,
        "p": p,
        "F": spec.friction,
        "alpha_start": spec.alpha_start,
        "alpha_end": spec.alpha_end,
        "E": spec.e,
        "nu": spec.nu,
        "mesh": spec.mesh_description(),
        "load": spec.load_name,
        "generator": "fricont::gen (plane strain, Q1, 2x2 Gauss)",
        "spec": spec,
    });
    Ok(CaseData {
        a,
        n_mat,
        t_mat,
        f0,
        f1,
        gap,
        friction: vec![spec.friction],
        alpha_start: spec.alpha_start,
        alpha_end: spec.alpha_end,
        meta,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The closed-form stiffness of a unit-square bilinear element in plane stress
    /// (Andreassen et al., "Efficient topology optimization in MATLAB using 88 lines of
    /// code", 2011, `lk`), turned into plane strain by `E → E/(1−ν²)`, `ν → ν/(1−ν)`.
    fn closed_form_unit_square(e: f64, nu: f64) -> [[f64; 8]; 8] {
        let (e, nu) = (e / (1.0 - nu * nu), nu / (1.0 - nu));
        let k = [
            0.5 - nu / 6.0,
            0.125 + nu / 8.0,
            -0.25 - nu / 12.0,
            -0.125 + 3.0 * nu / 8.0,
            -0.25 + nu / 12.0,
            -0.125 - nu / 8.0,
            nu / 6.0,
            0.125 - 3.0 * nu / 8.0,
        ];
        let idx = [
            [1, 2, 3, 4, 5, 6, 7, 8],
            [2, 1, 8, 7, 6, 5, 4, 3],
            [3, 8, 1, 6, 7, 4, 5, 2],
            [4, 7, 6, 1, 8, 3, 2, 5],
            [5, 6, 7, 8, 1, 2, 3, 4],
            [6, 5, 4, 3, 2, 1, 8, 7],
            [7, 4, 5, 2, 3, 8, 1, 6],
            [8, 3, 2, 5, 4, 7, 6, 1],
        ];
        let c = e / (1.0 - nu * nu);
        let mut out = [[0.0; 8]; 8];
        for r in 0..8 {
            for s in 0..8 {
                out[r][s] = c * k[idx[r][s] - 1];
            }
        }
        out
    }

    #[test]
    fn element_stiffness_matches_closed_form() {
        for &(e, nu) in &[(1.0, 0.3), (210.0, 0.0), (3.5, 0.45)] {
            let k = q1_element_stiffness(1.0, 1.0, e, nu, 1.0);
            let r = closed_form_unit_square(e, nu);
            for a in 0..8 {
                for b in 0..8 {
                    assert!(
                        (k[a][b] - r[a][b]).abs() <= 1e-13 * e,
                        "E={e} nu={nu} ({a},{b}): {} vs {}",
                        k[a][b],
                        r[a][b]
                    );
                }
            }
        }
    }

    #[test]
    fn element_stiffness_scales_like_the_mesh() {
        // a square of side h has the same stiffness as the unit square (2D elasticity is
        // scale-free); thickness multiplies it
        let k1 = q1_element_stiffness(1.0, 1.0, 2.0, 0.25, 1.0);
        let kh = q1_element_stiffness(0.1, 0.1, 2.0, 0.25, 3.0);
        for a in 0..8 {
            for b in 0..8 {
                assert!((kh[a][b] - 3.0 * k1[a][b]).abs() < 1e-13);
            }
        }
    }

    /// Unclamped stiffness of a small mesh, dense.
    fn dense_free(spec: &RectSpec) -> (usize, Vec<f64>) {
        let (hx, hy) = spec.h();
        let ke = q1_element_stiffness(hx, hy, spec.e, spec.nu, spec.thickness);
        let k = assemble_stiffness(spec.nx, spec.ny, &ke, false).unwrap();
        let m = k.nrows();
        let mut d = vec![0.0; m * m];
        for i in 0..m {
            for (j, v) in k.row(i) {
                d[i * m + j] = v;
            }
        }
        (m, d)
    }

    fn small_spec() -> RectSpec {
        RectSpec {
            nx: 5,
            ny: 4,
            lx: 2.0,
            ly: 0.9,
            e: 7.0,
            nu: 0.28,
            ..RectSpec::default()
        }
    }

    #[test]
    fn rigid_body_modes_are_in_the_kernel_of_the_unclamped_stiffness() {
        let spec = small_spec();
        let (hx, hy) = spec.h();
        let (m, k) = dense_free(&spec);
        let coords: Vec<(f64, f64)> = (0..m / 2)
            .map(|q| ((q % spec.nx) as f64 * hx, (q / spec.nx) as f64 * hy))
            .collect();
        let modes: Vec<Vec<f64>> = vec![
            coords.iter().flat_map(|_| [1.0, 0.0]).collect(),
            coords.iter().flat_map(|_| [0.0, 1.0]).collect(),
            coords.iter().flat_map(|&(x, y)| [-y, x]).collect(),
        ];
        let scale = k.iter().fold(0.0f64, |a, v| a.max(v.abs()));
        for u in &modes {
            for i in 0..m {
                let r: f64 = (0..m).map(|j| k[i * m + j] * u[j]).sum();
                assert!(r.abs() < 1e-13 * scale * 3.0, "row {i}: {r}");
            }
        }
        // and the stiffness is not zero on a stretching mode
        let stretch: Vec<f64> = coords.iter().flat_map(|&(x, _)| [x, 0.0]).collect();
        let energy: f64 = (0..m)
            .map(|i| stretch[i] * (0..m).map(|j| k[i * m + j] * stretch[j]).sum::<f64>())
            .sum();
        assert!(energy > 0.1 * scale);
    }

    #[test]
    fn direct_csr_assembly_equals_element_by_element_triplets() {
        let spec = small_spec();
        let (hx, hy) = spec.h();
        let ke = q1_element_stiffness(hx, hy, spec.e, spec.nu, 1.0);
        let a = assemble_stiffness(spec.nx, spec.ny, &ke, true).unwrap();
        // naive assembly over elements
        let mut t = Vec::new();
        let dof = case_dof(&spec);
        for ej in 0..spec.ny - 1 {
            for ei in 0..spec.nx - 1 {
                let corners = [(ei, ej), (ei + 1, ej), (ei + 1, ej + 1), (ei, ej + 1)];
                for (la, &(ia, ja)) in corners.iter().enumerate() {
                    for (lb, &(ib, jb)) in corners.iter().enumerate() {
                        if let (Some(da), Some(db)) = (dof(ia, ja), dof(ib, jb)) {
                            for c in 0..2 {
                                for d in 0..2 {
                                    t.push((da + c, db + d, ke[2 * la + c][2 * lb + d]));
                                }
                            }
                        }
                    }
                }
            }
        }
        let b = CsrMatrix::from_triplets("A", spec.n(), spec.n(), &t).unwrap();
        assert_eq!(a.row_ptr(), b.row_ptr());
        assert_eq!(a.col_idx(), b.col_idx());
        for (x, y) in a.values().iter().zip(b.values()) {
            assert!((x - y).abs() < 1e-14 * spec.e);
        }
        // symmetric
        let n = spec.n();
        let mut dense = vec![0.0; n * n];
        for i in 0..n {
            for (j, v) in a.row(i) {
                dense[i * n + j] = v;
            }
        }
        for i in 0..n {
            for j in 0..n {
                assert!((dense[i * n + j] - dense[j * n + i]).abs() < 1e-14);
            }
        }
    }

    #[test]
    fn patch_test_uniform_strain_is_reproduced() {
        // For a linear displacement field u = (a x + b y, c x + d y) the stress σ = D ε
        // is uniform; K u must equal the consistent nodal forces of the traction σ·n on
        // the boundary (interior rows vanish).
        let spec = small_spec();
        let (hx, hy) = spec.h();
        let (m, k) = dense_free(&spec);
        let (a, b, c, d) = (0.013, -0.007, 0.004, 0.021);
        let u: Vec<f64> = (0..m / 2)
            .flat_map(|q| {
                let (x, y) = ((q % spec.nx) as f64 * hx, (q / spec.nx) as f64 * hy);
                [a * x + b * y, c * x + d * y]
            })
            .collect();
        let dm = elasticity(spec.e, spec.nu, 1.0);
        let eps = [a, d, b + c];
        let s: Vec<f64> = (0..3)
            .map(|r| (0..3).map(|q| dm[r][q] * eps[q]).sum())
            .collect();
        let (sxx, syy, sxy) = (s[0], s[1], s[2]);
        let trac = |side, nrm: [f64; 2]| {
            Traction::uniform(
                side,
                [sxx * nrm[0] + sxy * nrm[1], sxy * nrm[0] + syy * nrm[1]],
            )
        };
        let ts = vec![
            trac(Side::Bottom, [0.0, -1.0]),
            trac(Side::Right, [1.0, 0.0]),
            trac(Side::Top, [0.0, 1.0]),
            trac(Side::Left, [-1.0, 0.0]),
        ];
        let mut f = vec![0.0; m];
        let nx = spec.nx;
        add_tractions(&spec, &ts, &move |i, j| Some(2 * (j * nx + i)), &mut f);
        for i in 0..m {
            let ku: f64 = (0..m).map(|j| k[i * m + j] * u[j]).sum();
            assert!(
                (ku - f[i]).abs() < 1e-13,
                "dof {i}: K u = {ku}, f = {}",
                f[i]
            );
        }
    }

    #[test]
    fn total_nodal_force_equals_the_traction_integral() {
        // right side: no clamped node, the whole integral arrives
        let spec = RectSpec {
            thickness: 2.0,
            ..small_spec()
        };
        let t = Traction::linear(Side::Right, [0.3, -1.0], [-0.1, 2.0]);
        for rule in [ForceRule::Consistent, ForceRule::Trapezoid] {
            let spec = RectSpec {
                rule,
                ..spec.clone()
            };
            let f = load_vector(&spec, &[t]);
            let fx: f64 = f.iter().step_by(2).sum();
            let fy: f64 = f.iter().skip(1).step_by(2).sum();
            // ∫ over the side of length ly of the linear profile = ly · mean, × thickness
            assert!((fx - 2.0 * spec.ly * (0.3 - 0.1) / 2.0).abs() < 1e-14);
            assert!((fy - 2.0 * spec.ly * (-1.0 + 2.0) / 2.0).abs() < 1e-14);
            // moment about the bottom-right corner: ∫ y t_x dy = ly² (t_a/6 + t_b/3) for the
            // consistent rule (exact), the trapezoidal rule differs by O(h²)
            let m: f64 = (0..spec.ny)
                .map(|j| {
                    let d = 2 * (j * (spec.nx - 1) + spec.nx - 2);
                    j as f64 * spec.h().1 * f[d]
                })
                .sum();
            let exact = 2.0 * spec.ly * spec.ly * (0.3 / 6.0 - 0.1 / 3.0);
            if rule == ForceRule::Consistent {
                assert!((m - exact).abs() < 1e-14, "{m} vs {exact}");
            }
        }
        // top side: the clamped corner node takes its share (consistent rule)
        let spec = small_spec();
        let t = Traction::linear(Side::Top, [0.0, -1.0], [0.0, -3.0]);
        let f = load_vector(&spec, &[t]);
        let fy: f64 = f.iter().skip(1).step_by(2).sum();
        let hx = spec.h().0;
        let t1 = -1.0 - 2.0 / (spec.nx - 1) as f64;
        let corner = hx * (-2.0 + t1) / 6.0;
        assert!((fy - (spec.lx * -2.0 - corner)).abs() < 1e-14);
    }

    #[test]
    fn generated_case_has_the_papers_dimensions_and_signs() {
        let spec = RectSpec::default();
        let c = generate(&spec).unwrap();
        assert_eq!(c.a.nrows(), 1320);
        assert_eq!(c.n_mat.nrows(), 30);
        assert_eq!(c.f0.len(), 1320);
        for i in 0..30 {
            assert_eq!(c.n_mat.row(i).collect::<Vec<_>>(), vec![(2 * i + 1, -1.0)]);
            assert_eq!(c.t_mat.row(i).collect::<Vec<_>>(), vec![(2 * i, 1.0)]);
        }
        assert!(c.gap.is_none());
        assert_eq!(c.meta["n"], 1320);
        assert_eq!(c.meta["p"], 30);
    }

    #[test]
    fn tractions_parse_from_the_command_line_form() {
        let t: Traction = "top:0,-0.004:0,-0.024".parse().unwrap();
        assert_eq!(t, Traction::linear(Side::Top, [0.0, -0.004], [0.0, -0.024]));
        let t: Traction = "Right:0,0.01".parse().unwrap();
        assert_eq!(t, Traction::uniform(Side::Right, [0.0, 0.01]));
        for bad in [
            "top",
            "top:1",
            "middle:0,1",
            "top:0,x",
            "top:0,1:2,3:4,5",
            "top:inf,0",
        ] {
            assert!(bad.parse::<Traction>().is_err(), "{bad}");
        }
    }

    #[test]
    fn bad_parameters_are_rejected_with_the_field_name() {
        let cases = [
            RectSpec {
                nx: 1,
                ..RectSpec::default()
            },
            RectSpec {
                nu: 0.5,
                ..RectSpec::default()
            },
            RectSpec {
                e: -1.0,
                ..RectSpec::default()
            },
            RectSpec {
                friction: f64::NAN,
                ..RectSpec::default()
            },
            RectSpec {
                alpha_end: -0.5,
                ..RectSpec::default()
            },
        ];
        for s in cases {
            let e = generate(&s).unwrap_err();
            assert!(
                matches!(e, Error::Core(fricont::Error::InvalidParameter(_))),
                "{e}"
            );
        }
    }
}
