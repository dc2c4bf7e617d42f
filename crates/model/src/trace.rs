//! Curves traced on morphed faces, and refinement carried over to a face's B-spline form.

use cadmorph_morph::Deformation;
use cadmorph_nurbs::math::Point3;
use cadmorph_nurbs::{NurbsCurve, NurbsSurface, Surface};

/// Whether `d` moves any of `pts`.
pub(crate) fn moved_by(d: &dyn Deformation, pts: &[Point3<f64>]) -> bool {
    pts.iter().any(|p| d.deform_point(p) != *p)
}

/// What took `base` to `refined` in one direction: the degree raised by `t` (A5.9,
/// which raises every distinct knot's multiplicity by `t`) and the knots inserted after
/// that (A5.4), each with its multiplicity; `None` when `refined` is not such a
/// refinement of `base` (a knot lost or moved).
fn elevated_and_inserted(
    base: &cadmorph_nurbs::KnotVector,
    p: usize,
    refined: &cadmorph_nurbs::KnotVector,
    q: usize,
) -> Option<(usize, Vec<f64>)> {
    let t = q.checked_sub(p)?;
    let (from, from_mult) = base.distinct();
    let (to, to_mult) = refined.distinct();
    let close = |a: f64, b: f64| (a - b).abs() <= 1e-12 * (1.0 + a.abs());
    let mut out = Vec::new();
    let mut i = 0;
    for (&x, &m) in to.iter().zip(&to_mult) {
        let had = if i < from.len() && close(from[i], x) {
            i += 1;
            from_mult[i - 1] + t
        } else {
            0
        };
        out.extend(std::iter::repeat_n(x, m.checked_sub(had)?));
    }
    (i == from.len()).then_some((t, out))
}

/// `target` (another copy of `base`'s geometry: the same degrees and knots, such as the
/// B-spline an analytic face becomes) raised to `refined`'s degrees and given the knots
/// that took `base` to `refined` (elevation first, then insertion, as the refinement
/// was planned); `target` itself where `target` does not have `base`'s degrees and knots
/// or `refined` is not a refinement of `base`, so the same steps would not mean the same
/// there.
pub(crate) fn refined_like(base: &NurbsSurface, refined: &NurbsSurface, target: &NurbsSurface) -> NurbsSurface {
    let same = |a: &cadmorph_nurbs::KnotVector, b: &cadmorph_nurbs::KnotVector| {
        a.len() == b.len()
            && a.as_slice().iter().zip(b.as_slice()).all(|(x, y)| (x - y).abs() <= 1e-12 * (1.0 + x.abs()))
    };
    if base.u_degree() != target.u_degree()
        || base.v_degree() != target.v_degree()
        || !same(base.u_knots(), target.u_knots())
        || !same(base.v_knots(), target.v_knots())
    {
        return target.clone();
    }
    let (Some((tu, xu)), Some((tv, xv))) = (
        elevated_and_inserted(base.u_knots(), base.u_degree(), refined.u_knots(), refined.u_degree()),
        elevated_and_inserted(base.v_knots(), base.v_degree(), refined.v_knots(), refined.v_degree()),
    ) else {
        return target.clone();
    };
    let mut out = target.clone();
    let steps = (if tu > 0 { out.elevate_u_degree(tu) } else { Ok(()) })
        .and_then(|()| if tv > 0 { out.elevate_v_degree(tv) } else { Ok(()) })
        .and_then(|()| out.refine_u(&xu))
        .and_then(|()| out.refine_v(&xv));
    if steps.is_err() {
        return target.clone();
    }
    out
}

/// The curve `c`, lying on `before`, made to lie on `after` (the same face morphed, in the
/// same parameters): its control points moved by `d` where that stays within `tol` of
/// the face's image of the curve (always for affine maps and for iso-boundaries that
/// share the face's knots), else a cubic fit of that image within `tol`; when the fit
/// runs out of poles, the fit within 10 or 100 `tol` if that is nearer the face than the
/// moved control points, else those. `None` when neither works (the curve is left as it
/// is).
pub(crate) fn follow_face(
    c: &NurbsCurve,
    before: &NurbsSurface,
    after: &NurbsSurface,
    d: &dyn Deformation,
    tol: f64,
) -> Option<NurbsCurve> {
    use cadmorph_nurbs::Curve;
    let dom = c.domain();
    let (t0, t1) = (*dom.start(), *dom.end());
    let size = before.control_extent().max(1.0);
    let ptol = 1e-12 * size;
    let on_face = 1e-6 * size;
    // A curve along an iso-line of the face (a boundary, a rim) is that iso-line of the
    // morphed face, exactly: told from 33 samples, each projection started from the last.
    // The same samples tell how far the curve lies from the face (a true circle bounding a
    // faceted face is off it by the facets' sagitta).
    let mut probe: Vec<(f64, f64)> = Vec::with_capacity(33);
    let mut off_face: f64 = 0.0;
    for k in 0..=32 {
        let t = t0 + (t1 - t0) * k as f64 / 32.0;
        let pr = before.project_near(&c.eval(t), probe.last().copied(), ptol, on_face);
        off_face = off_face.max(pr.distance_sq.sqrt());
        probe.push((pr.u, pr.v));
    }
    if off_face <= on_face {
        if let Some(iso) = iso_trace(c, before, after, &probe) {
            return Some(iso);
        }
    }
    // A local projection (Newton from a nearby known answer) is kept when it lands within
    // the distance the curve keeps from the face (twice what the samples saw, as the curve
    // may stray further between them; at most 1 % of the face's size): a point of the face
    // as close as the curve's own offset is as good an image as the closest one, and the
    // global search (a sampling of the whole face) is left for where the walk is lost.
    // Without this every sample of a curve off the face by more than 1e-6 of its size
    // searched globally: a morph of PyGeM's pipe took 33 s.
    let accept = on_face.max((2.0 * off_face).min(1e-2 * size));
    // Parameters on the face, each search started from a nearby known answer.
    let uv = |t: f64, near: Option<(f64, f64)>| {
        let pr = before.project_near(&c.eval(t), near, ptol, accept);
        (pr.u, pr.v)
    };
    let spans = |(u, v): (f64, f64)| {
        (after.u_knots().find_span(after.u_degree(), u), after.v_knots().find_span(after.v_degree(), v))
    };
    let crossings = after.u_knots().len() + after.v_knots().len();
    let m = (8 * crossings).clamp(32, 1024);
    let ts: Vec<f64> = (0..=m).map(|k| t0 + (t1 - t0) * k as f64 / m as f64).collect();
    let mut uvs: Vec<(f64, f64)> = Vec::with_capacity(ts.len());
    for &t in &ts {
        let near = uvs.last().copied();
        uvs.push(uv(t, near));
    }
    // The image of the curve on the morphed face, each projection started from the
    // answer of the nearest of the `m + 1` samples (the fit asks for parameters in any
    // order).
    let image = |t: f64| {
        let k = (((t - t0) / (t1 - t0)) * m as f64).round().clamp(0.0, m as f64) as usize;
        let (u, v) = uv(t, Some(uvs[k]));
        after.eval(u, v)
    };
    let mut moved = c.clone();
    d.deform(moved.control_points_mut());
    let n = 8 * moved.control_points().len() + 1;
    let off = (0..n).map(|k| t0 + (t1 - t0) * k as f64 / (n - 1) as f64).map(|t| (moved.eval(t) - image(t)).norm());
    let moved_off = off.fold(0.0, f64::max);
    if moved_off <= tol {
        return Some(moved);
    }
    // The image bends where the curve crosses a knot line of the morphed face, as smooth
    // as the face is across that line (C^(p − m) across a knot of multiplicity m): break
    // the fit there with that continuity, so a trim stays C1 across the simple knots of a
    // quadratic face instead of gaining a C0 point where readers split it into edges.
    let mut breaks = Vec::new();
    // The face's distinct knots in each direction, read once for every crossing.
    let (u_knots, v_knots) = (after.u_knots().distinct(), after.v_knots().distinct());
    let smoothness = |(values, mults): &(Vec<f64>, Vec<usize>), degree: usize, a: f64, b: f64| -> usize {
        let (lo, hi) = (a.min(b), a.max(b));
        values
            .iter()
            .zip(mults)
            .filter(|(k, _)| **k > lo && **k <= hi)
            .map(|(_, m)| degree.saturating_sub(*m))
            .min()
            .unwrap_or(degree)
    };
    for k in 0..m {
        let cell = spans(uvs[k]);
        if cell == spans(uvs[k + 1]) {
            continue;
        }
        let (mut lo, mut hi) = (ts[k], ts[k + 1]);
        let mut near = uvs[k];
        let mut far = uvs[k + 1];
        for _ in 0..40 {
            let mid = 0.5 * (lo + hi);
            let at = uv(mid, Some(near));
            if spans(at) == cell {
                lo = mid;
                near = at;
            } else {
                hi = mid;
                far = at;
            }
        }
        let continuity = smoothness(&u_knots, after.u_degree(), near.0, far.0).min(smoothness(
            &v_knots,
            after.v_degree(),
            near.1,
            far.1,
        ));
        let at = 0.5 * (lo + hi);
        breaks.push(cadmorph_nurbs::FitBreak { at, continuity });
    }
    // The curve's own full knots: its image keeps there what the curve keeps (C1 at a
    // NURBS circle's quarter points, whose Cartesian derivative is continuous although
    // the knots are double; a kink or a change of speed elsewhere).
    breaks.extend(full_knots(c).into_iter().map(|at| cadmorph_nurbs::FitBreak { at, continuity: c1_at(c, at) }));
    // A cubic needs about (r / tol)^(1/4) spans per turn of a curve of radius r: a full
    // circle at 1e-7 of its size takes some 300 poles.
    let max_poles = 2048 + 64 * breaks.len();
    if let Ok((f, _)) = cadmorph_nurbs::fit_curve_with_breaks(image, (t0, t1), &breaks, 3, tol, max_poles) {
        return Some(f);
    }
    // Out of poles (a curve across a hundred knot lines of a refined face can need more
    // than the budget at 1e-7 of the size): the fit within ten, then a hundred times the
    // tolerance, when it is nearer the face than the moved control points (which follow
    // the morph, not the face: on a refined shaft they were 5e-5 m off a fillet where
    // the fit reached 1.2e-7).
    for loose in [10.0 * tol, 100.0 * tol] {
        if let Ok((f, dev)) = cadmorph_nurbs::fit_curve_with_breaks(image, (t0, t1), &breaks, 3, loose, max_poles) {
            if dev < moved_off {
                return Some(f);
            }
        }
    }
    Some(moved)
}

/// 1 when `c`'s first derivatives on the two sides of its knot `at` agree (within 1e-9
/// of their length: the Cartesian curve is C1 there), else 0.
fn c1_at(c: &NurbsCurve, at: f64) -> usize {
    use cadmorph_nurbs::Curve;
    let Ok((left, right)) = c.split(at) else { return 0 };
    let (l, r) = (left.derivs(at, 1), right.derivs(at, 1));
    let (dl, dr) = (l[1], r[1]);
    usize::from((dl - dr).norm() <= 1e-9 * dl.norm().max(dr.norm()) && dl.norm() > 0.0)
}

/// The interior knots of `c` of full multiplicity (at least its degree): where the curve
/// may turn its speed or direction (a rational circle's quarter points), so where a fit of
/// its image is broken.
pub(crate) fn full_knots(c: &NurbsCurve) -> Vec<f64> {
    use cadmorph_nurbs::Curve;
    let dom = c.domain();
    let (t0, t1) = (*dom.start(), *dom.end());
    let (values, mults) = c.knots().distinct();
    values.iter().zip(&mults).filter(|(k, m)| **m >= c.degree() && **k > t0 && **k < t1).map(|(k, _)| *k).collect()
}

/// When the face parameters `uvs` of samples along `c` (evenly spaced in its parameter)
/// keep `u` (or `v`) constant and run monotonically in the other, the part of `after`'s
/// iso-curve there, running the way `c` runs (the whole iso-curve for a closed `c`).
/// `None` when `c` is not along an iso-line.
fn iso_trace(c: &NurbsCurve, before: &NurbsSurface, after: &NurbsSurface, uvs: &[(f64, f64)]) -> Option<NurbsCurve> {
    use cadmorph_nurbs::Curve;
    if uvs.len() < 5 {
        return None;
    }
    let (ud, vd) = before.domain();
    let (su, sv) = (ud.end() - ud.start(), vd.end() - vd.start());
    let eps = 1e-9;
    let u_const = uvs.iter().all(|q| (q.0 - uvs[0].0).abs() <= eps * su);
    let v_const = uvs.iter().all(|q| (q.1 - uvs[0].1).abs() <= eps * sv);
    let (iso, along, span) = match (u_const, v_const) {
        (true, false) => (after.u_iso(uvs[0].0), uvs.iter().map(|q| q.1).collect::<Vec<_>>(), sv),
        (false, true) => (after.v_iso(uvs[0].1), uvs.iter().map(|q| q.0).collect::<Vec<_>>(), su),
        _ => return None,
    };
    let d = c.domain();
    let closed =
        (c.eval(*d.start()) - c.eval(*d.end())).norm() <= 1e-9 * c.bounding_box().diagonal().max(f64::MIN_POSITIVE);
    let n = along.len();
    let dom = iso.domain();
    let (lo_dom, hi_dom) = (*dom.start(), *dom.end());
    let (a, b) = if closed {
        // A closed curve's ends may land on either side of the iso-curve's seam: the
        // direction from the middle samples, the whole iso-curve.
        let forward = along[n / 2] > along[n / 4];
        let interior = &along[n / 8..n - n / 8];
        let mono = interior.windows(2).all(|w| if forward { w[1] >= w[0] } else { w[1] <= w[0] });
        if !mono || (hi_dom - lo_dom - span).abs() > eps * span {
            return None;
        }
        if forward {
            (lo_dom, hi_dom)
        } else {
            (hi_dom, lo_dom)
        }
    } else {
        let forward = along[n - 1] > along[0];
        if !along.windows(2).all(|w| if forward { w[1] >= w[0] } else { w[1] <= w[0] }) {
            return None;
        }
        (along[0], along[n - 1])
    };
    // An end within rounding of a knot of the iso-curve (a knot line of a refined face
    // through the curve's end) is that knot: a split a few ulps beside it would leave a
    // span of zero length, which readers refuse.
    let knots = iso.knots().distinct().0;
    let snap = |x: f64| knots.iter().copied().find(|k| (k - x).abs() <= eps * span).unwrap_or(x);
    let (a, b) = (snap(a), snap(b));
    let (lo, hi) = (a.min(b), a.max(b));
    if hi - lo <= eps * span {
        return None;
    }
    let mut seg = iso;
    if lo > lo_dom + eps * span {
        seg = seg.split(lo).ok()?.1;
    }
    if hi < hi_dom - eps * span {
        seg = seg.split(hi).ok()?.0;
    }
    Some(if a > b { seg.reversed() } else { seg })
}

#[cfg(test)]
mod tests {
    use super::*;
    use cadmorph_morph::from_fn;
    use cadmorph_nurbs::{Curve, KnotVector, SurfaceProject};

    const R: f64 = 1000.0;

    /// A quarter cylinder of radius 1000 faceted into 30 flat strips (degree 1 × 1, as
    /// PyGeM's `test_pipe_out_true.step`) and its exact quarter circle at height 400
    /// (rational quadratic): the circle is off the facets by up to their sagitta, 0.086,
    /// some 6e-5 of the face's size, as an exporter's exact edge curve bounds a faceted face.
    fn faceted_face_and_circle() -> (NurbsSurface, NurbsCurve) {
        let n = 30;
        let mut poles = Vec::new();
        for i in 0..=n {
            let a = std::f64::consts::FRAC_PI_2 * i as f64 / n as f64;
            for z in [0.0, 500.0, 1000.0] {
                poles.push(Point3::new(R * a.cos(), R * a.sin(), z));
            }
        }
        let mut uk = vec![0.0, 0.0];
        uk.extend((1..n).map(|i| i as f64 / n as f64));
        uk.extend([1.0, 1.0]);
        let face = NurbsSurface::new(
            (1, 1),
            (KnotVector::try_new(uk).unwrap(), KnotVector::try_new(vec![0.0, 0.0, 0.5, 1.0, 1.0]).unwrap()),
            (n + 1, 3),
            poles,
            None,
        );
        let circle = NurbsCurve::new(
            2,
            KnotVector::try_new(vec![0.0, 0.0, 0.0, 1.0, 1.0, 1.0]).unwrap(),
            vec![Point3::new(R, 0.0, 400.0), Point3::new(R, R, 400.0), Point3::new(0.0, R, 400.0)],
            Some(vec![1.0, std::f64::consts::FRAC_1_SQRT_2, 1.0]),
        );
        (face, circle)
    }

    #[test]
    fn a_curve_off_its_faceted_face_is_traced_by_local_projections() {
        let (before, c) = faceted_face_and_circle();
        let d = from_fn(|p: &Point3<f64>| Point3::new(p.x, p.y + 20.0 * (p.x / 300.0).sin(), p.z + 2e-5 * p.x * p.y));
        let mut after = before.clone();
        d.deform(after.control_points_mut());
        let size = before.control_extent();
        let tol = 1e-7 * size;
        let traced = follow_face(&c, &before, &after, &d, tol).expect("traced");
        // The image through the closest point of the whole face (the global search):
        // the traced curve follows it within the fit's tolerance.
        let global = |t: f64| {
            let pr = before.project(&c.eval(t), 1e-12 * size);
            after.eval(pr.u, pr.v)
        };
        let worst =
            (0..=400).map(|k| k as f64 / 400.0).map(|t| (traced.eval(t) - global(t)).norm()).fold(0.0, f64::max);
        assert!(worst <= 2.0 * tol, "traced curve off the morphed face's image by {worst:e} (tol {tol:e})");
        // Its speed (local projections instead of a global search per sample: PyGeM's
        // pipe under fuzz_small.prm 32.7 s -> 0.5 s) is a benchmark's to show, not a test's.
    }
}
