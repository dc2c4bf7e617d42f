//! Unclamping a spline onto chosen outer knots (Piegl & Tiller A12.1, generalised),
//! and the knot vector that degree elevation gives an unclamped spline.
//!
//! Degree elevation (A5.9) works on clamped splines. An unclamped one, periodic ones
//! in particular, is clamped, elevated, and then unclamped again onto outer knots that
//! continue its own: every run of equal knots outside the domain gains the same `t`
//! copies as the interior ones, so a periodic spline of degree `p` comes back as the
//! periodic spline of degree `p + t` whose knot vector is
//! [`KnotVector::periodic`](crate::KnotVector::periodic) with every multiplicity
//! raised by `t`, and whose first `p + t` control points repeat at the end.
//!
//! A12.1 sets the outer knots to the periodic continuation of the interior ones. The
//! version here takes the outer knots from a target vector instead; the recurrences
//! are the book's (the inverse of inserting the end knot), which do not depend on the
//! values the outer knots take as long as they are non-decreasing and do not pass the
//! domain ends.

use crate::algo::Hom;

/// The knot vector of degree `p + t` with the interior of `clamped` (the A5.9 output,
/// domain ends of multiplicity `p + t + 1`) and outer knots continuing those of the
/// original unclamped vector `original` of degree `p`: the runs of equal knots among
/// `original[..=p]` and `original[m − p..]`, each lengthened by `t`, nearest first.
pub(crate) fn elevated_outer_knots(p: usize, original: &[f64], t: usize, clamped: &[f64]) -> Vec<f64> {
    let q = p + t;
    let mut target = clamped.to_vec();
    let len = target.len();
    let m = original.len() - 1;
    // Left end: runs of original[..=p], from u_p outwards.
    let left = lengthened_runs(original[..=p].iter().rev().copied(), t, q + 1);
    for (i, &v) in left.iter().enumerate() {
        target[q - i] = v;
    }
    // Right end: runs from the first copy of u_{m−p} outwards (a periodic vector in
    // the OCCT form keeps the end knot's copies before index m − p).
    let first_b = original.partition_point(|&k| k < original[m - p]);
    let right = lengthened_runs(original[first_b..].iter().copied(), t, q + 1);
    for (i, &v) in right.iter().enumerate() {
        target[len - 1 - q + i] = v;
    }
    target
}

/// The first `count` values of `knots` (a monotone run from a domain end outwards)
/// with every run of equal values lengthened by `t`. Past the end of `knots` the last
/// value repeats.
fn lengthened_runs(knots: impl Iterator<Item = f64>, t: usize, count: usize) -> Vec<f64> {
    let mut out: Vec<f64> = Vec::with_capacity(count + t);
    let mut previous: Option<f64> = None;
    for k in knots {
        if previous != Some(k) {
            out.extend(std::iter::repeat_n(k, t));
            previous = Some(k);
        }
        out.push(k);
        if out.len() >= count {
            break;
        }
    }
    let last = *out.last().expect("a domain end is always there");
    out.resize(count, last);
    out
}

/// Unclamps the degree-`q` spline (`clamped`, `pw`), whose ends have multiplicity
/// `q + 1`, onto `target`, a knot vector of the same length that agrees with `clamped`
/// from index `q` to index `len − q − 1` (the domain and its interior). Returns the
/// control points on `target`; the spline on the domain is unchanged.
///
/// Piegl & Tiller A12.1, left end then right end, with the new outer knots taken from
/// `target` rather than from the periodic continuation.
pub(crate) fn unclamp(q: usize, clamped: &[f64], pw: &[Hom], target: &[f64]) -> Vec<Hom> {
    let mut pw = pw.to_vec();
    let mut u = clamped.to_vec();
    let n = pw.len() - 1;
    if q >= 2 {
        for i in 0..=q - 2 {
            u[q - i - 1] = target[q - i - 1];
            let mut k = q - 1;
            for j in (0..=i).rev() {
                let num = u[q] - u[k];
                if num != 0.0 {
                    let alfa = num / (u[q + j + 1] - u[k]);
                    pw[j] = (pw[j] - pw[j + 1] * alfa) / (1.0 - alfa);
                }
                k -= 1;
            }
        }
        for i in 0..=q - 2 {
            u[n + i + 2] = target[n + i + 2];
            for j in (0..=i).rev() {
                let num = u[n + 1] - u[n - j];
                let den = u[n - j + i + 2] - u[n - j];
                if num != den {
                    let alfa = num / den;
                    pw[n - j] = (pw[n - j] - pw[n - j - 1] * (1.0 - alfa)) / alfa;
                }
            }
        }
    }
    pw
}

/// Degree elevation of an unclamped spline of degree `p` by `t`: clamp, A5.9, unclamp
/// onto [`elevated_outer_knots`]. If `knots` is the periodic form that
/// [`KnotVector::periodic`](crate::KnotVector::periodic) builds, the result is that
/// form again for degree `p + t` with every multiplicity raised by `t`: the knot
/// vector is lengthened at the end by knots whose basis functions vanish on the
/// domain, and their control points repeat those one period earlier.
pub(crate) fn elevate_unclamped(p: usize, knots: &[f64], pw: &[Hom], t: usize) -> (Vec<f64>, Vec<Hom>) {
    let (ck, cp) = crate::curve::clamp_hom(p, knots, pw);
    let (ek, ep) = crate::algo::elevate_degree(p, &ck, &cp, t);
    let target = elevated_outer_knots(p, knots, t, &ek);
    let mut qw = unclamp(p + t, &ek, &ep, &target);
    let Some((values, mults)) = periodic_form(p, knots) else { return (target, qw) };
    let raised: Vec<usize> = mults.iter().map(|m| m + t).collect();
    let Ok(full) = crate::KnotVector::periodic(p + t, &values, &raised) else { return (target, qw) };
    let full = full.into_vec();
    let q = p + t;
    let per_period = full.len() - 2 * q - 1;
    let same_prefix = full.len() >= target.len() && full[..target.len()] == target[..];
    let n_full = full.len() - q - 1;
    if !same_prefix || per_period == 0 || per_period > qw.len() {
        return (target, qw);
    }
    while qw.len() < n_full {
        let wrapped = qw[qw.len() - per_period];
        qw.push(wrapped);
    }
    (full, qw)
}

/// The distinct knots of one period and their multiplicities if `knots` is exactly
/// the vector [`KnotVector::periodic`](crate::KnotVector::periodic) builds from them
/// for degree `p`.
fn periodic_form(p: usize, knots: &[f64]) -> Option<(Vec<f64>, Vec<usize>)> {
    let m = knots.len() - 1;
    let (a, b) = (knots[p], knots[m - p]);
    let mut values: Vec<f64> = Vec::new();
    let mut mults: Vec<usize> = Vec::new();
    for &k in knots.iter().filter(|&&k| k >= a && k <= b) {
        if values.last() == Some(&k) {
            *mults.last_mut().expect("pushed with the value") += 1;
        } else {
            values.push(k);
            mults.push(1);
        }
    }
    let rebuilt = crate::KnotVector::periodic(p, &values, &mults).ok()?;
    let close = rebuilt.len() == knots.len()
        && rebuilt.as_slice().iter().zip(knots).all(|(x, y)| (x - y).abs() <= 1e-12 * (1.0 + (b - a).abs()));
    close.then_some((values, mults))
}
