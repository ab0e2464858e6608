//! Scalar root finding and bounds for the nonlinear steps: the minimum of a cubic
//! Hermite interpolant (a double crossing inside a step is not skipped) and Brent's
//! method for the crossing itself.

/// Minimum over [0, 1] of the cubic Hermite interpolant with values v0, v1 and
/// derivatives m0, m1 (with respect to the unit interval).
pub(super) fn hermite_min(v0: f64, v1: f64, m0: f64, m1: f64) -> f64 {
    // p(s) = v0 h00 + m0 h10 + v1 h01 + m1 h11; p'(s) = a s² + b s + c
    let a = 6.0 * v0 + 3.0 * m0 - 6.0 * v1 + 3.0 * m1;
    let b = -6.0 * v0 - 4.0 * m0 + 6.0 * v1 - 2.0 * m1;
    let c = m0;
    let p = |s: f64| {
        let s2 = s * s;
        let s3 = s2 * s;
        v0 * (2.0 * s3 - 3.0 * s2 + 1.0)
            + m0 * (s3 - 2.0 * s2 + s)
            + v1 * (-2.0 * s3 + 3.0 * s2)
            + m1 * (s3 - s2)
    };
    let mut best = v0.min(v1);
    let mut try_s = |s: f64| {
        if s > 0.0 && s < 1.0 {
            best = best.min(p(s));
        }
    };
    if a.abs() < 1e-300 {
        if b != 0.0 {
            try_s(-c / b);
        }
    } else {
        let disc = b * b - 4.0 * a * c;
        if disc >= 0.0 {
            let sq = disc.sqrt();
            try_s((-b + sq) / (2.0 * a));
            try_s((-b - sq) / (2.0 * a));
        }
    }
    best
}

/// Brent's method for a root of `f` in [a, b] with `f(a) > 0 > f(b)` (or any sign change),
/// to machine precision in the argument.
pub(super) fn brent(a: f64, b: f64, fa: f64, fb: f64, mut f: impl FnMut(f64) -> f64) -> f64 {
    let (mut a, mut b, mut fa, mut fb) = (a, b, fa, fb);
    if fa.abs() < fb.abs() {
        std::mem::swap(&mut a, &mut b);
        std::mem::swap(&mut fa, &mut fb);
    }
    let (mut c, mut fc) = (a, fa);
    let mut d = b - a;
    let mut e = d;
    for _ in 0..200 {
        if fb == 0.0 {
            return b;
        }
        if (fb > 0.0) == (fc > 0.0) {
            c = a;
            fc = fa;
            d = b - a;
            e = d;
        }
        if fc.abs() < fb.abs() {
            a = b;
            b = c;
            c = a;
            fa = fb;
            fb = fc;
            fc = fa;
        }
        let tol = 2.0 * f64::EPSILON * b.abs() + 1e-300;
        let mid = 0.5 * (c - b);
        if mid.abs() <= tol {
            return b;
        }
        if e.abs() >= tol && fa.abs() > fb.abs() {
            let s = fb / fa;
            let (mut pp, mut qq);
            if a == c {
                pp = 2.0 * mid * s;
                qq = 1.0 - s;
            } else {
                let q0 = fa / fc;
                let r = fb / fc;
                pp = s * (2.0 * mid * q0 * (q0 - r) - (b - a) * (r - 1.0));
                qq = (q0 - 1.0) * (r - 1.0) * (s - 1.0);
            }
            if pp > 0.0 {
                qq = -qq;
            } else {
                pp = -pp;
            }
            if 2.0 * pp < (3.0 * mid * qq - (tol * qq).abs()).min((e * qq).abs()) {
                e = d;
                d = pp / qq;
            } else {
                d = mid;
                e = d;
            }
        } else {
            d = mid;
            e = d;
        }
        a = b;
        fa = fb;
        b += if d.abs() > tol { d } else { tol * mid.signum() };
        fb = f(b);
        if fb.is_nan() {
            return b;
        }
    }
    b
}

/// A root of `f` between `a` and `b`, where `f` changes sign, from values and slopes
/// (`f` returns both): Newton steps kept inside the bracket, which shrinks at every
/// evaluation, and a bisection wherever Newton would leave it or not halve the step
/// before last (safeguarded Newton, as `rtsafe` in Numerical Recipes). Ends once the
/// value at the last point evaluated is within `accept` of zero (then at the Newton step
/// from it, where that stays inside the bracket), the Newton step from it is below machine
/// precision in the argument, or the bracket is at machine precision (then at that point).
/// The first error of `f` ends the search and is returned.
pub(super) fn newton_bracketed<E>(
    (a, fa, sa): (f64, f64, f64),
    (b, fb, sb): (f64, f64, f64),
    accept: f64,
    mut f: impl FnMut(f64) -> Result<(f64, f64), E>,
) -> Result<f64, E> {
    let (mut lo, mut hi, mut f_lo) = if a < b { (a, b, fa) } else { (b, a, fb) };
    let (mut x, mut fx, mut sx) = if fa.abs() <= fb.abs() {
        (a, fa, sa)
    } else {
        (b, fb, sb)
    };
    let mut dx = hi - lo;
    let mut dx_old = dx;
    for _ in 0..200 {
        let newton = x - fx / sx;
        let eps = 2.0 * f64::EPSILON * x.abs();
        if fx.abs() <= accept {
            // The last Newton step, not evaluated: from a value this small it lands at
            // the root to the rounding of the value (its error is the value's times the
            // slope's relative error), where x is off by the value over the slope.
            return Ok(if newton > lo && newton < hi {
                newton
            } else {
                x
            });
        }
        if (newton - x).abs() <= eps || hi - lo <= 2.0 * eps {
            break;
        }
        let y = if newton > lo && newton < hi && (2.0 * fx).abs() <= (dx_old * sx).abs() {
            dx_old = dx;
            dx = (newton - x).abs();
            newton
        } else {
            dx_old = dx;
            dx = 0.5 * (hi - lo);
            lo + dx
        };
        if y == x || y <= lo || y >= hi {
            break;
        }
        (fx, sx) = f(y)?;
        x = y;
        if fx.is_nan() {
            break;
        }
        if (fx > 0.0) == (f_lo > 0.0) {
            (lo, f_lo) = (x, fx);
        } else {
            hi = x;
        }
    }
    Ok(x)
}

/// [`brent`] on a fallible `f`: the first error ends the search and is returned.
pub(super) fn brent_fallible<E>(
    a: f64,
    b: f64,
    fa: f64,
    fb: f64,
    mut f: impl FnMut(f64) -> Result<f64, E>,
) -> Result<f64, E> {
    let mut err = None;
    let r = brent(a, b, fa, fb, |x| match f(x) {
        Ok(v) => v,
        Err(e) => {
            err = Some(e);
            f64::NAN
        }
    });
    match err {
        Some(e) => Err(e),
        None => Ok(r),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn brent_finds_cubic_root() {
        let f = |x: f64| 2.0 - x * x * x;
        let r = brent(0.0, 2.0, f(0.0), f(2.0), f);
        assert!((r - 2f64.cbrt()).abs() < 4.0 * f64::EPSILON);
    }

    #[test]
    fn newton_bracketed_finds_roots() {
        // a smooth root, from either side, to machine precision
        let f = |x: f64| Ok::<_, ()>((2.0 - x * x * x, -3.0 * x * x));
        for (a, b) in [(0.0, 2.0), (2.0, 0.0)] {
            let (fa, sa) = f(a).unwrap();
            let (fb, sb) = f(b).unwrap();
            let r = newton_bracketed((a, fa, sa), (b, fb, sb), 0.0, f).unwrap();
            assert!((r - 2f64.cbrt()).abs() < 4.0 * f64::EPSILON, "{r}");
        }
        // a flat start (zero slope at both ends): bisection until Newton takes over
        let g = |x: f64| Ok::<_, ()>(((x - 0.3).powi(3), 3.0 * (x - 0.3).powi(2)));
        let (fa, fb) = (g(0.3 - 1.0).unwrap().0, g(0.3 + 2.0).unwrap().0);
        let r = newton_bracketed((-0.7, fa, 0.0), (2.3, fb, 0.0), 1e-30, g).unwrap();
        assert!((r - 0.3).abs() < 1e-10, "{r}");
        // the error of f is passed on
        let e = newton_bracketed((0.0, 1.0, -1.0), (2.0, -1.0, -1.0), 0.0, |_| {
            Err::<(f64, f64), _>(7)
        });
        assert_eq!(e, Err(7));
    }

    #[test]
    fn hermite_detects_dip() {
        // p(s) = (s - 0.5)^2 - 0.01 : values 0.24 at both ends, slopes -1 and +1, min -0.01
        assert!(hermite_min(0.24, 0.24, -1.0, 1.0) < -0.009);
        assert!(hermite_min(1.0, 2.0, 1.0, 1.0) >= 1.0);
    }
}
