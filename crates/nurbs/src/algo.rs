//! Knot insertion, refinement, removal and degree elevation on homogeneous control
//! points (Piegl & Tiller A5.1, A5.4, A5.8, A5.9).
//!
//! Everything here works on one row of homogeneous points `Pw = (w·x, w·y, w·z, w)`;
//! curves call it once, surfaces once per row or column. Non-rational splines pass
//! `w = 1`, so one code path serves both.
//!
//! The loops follow the book's pseudocode line by line so each can be checked against
//! it; clippy's slice-copy and counter-loop rewrites would hide that correspondence.
#![allow(clippy::manual_memcpy, clippy::explicit_counter_loop)]

use nalgebra::Vector4;

pub(crate) type Hom = Vector4<f64>;

/// Index `k` of the last knot `≤ u`, and the multiplicity `s` of `u` (exact equality).
pub(crate) fn insertion_span(knots: &[f64], u: f64) -> (usize, usize) {
    let count_le = knots.partition_point(|&k| k <= u);
    let s = knots[..count_le].iter().rev().take_while(|&&k| k == u).count();
    (count_le.saturating_sub(1), s)
}

/// A5.1: inserts `u` `r` times (caller ensures `r + s ≤ p` and `u` inside the domain).
pub(crate) fn insert_knot(
    p: usize,
    knots: &[f64],
    pw: &[Hom],
    u: f64,
    k: usize,
    s: usize,
    r: usize,
) -> (Vec<f64>, Vec<Hom>) {
    let np = pw.len() - 1;
    let mp = np + p + 1;
    let mut uq = Vec::with_capacity(knots.len() + r);
    uq.extend_from_slice(&knots[..=k]);
    uq.extend(std::iter::repeat_n(u, r));
    uq.extend_from_slice(&knots[k + 1..=mp]);
    let mut qw = vec![Hom::zeros(); np + r + 1];
    qw[..=k - p].copy_from_slice(&pw[..=k - p]);
    for i in k - s..=np {
        qw[i + r] = pw[i];
    }
    let mut rw: Vec<Hom> = (0..=p - s).map(|i| pw[k - p + i]).collect();
    let mut l = k - p;
    for j in 1..=r {
        l = k - p + j;
        for i in 0..=p - j - s {
            let alpha = (u - knots[l + i]) / (knots[i + k + 1] - knots[l + i]);
            rw[i] = rw[i + 1] * alpha + rw[i] * (1.0 - alpha);
        }
        qw[l] = rw[0];
        qw[k + r - j - s] = rw[p - j - s];
    }
    for i in l + 1..k - s {
        qw[i] = rw[i - l];
    }
    (uq, qw)
}

/// A5.1 extended to multiplicity `p + 1`: inserts `u` `r` times where `s + r` may
/// reach `p + 1` (caller ensures `s + r ≤ p + 1` and `u` strictly inside the domain).
///
/// Up to multiplicity `p` this is [`insert_knot`]. The last copy, taking `u` from
/// multiplicity `p` to `p + 1`, has no affine combination left to form: with `k'` the
/// index of the last copy of `u`, every `αᵢ` of (5.15) for `k' − p + 1 ≤ i ≤ k' − p`
/// is absent, so the new net is the old one with `Pw_{k'−p}` (the point `C(u)`)
/// doubled. The basis then splits at `u` into two independent pieces (C⁻¹ there), as
/// in geomdl's `insert_knot` and Splipy's `insert_knot` at full multiplicity.
pub(crate) fn insert_knot_full(
    p: usize,
    knots: &[f64],
    pw: &[Hom],
    u: f64,
    k: usize,
    s: usize,
    r: usize,
) -> (Vec<f64>, Vec<Hom>) {
    if s + r <= p {
        return insert_knot(p, knots, pw, u, k, s, r);
    }
    let smooth = p - s;
    let (mut uq, mut qw) =
        if smooth > 0 { insert_knot(p, knots, pw, u, k, s, smooth) } else { (knots.to_vec(), pw.to_vec()) };
    let last = k + smooth;
    uq.insert(last + 1, u);
    let on_curve = qw[last - p];
    qw.insert(last - p + 1, on_curve);
    (uq, qw)
}

/// The first control point of each Bézier segment of a spline whose interior knots
/// all have multiplicity `p` or `p + 1` (after the refinement of A5.6): segment `i`
/// over `[values[i], values[i + 1]]` starts at control point `kᵢ − p`, `kᵢ` the last
/// index of `values[i]` in `knots`. Counting `i·p` would go wrong after a knot of
/// multiplicity `p + 1`, where the segments do not share an end point.
pub(crate) fn bezier_starts(p: usize, knots: &[f64], values: &[f64]) -> Vec<usize> {
    values[..values.len() - 1].iter().map(|&v| knots.partition_point(|&k| k <= v) - 1 - p).collect()
}

/// One step of knot refinement (A5.4), the same for every row of a net: the
/// coefficients depend on the knots and the inserted values only.
#[derive(Debug, Clone, Copy)]
pub(crate) enum RefineStep {
    /// `new[dst] = old[src]`.
    Old { dst: usize, src: usize },
    /// `new[dst] = new[src]`.
    New { dst: usize, src: usize },
    /// `new[dst] = alfa · new[dst] + (1 − alfa) · new[dst + 1]`.
    Blend { dst: usize, alfa: f64 },
}

/// The plan of A5.4 for inserting all of `x` (sorted, inside the domain) into `knots`
/// (degree `p`, `n + 1` control points): the refined knot vector and the steps that make
/// the `n + r + 2` new control points from the old ones, in order. Piegl & Tiller A5.4
/// with the point updates recorded instead of done, so that a surface (A5.5) computes
/// the coefficients once for all its rows.
pub(crate) fn refine_plan(p: usize, knots: &[f64], n: usize, x: &[f64]) -> (Vec<f64>, Vec<RefineStep>) {
    use RefineStep::{Blend, New, Old};
    let m = n + p + 1;
    let r = x.len() - 1;
    let a = crate::knots::find_span(knots, p, x[0]);
    let b = crate::knots::find_span(knots, p, x[r]) + 1;
    let mut steps = Vec::with_capacity(n + 2 + (r + 1) * (p + 2));
    let mut ub = vec![0.0; m + r + 2];
    steps.extend((0..=a - p).map(|j| Old { dst: j, src: j }));
    steps.extend((b - 1..=n).map(|j| Old { dst: j + r + 1, src: j }));
    ub[..=a].copy_from_slice(&knots[..=a]);
    for j in b + p..=m {
        ub[j + r + 1] = knots[j];
    }
    let mut i = b + p - 1;
    let mut k = b + p + r;
    for j in (0..=r).rev() {
        while x[j] <= knots[i] && i > a {
            steps.push(Old { dst: k - p - 1, src: i - p - 1 });
            ub[k] = knots[i];
            k -= 1;
            i -= 1;
        }
        steps.push(New { dst: k - p - 1, src: k - p });
        for l in 1..=p {
            let ind = k - p + l;
            let alfa = ub[k + l] - x[j];
            if alfa.abs() == 0.0 {
                steps.push(New { dst: ind - 1, src: ind });
            } else {
                steps.push(Blend { dst: ind - 1, alfa: alfa / (ub[k + l] - knots[i + l - p]) });
            }
        }
        ub[k] = x[j];
        k -= 1;
    }
    (ub, steps)
}

/// Runs a [`refine_plan`] on blocks of `width` values: control point `i` of the old
/// row is `old[i·width .. (i+1)·width]`, and likewise in `new` (of `n + r + 2` blocks).
/// A block may hold one homogeneous point, or a whole column of a net (all its rows at
/// once, contiguous: what A5.5 loops over, here in one pass the compiler vectorises).
pub(crate) fn run_plan(steps: &[RefineStep], old: &[f64], new: &mut [f64], width: usize) {
    for step in steps {
        match *step {
            RefineStep::Old { dst, src } => {
                new[dst * width..(dst + 1) * width].copy_from_slice(&old[src * width..(src + 1) * width]);
            }
            RefineStep::New { dst, src } => new.copy_within(src * width..(src + 1) * width, dst * width),
            RefineStep::Blend { dst, alfa } => {
                let (lo, hi) = new[dst * width..(dst + 2) * width].split_at_mut(width);
                let beta = 1.0 - alfa;
                for (q, &h) in lo.iter_mut().zip(hi.iter()) {
                    *q = *q * alfa + h * beta;
                }
            }
        }
    }
}

/// A5.4: inserts all of `x` (sorted, inside the domain) at once.
pub(crate) fn refine(p: usize, knots: &[f64], pw: &[Hom], x: &[f64]) -> (Vec<f64>, Vec<Hom>) {
    if x.is_empty() {
        return (knots.to_vec(), pw.to_vec());
    }
    let n = pw.len() - 1;
    let (ub, steps) = refine_plan(p, knots, n, x);
    let old: Vec<f64> = pw.iter().flat_map(|h| h.iter().copied()).collect();
    let mut new = vec![0.0; (n + x.len() + 1) * 4];
    run_plan(&steps, &old, &mut new, 4);
    (ub, new.chunks_exact(4).map(|c| Hom::new(c[0], c[1], c[2], c[3])).collect())
}

/// A5.8 on several rows at once: removes the knot `knots[r]` (last copy of its value,
/// multiplicity `s`) up to `num` times while every row stays within `tol` (homogeneous
/// distance). Returns the number of removals `t` and edits `knots` and `rows` in place.
pub(crate) fn remove_knot(
    p: usize,
    knots: &mut Vec<f64>,
    rows: &mut [Vec<Hom>],
    r: usize,
    s: usize,
    num: usize,
    tol: f64,
) -> usize {
    if s > p {
        // Multiplicity p + 1: the spline is two pieces whose end points Pw[r−p−1] and
        // Pw[r−p] are both C(u) when it is continuous there (the inverse of the last
        // step of [`insert_knot_full`]). One copy goes if they agree within `tol`;
        // the midpoint replaces both, so nothing moves by more than half their gap.
        let too_far = |pw: &Vec<Hom>| {
            let gap = (pw[r - p - 1] - pw[r - p]).norm();
            gap.is_nan() || gap > tol
        };
        if num == 0 || rows.iter().any(too_far) {
            return 0;
        }
        for pw in rows.iter_mut() {
            pw[r - p - 1] = (pw[r - p - 1] + pw[r - p]) * 0.5;
            pw.remove(r - p);
        }
        knots.remove(r);
        return 1 + remove_knot(p, knots, rows, r - 1, p, num - 1, tol);
    }
    let n = rows[0].len() - 1;
    let m = n + p + 1;
    let u = knots[r];
    let ord = p + 1;
    let fout = (2 * r - s - p) / 2;
    let mut first = r - p;
    let mut last = r - s;
    let mut t = 0;
    let mut temps: Vec<Vec<Hom>> = vec![vec![Hom::zeros(); 2 * p + 1]; rows.len()];
    while t < num {
        let off = first - 1;
        let mut ok = true;
        for (pw, temp) in rows.iter().zip(temps.iter_mut()) {
            temp[0] = pw[off];
            temp[last + 1 - off] = pw[last + 1];
            let (mut i, mut j) = (first, last);
            let (mut ii, mut jj) = (1usize, last - off);
            while j as isize - i as isize > t as isize {
                let alfi = (u - knots[i]) / (knots[i + ord + t] - knots[i]);
                let alfj = (u - knots[j - t]) / (knots[j + ord] - knots[j - t]);
                temp[ii] = (pw[i] - temp[ii - 1] * (1.0 - alfi)) / alfi;
                temp[jj] = (pw[j] - temp[jj + 1] * alfj) / (1.0 - alfj);
                i += 1;
                ii += 1;
                j -= 1;
                jj -= 1;
            }
            let dist = if j < i + t {
                (temp[ii - 1] - temp[jj + 1]).norm()
            } else {
                let alfi = (u - knots[i]) / (knots[i + ord + t] - knots[i]);
                (pw[i] - (temp[ii + t + 1] * alfi + temp[ii - 1] * (1.0 - alfi))).norm()
            };
            if dist.is_nan() || dist > tol {
                ok = false;
                break;
            }
        }
        if !ok {
            break;
        }
        for (pw, temp) in rows.iter_mut().zip(temps.iter()) {
            let (mut i, mut j) = (first, last);
            while j as isize - i as isize > t as isize {
                pw[i] = temp[i - off];
                pw[j] = temp[j - off];
                i += 1;
                j -= 1;
            }
        }
        first -= 1;
        last += 1;
        t += 1;
    }
    if t == 0 {
        return 0;
    }
    for k in r + 1..=m {
        knots[k - t] = knots[k];
    }
    knots.truncate(m + 1 - t);
    for pw in rows.iter_mut() {
        let mut j = fout;
        let mut i = j;
        for k in 1..t {
            if k % 2 == 1 {
                i += 1;
            } else {
                j -= 1;
            }
        }
        for k in i + 1..=n {
            pw[j] = pw[k];
            j += 1;
        }
        pw.truncate(n + 1 - t);
    }
    t
}

fn binomial(n: usize, k: usize) -> f64 {
    if k > n {
        return 0.0;
    }
    let k = k.min(n - k);
    let mut b = 1.0;
    for i in 0..k {
        b = b * (n - i) as f64 / (i + 1) as f64;
    }
    b
}

/// A5.9: raises the degree of a clamped spline from `p` to `p + t`.
pub(crate) fn elevate_degree(p: usize, knots: &[f64], pw: &[Hom], t: usize) -> (Vec<f64>, Vec<Hom>) {
    if t == 0 {
        return (knots.to_vec(), pw.to_vec());
    }
    let n = pw.len() - 1;
    let m = n + p + 1;
    let ph = p + t;
    let ph2 = ph / 2;
    // Bézier degree-elevation coefficients.
    let mut bezalfs = vec![vec![0.0; p + 1]; ph + 1];
    bezalfs[0][0] = 1.0;
    bezalfs[ph][p] = 1.0;
    for i in 1..=ph2 {
        let inv = 1.0 / binomial(ph, i);
        let mpi = p.min(i);
        for j in i.saturating_sub(t)..=mpi {
            bezalfs[i][j] = inv * binomial(p, j) * binomial(t, i - j);
        }
    }
    for i in ph2 + 1..ph {
        let mpi = p.min(i);
        for j in i.saturating_sub(t)..=mpi {
            bezalfs[i][j] = bezalfs[ph - i][p - j];
        }
    }
    // Upper bound on the output size: every distinct interior knot gains t copies.
    let distinct = {
        let mut d = 1;
        for w in knots.windows(2) {
            if w[1] != w[0] {
                d += 1;
            }
        }
        d
    };
    let cap = pw.len() + distinct * t + t + 1;
    let mut qw = vec![Hom::zeros(); cap];
    let mut uh = vec![0.0; cap + ph + 1];
    let mut bpts = vec![Hom::zeros(); p + 1];
    let mut ebpts = vec![Hom::zeros(); ph + 1];
    let mut next_bpts = vec![Hom::zeros(); p.saturating_sub(1).max(1)];
    let mut alfs = vec![0.0; p.saturating_sub(1).max(1)];

    let mut mh = ph;
    let mut kind = ph + 1;
    let mut r: isize = -1;
    let mut a = p;
    let mut b = p + 1;
    let mut cind = 1;
    let mut ua = knots[0];
    qw[0] = pw[0];
    for x in uh.iter_mut().take(ph + 1) {
        *x = ua;
    }
    bpts.copy_from_slice(&pw[..=p]);
    while b < m {
        let i0 = b;
        while b < m && knots[b] == knots[b + 1] {
            b += 1;
        }
        let mul = b - i0 + 1;
        mh += mul + t;
        let ub = knots[b];
        let oldr = r;
        r = p as isize - mul as isize;
        let lbz = if oldr > 0 { ((oldr + 2) / 2) as usize } else { 1 };
        let rbz = if r > 0 { ph - ((r + 1) / 2) as usize } else { ph };
        if r > 0 {
            let numer = ub - ua;
            let mut k = p;
            while k > mul {
                alfs[k - mul - 1] = numer / (knots[a + k] - ua);
                k -= 1;
            }
            for j in 1..=r as usize {
                let save = r as usize - j;
                let s = mul + j;
                let mut k = p;
                while k >= s {
                    bpts[k] = bpts[k] * alfs[k - s] + bpts[k - 1] * (1.0 - alfs[k - s]);
                    k -= 1;
                }
                next_bpts[save] = bpts[p];
            }
        }
        for i in lbz..=ph {
            let mut e = Hom::zeros();
            let mpi = p.min(i);
            for j in i.saturating_sub(t)..=mpi {
                e += bpts[j] * bezalfs[i][j];
            }
            ebpts[i] = e;
        }
        if oldr > 1 {
            let mut first = kind - 2;
            let mut last = kind;
            let den = ub - ua;
            let bet = (ub - uh[kind - 1]) / den;
            for tr in 1..oldr as usize {
                let mut i = first;
                let mut j = last;
                let mut kj = j as isize - kind as isize + 1;
                while j - i > tr {
                    if i < cind {
                        let alf = (ub - uh[i]) / (ua - uh[i]);
                        qw[i] = qw[i] * alf + qw[i - 1] * (1.0 - alf);
                    }
                    if j >= lbz {
                        let kju = kj as usize;
                        if (j as isize - tr as isize) <= kind as isize - ph as isize + oldr {
                            let gam = (ub - uh[j - tr]) / den;
                            ebpts[kju] = ebpts[kju] * gam + ebpts[kju + 1] * (1.0 - gam);
                        } else {
                            ebpts[kju] = ebpts[kju] * bet + ebpts[kju + 1] * (1.0 - bet);
                        }
                    }
                    i += 1;
                    j -= 1;
                    kj -= 1;
                }
                first -= 1;
                last += 1;
            }
        }
        if a != p {
            for _ in 0..(ph as isize - oldr) as usize {
                uh[kind] = ua;
                kind += 1;
            }
        }
        for j in lbz..=rbz {
            qw[cind] = ebpts[j];
            cind += 1;
        }
        if b < m {
            for j in 0..r.max(0) as usize {
                bpts[j] = next_bpts[j];
            }
            for j in r.max(0) as usize..=p {
                bpts[j] = pw[b - p + j];
            }
            a = b;
            b += 1;
            ua = ub;
        } else {
            for i in 0..=ph {
                uh[kind + i] = ub;
            }
        }
    }
    let nh = mh - ph - 1;
    qw.truncate(nh + 1);
    uh.truncate(nh + ph + 2);
    (uh, qw)
}
