//! B-spline basis functions and their derivatives (Piegl & Tiller A2.2, A2.3).

/// The `p + 1` non-zero basis functions `N_{span−p,p}(u) … N_{span,p}(u)` written into
/// `out[..=p]` (Piegl & Tiller A2.2). `left` and `right` are scratch of length `p + 1`.
#[inline(always)]
pub(crate) fn basis_funs_into(
    knots: &[f64],
    span: usize,
    u: f64,
    p: usize,
    out: &mut [f64],
    left: &mut [f64],
    right: &mut [f64],
) {
    out[0] = 1.0;
    for j in 1..=p {
        left[j] = u - knots[span + 1 - j];
        right[j] = knots[span + j] - u;
        let mut saved = 0.0;
        for r in 0..j {
            let temp = out[r] / (right[r + 1] + left[j - r]);
            out[r] = saved + right[r + 1] * temp;
            saved = left[j - r] * temp;
        }
        out[j] = saved;
    }
}

/// The non-zero basis functions at `u` in span `span` (Piegl & Tiller A2.2).
///
/// # Examples
///
/// ```
/// use cadmorph_nurbs::{basis_funs, KnotVector};
/// // The NURBS Book Ex. 2.3: U = {0,0,0,1,2,3,4,4,5,5,5}, p = 2, u = 5/2:
/// // N2,2 = 1/8, N3,2 = 6/8, N4,2 = 1/8.
/// let u = KnotVector::try_new(vec![0., 0., 0., 1., 2., 3., 4., 4., 5., 5., 5.]).unwrap();
/// let n = basis_funs(&u, 2, 2.5);
/// assert_eq!(n, vec![0.125, 0.75, 0.125]);
/// ```
pub fn basis_funs(knots: &crate::KnotVector, p: usize, u: f64) -> Vec<f64> {
    let span = knots.find_span(p, u);
    let mut out = vec![0.0; p + 1];
    let mut left = vec![0.0; p + 1];
    let mut right = vec![0.0; p + 1];
    basis_funs_into(knots.as_slice(), span, u, p, &mut out, &mut left, &mut right);
    out
}

/// Basis functions and their derivatives up to order `n` at `u` (Piegl & Tiller A2.3):
/// `ders[k][j]` is the `k`-th derivative of `N_{span−p+j,p}`. Derivatives above `p`
/// are zero.
///
/// # Examples
///
/// ```
/// use cadmorph_nurbs::{ders_basis_funs, KnotVector};
/// // The NURBS Book Ex. 2.4 at u = 5/2: N'2,2 = -1/2, N'3,2 = 0, N'4,2 = 1/2.
/// let u = KnotVector::try_new(vec![0., 0., 0., 1., 2., 3., 4., 4., 5., 5., 5.]).unwrap();
/// let d = ders_basis_funs(&u, 2, 2.5, 2);
/// assert_eq!(d[1], vec![-0.5, 0.0, 0.5]);
/// assert_eq!(d[2], vec![1.0, -2.0, 1.0]);
/// ```
pub fn ders_basis_funs(knots: &crate::KnotVector, p: usize, u: f64, n: usize) -> Vec<Vec<f64>> {
    let span = knots.find_span(p, u);
    let mut ders = vec![vec![0.0; p + 1]; n + 1];
    ders_basis_funs_into(knots.as_slice(), span, u, p, n, &mut ders);
    ders
}

/// A2.3 into a caller-provided table `ders[0..=n][0..=p]`.
pub(crate) fn ders_basis_funs_into(knots: &[f64], span: usize, u: f64, p: usize, n: usize, ders: &mut [Vec<f64>]) {
    let mut ndu = vec![vec![0.0; p + 1]; p + 1];
    let mut left = vec![0.0; p + 1];
    let mut right = vec![0.0; p + 1];
    ndu[0][0] = 1.0;
    for j in 1..=p {
        left[j] = u - knots[span + 1 - j];
        right[j] = knots[span + j] - u;
        let mut saved = 0.0;
        for r in 0..j {
            // Lower triangle: knot differences.
            ndu[j][r] = right[r + 1] + left[j - r];
            let temp = ndu[r][j - 1] / ndu[j][r];
            // Upper triangle: basis functions.
            ndu[r][j] = saved + right[r + 1] * temp;
            saved = left[j - r] * temp;
        }
        ndu[j][j] = saved;
    }
    for j in 0..=p {
        ders[0][j] = ndu[j][p];
    }
    for row in ders.iter_mut().skip(1) {
        row.iter_mut().for_each(|d| *d = 0.0);
    }
    let nmax = n.min(p);
    let mut a = [vec![0.0; p + 1], vec![0.0; p + 1]];
    for r in 0..=p {
        let (mut s1, mut s2) = (0usize, 1usize);
        a[0][0] = 1.0;
        for k in 1..=nmax {
            let mut d = 0.0;
            let rk = r as isize - k as isize;
            let pk = p - k;
            if r >= k {
                a[s2][0] = a[s1][0] / ndu[pk + 1][rk as usize];
                d = a[s2][0] * ndu[rk as usize][pk];
            }
            let j1 = if rk >= -1 { 1 } else { (-rk) as usize };
            let j2 = if (r as isize - 1) <= pk as isize { k - 1 } else { p - r };
            for j in j1..=j2 {
                let idx = (rk + j as isize) as usize;
                a[s2][j] = (a[s1][j] - a[s1][j - 1]) / ndu[pk + 1][idx];
                d += a[s2][j] * ndu[idx][pk];
            }
            if r <= pk {
                a[s2][k] = -a[s1][k - 1] / ndu[pk + 1][r];
                d += a[s2][k] * ndu[r][pk];
            }
            ders[k][r] = d;
            std::mem::swap(&mut s1, &mut s2);
        }
    }
    let mut factor = p as f64;
    for k in 1..=nmax {
        for j in 0..=p {
            ders[k][j] *= factor;
        }
        factor *= (p - k) as f64;
    }
}
