//! A trimmed face's bound curves chained into closed loops, for writing it in the other
//! format ([`cadmorph_brep::BoundedFace`]).
//!
//! The documents give a face's bound curves (IGES 142 model curves and their 102 pieces,
//! 504 edges of 508 loops, STEP `EDGE_CURVE`s of `EDGE_LOOP`s) as model-space curves with
//! the part of each that bounds the face. Here each is cut to that part, the pieces are
//! chained end to start into closed loops (nearest end first, within the chaining
//! tolerance; the two ends at a joint are made one point), and each loop is measured in
//! the surface's parameters by its signed area (the shoelace formula over points
//! projected onto the surface): the loop of largest area is the outer one and runs
//! counterclockwise around the face normal, the others are holes and run clockwise.
//!
//! On a closed surface (a cylinder, a torus, a surface of revolution) the written
//! surface is a clamped B-spline whose domain has a seam line, and a face's loops must
//! close inside that domain:
//!
//! - a face that crosses the seam without going round (a torus band cut across it) gets
//!   the seam moved into the largest gap between its loops
//!   ([`NurbsSurface::reseamed_u`]);
//! - a face that goes round and has its own seam (an iso-line its loops run along both
//!   ways) gets the domain's seam moved there;
//! - otherwise (a shaft bored across its seam, a tee) its loops are built again in
//!   `(u, v)`: bounds cut where they cross the seam line, seam pieces taken on the side
//!   their neighbours meet (both for a seam run along twice), joined along the seam line
//!   where the file has no edge there.
//!
//! `tests/convert.rs` checks these with OCCT on solids OCCT's booleans make
//! (`tests/occt/writer_solids.py make DIR --pierced`).

use cadmorph_brep::pcurve::{signed_area, uv_polyline, wrap, Periods};
use cadmorph_brep::{BoundedFace, CadDocument};
use cadmorph_model::{Error, Model, Result};
use cadmorph_nurbs::math::Point3;
use cadmorph_nurbs::{Curve, NurbsCurve, NurbsSurface, Surface};

/// The face `i` of `m` with its bounds as closed loops; `tol` is how far apart two
/// curve ends may be and still meet.
pub(crate) fn bounded_face<D: CadDocument>(m: &Model<D>, i: usize, tol: f64) -> Result<BoundedFace> {
    let face = &m.patches()[i];
    let fail = |reason: String| Error::Convert { face: face.entity, reason };
    let mut pieces = Vec::new();
    for b in m.bound_curves().iter().filter(|b| b.face == i) {
        let (lo, hi) = (b.range.0.min(b.range.1), b.range.0.max(b.range.1));
        let c = b.curve.clamped().segment(lo, hi).map_err(|e| fail(format!("bound curve {}: {e}", b.label)))?;
        pieces.push(c);
    }
    if pieces.is_empty() {
        return Err(fail("a trimmed face without bound curves".into()));
    }
    let loops = chain(pieces, tol).map_err(fail)?;
    let s = &face.surface;
    let polys: Vec<Vec<(f64, f64)>> = loops.iter().map(|lp| uv_polyline(s, lp, m.size())).collect();
    // A face whose loops all run along the sides of one box in (u, v) (a plane's
    // rectangle; a cylinder's band with its seam, or in loops that close only across
    // the seam, as two full circles) is the whole of the surface cut to that box.
    // Where each loop ends, unwrapped after its last point (`uv_polyline` leaves each
    // curve's end out): a whole period from its start when it closes across the seam.
    let periods = Periods::of(s, 1e-7 * m.size());
    let ends: Vec<Option<(f64, f64)>> =
        polys.iter().zip(&loops).map(|(p, lp)| loop_end(p, lp, s, periods, m.size())).collect();
    let mut all = polys.concat();
    all.extend(ends.iter().flatten());
    if let Some(b) = iso_box(&all) {
        let sub = sub_surface(s, b).map_err(|e| fail(format!("cutting its surface to its box: {e}")))?;
        return Ok(BoundedFace::natural(sub, face.reversed, tol));
    }
    // A face across its surface's seam (a shaft's side pierced where the seam runs, a
    // torus band cut by a plane): loops that close in model space but not in (u, v) are
    // built again in (u, v), cut at the seam.
    let wrapping = polys.iter().zip(&ends).any(|(p, end)| {
        let off = |d: f64, p: Option<f64>| p.is_some_and(|p| d.abs() > 0.5 * p);
        matches!((p.first(), end), (Some(a), Some(e)) if off(e.0 - a.0, periods.u) || off(e.1 - a.1, periods.v))
    });
    // A face across the seam that does not go all the way round (a torus band's end
    // cut off across it): the seam is moved into the largest gap between its loops.
    let mut moved = None;
    if wrapping {
        // The face's own seam (an iso-line its loops run along twice, as its file's
        // parametrisation has it) inside this domain: the domain's seam is moved there,
        // so that the face's bounds need no cut.
        if let Some((k, c)) = file_seam(s, &loops.concat(), periods, m.size()) {
            let r = if k == 0 { s.reseamed_u(c, 1e-7 * m.size()) } else { s.reseamed_v(c, 1e-7 * m.size()) };
            moved = Some(r.map_err(|e| fail(format!("moving its surface's seam to the face's: {e}")))?);
        }
    } else {
        let (du, dv) = s.domain();
        for (k, p, x0) in [(0, periods.u, *du.start()), (1, periods.v, *dv.start())] {
            let Some(p) = p else { continue };
            let Some(c) = seam_in_gap(&polys, k, p, x0) else { continue };
            let base = moved.as_ref().unwrap_or(s);
            let r = if k == 0 { base.reseamed_u(c, 1e-7 * m.size()) } else { base.reseamed_v(c, 1e-7 * m.size()) };
            moved = Some(r.map_err(|e| fail(format!("moving its surface's seam off the face: {e}")))?);
        }
    }
    let s = moved.as_ref().unwrap_or(s);
    let polys = if moved.is_some() { loops.iter().map(|lp| uv_polyline(s, lp, m.size())).collect() } else { polys };
    let (mut loops, polys) = if wrapping {
        seam_loops(s, &loops.concat(), periods, m.size()).ok_or_else(|| {
            fail("its bounds close only across the seam of its closed surface, and do not close into loops when cut there".into())
        })?
    } else {
        (loops, polys)
    };
    let areas: Vec<f64> = polys.iter().map(|p| signed_area(p)).collect();
    let outer = (0..loops.len()).max_by(|&a, &b| areas[a].abs().total_cmp(&areas[b].abs())).unwrap_or(0);
    if areas[outer] == 0.0 {
        return Err(fail("its outer loop encloses no area on the surface".into()));
    }
    loops.swap(0, outer);
    let mut areas = areas;
    areas.swap(0, outer);
    for (k, (lp, a)) in loops.iter_mut().zip(&areas).enumerate() {
        // Counterclockwise in (u, v) for the outer loop, clockwise for the holes; then
        // the other way for a reversed face (the loops go round the face normal).
        let ccw = (k == 0) != face.reversed;
        if (*a > 0.0) != ccw {
            *lp = lp.iter().rev().map(NurbsCurve::reversed).collect();
        }
    }
    Ok(BoundedFace { surface: s.clone(), reversed: face.reversed, loops })
}

fn ends(c: &NurbsCurve) -> (Point3<f64>, Point3<f64>) {
    let d = c.domain();
    (c.eval(*d.start()), c.eval(*d.end()))
}

/// Chains `pieces` into closed loops: from the first unused piece, the next is the
/// unused one with an end nearest to the chain's end, reversed when that is its own end,
/// until the chain closes. Fails naming the gap when none is within `tol`.
fn chain(pieces: Vec<NurbsCurve>, tol: f64) -> std::result::Result<Vec<Vec<NurbsCurve>>, String> {
    let mut pieces: Vec<Option<NurbsCurve>> = pieces.into_iter().map(Some).collect();
    let tol_sq = tol * tol;
    let mut loops = Vec::new();
    while let Some(first) = pieces.iter().position(Option::is_some) {
        let Some(c) = pieces[first].take() else { break };
        let (start, mut end) = ends(&c);
        let mut lp = vec![c];
        let mut last = first;
        loop {
            if (end - start).norm_squared() <= tol_sq {
                // Closed, unless the file's next curve goes on from here: a closed curve
                // followed by a seam (a cylinder's band bounded by its two circles and
                // the seam between them, as one loop).
                let next = pieces.iter().enumerate().skip(last + 1).find_map(|(k, p)| p.as_ref().map(|p| (k, p)));
                let goes_on = next.is_some_and(|(_, p)| {
                    let (a, b) = ends(p);
                    (a - b).norm_squared() > tol_sq
                        && ((a - end).norm_squared() <= tol_sq || (b - end).norm_squared() <= tol_sq)
                });
                match next {
                    Some((k, _)) if goes_on => {
                        let Some(p) = pieces[k].take() else { break };
                        let (a, _) = ends(&p);
                        let p = if (a - end).norm_squared() <= tol_sq { p } else { p.reversed() };
                        end = ends(&p).1;
                        lp.push(p);
                        last = k;
                        continue;
                    }
                    _ => break,
                }
            }
            let mut best: Option<(f64, usize, bool)> = None;
            for (k, p) in pieces.iter().enumerate() {
                let Some(p) = p else { continue };
                let (a, b) = ends(p);
                for (d, rev) in [((a - end).norm_squared(), false), ((b - end).norm_squared(), true)] {
                    if best.is_none_or(|x| d < x.0) {
                        best = Some((d, k, rev));
                    }
                }
            }
            // A curve this loop used already, whose other end is elsewhere: the seam of a
            // closed surface, which a loop runs along twice but some files list once.
            let again = lp.iter().find_map(|q| {
                let (a, b) = ends(q);
                ((b - end).norm_squared() <= tol_sq && (a - b).norm_squared() > tol_sq).then(|| q.reversed())
            });
            match best {
                Some((d, k, rev)) if d <= tol_sq => {
                    let Some(p) = pieces[k].take() else { break };
                    let p = if rev { p.reversed() } else { p };
                    end = ends(&p).1;
                    lp.push(p);
                    last = k;
                }
                _ if again.is_some() => {
                    let Some(p) = again else { break };
                    end = ends(&p).1;
                    lp.push(p);
                }
                _ => {
                    let gap = best.map_or(f64::INFINITY, |b| b.0.sqrt());
                    return Err(format!(
                        "its bound curves do not close into loops: the chain from ({:.6}, {:.6}, {:.6}) ends at ({:.6}, {:.6}, {:.6}), {gap:.3e} from the nearest free curve end (tolerance {tol:.3e})",
                        start.x, start.y, start.z, end.x, end.y, end.z
                    ));
                }
            }
        }
        weld(&mut lp);
        loops.push(lp);
    }
    Ok(loops)
}

/// Makes each joint of a closed loop one point: the end of a curve and the start of the
/// next (within the chaining tolerance) both move to their midpoint, by the curves' end
/// control points (the curves are clamped, so those are their end points).
fn weld(lp: &mut [NurbsCurve]) {
    let n = lp.len();
    for k in 0..n {
        let next = (k + 1) % n;
        let a = *lp[k].control_points().last().expect("a curve has control points");
        let b = lp[next].control_points()[0];
        let m = Point3::from((a.coords + b.coords) * 0.5);
        if let Some(p) = lp[k].control_points_mut().last_mut() {
            *p = m;
        }
        lp[next].control_points_mut()[0] = m;
    }
}

/// The box `[u0, u1, v0, v1]` when every point lies on one of its sides (within 1e-9 of
/// its size in that parameter) and it has an area.
fn iso_box(uv: &[(f64, f64)]) -> Option<[f64; 4]> {
    let (mut b, inf) = ([f64::INFINITY, f64::NEG_INFINITY, f64::INFINITY, f64::NEG_INFINITY], f64::INFINITY);
    for &(u, v) in uv {
        b = [b[0].min(u), b[1].max(u), b[2].min(v), b[3].max(v)];
    }
    let (du, dv) = (b[1] - b[0], b[3] - b[2]);
    if !(du > 0.0 && dv > 0.0 && du < inf && dv < inf) {
        return None;
    }
    let on = |x: f64, lo: f64, hi: f64, d: f64| (x - lo).abs() <= 1e-9 * d || (x - hi).abs() <= 1e-9 * d;
    uv.iter().all(|&(u, v)| on(u, b[0], b[1], du) || on(v, b[2], b[3], dv)).then_some(b)
}

/// `s` cut to the box `[u0, u1, v0, v1]` (its own parameters; a box beyond the domain
/// in a closed direction is moved back by whole periods first).
fn sub_surface(s: &NurbsSurface, b: [f64; 4]) -> cadmorph_nurbs::Result<NurbsSurface> {
    let (du, dv) = s.domain();
    let shift = |lo: f64, hi: f64, d0: f64, d1: f64| {
        let p = d1 - d0;
        if lo < d0 - 1e-9 * p || hi > d1 + 1e-9 * p {
            let k = ((lo - d0) / p).floor();
            (lo - k * p, hi - k * p)
        } else {
            (lo, hi)
        }
    };
    let (u0, u1) = shift(b[0], b[1], *du.start(), *du.end());
    let (v0, v1) = shift(b[2], b[3], *dv.start(), *dv.end());
    let inside = |x: f64, d0: f64, d1: f64| x > d0 + 1e-12 * (d1 - d0) && x < d1 - 1e-12 * (d1 - d0);
    let mut out = s.clone();
    if inside(u0, *du.start(), *du.end()) {
        out = out.split_u(u0)?.1;
    }
    if inside(u1, *du.start(), *du.end()) {
        out = out.split_u(u1)?.0;
    }
    if inside(v0, *dv.start(), *dv.end()) {
        out = out.split_v(v0)?.1;
    }
    if inside(v1, *dv.start(), *dv.end()) {
        out = out.split_v(v1)?.0;
    }
    Ok(out)
}

/// Whether `x` and `y` are one curve (either way round): their ends and middles within
/// `1e-9` of the model's `size`.
fn same_curve(x: &NurbsCurve, y: &NurbsCurve, size: f64) -> bool {
    let key = |c: &NurbsCurve| {
        let d = c.domain();
        (c.eval(*d.start()), c.eval(*d.end()), c.eval(0.5 * (d.start() + d.end())))
    };
    let ((a, b, m), (p, q, r)) = (key(x), key(y));
    let close = |u: Point3<f64>, w: Point3<f64>| (u - w).norm() <= 1e-9 * size;
    close(m, r) && ((close(a, p) && close(b, q)) || (close(a, q) && close(b, p)))
}

/// The face's own seam among `pieces`: a piece listed twice (the loops run along it both
/// ways) that is an iso-line in a closed direction `k` of `s`; `(k, its coordinate)`.
fn file_seam(s: &NurbsSurface, pieces: &[NurbsCurve], periods: Periods, size: f64) -> Option<(usize, f64)> {
    (0..pieces.len()).find_map(|i| {
        if !pieces[i + 1..].iter().any(|q| same_curve(&pieces[i], q, size)) {
            return None;
        }
        let path = uv_path(s, &pieces[i], periods, size, None);
        [(0, periods.u), (1, periods.v)].into_iter().find_map(|(k, p)| {
            let p = p?;
            let x = coord(path[0], k);
            path.iter().all(|&q| (coord(q, k) - x).abs() <= 1e-9 * p).then_some((k, x))
        })
    })
}

/// Where to move the seam of a closed direction (coordinate `k`, period `p`, domain
/// from `x0`) so that no loop crosses it: the middle of the largest gap between the
/// loops' ranges taken round the period; `None` when the seam at `x0` crosses no loop
/// already (or the loops leave no gap).
fn seam_in_gap(polys: &[Vec<(f64, f64)>], k: usize, p: f64, x0: f64) -> Option<f64> {
    let mut arcs: Vec<(f64, f64)> = Vec::new();
    for poly in polys {
        let xs = poly.iter().map(|&q| coord(q, k));
        let (lo, hi) = xs.fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), x| (a.min(x), b.max(x)));
        if hi - lo >= p || (hi - lo).is_nan() {
            return None;
        }
        let s = x0 + (lo - x0).rem_euclid(p);
        arcs.push((s, s + (hi - lo)));
    }
    // The seam crosses a loop when an arc reaches past the domain's end.
    let eps = 1e-9 * p;
    if arcs.iter().all(|&(_, e)| e <= x0 + p + eps) {
        return None;
    }
    arcs.sort_by(|a, b| a.0.total_cmp(&b.0));
    let mut merged: Vec<(f64, f64)> = Vec::new();
    for (s, e) in arcs {
        match merged.last_mut() {
            Some(last) if s <= last.1 => last.1 = last.1.max(e),
            _ => merged.push((s, e)),
        }
    }
    let n = merged.len();
    let (mut best, mut at) = (0.0, None);
    for i in 0..n {
        let next = if i + 1 < n { merged[i + 1].0 } else { merged[0].0 + p };
        let gap = next - merged[i].1;
        if gap > best {
            best = gap;
            at = Some(merged[i].1 + 0.5 * gap);
        }
    }
    at.filter(|_| best > eps)
}

/// Where the loop `lp`, whose points in `(u, v)` are `uv` (as [`uv_polyline`] gives them,
/// each curve's end left out), ends: its last curve's end, unwrapped after its last
/// point. A whole period away from its first point when it closes in model space only
/// across the surface's seam.
fn loop_end(uv: &[(f64, f64)], lp: &[NurbsCurve], s: &NurbsSurface, periods: Periods, size: f64) -> Option<(f64, f64)> {
    let (&last, c) = (uv.last()?, lp.last()?);
    let pr = s.project_near(&c.eval(*c.domain().end()), Some(last), 1e-12 * size, 1e-3 * size);
    Some(periods.unwrap((pr.u, pr.v), last))
}

/// One piece of a loop built in `(u, v)`: its model-space curve and its points in
/// `(u, v)` from start to end.
struct UvPiece {
    curve: NurbsCurve,
    uv: Vec<(f64, f64)>,
    /// One side of a piece along the seam line.
    seam: bool,
}

/// The points of `c` in `(u, v)`, from start to end (`2 n + 1` samples, `n` its control
/// points, 16 to 256), each projected from the one before and unwrapped across the seam;
/// the first from `start` (unwrapped next to it) when given, else from anywhere.
fn uv_path(
    s: &NurbsSurface,
    c: &NurbsCurve,
    periods: Periods,
    size: f64,
    start: Option<(f64, f64)>,
) -> Vec<(f64, f64)> {
    let d = c.domain();
    let n = (2 * c.control_points().len()).clamp(16, 256);
    let mut out: Vec<(f64, f64)> = Vec::with_capacity(n + 1);
    let mut near = start.map(|q| wrap(q, s));
    for k in 0..=n {
        let t = d.start() + (d.end() - d.start()) * k as f64 / n as f64;
        let pr = s.project_near(&c.eval(t), near, 1e-12 * size, 1e-3 * size);
        near = Some((pr.u, pr.v));
        let from = out.last().copied().or(start);
        out.push(from.map_or((pr.u, pr.v), |q| periods.unwrap((pr.u, pr.v), q)));
    }
    out
}

/// The loops of a face on a closed surface built in its `(u, v)` from the model-space
/// `pieces` of its bounds (in any order; a piece the loops run along twice listed twice):
///
/// - a piece along a seam line (`u = u0 + k P`, or in `v`) is taken on both sides of the
///   domain (a face runs along its seam once on each side);
/// - a piece run along twice elsewhere is the seam of the file's own parametrisation,
///   inside this domain: the face lies on both sides of it, and it is left out;
/// - every piece is cut where it crosses a seam line, and each part moved by whole
///   periods into the domain;
/// - the parts are chained by their ends in `(u, v)`, nearest first; where a chain
///   reaches a seam line and no part goes on, it goes along the line (an iso-parametric
///   curve of the surface) to the nearest free end on it.
///
/// Returns the loops and their points in `(u, v)` (as [`uv_polyline`] gives them), or
/// `None` when the parts do not close into loops.
#[allow(clippy::type_complexity)]
fn seam_loops(
    s: &NurbsSurface,
    pieces: &[NurbsCurve],
    periods: Periods,
    size: f64,
) -> Option<(Vec<Vec<NurbsCurve>>, Vec<Vec<(f64, f64)>>)> {
    let (du, dv) = s.domain();
    let lines = [(periods.u, *du.start()), (periods.v, *dv.start())];
    // Each distinct piece and how many times the loops run along it.
    let mut distinct: Vec<(&NurbsCurve, usize)> = Vec::new();
    for c in pieces {
        match distinct.iter_mut().find(|(d, _)| same_curve(d, c, size)) {
            Some((_, uses)) => *uses += 1,
            None => distinct.push((c, 1)),
        }
    }
    let mut parts: Vec<UvPiece> = Vec::new();
    // Both sides of each part of a piece along a seam line, and the piece's uses.
    let mut seam_sides: Vec<((UvPiece, UvPiece), usize)> = Vec::new();
    for (c, uses) in distinct {
        let path = uv_path(s, c, periods, size, None);
        let on_line = lines.iter().enumerate().find_map(|(k, &(p, x0))| {
            let p = p?;
            let x = coord(path[0], k);
            let line = x0 + ((x - x0) / p).round() * p;
            path.iter().all(|&q| (coord(q, k) - line).abs() <= 1e-9 * p).then_some((k, x0, p))
        });
        match on_line {
            Some((k, x0, p)) => {
                let mut sides = Vec::with_capacity(2);
                for side in [x0, x0 + p] {
                    let image: Vec<(f64, f64)> = path.iter().map(|&q| set(q, k, side)).collect();
                    let cut = cut_at_lines(s, c, &image, Some(k), lines, periods, size)?;
                    sides.push(
                        cut.into_iter()
                            .map(|(curve, uv)| UvPiece {
                                curve,
                                uv: uv.iter().map(|&q| set(q, k, side)).collect(),
                                seam: true,
                            })
                            .collect::<Vec<_>>(),
                    );
                }
                let (a, b) = (sides.remove(0), sides.remove(0));
                seam_sides.extend(a.into_iter().zip(b).map(|pair| (pair, uses)));
            }
            None if uses >= 2 => {}
            None => {
                for (curve, uv) in cut_at_lines(s, c, &path, None, lines, periods, size)? {
                    parts.push(UvPiece { curve, uv, seam: false });
                }
            }
        }
    }
    let diag = (du.end() - du.start()).hypot(dv.end() - dv.start());
    let tol = 1e-6 * diag;
    let dist = |a: (f64, f64), b: (f64, f64)| (a.0 - b.0).hypot(a.1 - b.1);
    // A piece along a seam line that the loops run along once bounds the face on one
    // side only: the side where the other parts' ends meet its ends (both when that
    // does not tell).
    let meets = |q: (f64, f64), parts: &[UvPiece]| {
        parts.iter().filter(|p| dist(p.uv[0], q) <= tol || p.uv.last().is_some_and(|&e| dist(e, q) <= tol)).count()
    };
    let mut sided = Vec::new();
    for ((a, b), uses) in seam_sides {
        let score = |x: &UvPiece| meets(x.uv[0], &parts) + x.uv.last().map_or(0, |&e| meets(e, &parts));
        let (sa, sb) = (score(&a), score(&b));
        if uses >= 2 || sa == sb {
            sided.push(a);
            sided.push(b);
        } else {
            sided.push(if sa > sb { a } else { b });
        }
    }
    parts.extend(sided);
    // Chain by ends in (u, v).
    // The seam lines through `q`, as (direction, value).
    let lines_through = |q: (f64, f64)| {
        let mut out = Vec::with_capacity(2);
        for (k, &(p, x0)) in lines.iter().enumerate() {
            let Some(p) = p else { continue };
            let x = coord(q, k);
            let line = x0 + ((x - x0) / p).round() * p;
            if (x - line).abs() <= 1e-9 * p {
                out.push((k, line));
            }
        }
        out
    };
    let mut used = vec![false; parts.len()];
    let mut loops = Vec::new();
    let mut polys = Vec::new();
    // Loops start from a part off the seam lines (a seam side left over is not a bound).
    while let Some(first) = (0..parts.len()).find(|&i| !used[i] && !parts[i].seam) {
        used[first] = true;
        let start = parts[first].uv[0];
        let mut end = *parts[first].uv.last()?;
        let mut lp = vec![parts[first].curve.clone()];
        let mut poly: Vec<(f64, f64)> = parts[first].uv[..parts[first].uv.len() - 1].to_vec();
        let mut steps = 0;
        while dist(end, start) > tol {
            steps += 1;
            if steps > 4 * parts.len() + 8 {
                return None;
            }
            let mut best: Option<(f64, usize, bool)> = None;
            for (i, part) in parts.iter().enumerate() {
                if used[i] {
                    continue;
                }
                for (q, rev) in [(part.uv[0], false), (*part.uv.last()?, true)] {
                    let d = dist(q, end);
                    if best.is_none_or(|b| d < b.0) {
                        best = Some((d, i, rev));
                    }
                }
            }
            match best {
                Some((d, i, rev)) if d <= tol => {
                    used[i] = true;
                    let mut uv = parts[i].uv.clone();
                    let mut curve = parts[i].curve.clone();
                    if rev {
                        uv.reverse();
                        curve = curve.reversed();
                    }
                    end = *uv.last()?;
                    poly.extend_from_slice(&uv[..uv.len() - 1]);
                    lp.push(curve);
                }
                _ => {
                    // Along a seam line through the end (two at a corner of the domain)
                    // to the nearest free end on it (or the start).
                    let mut targets: Vec<(usize, f64, (f64, f64))> = Vec::new();
                    for (k, line) in lines_through(end) {
                        let on = |q: (f64, f64)| (coord(q, k) - line).abs() <= tol;
                        if on(start) {
                            targets.push((k, line, start));
                        }
                        for (i, part) in parts.iter().enumerate() {
                            if !used[i] {
                                for q in [part.uv[0], *part.uv.last()?] {
                                    if on(q) {
                                        targets.push((k, line, q));
                                    }
                                }
                            }
                        }
                    }
                    let (k, line, to) = targets
                        .into_iter()
                        .filter(|&(_, _, q)| dist(q, end) > tol)
                        .min_by(|a, b| dist(a.2, end).total_cmp(&dist(b.2, end)))?;
                    let other = 1 - k;
                    let (a, b) = (coord(end, other), coord(to, other));
                    let iso = if k == 0 { s.u_iso(line) } else { s.v_iso(line) };
                    let piece = iso.segment(a.min(b), a.max(b)).ok()?;
                    let n = 16;
                    let uv: Vec<(f64, f64)> =
                        (0..n).map(|j| set(set(end, other, a + (b - a) * j as f64 / n as f64), k, line)).collect();
                    poly.extend_from_slice(&uv);
                    lp.push(if a <= b { piece } else { piece.reversed() });
                    end = to;
                }
            }
        }
        loops.push(lp);
        polys.push(poly);
    }
    (!loops.is_empty()).then_some((loops, polys))
}

/// Coordinate `k` of a point in `(u, v)`.
fn coord(q: (f64, f64), k: usize) -> f64 {
    if k == 0 {
        q.0
    } else {
        q.1
    }
}

/// `q` with coordinate `k` set to `x`.
fn set(q: (f64, f64), k: usize, x: f64) -> (f64, f64) {
    if k == 0 {
        (x, q.1)
    } else {
        (q.0, x)
    }
}

/// The curve `c`, whose points in `(u, v)` are `path` (its samples at even steps of its
/// parameter), cut where the path crosses a seam line `x0 + k P` of a closed direction
/// other than `skip`; each part with its own points in `(u, v)`, moved by whole periods
/// so that its middle lies in the domain, and a cut end put on its line.
#[allow(clippy::type_complexity)]
fn cut_at_lines(
    s: &NurbsSurface,
    c: &NurbsCurve,
    path: &[(f64, f64)],
    skip: Option<usize>,
    lines: [(Option<f64>, f64); 2],
    periods: Periods,
    size: f64,
) -> Option<Vec<(NurbsCurve, Vec<(f64, f64)>)>> {
    let d = c.domain();
    let n = path.len() - 1;
    let t_at = |i: usize| d.start() + (d.end() - d.start()) * i as f64 / n as f64;
    let mut cuts: Vec<f64> = Vec::new();
    for (k, &(p, x0)) in lines.iter().enumerate() {
        let Some(p) = p.filter(|_| skip != Some(k)) else { continue };
        let cell = |x: f64| ((x - x0) / p).floor();
        let on_line = |x: f64| {
            let line = x0 + ((x - x0) / p).round() * p;
            (x - line).abs() <= 1e-9 * p
        };
        for i in 0..n {
            let (a, b) = (coord(path[i], k), coord(path[i + 1], k));
            // A sample inside the piece on the line: cut there.
            if i > 0 && on_line(a) {
                cuts.push(t_at(i));
                continue;
            }
            if on_line(a) || on_line(b) || cell(a) == cell(b) {
                continue;
            }
            // Bisection on the unwrapped coordinate between the two samples.
            let line = x0 + cell(a).max(cell(b)) * p;
            let (mut lo, mut hi) = (t_at(i), t_at(i + 1));
            for _ in 0..60 {
                let mid = 0.5 * (lo + hi);
                let pr = s.project_near(&c.eval(mid), Some(path[i]), 1e-12 * size, 1e-3 * size);
                let x = coord(periods.unwrap((pr.u, pr.v), path[i]), k);
                if (x < line) == (a < line) {
                    lo = mid;
                } else {
                    hi = mid;
                }
            }
            cuts.push(0.5 * (lo + hi));
        }
    }
    cuts.sort_by(f64::total_cmp);
    let mut bounds = vec![*d.start()];
    bounds.extend(cuts);
    bounds.push(*d.end());
    let mut out = Vec::with_capacity(bounds.len() - 1);
    for w in bounds.windows(2) {
        let part = if w[0] == *d.start() && w[1] == *d.end() { c.clone() } else { c.segment(w[0], w[1]).ok()? };
        // Projected from the whole piece's sample next to the part's start.
        let from = path[(((w[0] - d.start()) / (d.end() - d.start()) * n as f64).round() as usize).min(n)];
        let mut uv = uv_path(s, &part, periods, size, Some(from));
        // Moved by whole periods so that its middle lies in the domain.
        let mid = uv[uv.len() / 2];
        for (k, &(p, x0)) in lines.iter().enumerate() {
            let Some(p) = p.filter(|_| skip != Some(k)) else { continue };
            let shift = -((coord(mid, k) - x0) / p).floor() * p;
            for q in &mut uv {
                *q = set(*q, k, coord(*q, k) + shift);
            }
        }
        // A cut end lies on the seam line (its projection there, at the domain's edge,
        // can stop short of it).
        let last = uv.len() - 1;
        for (end, cut) in [(0, w[0] != *d.start()), (last, w[1] != *d.end())] {
            for (k, &(p, x0)) in lines.iter().enumerate() {
                let Some(p) = p.filter(|_| cut && skip != Some(k)) else { continue };
                let x = coord(uv[end], k);
                let line = x0 + ((x - x0) / p).round() * p;
                if (x - line).abs() <= 0.01 * p {
                    uv[end] = set(uv[end], k, line);
                }
            }
        }
        out.push((part, uv));
    }
    Some(out)
}
