//! Dense LU and Cholesky factorisations, on the calling thread or a private pool.
//!
//! faer's high-level solvers (`Mat::llt`, `partial_piv_lu`, …) read faer's *global*
//! parallelism setting, which with faer's `rayon` feature (needed for the problem's
//! `threads` option) defaults to rayon's global pool: calling them would start a thread
//! pool inside the host program. These wrappers call faer's kernels with an explicit
//! parallelism: `Par::Seq`, except for the passes of order ≥ [`PARALLEL_MIN_ORDER`]
//! made inside a [`TracePoolScope`] (the tracer's calls on a problem built with
//! [`crate::ProblemBuilder::threads`] > 1), which run on that call's private pool. The
//! only threads fricont ever starts are those private pools.

use faer::dyn_stack::{MemBuffer, MemStack};
use faer::linalg::cholesky::llt::factor::{LltError, cholesky_in_place, cholesky_in_place_scratch};
use faer::linalg::lu::{full_pivoting, partial_pivoting};
use faer::linalg::triangular_solve::{
    solve_unit_lower_triangular_in_place, solve_upper_triangular_in_place,
};
use faer::{Mat, MatMut, MatRef, Par};

/// The order m = 2p from which the tracer's dense passes (LU factorisations and solves of
/// piece matrices, products with W) use the problem's threads
/// ([`crate::ProblemBuilder::threads`] > 1). Below it W and a factor fit in a processor's
/// cache and one thread is as fast: measured on a 2-thread machine, a product of W with
/// two columns took 0.11 ms on one thread and as long on two at m = 960, 2.6 and 1.4 ms
/// at m = 2000, 13 and 7 ms at m = 4000 (triangular solves: 6.7 and 4.4 ms at m = 4000).
pub const PARALLEL_MIN_ORDER: usize = 2048;

#[cfg(feature = "threads")]
thread_local! {
    /// The pool of the tracer's current call on this thread (see [`TracePoolScope`]).
    static TRACE_POOL: std::cell::RefCell<Option<std::rc::Rc<rayon::ThreadPool>>> =
        const { std::cell::RefCell::new(None) };
}

/// A private pool of threads for the dense passes of order ≥ [`PARALLEL_MIN_ORDER`] made
/// on this thread while it lives (one call of the tracer): started by [`Self::enter`],
/// stopped when dropped. Only the passes run on the pool: the tracer's logic, and the
/// load, solve and monitor callbacks it makes, stay on the calling thread.
pub(crate) struct TracePoolScope {
    #[cfg(feature = "threads")]
    owner: bool,
}

impl TracePoolScope {
    /// Starts a pool of `threads` threads for a problem of order `order`. Nothing is
    /// started when `threads` ≤ 1, when `order` is below [`PARALLEL_MIN_ORDER`], inside
    /// another scope (its pool serves), or when the pool cannot be started (the passes
    /// then run on the calling thread, with the same results to rounding).
    pub(crate) fn enter(threads: usize, order: usize) -> Self {
        #[cfg(feature = "threads")]
        {
            let owner = threads > 1
                && order >= PARALLEL_MIN_ORDER
                && TRACE_POOL.with(|p| p.borrow().is_none())
                && rayon::ThreadPoolBuilder::new()
                    .num_threads(threads)
                    .thread_name(|i| format!("fricont-{i}"))
                    .build()
                    .map(|pool| TRACE_POOL.with(|p| *p.borrow_mut() = Some(std::rc::Rc::new(pool))))
                    .is_ok();
            Self { owner }
        }
        #[cfg(not(feature = "threads"))]
        {
            let _ = (threads, order);
            Self {}
        }
    }
}

impl Drop for TracePoolScope {
    fn drop(&mut self) {
        #[cfg(feature = "threads")]
        if self.owner {
            TRACE_POOL.with(|p| p.borrow_mut().take());
        }
    }
}

/// Runs the kernel `f` of order `m` on the current call's pool (see [`TracePoolScope`])
/// with that many threads, else on the calling thread with `Par::Seq`.
fn par_kernel<T: Send>(m: usize, f: impl FnOnce(Par) -> T + Send) -> T {
    #[cfg(feature = "threads")]
    if m >= PARALLEL_MIN_ORDER
        && let Some(p) = TRACE_POOL.with(|p| p.borrow().clone())
    {
        let threads = p.current_num_threads();
        return p.install(move || f(Par::rayon(threads)));
    }
    #[cfg(not(feature = "threads"))]
    let _ = m;
    f(Par::Seq)
}

/// `P A Q = L U` (square A): `L` unit lower, `U` upper; row `i` of `P A` is row
/// `row_fwd[i]` of A, column `j` of `A Q` is column `col_fwd[j]` of A (identity for
/// partial pivoting).
pub(crate) struct Lu {
    pub l: Mat<f64>,
    pub u: Mat<f64>,
    pub row_fwd: Vec<usize>,
    pub col_fwd: Vec<usize>,
}

fn split(lu: Mat<f64>) -> (Mat<f64>, Mat<f64>) {
    let (m, n) = lu.shape();
    let k = m.min(n);
    let l = Mat::from_fn(m, k, |i, j| match i.cmp(&j) {
        std::cmp::Ordering::Greater => lu[(i, j)],
        std::cmp::Ordering::Equal => 1.0,
        std::cmp::Ordering::Less => 0.0,
    });
    let u = Mat::from_fn(k, n, |i, j| if i <= j { lu[(i, j)] } else { 0.0 });
    (l, u)
}

/// `P A = L U` of a square matrix with partial (row) pivoting, both factors packed in
/// one matrix (`L` unit lower below the diagonal, `U` on and above it): a solve reads
/// m² numbers, once.
pub(crate) struct PartialLu {
    pub lu: Mat<f64>,
    /// Row `i` of `P A` is row `row_fwd[i]` of A.
    pub row_fwd: Vec<usize>,
}

/// LU with partial (row) pivoting of a square matrix, factorised in place (the caller
/// hands over its copy: on a large base piece a second m² array would cost its
/// allocation, page faults and copy at every refactorisation).
pub(crate) fn partial_piv_lu(mut lu: Mat<f64>) -> PartialLu {
    let (m, n) = lu.shape();
    let mut fwd = vec![0usize; m];
    let mut bwd = vec![0usize; m];
    par_kernel(m, |par| {
        let mut mem = MemBuffer::new(partial_pivoting::factor::lu_in_place_scratch::<usize, f64>(
            m,
            n,
            par,
            Default::default(),
        ));
        partial_pivoting::factor::lu_in_place(
            lu.as_mut(),
            &mut fwd,
            &mut bwd,
            par,
            MemStack::new(&mut mem),
            Default::default(),
        );
    });
    PartialLu { lu, row_fwd: fwd }
}

impl PartialLu {
    /// Solves `A X = B` in place (every column of `rhs`).
    pub(crate) fn solve_in_place(&self, mut rhs: MatMut<'_, f64>) {
        let n = rhs.nrows();
        let mut b = vec![0.0; n];
        for c in 0..rhs.ncols() {
            for (i, v) in b.iter_mut().enumerate() {
                *v = rhs[(self.row_fwd[i], c)];
            }
            for (i, v) in b.iter().enumerate() {
                rhs[(i, c)] = *v;
            }
        }
        // The triangular solves read only their own triangle of the packed factor.
        let lu = self.lu.as_ref();
        par_kernel(n, |par| {
            solve_unit_lower_triangular_in_place(lu, rhs.as_mut(), par);
            solve_upper_triangular_in_place(lu, rhs.as_mut(), par);
        });
    }
}

/// LU with full (row and column) pivoting of an m × n matrix.
pub(crate) fn full_piv_lu(a: MatRef<'_, f64>) -> Lu {
    let (m, n) = a.shape();
    let mut lu = a.to_owned();
    let (mut rf, mut rb) = (vec![0usize; m], vec![0usize; m]);
    let (mut cf, mut cb) = (vec![0usize; n], vec![0usize; n]);
    let par = Par::Seq;
    let mut mem = MemBuffer::new(full_pivoting::factor::lu_in_place_scratch::<usize, f64>(
        m,
        n,
        par,
        Default::default(),
    ));
    full_pivoting::factor::lu_in_place(
        lu.as_mut(),
        &mut rf,
        &mut rb,
        &mut cf,
        &mut cb,
        par,
        MemStack::new(&mut mem),
        Default::default(),
    );
    let (l, u) = split(lu);
    Lu {
        l,
        u,
        row_fwd: rf,
        col_fwd: cf,
    }
}

/// The Cholesky factor `L` (lower, `A = L Lᵀ`) of a symmetric matrix given by its lower
/// triangle. Errors: a non-positive pivot.
pub(crate) fn llt_lower(a: MatRef<'_, f64>) -> Result<Mat<f64>, LltError> {
    let n = a.nrows();
    let mut l = Mat::from_fn(n, n, |i, j| if i >= j { a[(i, j)] } else { 0.0 });
    let par = Par::Seq;
    let mut mem = MemBuffer::new(cholesky_in_place_scratch::<f64>(n, par, Default::default()));
    cholesky_in_place(
        l.as_mut(),
        Default::default(),
        par,
        MemStack::new(&mut mem),
        Default::default(),
    )?;
    for j in 0..n {
        for i in 0..j {
            l[(i, j)] = 0.0;
        }
    }
    Ok(l)
}

/// `max_i |v_i|` (0 for an empty `v`), NaN when some `v_i` is NaN: a residual or a
/// solution with a NaN in it never passes for small (`f64::max` alone skips a NaN).
pub(crate) fn inf_norm(v: &[f64]) -> f64 {
    // Eight independent lanes (`f64::max` in one chain costs several cycles an entry);
    // `a > m` is false for a NaN, which the lanes' flags catch instead.
    const L: usize = 8;
    let (mut mx, mut nan) = ([0.0f64; L], [false; L]);
    let mut lane = |l: usize, x: f64| {
        let a = x.abs();
        mx[l] = if a > mx[l] { a } else { mx[l] };
        nan[l] |= a.is_nan();
    };
    let chunks = v.chunks_exact(L);
    let rest = chunks.remainder();
    for c in chunks {
        for (l, &x) in c.iter().enumerate() {
            lane(l, x);
        }
    }
    for (l, &x) in rest.iter().enumerate() {
        lane(l, x);
    }
    if nan.contains(&true) {
        f64::NAN
    } else {
        mx.into_iter().fold(0.0, f64::max)
    }
}

/// `max_i |a_i − b_i|` (0 for empty slices); a NaN difference is skipped (`f64::max`), so
/// callers compare vectors they know to be finite.
pub(crate) fn max_abs_diff(a: &[f64], b: &[f64]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(x, y)| (x - y).abs())
        .fold(0.0, f64::max)
}

/// `Σ a_i b_i` in eight independent lanes, compiled for the machine's vector instructions
/// by faer's dispatch (a plain `.sum()` is one sequential chain of additions that the
/// compiler may not reorder, about one addition per cycle).
pub(crate) fn dot(a: &[f64], b: &[f64]) -> f64 {
    faer::traits::pulp::Arch::new().dispatch(Dot::<false>(a, b))
}

/// `Σ |a_i| b_i`, as [`dot`].
pub(crate) fn abs_dot(a: &[f64], b: &[f64]) -> f64 {
    faer::traits::pulp::Arch::new().dispatch(Dot::<true>(a, b))
}

/// The sum of [`dot`] (`ABS`: of [`abs_dot`]).
struct Dot<'a, const ABS: bool>(&'a [f64], &'a [f64]);

impl<const ABS: bool> faer::traits::pulp::WithSimd for Dot<'_, ABS> {
    type Output = f64;
    #[inline(always)]
    fn with_simd<S: faer::traits::pulp::Simd>(self, _: S) -> f64 {
        let (a, b) = (self.0, self.1);
        let n = a.len().min(b.len());
        let (a, b) = (&a[..n], &b[..n]);
        let f = |x: f64| if ABS { x.abs() } else { x };
        let mut s = [0.0f64; 8];
        let (ca, cb) = (a.chunks_exact(8), b.chunks_exact(8));
        let (ra, rb) = (ca.remainder(), cb.remainder());
        for (x, y) in ca.zip(cb) {
            for l in 0..8 {
                s[l] = f(x[l]).mul_add(y[l], s[l]);
            }
        }
        let mut tail = 0.0;
        for (x, y) in ra.iter().zip(rb) {
            tail += f(*x) * y;
        }
        ((s[0] + s[4]) + (s[1] + s[5])) + ((s[2] + s[6]) + (s[3] + s[7])) + tail
    }
}

/// `y += a x`, compiled for the machine's vector instructions by faer's dispatch.
pub(crate) fn axpy(y: &mut [f64], a: f64, x: &[f64]) {
    struct Axpy<'a>(&'a mut [f64], f64, &'a [f64]);
    impl faer::traits::pulp::WithSimd for Axpy<'_> {
        type Output = ();
        #[inline(always)]
        fn with_simd<S: faer::traits::pulp::Simd>(self, _: S) {
            let a = self.1;
            for (yi, xi) in self.0.iter_mut().zip(self.2) {
                *yi = a.mul_add(*xi, *yi);
            }
        }
    }
    faer::traits::pulp::Arch::new().dispatch(Axpy(y, a, x))
}

/// `out −= a b` (on the call's pool from order [`PARALLEL_MIN_ORDER`], see
/// [`TracePoolScope`]).
pub(crate) fn mat_mul_sub(out: MatMut<'_, f64>, a: MatRef<'_, f64>, b: MatRef<'_, f64>) {
    par_kernel(a.nrows().max(a.ncols()), |par| {
        faer::linalg::matmul::matmul(out, faer::Accum::Add, a, b, -1.0, par)
    });
}

/// `W x` for every x, W symmetric (m × m, column-major; every W of fricont is symmetric
/// to the last bit, see `condense::symmetrise` and `problem::equilibrated_w`): one pass
/// over W's lower triangle for all of them, on the calling thread; on the call's pool
/// from order [`PARALLEL_MIN_ORDER`] (see [`TracePoolScope`]), a general product. Each x
/// has m entries. Half of W's bytes and of the loads of x and y of a general product:
/// one product at m = 960 took 53 µs against faer's general product's 74 µs, and at
/// m = 3840 (W beyond the caches) 3.2 ms against 4.9 ms, measured in one run.
pub(crate) fn mat_mul(w: MatRef<'_, f64>, xs: &[&[f64]]) -> Vec<Vec<f64>> {
    let m = w.nrows();
    debug_assert!(w.ncols() == m && xs.iter().all(|x| x.len() == m));
    par_kernel(m, |par| match par {
        Par::Seq => {
            let mut out = vec![vec![0.0; m]; xs.len()];
            faer::traits::pulp::Arch::new().dispatch(SymMul {
                w,
                xs,
                out: &mut out,
            });
            out
        }
        par => {
            let xm = Mat::<f64>::from_fn(m, xs.len(), |i, j| xs[j][i]);
            let mut out = Mat::<f64>::zeros(m, xs.len());
            faer::linalg::matmul::matmul(
                out.as_mut(),
                faer::Accum::Replace,
                w,
                xm.as_ref(),
                1.0,
                par,
            );
            (0..xs.len())
                .map(|j| out.col(j).iter().copied().collect())
                .collect()
        }
    })
}

/// The lower-triangle kernel of [`mat_mul`]: each column j of W below the diagonal is
/// added to `y[j+1..]` (times `x_j`) and dotted with `x[j+1..]` into `y_j` in one pass,
/// four columns at a time (see [`below4`]).
struct SymMul<'a> {
    w: MatRef<'a, f64>,
    xs: &'a [&'a [f64]],
    out: &'a mut [Vec<f64>],
}

impl faer::traits::pulp::WithSimd for SymMul<'_> {
    type Output = ();
    #[inline(always)]
    fn with_simd<S: faer::traits::pulp::Simd>(self, simd: S) {
        let m = self.w.nrows();
        let col = |j: usize| {
            self.w
                .col(j)
                .try_as_col_major()
                .expect("contiguous column")
                .as_slice()
        };
        // Four columns at a time: each load of x and y below them serves four entries of
        // W (the pass is bound by loads and multiply-adds, not by W's bytes). The last
        // block may be narrower and has no rows below it.
        let mut j0 = 0;
        while j0 < m {
            let nb = (m - j0).min(4);
            for (x, y) in self.xs.iter().zip(self.out.iter_mut()) {
                // The diagonal block: rows j0..j0+nb of columns j0..j0+nb.
                for j in j0..j0 + nb {
                    let a = col(j);
                    y[j] = a[j].mul_add(x[j], y[j]);
                    for i in j + 1..j0 + nb {
                        y[i] = a[i].mul_add(x[j], y[i]);
                        y[j] = a[i].mul_add(x[i], y[j]);
                    }
                }
                let r0 = j0 + nb;
                if r0 < m {
                    let a = [0, 1, 2, 3].map(|k| &col(j0 + k)[r0..]);
                    let (head, yb) = y.split_at_mut(r0);
                    let sums = below4(simd, a, &x[j0..r0], &x[r0..], yb);
                    for (h, s) in head[j0..].iter_mut().zip(sums) {
                        *h += s;
                    }
                }
            }
            j0 += nb;
        }
    }
}

/// For four columns `a` of W below a diagonal block, with their entries `xj` of x: adds
/// `Σ_k a_k xj_k` to `y` and returns each `a_k · x`.
#[inline(always)]
fn below4<S: faer::traits::pulp::Simd>(
    simd: S,
    a: [&[f64]; 4],
    xj: &[f64],
    x: &[f64],
    y: &mut [f64],
) -> [f64; 4] {
    let xs = [0, 1, 2, 3].map(|k| simd.splat_f64s(xj[k]));
    let av = a.map(|a| S::as_simd_f64s(a));
    let (xv, xt) = S::as_simd_f64s(x);
    let (yv, yt) = S::as_mut_simd_f64s(y);
    let mut acc = [simd.splat_f64s(0.0); 4];
    for (i, (c, b)) in yv.iter_mut().zip(xv).enumerate() {
        let w = [0, 1, 2, 3].map(|k| av[k].0[i]);
        let t1 = simd.mul_add_e_f64s(w[1], xs[1], simd.mul_f64s(w[0], xs[0]));
        let t2 = simd.mul_add_e_f64s(w[3], xs[3], simd.mul_f64s(w[2], xs[2]));
        *c = simd.add_f64s(*c, simd.add_f64s(t1, t2));
        for k in 0..4 {
            acc[k] = simd.mul_add_e_f64s(w[k], *b, acc[k]);
        }
    }
    let mut out = acc.map(|v| simd.reduce_sum_f64s(v));
    for (i, (c, b)) in yt.iter_mut().zip(xt).enumerate() {
        for k in 0..4 {
            let w = av[k].1[i];
            *c = w.mul_add(xj[k], *c);
            out[k] = w.mul_add(*b, out[k]);
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_symmetric_product_reads_the_lower_triangle_as_the_whole_matrix() {
        // W_ij = (i + 1)(j + 1) + |i − j| mod 5 − 2 (symmetric, small integers) and
        // integer x: every sum is exact in double, so the product must equal the naive
        // row-by-row sum over both triangles exactly. Orders around the 8 lanes; two x
        // at once.
        for m in [1usize, 2, 7, 8, 9, 15, 16, 17, 40] {
            let w = Mat::<f64>::from_fn(m, m, |i, j| {
                ((i + 1) * (j + 1)) as f64 + (i.abs_diff(j) % 5) as f64 - 2.0
            });
            let x1: Vec<f64> = (0..m).map(|i| (i % 7) as f64 - 3.0).collect();
            let x2: Vec<f64> = (0..m).map(|i| ((3 * i) % 11) as f64 - 5.0).collect();
            let got = mat_mul(w.as_ref(), &[&x1, &x2]);
            for (x, y) in [&x1, &x2].into_iter().zip(&got) {
                for i in 0..m {
                    let want: f64 = (0..m).map(|j| w[(i, j)] * x[j]).sum();
                    assert_eq!(y[i], want, "m = {m}, row {i}");
                }
            }
        }
    }

    #[test]
    fn dot_and_abs_dot_sum_every_lane_and_the_tail() {
        // a_i = (−1)^i (i + 1), b_i = 2 (i + 1): integer sums, exact in double. Lengths
        // around the 8 lanes.
        for n in [0usize, 1, 7, 8, 9, 16, 23, 100] {
            let a: Vec<f64> = (0..n)
                .map(|i| if i % 2 == 0 { 1.0 } else { -1.0 } * (i + 1) as f64)
                .collect();
            let b: Vec<f64> = (0..n).map(|i| 2.0 * (i + 1) as f64).collect();
            // Σ ±2(i+1)² and Σ 2(i+1)², by hand: the alternating sum of squares of 1..n
            // is (−1)^(n+1) n(n+1)/2, the sum n(n+1)(2n+1)/6.
            let nf = n as f64;
            let alt = if n % 2 == 1 { 1.0 } else { -1.0 } * nf * (nf + 1.0) / 2.0;
            let all = nf * (nf + 1.0) * (2.0 * nf + 1.0) / 6.0;
            assert_eq!(dot(&a, &b), 2.0 * if n == 0 { 0.0 } else { alt }, "n = {n}");
            assert_eq!(abs_dot(&a, &b), 2.0 * all, "n = {n}");
        }
    }
}
