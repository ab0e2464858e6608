//! Double-double numbers: an unevaluated sum `hi + lo` with `|lo| ≤ ulp(hi)/2`, about 32
//! significant digits, from error-free transformations (Knuth's two-sum, the fused
//! multiply-add's exact product error). Used where the data are exact doubles but a
//! quantity derived from them (W of a slender body, the point of a transition on its
//! piece) is needed beyond double precision: mixed-precision refinement computes residuals
//! in double-double and corrections with the ordinary double factorisations.

use std::ops::{Add, Mul, Neg, Sub};

/// `a + b = s + e` exactly (Knuth's two-sum: no assumption on the sizes).
#[inline]
pub(crate) fn two_sum(a: f64, b: f64) -> (f64, f64) {
    let s = a + b;
    let bb = s - a;
    let e = (a - (s - bb)) + (b - bb);
    (s, e)
}

/// `a · b = p + e` exactly (p the rounded product, e from a fused multiply-add).
#[inline]
pub(crate) fn two_prod(a: f64, b: f64) -> (f64, f64) {
    let p = a * b;
    (p, a.mul_add(b, -p))
}

/// A double-double number `hi + lo`.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub(crate) struct Dd {
    pub hi: f64,
    pub lo: f64,
}

impl Dd {
    pub const ZERO: Dd = Dd { hi: 0.0, lo: 0.0 };

    /// `hi + lo` renormalised.
    #[inline]
    pub fn new(hi: f64, lo: f64) -> Dd {
        let (s, e) = two_sum(hi, lo);
        Dd { hi: s, lo: e }
    }

    /// The nearest double.
    #[inline]
    pub fn to_f64(self) -> f64 {
        self.hi + self.lo
    }

    /// `a · b` of two doubles, exactly.
    #[inline]
    pub fn prod(a: f64, b: f64) -> Dd {
        let (p, e) = two_prod(a, b);
        Dd { hi: p, lo: e }
    }

    /// `self + x` for a double x.
    #[inline]
    pub fn add_f64(self, x: f64) -> Dd {
        let (s, e) = two_sum(self.hi, x);
        Dd::new(s, e + self.lo)
    }

    /// `self · x` for a double x.
    #[inline]
    pub fn mul_f64(self, x: f64) -> Dd {
        let (p, e) = two_prod(self.hi, x);
        Dd::new(p, e + self.lo * x)
    }

    /// `self / other` (one Newton correction of the double quotient).
    #[inline]
    pub fn div(self, other: Dd) -> Dd {
        let q1 = self.hi / other.hi;
        let r = self - other.mul_f64(q1);
        let q2 = r.hi / other.hi;
        let r = r - other.mul_f64(q2);
        let q3 = r.hi / other.hi;
        Dd::new(q1, q2).add_f64(q3)
    }
}

impl Add for Dd {
    type Output = Dd;
    #[inline]
    fn add(self, o: Dd) -> Dd {
        let (s, e) = two_sum(self.hi, o.hi);
        let (t, f) = two_sum(self.lo, o.lo);
        let r = Dd::new(s, e + t);
        Dd::new(r.hi, r.lo + f)
    }
}

impl Neg for Dd {
    type Output = Dd;
    #[inline]
    fn neg(self) -> Dd {
        Dd {
            hi: -self.hi,
            lo: -self.lo,
        }
    }
}

impl Sub for Dd {
    type Output = Dd;
    #[inline]
    fn sub(self, o: Dd) -> Dd {
        self + (-o)
    }
}

impl Mul for Dd {
    type Output = Dd;
    #[inline]
    fn mul(self, o: Dd) -> Dd {
        let (p, e) = two_prod(self.hi, o.hi);
        Dd::new(p, e + (self.hi * o.lo + self.lo * o.hi))
    }
}

/// `Σ a_k x_k` in double-double for double `a` and double-double `x = x_hi + x_lo`
/// (the `a_k x_lo,k` terms, already tiny, summed in double): the compensated dot
/// product of Ogita, Rump and Oishi with the low parts added (the plain reference of
/// [`sym_gemv_dd`] in the tests).
#[cfg(test)]
pub(crate) fn dot_dd(a: &[f64], x_hi: &[f64], x_lo: &[f64]) -> Dd {
    let (mut s, mut c) = (0.0f64, 0.0f64);
    for k in 0..a.len() {
        let (p, e) = two_prod(a[k], x_hi[k]);
        let (s2, f) = two_sum(s, p);
        s = s2;
        c += e + f + a[k] * x_lo[k];
    }
    Dd::new(s, c)
}

/// `W x` in double-double for the symmetric `W` (m × m, column-major, each column
/// contiguous) and each double-double vector `x = x_hi + x_lo` of `xs`: row k is read as
/// column k, and every dot product runs in four independent lanes (compensated), as
/// vectors of four lanes where faer's dispatch gives them (AVX2 with fused multiply-adds;
/// 0.28 ms at m = 960 against 1.03 ms in scalar code), four rows at a time; else in
/// scalar code, with the same bits.
pub(crate) fn sym_gemv_dd(w: faer::MatRef<'_, f64>, xs: &[(&[f64], &[f64])]) -> Vec<Vec<Dd>> {
    let mut out = vec![vec![Dd::ZERO; w.nrows()]; xs.len()];
    faer::traits::pulp::Arch::new().dispatch(GemvDd {
        w,
        xs,
        out: &mut out,
    });
    out
}

struct GemvDd<'a> {
    w: faer::MatRef<'a, f64>,
    xs: &'a [(&'a [f64], &'a [f64])],
    out: &'a mut [Vec<Dd>],
}

impl faer::traits::pulp::WithSimd for GemvDd<'_> {
    type Output = ();

    #[inline(always)]
    fn with_simd<S: faer::traits::pulp::Simd>(self, simd: S) {
        let m = self.w.nrows();
        let col = |k: usize| {
            self.w
                .col(k)
                .try_as_col_major()
                .expect("contiguous column")
                .as_slice()
        };
        // Lane l of a vector holds the entries 4j + l: the scalar lanes of `dot_lanes`,
        // so both give the same bits. Four rows at a time share the loads of x.
        let four = S::F64_LANES == 4;
        let mut k = 0;
        while four && k + 4 <= m {
            let rows = [0, 1, 2, 3].map(|r| col(k + r));
            for (out, &(xh, xl)) in self.out.iter_mut().zip(self.xs) {
                out[k..k + 4].copy_from_slice(&dot4_dd(simd, rows, xh, xl));
            }
            k += 4;
        }
        for k in k..m {
            for (out, &(xh, xl)) in self.out.iter_mut().zip(self.xs) {
                out[k] = dot_lanes(col(k), xh, xl);
            }
        }
    }
}

/// The compensated sum of `a_i (xh_i + xl_i)` in four lanes (lane l: the entries 4j + l,
/// the rest after the lanes are combined): the products' errors from the fused
/// multiply-add, the sums' from two-sum.
#[inline(always)]
fn dot_lanes(a: &[f64], xh: &[f64], xl: &[f64]) -> Dd {
    let m = a.len();
    let (mut s, mut c) = ([0.0f64; 4], [0.0f64; 4]);
    let chunks = m / 4;
    for j in 0..chunks {
        for l in 0..4 {
            let i = 4 * j + l;
            let p = a[i] * xh[i];
            let e = a[i].mul_add(xh[i], -p);
            let s2 = s[l] + p;
            let bb = s2 - s[l];
            let f = (s[l] - (s2 - bb)) + (p - bb);
            s[l] = s2;
            c[l] += e + f + a[i] * xl[i];
        }
    }
    finish_lanes(s, c, &a[4 * chunks..], &xh[4 * chunks..], &xl[4 * chunks..])
}

/// The four lanes `(s, c)` combined, then the entries after them added.
#[inline(always)]
fn finish_lanes(s: [f64; 4], c: [f64; 4], a: &[f64], xh: &[f64], xl: &[f64]) -> Dd {
    let mut tot = Dd::ZERO;
    for l in 0..4 {
        tot = tot + Dd::new(s[l], c[l]);
    }
    for i in 0..a.len() {
        tot = tot + Dd::prod(a[i], xh[i]).add_f64(a[i] * xl[i]);
    }
    tot
}

/// [`dot_lanes`] of four columns `a` with the same x, in vectors of four lanes
/// (`S::F64_LANES == 4`): the same operations on the same entries.
#[inline(always)]
fn dot4_dd<S: faer::traits::pulp::Simd>(
    simd: S,
    a: [&[f64]; 4],
    xh: &[f64],
    xl: &[f64],
) -> [Dd; 4] {
    let av = a.map(|a| S::as_simd_f64s(a).0);
    let (hv, _) = S::as_simd_f64s(xh);
    let (lv, _) = S::as_simd_f64s(xl);
    let zero = simd.splat_f64s(0.0);
    let (mut s, mut c) = ([zero; 4], [zero; 4]);
    for (j, (&h, &lo)) in hv.iter().zip(lv).enumerate() {
        for r in 0..4 {
            let w = av[r][j];
            let p = simd.mul_f64s(w, h);
            let e = simd.mul_add_f64s(w, h, simd.neg_f64s(p));
            let s2 = simd.add_f64s(s[r], p);
            let bb = simd.sub_f64s(s2, s[r]);
            let f = simd.add_f64s(
                simd.sub_f64s(s[r], simd.sub_f64s(s2, bb)),
                simd.sub_f64s(p, bb),
            );
            s[r] = s2;
            let t = simd.add_f64s(simd.add_f64s(e, f), simd.mul_f64s(w, lo));
            c[r] = simd.add_f64s(c[r], t);
        }
    }
    let lanes = |v: S::f64s| {
        let mut out = [0.0f64; 4];
        S::as_mut_simd_f64s(&mut out[..]).0[0] = v;
        out
    };
    let done = 4 * hv.len();
    [0, 1, 2, 3].map(|r| {
        finish_lanes(
            lanes(s[r]),
            lanes(c[r]),
            &a[r][done..],
            &xh[done..],
            &xl[done..],
        )
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn exact_transformations() {
        // 1 + 2^-60 is not a double; its parts are kept.
        let (s, e) = two_sum(1.0, 2f64.powi(-60));
        assert_eq!((s, e), (1.0, 2f64.powi(-60)));
        // (1 + 2^-30)^2 = 1 + 2^-29 + 2^-60
        let x = 1.0 + 2f64.powi(-30);
        let (p, e) = two_prod(x, x);
        assert_eq!(p, 1.0 + 2f64.powi(-29));
        assert_eq!(e, 2f64.powi(-60));
    }

    #[test]
    fn division_and_dot_beyond_double() {
        // 1/3 in double-double: 3 · (1/3) − 1 vanishes to ~1e-32.
        let third = Dd::new(1.0, 0.0).div(Dd::new(3.0, 0.0));
        let back = third.mul_f64(3.0) - Dd::new(1.0, 0.0);
        assert!(back.to_f64().abs() < 1e-31, "{back:?}");
        // A cancelling dot product: 1e16 + 1 − 1e16 = 1 (double gives 0 or 2).
        let d = dot_dd(&[1e16, 1.0, -1e16], &[1.0, 1.0, 1.0], &[0.0; 3]);
        assert_eq!(d.to_f64(), 1.0);
        // The low parts count: x = 1 + 2^-70 as (1, 2^-70), 2^70 x − 2^70 = 1.
        let t70 = 2f64.powi(70);
        let d = dot_dd(&[t70, -t70], &[1.0, 1.0], &[2f64.powi(-70), 0.0]);
        assert_eq!(d.to_f64(), 1.0);
    }

    #[test]
    fn symmetric_products_agree_with_the_scalar_dot() {
        // Symmetric W of mixed sizes: rows in blocks of four and after them, columns in
        // chunks of four lanes and a remainder; two x at once. Each entry within 1e-30
        // of the one-lane compensated dot, and bitwise the scalar four-lane sum (the
        // vector kernel must do the same operations on the same entries).
        for m in [3usize, 4, 11, 17] {
            let w = faer::Mat::<f64>::from_fn(m, m, |i, j| {
                let (a, b) = (i.min(j) as f64, i.max(j) as f64);
                (1.0 + a * 0.37 + b * 1.3).sin() * 10f64.powi(((a + b) as i32 % 7) - 3)
            });
            let xh: Vec<f64> = (0..m).map(|i| (i as f64 * 0.9).cos() * 1e3).collect();
            let xl: Vec<f64> = xh.iter().map(|v| v * 1e-17).collect();
            let yh: Vec<f64> = (0..m).map(|i| (i as f64 * 2.1).sin() * 1e-2).collect();
            let yl: Vec<f64> = yh.iter().map(|v| -v * 3e-18).collect();
            let got = sym_gemv_dd(w.as_ref(), &[(&xh, &xl), (&yh, &yl)]);
            for (v, (h, l)) in [(&xh, &xl), (&yh, &yl)].into_iter().enumerate() {
                for k in 0..m {
                    let col: Vec<f64> = (0..m).map(|i| w[(i, k)]).collect();
                    let want = dot_dd(&col, h, l);
                    let d = (got[v][k] - want).to_f64().abs();
                    assert!(
                        d <= 1e-30 * want.to_f64().abs().max(1.0),
                        "m {m} row {k}: {d:e}"
                    );
                    assert_eq!(got[v][k], dot_lanes(&col, h, l), "m {m}, x {v}, row {k}");
                }
            }
        }
    }
}
