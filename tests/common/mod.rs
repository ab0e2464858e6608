//! Shared helpers of the `core_*` integration tests.
//!
//! Everything here is **independent of the library's numerics**: the problem data are kept
//! as dense nalgebra matrices, the Delassus operator is formed with nalgebra's Cholesky,
//! and the brute-force solver enumerates all `4^p` class assignments, solving each
//! piece's linear equations with nalgebra's LU. Only the library's public API is used, and
//! only to build the problem and to read what it traced.
#![allow(dead_code)]

use std::sync::Arc;

use fricont::path::State;
use fricont::{Class, CsrMatrix, Load, Path, PathOptions, Problem, ProblemBuilder, Storage};
use nalgebra::{DMatrix, DVector};

pub mod reference;

// ---------------------------------------------------------------------------------------
// Random numbers: xorshift64* with a fixed seed (no dependency).
// ---------------------------------------------------------------------------------------

/// xorshift64* generator.
pub struct Rng(u64);

impl Rng {
    pub fn new(seed: u64) -> Self {
        let mut s = seed.wrapping_mul(0x9E37_79B9_7F4A_7C15) ^ 0xD1B5_4A32_D192_ED03;
        if s == 0 {
            s = 1;
        }
        let mut r = Rng(s);
        for _ in 0..8 {
            r.next_u64();
        }
        r
    }
    pub fn next_u64(&mut self) -> u64 {
        let mut x = self.0;
        x ^= x >> 12;
        x ^= x << 25;
        x ^= x >> 27;
        self.0 = x;
        x.wrapping_mul(0x2545_F491_4F6C_DD1D)
    }
    /// Uniform in [0, 1).
    pub fn uniform(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 / (1u64 << 53) as f64
    }
    /// Uniform in [a, b).
    pub fn range(&mut self, a: f64, b: f64) -> f64 {
        a + (b - a) * self.uniform()
    }
    /// Uniform integer in lo..=hi.
    pub fn int(&mut self, lo: usize, hi: usize) -> usize {
        lo + (self.next_u64() % (hi - lo + 1) as u64) as usize
    }
}

// ---------------------------------------------------------------------------------------
// Problem data kept by the test.
// ---------------------------------------------------------------------------------------

/// Dense problem data with an affine load `f0 + α f1`.
#[derive(Clone, Debug)]
pub struct Data {
    pub n: usize,
    pub p: usize,
    pub a: DMatrix<f64>,
    pub nm: DMatrix<f64>,
    pub tm: DMatrix<f64>,
    pub friction: Vec<f64>,
    pub gap: Vec<f64>,
    pub f0: DVector<f64>,
    pub f1: DVector<f64>,
}

fn to_csr(m: &DMatrix<f64>) -> CsrMatrix {
    let mut rm = Vec::with_capacity(m.nrows() * m.ncols());
    for i in 0..m.nrows() {
        for j in 0..m.ncols() {
            rm.push(m[(i, j)]);
        }
    }
    CsrMatrix::from_dense(m.nrows(), m.ncols(), &rm).expect("test data is valid")
}

impl Data {
    /// Data from row-major arrays.
    #[allow(clippy::too_many_arguments)]
    pub fn from_rows(
        n: usize,
        p: usize,
        a: &[f64],
        nm: &[f64],
        tm: &[f64],
        friction: Vec<f64>,
        f0: &[f64],
        f1: &[f64],
    ) -> Data {
        Data {
            n,
            p,
            a: DMatrix::from_row_slice(n, n, a),
            nm: DMatrix::from_row_slice(p, n, nm),
            tm: DMatrix::from_row_slice(p, n, tm),
            friction,
            gap: vec![0.0; p],
            f0: DVector::from_column_slice(f0),
            f1: DVector::from_column_slice(f1),
        }
    }

    /// A random problem: `A = M Mᵀ + (n/2) I` (exactly symmetric), dense random `N`, `T`
    /// (full rank with probability one), friction uniform in `[fmin, fmax]` per node,
    /// optionally a random gap, random affine load.
    pub fn random(rng: &mut Rng, p: usize, n: usize, fmin: f64, fmax: f64, gap: bool) -> Data {
        let m = DMatrix::from_fn(n, n, |_, _| rng.range(-1.0, 1.0));
        let mut a = &m * m.transpose() + DMatrix::identity(n, n) * (0.5 * n as f64);
        let at = a.transpose();
        a = (a + at) * 0.5;
        let nm = DMatrix::from_fn(p, n, |_, _| rng.range(-1.0, 1.0));
        let tm = DMatrix::from_fn(p, n, |_, _| rng.range(-1.0, 1.0));
        let friction = (0..p).map(|_| rng.range(fmin, fmax)).collect();
        let gap = (0..p)
            .map(|_| if gap { rng.range(-0.2, 0.2) } else { 0.0 })
            .collect();
        let f0 = DVector::from_fn(n, |_, _| rng.range(-1.0, 1.0));
        let f1 = DVector::from_fn(n, |_, _| rng.range(-1.0, 1.0));
        Data {
            n,
            p,
            a,
            nm,
            tm,
            friction,
            gap,
            f0,
            f1,
        }
    }

    /// The library's problem for these data (full storage, default r).
    pub fn problem(&self) -> Problem {
        self.builder().build().expect("valid test problem")
    }

    /// The builder for these data.
    pub fn builder(&self) -> ProblemBuilder {
        ProblemBuilder::new(
            to_csr(&self.a),
            Storage::Full,
            to_csr(&self.nm),
            to_csr(&self.tm),
        )
        .friction(self.friction.clone())
        .gap(self.gap.clone())
    }

    pub fn affine_load(&self) -> Load {
        Load::affine(self.f0.as_slice().to_vec(), self.f1.as_slice().to_vec()).unwrap()
    }

    /// `f(α) = f0 + φ f1`.
    pub fn force(&self, phi: f64) -> DVector<f64> {
        &self.f0 + &self.f1 * phi
    }
}

/// Starts a path on `problem` with `load` at `a0`, toward `a1`, and runs it to its end.
pub fn trace(problem: Arc<Problem>, load: Load, a0: f64, a1: f64) -> Path {
    let mut path = Path::new(problem, load, PathOptions::window(a0, a1)).expect("Path::new");
    path.start(a0, None).expect("start");
    path.run().expect("run");
    path
}

/// `(λν, λt)` of a state as one vector.
pub fn lambda_of(s: &State) -> DVector<f64> {
    DVector::from_iterator(
        s.lambda_n.len() * 2,
        s.lambda_n.iter().chain(s.lambda_t.iter()).copied(),
    )
}

/// The class a node's mirror image takes: slip+ and slip− swapped (a body mirrored about
/// a vertical axis measures its tangential displacements the other way).
pub fn mirror_class(c: Class) -> Class {
    match c {
        Class::SlipPlus => Class::SlipMinus,
        Class::SlipMinus => Class::SlipPlus,
        c => c,
    }
}

/// `|a − b| ≤ tol · max(1, |a|, |b|)`.
pub fn close(a: f64, b: f64, tol: f64) -> bool {
    (a - b).abs() <= tol * 1f64.max(a.abs()).max(b.abs())
}

pub fn vclose(a: &DVector<f64>, b: &DVector<f64>, tol: f64) -> bool {
    let s = 1f64.max(a.amax()).max(b.amax());
    a.len() == b.len() && (a - b).amax() <= tol * s
}

// ---------------------------------------------------------------------------------------
// Brute force: every class assignment, each piece solved with nalgebra.
// ---------------------------------------------------------------------------------------

/// A guard `g0 + φ g1 > 0` of one node (kind: 0 = normal, 1 = tangential lower/positive
/// side, 2 = tangential upper side; only used for reports).
#[derive(Clone, Copy, Debug)]
pub struct Guard {
    pub node: usize,
    pub g0: f64,
    pub g1: f64,
}

/// A smooth piece in the load parameter `φ` (= α for an affine load): `λ(φ) = l0 + φ l1`,
/// valid on the open interval `(lo, hi)` where all its guards are strictly positive.
#[derive(Clone, Debug)]
pub struct BrutePiece {
    pub classes: Vec<Class>,
    pub l0: DVector<f64>,
    pub l1: DVector<f64>,
    pub lo: f64,
    pub hi: f64,
}

impl BrutePiece {
    pub fn lambda(&self, phi: f64) -> DVector<f64> {
        &self.l0 + &self.l1 * phi
    }
}

/// The condensed problem computed independently with nalgebra.
pub struct Brute {
    pub data: Data,
    pub p: usize,
    pub b: DMatrix<f64>,
    pub w: DMatrix<f64>,
    pub q0: DVector<f64>,
    pub q1: DVector<f64>,
    /// Every piece with a non-empty interval, singular pieces excluded.
    pub pieces: Vec<BrutePiece>,
    /// Number of class assignments with a (numerically) singular matrix.
    pub singular: usize,
    /// Refine piece solves and evaluate guards with compensated (twice-the-precision)
    /// dot products.
    pub precise: bool,
}

/// Error-free transformation `a + b = s + e`.
fn two_sum(a: f64, b: f64) -> (f64, f64) {
    let s = a + b;
    let bb = s - a;
    (s, (a - (s - bb)) + (b - bb))
}

/// `Σ a_k b_k` as if computed in twice the working precision, then rounded (the Dot2
/// algorithm of Ogita, Rump and Oishi).
pub fn dot2(terms: impl Iterator<Item = (f64, f64)>) -> f64 {
    let (mut hi, mut lo) = (0.0f64, 0.0f64);
    for (a, b) in terms {
        let p = a * b;
        let pe = a.mul_add(b, -p);
        let (s, se) = two_sum(hi, p);
        hi = s;
        lo += se + pe;
    }
    hi + lo
}

impl Brute {
    /// `(B, W)` of the data.
    pub fn condensed(data: &Data) -> (DMatrix<f64>, DMatrix<f64>) {
        let (p, n) = (data.p, data.n);
        let mut b = DMatrix::zeros(2 * p, n);
        b.rows_mut(0, p).copy_from(&data.nm);
        b.rows_mut(p, p).copy_from(&data.tm);
        let chol = data.a.clone().cholesky().expect("A SPD");
        let ainv_bt = chol.solve(&b.transpose());
        let mut w = &b * &ainv_bt;
        let wt = w.transpose();
        w = (w + wt) * 0.5;
        (b, w)
    }

    /// The condensed problem and every piece (4^p class assignments).
    pub fn new(data: &Data) -> Brute {
        let mut br = Brute::condensed_only(data);
        br.enumerate();
        br
    }

    /// The condensed problem without the enumeration (for large p): use
    /// [`Brute::piece_interval`] on given class vectors.
    pub fn condensed_only(data: &Data) -> Brute {
        let p = data.p;
        let (b, w) = Brute::condensed(data);
        let chol = data.a.clone().cholesky().expect("A SPD");
        let q0 = &b * chol.solve(&data.f0);
        let q1 = &b * chol.solve(&data.f1);
        Brute {
            data: data.clone(),
            p,
            b,
            w,
            q0,
            q1,
            pieces: Vec::new(),
            singular: 0,
            precise: false,
        }
    }

    /// Like [`Brute::condensed_only`], but as accurate as the data allow: every solve with
    /// A is refined with residuals from compensated dot products (mixed-precision iterative
    /// refinement), W and q are formed with compensated dot products, and so are the
    /// piece solves and guards afterwards. The reference for transition points of
    /// realistic (ill-conditioned A) problems.
    pub fn condensed_precise(data: &Data) -> Brute {
        let (p, n) = (data.p, data.n);
        let mut b = DMatrix::zeros(2 * p, n);
        b.rows_mut(0, p).copy_from(&data.nm);
        b.rows_mut(p, p).copy_from(&data.tm);
        let rows: Vec<Vec<(usize, f64)>> = (0..n)
            .map(|i| {
                (0..n)
                    .filter(|&j| data.a[(i, j)] != 0.0)
                    .map(|j| (j, data.a[(i, j)]))
                    .collect()
            })
            .collect();
        let chol = data.a.clone().cholesky().expect("A SPD");
        let solve = |rhs: &DVector<f64>| -> DVector<f64> {
            let mut x = chol.solve(rhs);
            for _ in 0..4 {
                let r = DVector::from_fn(n, |i, _| {
                    dot2(
                        std::iter::once((1.0, rhs[i]))
                            .chain(rows[i].iter().map(|&(j, v)| (-v, x[j]))),
                    )
                });
                x += chol.solve(&r);
            }
            x
        };
        let bdot = |k: usize, x: &DVector<f64>| dot2((0..n).map(|j| (b[(k, j)], x[j])));
        let xs: Vec<DVector<f64>> = (0..2 * p).map(|k| solve(&b.row(k).transpose())).collect();
        let mut w = DMatrix::from_fn(2 * p, 2 * p, |k, l| bdot(k, &xs[l]));
        let wt = w.transpose();
        w = (w + wt) * 0.5;
        let x0 = solve(&data.f0);
        let x1 = solve(&data.f1);
        let q0 = DVector::from_fn(2 * p, |k, _| bdot(k, &x0));
        let q1 = DVector::from_fn(2 * p, |k, _| bdot(k, &x1));
        Brute {
            data: data.clone(),
            p,
            b,
            w,
            q0,
            q1,
            pieces: Vec::new(),
            singular: 0,
            precise: true,
        }
    }

    /// The displacement `u = A⁻¹ (f + Bᵀ λ)`.
    pub fn displacement(&self, phi: f64, lambda: &DVector<f64>) -> DVector<f64> {
        let chol = self.data.a.clone().cholesky().unwrap();
        chol.solve(&(self.data.force(phi) + self.b.transpose() * lambda))
    }

    /// Solves the piece equations of `classes`: `M λ = r0 + φ r1`. `None` when `M` is
    /// numerically singular.
    pub fn piece(&self, classes: &[Class]) -> Option<(DVector<f64>, DVector<f64>)> {
        let p = self.p;
        let m2 = 2 * p;
        let mut m = DMatrix::zeros(m2, m2);
        let mut r0 = DVector::zeros(m2);
        let mut r1 = DVector::zeros(m2);
        for (i, &c) in classes.iter().enumerate() {
            let f = self.data.friction[i];
            match c {
                Class::Open => {
                    m[(i, i)] = 1.0;
                    m[(p + i, p + i)] = 1.0;
                }
                Class::Stick => {
                    m.row_mut(i).copy_from(&self.w.row(i));
                    r0[i] = -(self.q0[i] - self.data.gap[i]);
                    r1[i] = -self.q1[i];
                    m.row_mut(p + i).copy_from(&self.w.row(p + i));
                    r0[p + i] = -self.q0[p + i];
                    r1[p + i] = -self.q1[p + i];
                }
                Class::SlipPlus | Class::SlipMinus => {
                    m.row_mut(i).copy_from(&self.w.row(i));
                    r0[i] = -(self.q0[i] - self.data.gap[i]);
                    r1[i] = -self.q1[i];
                    let s = if c == Class::SlipPlus { 1.0 } else { -1.0 };
                    // λt − s F λν = 0
                    m[(p + i, p + i)] = 1.0;
                    m[(p + i, i)] = -s * f;
                }
            }
        }
        let svd = m.clone().svd(false, false);
        let smax = svd.singular_values.max();
        let smin = svd.singular_values.min();
        if smin <= 1e-11 * smax {
            return None;
        }
        let lu = m.clone().lu();
        let mut l0 = lu.solve(&r0)?;
        let mut l1 = lu.solve(&r1)?;
        if self.precise {
            for _ in 0..4 {
                for (l, r) in [(&mut l0, &r0), (&mut l1, &r1)] {
                    let res = DVector::from_fn(m2, |i, _| {
                        dot2(
                            std::iter::once((1.0, r[i])).chain((0..m2).map(|j| (-m[(i, j)], l[j]))),
                        )
                    });
                    *l += lu.solve(&res)?;
                }
            }
        }
        Some((l0, l1))
    }

    /// `d(λ, φ) = q(φ) + W λ − (g, 0)` for `λ = l0 + φ l1`, as `(d0, d1)`.
    fn gaps(&self, l0: &DVector<f64>, l1: &DVector<f64>) -> (DVector<f64>, DVector<f64>) {
        if self.precise {
            let m2 = 2 * self.p;
            let d = |q: &DVector<f64>, l: &DVector<f64>, gap: bool| {
                DVector::from_fn(m2, |i, _| {
                    let g = if gap && i < self.p {
                        self.data.gap[i]
                    } else {
                        0.0
                    };
                    dot2(
                        [(1.0, q[i]), (-1.0, g)]
                            .into_iter()
                            .chain((0..m2).map(|j| (self.w[(i, j)], l[j]))),
                    )
                })
            };
            return (d(&self.q0, l0, true), d(&self.q1, l1, false));
        }
        let mut d0 = &self.q0 + &self.w * l0;
        for (d, g) in d0.iter_mut().zip(&self.data.gap) {
            *d -= g;
        }
        let d1 = &self.q1 + &self.w * l1;
        (d0, d1)
    }

    /// The guards of a piece (SPEC §3 table), each `g0 + φ g1 > 0` inside.
    pub fn guards(&self, classes: &[Class], l0: &DVector<f64>, l1: &DVector<f64>) -> Vec<Guard> {
        let p = self.p;
        let (d0, d1) = self.gaps(l0, l1);
        let mut g = Vec::new();
        for (i, &c) in classes.iter().enumerate() {
            let f = self.data.friction[i];
            let (ln0, ln1, lt0, lt1) = (l0[i], l1[i], l0[p + i], l1[p + i]);
            match c {
                Class::Open => g.push(Guard {
                    node: i,
                    g0: -d0[i],
                    g1: -d1[i],
                }),
                Class::Stick => {
                    g.push(Guard {
                        node: i,
                        g0: -ln0,
                        g1: -ln1,
                    });
                    g.push(Guard {
                        node: i,
                        g0: lt0 - f * ln0,
                        g1: lt1 - f * ln1,
                    });
                    g.push(Guard {
                        node: i,
                        g0: -f * ln0 - lt0,
                        g1: -f * ln1 - lt1,
                    });
                }
                Class::SlipPlus | Class::SlipMinus => {
                    let s = if c == Class::SlipPlus { 1.0 } else { -1.0 };
                    g.push(Guard {
                        node: i,
                        g0: -ln0,
                        g1: -ln1,
                    });
                    g.push(Guard {
                        node: i,
                        g0: s * d0[p + i],
                        g1: s * d1[p + i],
                    });
                }
            }
        }
        g
    }

    /// The piece of `classes` with its α-interval (possibly empty: `lo ≥ hi`); `None` if
    /// its matrix is singular.
    pub fn piece_interval(&self, classes: &[Class]) -> Option<BrutePiece> {
        let (l0, l1) = self.piece(classes)?;
        let mut lo = f64::NEG_INFINITY;
        let mut hi = f64::INFINITY;
        for gd in self.guards(classes, &l0, &l1) {
            if gd.g1 > 0.0 {
                lo = lo.max(-gd.g0 / gd.g1);
            } else if gd.g1 < 0.0 {
                hi = hi.min(-gd.g0 / gd.g1);
            } else if gd.g0 <= 0.0 {
                hi = f64::NEG_INFINITY;
            }
        }
        Some(BrutePiece {
            classes: classes.to_vec(),
            l0,
            l1,
            lo,
            hi,
        })
    }

    fn enumerate(&mut self) {
        let p = self.p;
        let total = 4usize.pow(p as u32);
        for code in 0..total {
            let classes: Vec<Class> = (0..p).map(|i| Class::ALL[(code >> (2 * i)) & 3]).collect();
            match self.piece_interval(&classes) {
                None => self.singular += 1,
                Some(pc) if pc.lo < pc.hi => self.pieces.push(pc),
                Some(_) => {}
            }
        }
    }

    /// All solutions at `φ` (φ strictly inside the pieces' intervals).
    pub fn solutions_at(&self, phi: f64) -> Vec<(Vec<Class>, DVector<f64>)> {
        self.pieces
            .iter()
            .filter(|pc| pc.lo < phi && phi < pc.hi)
            .map(|pc| (pc.classes.clone(), pc.lambda(phi)))
            .collect()
    }

    /// All interval endpoints (transition values of φ) in the open interval (a, b).
    pub fn breakpoints(&self) -> Vec<f64> {
        let mut v: Vec<f64> = self
            .pieces
            .iter()
            .flat_map(|pc| [pc.lo, pc.hi])
            .filter(|x| x.is_finite())
            .collect();
        v.sort_by(f64::total_cmp);
        v
    }

    /// Independent path tracer: walks the connected component of the solution set through
    /// the start point, from `phi0` toward `phi_end`, joining pieces at shared endpoints.
    /// Returns `None` when the walk meets a non-generic situation (not exactly one other
    /// piece at an endpoint, or it differs in more than one node).
    pub fn walk(&self, phi0: f64, phi_end: f64, start: &DVector<f64>) -> Option<Walk> {
        let (pmin, pmax) = (phi0.min(phi_end), phi0.max(phi_end));
        let cands: Vec<usize> = (0..self.pieces.len())
            .filter(|&k| {
                let pc = &self.pieces[k];
                pc.lo < phi0 && phi0 < pc.hi && vclose(&pc.lambda(phi0), start, 1e-7)
            })
            .collect();
        if cands.len() != 1 {
            return None;
        }
        let mut cur = cands[0];
        let mut dir: f64 = if phi_end > phi0 { 1.0 } else { -1.0 };
        let mut from = phi0;
        let mut w = Walk::default();
        let mut visited: Vec<(usize, i32)> = Vec::new();
        for _ in 0..500 {
            if visited.contains(&(cur, dir as i32)) {
                w.closed = true;
                return Some(w);
            }
            visited.push((cur, dir as i32));
            let pc = &self.pieces[cur];
            let exit = if dir > 0.0 { pc.hi } else { pc.lo };
            if (dir > 0.0 && exit >= pmax) || (dir < 0.0 && exit <= pmin) {
                let to = if dir > 0.0 { pmax } else { pmin };
                w.steps.push(WalkStep {
                    piece: cur,
                    from,
                    to,
                });
                return Some(w);
            }
            w.steps.push(WalkStep {
                piece: cur,
                from,
                to: exit,
            });
            let lam = pc.lambda(exit);
            let scale = 1f64.max(exit.abs());
            let mut next = Vec::new();
            for (k, q) in self.pieces.iter().enumerate() {
                if k == cur {
                    continue;
                }
                for (end, ndir) in [(q.lo, 1.0), (q.hi, -1.0)] {
                    if (end - exit).abs() <= 1e-9 * scale && vclose(&q.lambda(exit), &lam, 1e-7) {
                        next.push((k, ndir));
                    }
                }
            }
            if next.len() != 1 {
                return None;
            }
            let (k, ndir) = next[0];
            let diff: Vec<usize> = (0..self.p)
                .filter(|&i| self.pieces[k].classes[i] != pc.classes[i])
                .collect();
            if diff.len() != 1 {
                return None;
            }
            let node = diff[0];
            w.events.push(WalkEvent {
                phi: exit,
                node,
                from: pc.classes[node],
                to: self.pieces[k].classes[node],
                fold: ndir != dir,
            });
            cur = k;
            dir = ndir;
            from = exit;
        }
        None
    }
}

/// One piece traversed by the walk, from φ = `from` to φ = `to`.
#[derive(Clone, Debug)]
pub struct WalkStep {
    pub piece: usize,
    pub from: f64,
    pub to: f64,
}

#[derive(Clone, Debug)]
pub struct WalkEvent {
    pub phi: f64,
    pub node: usize,
    pub from: Class,
    pub to: Class,
    pub fold: bool,
}

#[derive(Clone, Debug, Default)]
pub struct Walk {
    pub steps: Vec<WalkStep>,
    pub events: Vec<WalkEvent>,
    pub closed: bool,
}

impl Walk {
    /// The walk's solutions at φ: one per traversed piece whose range contains φ.
    pub fn solutions_at(&self, br: &Brute, phi: f64) -> Vec<DVector<f64>> {
        let mut out: Vec<DVector<f64>> = Vec::new();
        for s in &self.steps {
            if s.from.min(s.to) <= phi && phi <= s.from.max(s.to) {
                let l = br.pieces[s.piece].lambda(phi);
                if !out.iter().any(|o| vclose(o, &l, 1e-9)) {
                    out.push(l);
                }
            }
        }
        out
    }
}

// ---------------------------------------------------------------------------------------
// Independent check of a reported state against the equations of SPEC §1.
// ---------------------------------------------------------------------------------------

/// Checks that `s` solves the problem at load `f` (equilibrium, Signorini, Coulomb) and is
/// consistent with its reported classes, with relative tolerance `tol`. Returns a message
/// on failure.
pub fn check_state(data: &Data, f: &DVector<f64>, s: &State, tol: f64) -> Result<(), String> {
    let p = data.p;
    let u = DVector::from_column_slice(&s.u);
    let ln = DVector::from_column_slice(&s.lambda_n);
    let lt = DVector::from_column_slice(&s.lambda_t);
    let scale_f = 1f64.max(f.amax()).max(ln.amax()).max(lt.amax());
    let eq = &data.a * &u - f - data.nm.transpose() * &ln - data.tm.transpose() * &lt;
    if eq.amax() > tol * scale_f * (1.0 + data.a.amax()) {
        return Err(format!("equilibrium residual {:e}", eq.amax()));
    }
    let scale_u = 1f64.max(u.amax());
    let nu = &data.nm * &u;
    let tu = &data.tm * &u;
    for i in 0..p {
        let dn = nu[i] - data.gap[i];
        let dt = tu[i];
        let f = data.friction[i];
        let (l, t) = (ln[i], lt[i]);
        let et = tol * scale_f;
        let eu = tol * scale_u;
        match s.classes[i] {
            Class::Open => {
                if l.abs() > et || t.abs() > et || dn > eu {
                    return Err(format!("node {i} open: λ = ({l}, {t}), dν = {dn}"));
                }
            }
            Class::Stick => {
                if dn.abs() > eu || dt.abs() > eu || l > et || t.abs() > -f * l + et {
                    return Err(format!("node {i} stick: λ = ({l}, {t}), d = ({dn}, {dt})"));
                }
            }
            Class::SlipPlus | Class::SlipMinus => {
                let sg = if s.classes[i] == Class::SlipPlus {
                    1.0
                } else {
                    -1.0
                };
                if dn.abs() > eu || l > et || (t - sg * f * l).abs() > et || sg * dt < -eu {
                    return Err(format!(
                        "node {i} {}: λ = ({l}, {t}), d = ({dn}, {dt})",
                        s.classes[i]
                    ));
                }
            }
        }
    }
    Ok(())
}

/// Checks that the equations of class `class` hold at `node` for state `s` (used at a
/// transition point, which must satisfy the equations of the classes on both sides).
pub fn class_equations_hold(
    data: &Data,
    s: &State,
    node: usize,
    class: Class,
    tol: f64,
) -> Result<(), String> {
    let u = DVector::from_column_slice(&s.u);
    let (l, t) = (s.lambda_n[node], s.lambda_t[node]);
    let dn = (data.nm.row(node) * &u)[0] - data.gap[node];
    let dt = (data.tm.row(node) * &u)[0];
    let f = data.friction[node];
    let et = tol * 1f64.max(l.abs()).max(t.abs());
    let eu = tol * 1f64.max(u.amax());
    let ok = match class {
        Class::Open => l.abs() <= et && t.abs() <= et,
        Class::Stick => dn.abs() <= eu && dt.abs() <= eu,
        Class::SlipPlus => dn.abs() <= eu && (t - f * l).abs() <= et,
        Class::SlipMinus => dn.abs() <= eu && (t + f * l).abs() <= et,
    };
    if ok {
        Ok(())
    } else {
        Err(format!(
            "node {node}: {class} equations fail: λ = ({l}, {t}), d = ({dn}, {dt})"
        ))
    }
}

// ---------------------------------------------------------------------------------------
// A small Matrix Market / vector reader for the shared sample (independent of src/io.rs).
// ---------------------------------------------------------------------------------------

/// Reads a Matrix Market `coordinate real general|symmetric` file as 0-based triplets
/// (a symmetric file is expanded to both triangles).
pub fn read_mtx(path: &std::path::Path) -> (usize, usize, Vec<(usize, usize, f64)>) {
    let text = std::fs::read_to_string(path).expect("read mtx");
    let mut lines = text.lines();
    let header = lines.next().expect("header").to_lowercase();
    assert!(header.starts_with("%%matrixmarket matrix coordinate real"));
    let symmetric = header.contains("symmetric");
    let mut dims: Option<(usize, usize)> = None;
    let mut t = Vec::new();
    for l in lines {
        let l = l.trim();
        if l.is_empty() || l.starts_with('%') {
            continue;
        }
        let w: Vec<&str> = l.split_whitespace().collect();
        if dims.is_none() {
            dims = Some((w[0].parse().unwrap(), w[1].parse().unwrap()));
            continue;
        }
        let i: usize = w[0].parse::<usize>().unwrap() - 1;
        let j: usize = w[1].parse::<usize>().unwrap() - 1;
        let v: f64 = w[2].parse().unwrap();
        t.push((i, j, v));
        if symmetric && i != j {
            t.push((j, i, v));
        }
    }
    let (r, c) = dims.unwrap();
    (r, c, t)
}

/// Reads a vector file (one number a line).
pub fn read_vec(path: &std::path::Path) -> Vec<f64> {
    std::fs::read_to_string(path)
        .expect("read vector")
        .split_whitespace()
        .map(|x| x.parse().unwrap())
        .collect()
}

// ---------------------------------------------------------------------------------------
// Random test cases shared by several test files.
// ---------------------------------------------------------------------------------------

/// A random case: data and the α-window `[a0, a1]` (traced from a0 toward a1).
pub struct Case {
    pub seed: u64,
    pub data: Data,
    pub a0: f64,
    pub a1: f64,
}

/// Random case number `seed`: p = 1..=5 cycling, n = 2p + 0..=3, friction small
/// (0.05–0.3) for even seeds and up to 3 for odd seeds, a gap for every third seed,
/// window of random length traced upward or downward.
pub fn random_case(seed: u64) -> Case {
    let friction = if seed.is_multiple_of(2) {
        (0.05, 0.3)
    } else {
        (0.05, 3.0)
    };
    random_case_from(seed, Rng::new(seed), friction)
}

/// As [`random_case`] with large friction: 2–5 for even seeds, 0.05–5 for odd ones (its
/// own random stream).
pub fn large_friction_case(seed: u64) -> Case {
    let friction = if seed.is_multiple_of(2) {
        (2.0, 5.0)
    } else {
        (0.05, 5.0)
    };
    random_case_from(seed, Rng::new(seed ^ 0x5555), friction)
}

fn random_case_from(seed: u64, mut rng: Rng, (fmin, fmax): (f64, f64)) -> Case {
    let p = 1 + (seed % 5) as usize;
    let n = 2 * p + rng.int(0, 3);
    // Resample until W = B A⁻¹ Bᵀ is well conditioned (κ(W) ≤ 1e3): random dense N, T
    // can make B nearly rank-deficient, and then transition points are only determined
    // to κ·ε by the data themselves, whatever the algorithm.
    let data = loop {
        let d = Data::random(&mut rng, p, n, fmin, fmax, seed.is_multiple_of(3));
        let br = Brute::condensed(&d);
        let ev = br.1.symmetric_eigenvalues();
        if ev.max() <= 1e3 * ev.min() {
            break d;
        }
    };
    let lo = rng.range(-4.0, -1.0);
    let hi = rng.range(1.0, 4.0);
    let (a0, a1) = if seed % 4 == 3 { (hi, lo) } else { (lo, hi) };
    Case { seed, data, a0, a1 }
}

/// `n` sample values in the window of `case`, at least `margin` away from every
/// breakpoint of the brute force (so each sample lies inside its pieces).
pub fn samples(case: &Case, br: &Brute, count: usize, margin: f64) -> Vec<f64> {
    let mut rng = Rng::new(case.seed ^ 0xABCDEF);
    let bps = br.breakpoints();
    let (lo, hi) = (case.a0.min(case.a1), case.a0.max(case.a1));
    let mut out = Vec::new();
    let mut tries = 0;
    while out.len() < count && tries < 100 * count {
        tries += 1;
        let a = rng.range(lo, hi);
        if bps.iter().all(|b| (b - a).abs() > margin) {
            out.push(a);
        }
    }
    out
}

// ---------------------------------------------------------------------------------------
// The hand-derived problems of core_hand.rs (derivations there).
// ---------------------------------------------------------------------------------------

/// One node, n = 3 dofs, `A = diag(1, 1, 4)`, `N = [1 0 0]`, `T = [−1 1 0]`.
/// Then `A⁻¹ = diag(1, 1, 1/4)` and, with `B = [[1, 0, 0], [−1, 1, 0]]`,
///
/// ```text
/// W = B A⁻¹ Bᵀ = [[1, −1], [−1, 2]],    q = B A⁻¹ f = (f₁, f₂ − f₁)
/// ```
///
/// (the third dof is decoupled from the contact node and only makes n > 2p).
pub fn one_node(friction: f64, f0: [f64; 3], f1: [f64; 3]) -> Data {
    Data::from_rows(
        3,
        1,
        &[1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 4.0],
        &[1.0, 0.0, 0.0],
        &[-1.0, 1.0, 0.0],
        vec![friction],
        &f0,
        &f1,
    )
}

/// Two mirror-symmetric nodes (see `core_hand.rs::degenerate_symmetric_transition`):
/// n = 5 dofs `(a₁, b₁, a₂, b₂, c)`, `A = I`, `N₁ = a₁ + c`, `T₁ = b₁ + c`, `N₂ = a₂ − c`,
/// `T₂ = −b₂ − c`, F = 0.5, load `f = (α, 1, α, −1, 0)`.
pub fn mirror_pair() -> Data {
    #[rustfmt::skip]
    let nm = [
        1.0, 0.0, 0.0, 0.0, 1.0,
        0.0, 0.0, 1.0, 0.0, -1.0,
    ];
    #[rustfmt::skip]
    let tm = [
        0.0, 1.0, 0.0, 0.0, 1.0,
        0.0, 0.0, 0.0, -1.0, -1.0,
    ];
    let mut a = [0.0; 25];
    for i in 0..5 {
        a[i * 5 + i] = 1.0;
    }
    Data::from_rows(
        5,
        2,
        &a,
        &nm,
        &tm,
        vec![0.5, 0.5],
        &[0.0, 1.0, 0.0, -1.0, 0.0],
        &[1.0, 0.0, 1.0, 0.0, 0.0],
    )
}

/// The fold problem of `core_hand.rs::two_folds_three_solutions` (window [−3, 3]).
pub fn fold_problem() -> Data {
    one_node(2.0, [0.0, 1.0, 0.7], [1.0, -1.5, -0.3])
}

/// The vertical-piece problem of `core_hand.rs::vertical_piece_continuum` (window [−1, 1]).
pub fn vertical_problem() -> Data {
    one_node(1.0, [-0.25, 0.75, 0.0], [1.0, 1.0, 0.0])
}

impl Brute {
    /// Every piece (of length > `min_len` in φ) whose closure contains the point
    /// `(φ, λ)`: at a transition point, the pieces that meet there.
    pub fn incident(&self, phi: f64, lam: &DVector<f64>, min_len: f64) -> Vec<Vec<Class>> {
        let tol = 1e-9 * 1f64.max(phi.abs());
        self.pieces
            .iter()
            .filter(|pc| pc.hi - pc.lo > min_len)
            .filter(|pc| (pc.lo - phi).abs() <= tol || (pc.hi - phi).abs() <= tol)
            .filter(|pc| vclose(&pc.lambda(phi), lam, 1e-7))
            .map(|pc| pc.classes.clone())
            .collect()
    }
}

/// A random mirror-symmetric problem: a signed-permutation involution `P` (side dofs of
/// node 1 ↔ side dofs of node 2, centre dofs fixed or negated), `A = (A₀ + P A₀ P)/2`,
/// node 2 the mirror image of node 1 (`N₂ = N₁ P`, `T₂ = T₁ P`, same F and gap), an
/// optional centre node 3 on the axis (`N₃ P = N₃`, `T₃ P = −T₃`), a symmetric load
/// (`P f = f`). The symmetric solution has nodes 1 and 2 in the same class, switching at
/// the same α, and the centre node with `λt = dt = 0`.
pub fn symmetric_case(seed: u64, centre: bool) -> Case {
    let mut rng = Rng::new(seed.wrapping_add(0x5EED));
    let k = rng.int(2, 3);
    let cs = rng.int(1, 2);
    let ca = rng.int(1, 2);
    let n = 2 * k + cs + ca;
    let mut pm = DMatrix::zeros(n, n);
    for j in 0..k {
        let s = if rng.uniform() < 0.5 { 1.0 } else { -1.0 };
        pm[(k + j, j)] = s;
        pm[(j, k + j)] = s;
    }
    for j in 0..cs {
        pm[(2 * k + j, 2 * k + j)] = 1.0;
    }
    for j in 0..ca {
        pm[(2 * k + cs + j, 2 * k + cs + j)] = -1.0;
    }
    let p = if centre { 3 } else { 2 };
    let fr = rng.range(0.1, 3.0);
    let fc = rng.range(0.1, 3.0);
    let gap = if seed.is_multiple_of(3) {
        rng.range(-0.1, 0.1)
    } else {
        0.0
    };
    let data = loop {
        let m = DMatrix::from_fn(n, n, |_, _| rng.range(-1.0, 1.0));
        let a0 = &m * m.transpose() + DMatrix::identity(n, n) * (0.5 * n as f64);
        let mut a = (&a0 + &pm * &a0 * &pm) * 0.5;
        let at = a.transpose();
        a = (a + at) * 0.5;
        let n1 = DMatrix::from_fn(1, n, |_, _| rng.range(-1.0, 1.0));
        let t1 = DMatrix::from_fn(1, n, |_, _| rng.range(-1.0, 1.0));
        let mut nm = DMatrix::zeros(p, n);
        let mut tm = DMatrix::zeros(p, n);
        nm.row_mut(0).copy_from(&n1);
        tm.row_mut(0).copy_from(&t1);
        nm.row_mut(1).copy_from(&(&n1 * &pm));
        tm.row_mut(1).copy_from(&(&t1 * &pm));
        if centre {
            let r = DMatrix::from_fn(1, n, |_, _| rng.range(-1.0, 1.0));
            let s = DMatrix::from_fn(1, n, |_, _| rng.range(-1.0, 1.0));
            nm.row_mut(2).copy_from(&((&r + &r * &pm) * 0.5));
            tm.row_mut(2).copy_from(&((&s - &s * &pm) * 0.5));
        }
        let sym = |v: DVector<f64>| (&v + &pm * &v) * 0.5;
        let f0 = sym(DVector::from_fn(n, |_, _| rng.range(-1.0, 1.0)));
        let f1 = sym(DVector::from_fn(n, |_, _| rng.range(-1.0, 1.0)));
        let mut friction = vec![fr, fr];
        let mut gaps = vec![gap, gap];
        if centre {
            friction.push(fc);
            gaps.push(0.0);
        }
        let d = Data {
            n,
            p,
            a,
            nm,
            tm,
            friction,
            gap: gaps,
            f0,
            f1,
        };
        let (_, w) = Brute::condensed(&d);
        let ev = w.symmetric_eigenvalues();
        if ev.max() <= 1e3 * ev.min() {
            break d;
        }
    };
    let lo = rng.range(-4.0, -1.0);
    let hi = rng.range(1.0, 4.0);
    let (a0, a1) = if seed % 2 == 1 { (hi, lo) } else { (lo, hi) };
    Case { seed, data, a0, a1 }
}

/// The stiffness (n × n) of plane-strain Q1 elements (E = 1, ν = 0.3, 2×2 Gauss) of size
/// `hx × hy` on an `nx × ny` grid of elements, node (i, j) at (i hx, j hy); `dof(i, j, k)`
/// numbers the free dofs (k = 0: x, 1: y), None for a clamped one.
fn assemble_q1(
    nx: usize,
    ny: usize,
    hx: f64,
    hy: f64,
    n: usize,
    dof: impl Fn(usize, usize, usize) -> Option<usize>,
) -> DMatrix<f64> {
    let d = plane_strain();
    // element stiffness (8×8), local nodes (0,0), (1,0), (1,1), (0,1)
    let xi = [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)];
    let g = 1.0 / 3f64.sqrt();
    let mut ke = [[0.0; 8]; 8];
    for &(gx, gy) in &[(-g, -g), (g, -g), (g, g), (-g, g)] {
        let mut b = [[0.0; 8]; 3];
        for (a, &(xa, ya)) in xi.iter().enumerate() {
            let dx = 0.25 * xa * (1.0 + ya * gy) * 2.0 / hx;
            let dy = 0.25 * ya * (1.0 + xa * gx) * 2.0 / hy;
            b[0][2 * a] = dx;
            b[1][2 * a + 1] = dy;
            b[2][2 * a] = dy;
            b[2][2 * a + 1] = dx;
        }
        let det = hx * hy / 4.0;
        for i in 0..8 {
            for j in 0..8 {
                let mut s = 0.0;
                for k in 0..3 {
                    for l in 0..3 {
                        s += b[k][i] * d[k][l] * b[l][j];
                    }
                }
                ke[i][j] += s * det;
            }
        }
    }
    assemble_elements(nx, ny, n, dof, |_, _| ke)
}

/// The stiffness matrix (n × n) of an `nx × ny` grid of Q1 elements, element `(ei, ej)`
/// (nodes `(ei, ej)`, `(ei + 1, ej)`, `(ei + 1, ej + 1)`, `(ei, ej + 1)`) with stiffness
/// `ke_of(ei, ej)`; `dof(i, j, k)` is the dof of node `(i, j)` in direction k, None where
/// it is eliminated (clamped).
fn assemble_elements(
    nx: usize,
    ny: usize,
    n: usize,
    dof: impl Fn(usize, usize, usize) -> Option<usize>,
    ke_of: impl Fn(usize, usize) -> [[f64; 8]; 8],
) -> DMatrix<f64> {
    let mut a = DMatrix::zeros(n, n);
    for ei in 0..nx {
        for ej in 0..ny {
            let ke = ke_of(ei, ej);
            let nodes = [(ei, ej), (ei + 1, ej), (ei + 1, ej + 1), (ei, ej + 1)];
            for (la, &(ia, ja)) in nodes.iter().enumerate() {
                for ka in 0..2 {
                    let Some(ra) = dof(ia, ja, ka) else { continue };
                    for (lb, &(ib, jb)) in nodes.iter().enumerate() {
                        for kb in 0..2 {
                            let Some(cb) = dof(ib, jb, kb) else { continue };
                            a[(ra, cb)] += ke[2 * la + ka][2 * lb + kb];
                        }
                    }
                }
            }
        }
    }
    a
}

/// A small finite-element case (independent of `src/gen.rs`): plane-strain Q1 elements
/// (E = 1, ν = 0.3, 2×2 Gauss) on an `nx × ny` grid of the rectangle (0, L) × (0, H), the
/// left edge clamped (its dofs eliminated), the bottom nodes right of the corner in
/// contact with a rigid foundation (`N u = −u_y`, `T u = u_x`, so p = nx), a top
/// pressure plus random perturbations as f0, a random top shear/lift and right-edge
/// traction as f1, friction `friction` at every node.
pub fn fe_case(seed: u64, nx: usize, ny: usize, friction: f64) -> Case {
    fe_case_sized(seed, nx, ny, friction, None)
}

/// [`fe_case`] on the rectangle (0, lx) × (0, ly) (a slender strip where `lx ≫ ly`).
pub fn fe_strip(seed: u64, nx: usize, ny: usize, friction: f64, lx: f64, ly: f64) -> Case {
    fe_case_sized(seed, nx, ny, friction, Some((lx, ly)))
}

fn fe_case_sized(seed: u64, nx: usize, ny: usize, friction: f64, size: Option<(f64, f64)>) -> Case {
    let mut rng = Rng::new(seed.wrapping_add(0xFE));
    let drawn = (rng.range(1.0, 3.0), rng.range(0.5, 2.0));
    let (lx, ly) = size.unwrap_or(drawn);
    let (hx, hy) = (lx / nx as f64, ly / ny as f64);
    // free dofs: nodes with i ≥ 1
    let dof = |i: usize, j: usize, k: usize| -> Option<usize> {
        if i == 0 {
            None
        } else {
            Some(2 * (j * nx + (i - 1)) + k)
        }
    };
    let n = 2 * nx * (ny + 1);
    let mut a = assemble_q1(nx, ny, hx, hy, n, dof);
    let at = a.transpose();
    a = (a + at) * 0.5;
    let p = nx;
    let mut nm = DMatrix::zeros(p, n);
    let mut tm = DMatrix::zeros(p, n);
    for i in 1..=nx {
        nm[(i - 1, dof(i, 0, 1).unwrap())] = -1.0;
        tm[(i - 1, dof(i, 0, 0).unwrap())] = 1.0;
    }
    let mut f0 = DVector::from_fn(n, |_, _| rng.range(-0.02, 0.02));
    let mut f1 = DVector::from_fn(n, |_, _| rng.range(-0.02, 0.02));
    let press = rng.range(0.05, 0.2);
    let (sx, sy) = (rng.range(-0.2, 0.2), rng.range(-0.1, 0.1));
    let (rx, ry) = (rng.range(-0.1, 0.1), rng.range(-0.1, 0.1));
    for i in 1..=nx {
        f0[dof(i, ny, 1).unwrap()] -= press / nx as f64;
        f1[dof(i, ny, 0).unwrap()] += sx / nx as f64;
        f1[dof(i, ny, 1).unwrap()] += sy / nx as f64;
    }
    for j in 0..=ny {
        f1[dof(nx, j, 0).unwrap()] += rx / (ny + 1) as f64;
        f1[dof(nx, j, 1).unwrap()] += ry / (ny + 1) as f64;
    }
    let gap = (0..p)
        .map(|_| {
            if seed.is_multiple_of(3) {
                rng.range(0.0, 0.05)
            } else {
                0.0
            }
        })
        .collect();
    let data = Data {
        n,
        p,
        a,
        nm,
        tm,
        friction: vec![friction; p],
        gap,
        f0,
        f1,
    };
    let (a0, a1) = if seed.is_multiple_of(2) {
        (-2.0, 4.0)
    } else {
        (4.0, -2.0)
    };
    Case { seed, data, a0, a1 }
}

/// A mirror-symmetric finite-element case: plane-strain Q1 elements (as [`fe_case`]) on
/// an `nx × ny` grid of (0, L) × (0, H), the top edge clamped, every bottom node (i =
/// 0..=nx, so p = nx + 1; a centre node when nx is even) on the rigid foundation; f0 a
/// uniform downward push on every free node, f1 a symmetric side traction (outward
/// `±s_x`, upward `s_y` on both sides) plus a symmetric vertical profile. Node i and
/// node nx − i are mirror images (their t-directions opposite). Window [−1, 3].
pub fn symmetric_fe_case(seed: u64, nx: usize, ny: usize, friction: f64) -> Case {
    let mut rng = Rng::new(seed.wrapping_add(0x5F));
    let (lx, ly) = (rng.range(1.0, 4.0), rng.range(0.3, 2.0));
    let (hx, hy) = (lx / nx as f64, ly / ny as f64);
    // free dofs: nodes with j < ny (the top row clamped)
    let dof = |i: usize, j: usize, k: usize| -> Option<usize> {
        if j == ny {
            None
        } else {
            Some(2 * (j * (nx + 1) + i) + k)
        }
    };
    let n = 2 * (nx + 1) * ny;
    let mut a = assemble_q1(nx, ny, hx, hy, n, dof);
    let at = a.transpose();
    a = (a + at) * 0.5;
    let p = nx + 1;
    let mut nm = DMatrix::zeros(p, n);
    let mut tm = DMatrix::zeros(p, n);
    for i in 0..=nx {
        nm[(i, dof(i, 0, 1).unwrap())] = -1.0;
        tm[(i, dof(i, 0, 0).unwrap())] = 1.0;
    }
    let mut f0 = DVector::zeros(n);
    let mut f1 = DVector::zeros(n);
    let cells = ((nx + 1) * ny) as f64;
    let push = rng.range(0.01, 0.1) / cells;
    let (sx, sy) = (rng.range(0.0, 0.2), rng.range(-0.1, 0.1));
    let bump = rng.range(-0.05, 0.05);
    for j in 0..ny {
        for i in 0..=nx {
            f0[dof(i, j, 1).unwrap()] -= push;
            let xr = (i as f64 / nx as f64 - 0.5).abs();
            f1[dof(i, j, 1).unwrap()] += bump * (1.0 - 2.0 * xr) / cells;
        }
        f1[dof(0, j, 0).unwrap()] -= sx / ny as f64;
        f1[dof(nx, j, 0).unwrap()] += sx / ny as f64;
        f1[dof(0, j, 1).unwrap()] += sy / ny as f64;
        f1[dof(nx, j, 1).unwrap()] += sy / ny as f64;
    }
    let data = Data {
        n,
        p,
        a,
        nm,
        tm,
        friction: vec![friction; p],
        gap: vec![0.0; p],
        f0,
        f1,
    };
    Case {
        seed,
        data,
        a0: -1.0,
        a1: 3.0,
    }
}

/// An event with its full state (u by one back-solve, residual), as the tests read them;
/// derefs to the event.
#[derive(Debug)]
pub struct EvState {
    pub ev: fricont::Event,
    pub state: State,
}

impl std::ops::Deref for EvState {
    type Target = fricont::Event;
    fn deref(&self) -> &fricont::Event {
        &self.ev
    }
}

/// Every event of the path with its state (`Path::event_state`).
pub fn events_with_state(path: &Path) -> Vec<EvState> {
    (0..path.events().len())
        .map(|k| EvState {
            ev: path.events()[k].clone(),
            state: path.event_state(k).expect("event state"),
        })
        .collect()
}

/// `(λν, λt)` of an event as one vector.
pub fn lambda_ev(e: &fricont::Event) -> DVector<f64> {
    DVector::from_iterator(
        e.lambda_n.len() * 2,
        e.lambda_n.iter().chain(e.lambda_t.iter()).copied(),
    )
}

/// Asserts that traced events equal a brute-force walk's: same count, α to `tol` relative
/// (to max(1, |α|)), same node, classes and fold flag, and no bifurcation. Returns the
/// number of folds.
pub fn assert_events_match_walk(ctx: &str, ev: &[fricont::Event], w: &Walk, tol: f64) -> usize {
    let show = |a: f64, n: usize, f: Class, t: Class, fold: bool| {
        format!("{a:.15} node {n} {f} -> {t} fold {fold}")
    };
    let exp: Vec<String> = w
        .events
        .iter()
        .map(|e| show(e.phi, e.node, e.from, e.to, e.fold))
        .collect();
    let got: Vec<String> = ev
        .iter()
        .map(|e| show(e.alpha, e.node, e.from, e.to, e.fold))
        .collect();
    assert_eq!(
        ev.len(),
        w.events.len(),
        "{ctx}: events\n expected {exp:#?}\n got {got:#?}"
    );
    let mut folds = 0;
    for (e, x) in ev.iter().zip(&w.events) {
        assert!(
            (e.alpha - x.phi).abs() <= tol * 1f64.max(x.phi.abs()),
            "{ctx}: event {} α = {:.17e}, brute force {:.17e} (diff {:e})",
            e.index,
            e.alpha,
            x.phi,
            e.alpha - x.phi
        );
        assert_eq!(
            (e.node, e.from, e.to, e.fold, e.bifurcation),
            (x.node, x.from, x.to, x.fold, false),
            "{ctx}: event {}\n expected {exp:#?}\n got {got:#?}",
            e.index
        );
        folds += e.fold as usize;
    }
    folds
}

/// The plane-strain material matrix for E = 1, ν = 0.3 (stresses from strains
/// `(ε_xx, ε_yy, γ_xy)`).
fn plane_strain() -> [[f64; 3]; 3] {
    let (e, nu) = (1.0, 0.3);
    let c = e / ((1.0 + nu) * (1.0 - 2.0 * nu));
    [
        [c * (1.0 - nu), c * nu, 0.0],
        [c * nu, c * (1.0 - nu), 0.0],
        [0.0, 0.0, c * (1.0 - 2.0 * nu) / 2.0],
    ]
}

/// Plane-strain stiffness (E = 1, ν = 0.3, 2×2 Gauss) of an isoparametric Q1 element with
/// corners `xy` counter-clockwise (any convex quadrilateral; [`assemble_q1`]'s elements
/// are its rectangles).
fn q1_iso_element(xy: [(f64, f64); 4]) -> [[f64; 8]; 8] {
    let d = plane_strain();
    let corners = [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)];
    let g = 1.0 / 3f64.sqrt();
    let mut ke = [[0.0; 8]; 8];
    for (gx, gy) in [(-g, -g), (g, -g), (g, g), (-g, g)] {
        // shape-function derivatives in the reference square, then the Jacobian
        let dn = corners.map(|(xa, ya)| (0.25 * xa * (1.0 + ya * gy), 0.25 * ya * (1.0 + xa * gx)));
        let mut j = [[0.0; 2]; 2];
        for (a, &(dxi, deta)) in dn.iter().enumerate() {
            j[0][0] += dxi * xy[a].0;
            j[0][1] += dxi * xy[a].1;
            j[1][0] += deta * xy[a].0;
            j[1][1] += deta * xy[a].1;
        }
        let det = j[0][0] * j[1][1] - j[0][1] * j[1][0];
        assert!(det > 0.0, "an inverted element");
        let mut b = [[0.0; 8]; 3];
        for (a, &(dxi, deta)) in dn.iter().enumerate() {
            let dx = (j[1][1] * dxi - j[0][1] * deta) / det;
            let dy = (-j[1][0] * dxi + j[0][0] * deta) / det;
            b[0][2 * a] = dx;
            b[1][2 * a + 1] = dy;
            b[2][2 * a] = dy;
            b[2][2 * a + 1] = dx;
        }
        for (r, row) in ke.iter_mut().enumerate() {
            for (s, v) in row.iter_mut().enumerate() {
                let mut sum = 0.0;
                for k in 0..3 {
                    for l in 0..3 {
                        sum += b[k][r] * d[k][l] * b[l][s];
                    }
                }
                *v += sum * det;
            }
        }
    }
    ke
}

/// A curved body: plane-strain isoparametric Q1 elements on a mapped `nx × ny` grid over
/// x ∈ [−a, a], graded towards the middle (spacing ratio up to 10 between the middle and
/// the ends), its bottom the parabola `y = κ x²`, its top `y = H` clamped (its dofs
/// eliminated), the rows sheared sideways by up to 0.3 H. Every bottom node (p = nx + 1)
/// rests on the flat rigid foundation `y = −g0` (`N u = −u_y`, `T u = ±u_x`, the sign by
/// seed), its gap `κ x² + g0` (g0 = 0 in a third of the seeds, an overlap of up to 0.01
/// in some). f0: small random forces plus a sideways body force; f1: a downward body force
/// plus a sideways one. With `through_zero`: nx even (a node at the apex, x = 0), g0 = 0
/// and f0 = 0, so that the load `α f1` passes through zero at α = 0 with the apex node
/// alone at zero gap (all forces vanish there, and that node is at the vertex).
pub fn curved_body(seed: u64, through_zero: bool) -> Case {
    let mut rng = Rng::new(seed * 6151 + 3);
    let mut nx = rng.int(4, 40);
    if through_zero {
        nx += nx % 2;
    }
    let ny = rng.int(1, 6);
    let friction = [0.1, 0.3, 0.8, 1.5, 3.0, 5.0][rng.int(0, 5)];
    let (half, height) = (rng.range(0.5, 2.0), rng.range(0.2, 1.5));
    let curv = rng.range(0.0, 0.5) * height / (half * half);
    let (grade, skew) = (rng.range(0.0, 0.9), rng.range(-0.3, 0.3));
    let node = |i: usize, j: usize| -> (f64, f64) {
        // s ∈ [−1, 1], exactly 0 at i = nx / 2 for an even nx
        let s = (2 * i) as f64 / nx as f64 - 1.0;
        let x = half * (s - 0.5 * grade * s * (1.0 - s * s));
        let bottom = curv * x * x;
        let t = j as f64 / ny as f64;
        (
            x + skew * t * (1.0 - t) * height,
            bottom + t * (height - bottom),
        )
    };
    let dof = |i: usize, j: usize, k: usize| (j < ny).then(|| 2 * (j * (nx + 1) + i) + k);
    let n = 2 * (nx + 1) * ny;
    let mut a = assemble_elements(nx, ny, n, dof, |ei, ej| {
        let corners = [(ei, ej), (ei + 1, ej), (ei + 1, ej + 1), (ei, ej + 1)];
        q1_iso_element(corners.map(|(i, j)| node(i, j)))
    });
    let at = a.transpose();
    a = (a + at) * 0.5;
    let p = nx + 1;
    let mut nm = DMatrix::zeros(p, n);
    let mut tm = DMatrix::zeros(p, n);
    let t_sign = if seed.is_multiple_of(2) { 1.0 } else { -1.0 };
    for i in 0..p {
        nm[(i, dof(i, 0, 1).unwrap())] = -1.0;
        tm[(i, dof(i, 0, 0).unwrap())] = t_sign;
    }
    let g0 = if through_zero || seed.is_multiple_of(3) {
        0.0
    } else {
        rng.range(-0.01, 0.02)
    };
    let gap = (0..p).map(|i| node(i, 0).1 + g0).collect();
    let cells = (n / 2) as f64;
    let (down, side0, side1) = (
        rng.range(0.05, 0.3),
        rng.range(-0.1, 0.1),
        rng.range(-0.2, 0.2),
    );
    let mut f0 = DVector::zeros(n);
    let mut f1 = DVector::zeros(n);
    for j in 0..ny {
        for i in 0..p {
            let r = dof(i, j, 0).unwrap();
            if !through_zero {
                f0[r] += rng.range(-0.005, 0.005) + side0 / cells;
                f0[r + 1] += rng.range(-0.005, 0.005);
            }
            f1[r] += side1 / cells;
            f1[r + 1] -= down / cells;
        }
    }
    let data = Data {
        n,
        p,
        a,
        nm,
        tm,
        friction: vec![friction; p],
        gap,
        f0,
        f1,
    };
    let (a0, a1) = if seed % 5 == 2 {
        (4.0, -1.0)
    } else {
        (-1.0, 4.0)
    };
    Case { seed, data, a0, a1 }
}
