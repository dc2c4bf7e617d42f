//! Seam repair between two iso boundaries: compatible knots, identical boundary rows
//! (exact C0), and optionally collinear cross-boundary legs (G1).

use cadmorph_nurbs::{NurbsSurface, Side, Surface};

use crate::{Error, Result, SharedBoundary};

/// Brings `s` into the frame where `side` is `UMax` (`first`) or `UMin` (the other
/// patch): returns the surface and whether it was transposed and u-reversed. The
/// parameter along the edge becomes v, running the same way as before.
fn frame(s: &NurbsSurface, side: Side, first: bool) -> (NurbsSurface, bool, bool) {
    let (t, transposed, side) = match side {
        Side::UMin | Side::UMax => (s.clone(), false, side),
        Side::VMin => (s.transposed(), true, Side::UMin),
        Side::VMax => (s.transposed(), true, Side::UMax),
    };
    let want = if first { Side::UMax } else { Side::UMin };
    if side == want {
        (t, transposed, false)
    } else {
        (t.u_reversed(), transposed, true)
    }
}

fn unframe(s: NurbsSurface, transposed: bool, u_reversed: bool, v_reversed: bool) -> NurbsSurface {
    let mut s = s;
    if v_reversed {
        s = s.v_reversed();
    }
    if u_reversed {
        s = s.u_reversed();
    }
    if transposed {
        s = s.transposed();
    }
    s
}

fn normalised_knots(s: &NurbsSurface) -> (Vec<f64>, Vec<usize>) {
    let (_, vd) = s.domain();
    let (a, b) = (*vd.start(), *vd.end());
    let (vals, mults) = s.v_knots().distinct();
    (vals.iter().map(|&k| (k - a) / (b - a)).collect(), mults)
}

/// Inserts into `s` (v direction) the normalised knots of `other` it lacks, so both
/// end with the same normalised knot multiset.
fn insert_missing(s: &mut NurbsSurface, other: &[(f64, usize)], ptol: f64) -> Result<()> {
    let (_, vd) = s.domain();
    let (a, b) = (*vd.start(), *vd.end());
    let (mine, my_mults) = normalised_knots(s);
    let mut x = Vec::new();
    for &(k, m) in other {
        let have = mine.iter().zip(&my_mults).find(|(v, _)| (**v - k).abs() <= ptol).map_or(0, |(_, m)| *m);
        if m > have {
            let value = mine.iter().find(|v| (**v - k).abs() <= ptol).map_or(a + k * (b - a), |v| a + v * (b - a));
            x.extend(std::iter::repeat_n(value, m - have));
        }
    }
    x.retain(|&v| v > a && v < b);
    s.refine_v(&x)?;
    Ok(())
}

/// Two patches in the common frame of [`frame`], with compatible knots along the edge.
struct Framed {
    a: NurbsSurface,
    b: NurbsSurface,
    undo_a: (bool, bool),
    undo_b: (bool, bool),
    v_reversed: bool,
}

/// Whether the parameter range `r` along `side` of `s` is the side's whole length (up to
/// `1e-9` of it): the edges [`repair`] and [`make_compatible`] can make exact.
pub fn covers_side(s: &NurbsSurface, side: Side, r: (f64, f64)) -> bool {
    let (ud, vd) = s.domain();
    let d = if matches!(side, Side::UMin | Side::UMax) { vd } else { ud };
    let len = d.end() - d.start();
    let (lo, hi) = (r.0.min(r.1), r.0.max(r.1));
    (lo - d.start()).abs() <= 1e-9 * len && (hi - d.end()).abs() <= 1e-9 * len
}

/// Frames both patches ([`frame`]), raises them to the same degree along the edge and
/// inserts into each the (normalised) knots along the edge that only the other has, so
/// their boundary rows correspond one to one.
fn compatible_frames(a: &NurbsSurface, b: &NurbsSurface, edge: &SharedBoundary) -> Result<Framed> {
    if !covers_side(a, edge.a.side, edge.a_range) || !covers_side(b, edge.b.side, edge.b_range) {
        return Err(Error::PartialEdge { a: edge.a.patch, b: edge.b.patch });
    }
    let (mut fa, ta, ra) = frame(&a.clamped(), edge.a.side, true);
    let (mut fb, tb, rb) = frame(&b.clamped(), edge.b.side, false);
    let v_reversed = edge.reversed();
    if v_reversed {
        fb = fb.v_reversed();
    }
    let q = fa.v_degree().max(fb.v_degree());
    fa.elevate_v_degree(q - fa.v_degree())?;
    fb.elevate_v_degree(q - fb.v_degree())?;
    let ptol = 1e-10;
    let (ka, ma) = normalised_knots(&fa);
    let (kb, mb) = normalised_knots(&fb);
    insert_missing(&mut fa, &kb.iter().copied().zip(mb).collect::<Vec<_>>(), ptol)?;
    insert_missing(&mut fb, &ka.iter().copied().zip(ma).collect::<Vec<_>>(), ptol)?;
    debug_assert_eq!(fa.n_v(), fb.n_v());
    Ok(Framed { a: fa, b: fb, undo_a: (ta, ra), undo_b: (tb, rb), v_reversed })
}

/// Makes the knots along every edge of `edges` compatible on both sides (same degree,
/// same normalised knots along the edge) by degree elevation and knot insertion, which
/// change no geometry. Two compatible sides that met before a morph have the same
/// boundary control row, so moving control points with any map keeps them met exactly.
/// Insertions run across the whole patch and reach its other edges, so the edges are
/// swept until nothing changes (at most `edges.len() + 1` sweeps). Edges that cover
/// their sides only in part are skipped. Returns the control points added.
///
/// # Errors
///
/// Kernel errors from degree elevation (past the maximum degree).
pub fn make_compatible(patches: &mut [NurbsSurface], edges: &[SharedBoundary]) -> Result<usize> {
    let before: usize = patches.iter().map(|s| s.control_points().len()).sum();
    for _ in 0..=edges.len() {
        let mut changed = false;
        for e in edges {
            let (a, b) = (&patches[e.a.patch], &patches[e.b.patch]);
            if e.a.patch == e.b.patch || !covers_side(a, e.a.side, e.a_range) || !covers_side(b, e.b.side, e.b_range) {
                continue;
            }
            let f = compatible_frames(a, b, e)?;
            let na = unframe(f.a, f.undo_a.0, f.undo_a.1, false);
            let nb = unframe(f.b, f.undo_b.0, f.undo_b.1, f.v_reversed);
            if na.control_points().len() != a.control_points().len()
                || na.u_degree() != a.u_degree()
                || na.v_degree() != a.v_degree()
            {
                patches[e.a.patch] = na;
                changed = true;
            }
            let b = &patches[e.b.patch];
            if nb.control_points().len() != b.control_points().len()
                || nb.u_degree() != b.u_degree()
                || nb.v_degree() != b.v_degree()
            {
                patches[e.b.patch] = nb;
                changed = true;
            }
        }
        if !changed {
            break;
        }
    }
    Ok(patches.iter().map(|s| s.control_points().len()).sum::<usize>() - before)
}

/// What [`repair`] changed.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct Repair {
    /// Control points added to the first patch to make the knots compatible.
    pub added_a: usize,
    /// Control points added to the second patch.
    pub added_b: usize,
    /// Largest distance a boundary control point moved to meet its partner.
    pub max_move: f64,
    /// Whether the cross-boundary legs were aligned (G1).
    pub g1: bool,
}

/// Makes the shared boundary `edge` between `a` and `b` exact: both boundary curves get
/// the same degree and (normalised) knots, then each pair of boundary control points
/// (and weights) is replaced by its average, so the two boundaries are the same curve
/// and the C0 gap is zero up to rounding. With `g1`, and for non-rational patches, the
/// legs from the boundary row to the next row are then made parallel with one common
/// length ratio, which gives both patches the same tangent plane all along the edge.
///
/// The edge must cover both sides completely (a T-junction cannot be repaired this way).
///
/// # Errors
///
/// [`Error::PartialEdge`] for a partial overlap, and kernel errors from degree elevation.
pub fn repair(a: &mut NurbsSurface, b: &mut NurbsSurface, edge: &SharedBoundary, g1: bool) -> Result<Repair> {
    let (na0, nb0) = (a.control_points().len(), b.control_points().len());
    let Framed { a: fa, b: fb, undo_a: (ta, ra), undo_b: (tb, rb), v_reversed: vb_rev } =
        compatible_frames(a, b, edge)?;
    // Average the boundary rows: A's last u row, B's first.
    let n_v = fa.n_v();
    let ia = fa.n_u() - 1;
    let mut max_move: f64 = 0.0;
    let mut pa = fa.control_points().to_vec();
    let mut pb = fb.control_points().to_vec();
    let mut wa = fa.weights().map(<[f64]>::to_vec);
    let mut wb = fb.weights().map(<[f64]>::to_vec);
    for j in 0..n_v {
        let (x, y) = (pa[ia * n_v + j], pb[j]);
        let mid = nalgebra::center(&x, &y);
        max_move = max_move.max((x - mid).norm());
        pa[ia * n_v + j] = mid;
        pb[j] = mid;
        let w = match (&wa, &wb) {
            (Some(wa), Some(wb)) => 0.5 * (wa[ia * n_v + j] + wb[j]),
            (Some(wa), None) => 0.5 * (wa[ia * n_v + j] + 1.0),
            (None, Some(wb)) => 0.5 * (1.0 + wb[j]),
            (None, None) => 1.0,
        };
        if wa.is_some() || wb.is_some() {
            let wa = wa.get_or_insert_with(|| vec![1.0; pa.len()]);
            let wb = wb.get_or_insert_with(|| vec![1.0; pb.len()]);
            wa[ia * n_v + j] = w;
            wb[j] = w;
        }
    }
    let rational = wa.is_some() || wb.is_some();
    let aligned = g1 && !rational && fa.n_u() >= 2 && fb.n_u() >= 2;
    if aligned {
        // Legs d_a = P_a[last] − P_a[last−1] and d_b = P_b[1] − P_b[0]; one ratio λ.
        let legs_a: Vec<_> = (0..n_v).map(|j| pa[ia * n_v + j] - pa[(ia - 1) * n_v + j]).collect();
        let legs_b: Vec<_> = (0..n_v).map(|j| pb[n_v + j] - pb[j]).collect();
        let sa: f64 = legs_a.iter().map(|d| d.norm()).sum();
        let sb: f64 = legs_b.iter().map(|d| d.norm()).sum();
        if sa > 0.0 && sb > 0.0 {
            let lambda = sb / sa;
            for j in 0..n_v {
                let w = (legs_a[j] + legs_b[j] / lambda) * 0.5;
                pa[(ia - 1) * n_v + j] = pa[ia * n_v + j] - w;
                pb[n_v + j] = pb[j] + w * lambda;
            }
        }
    }
    let rebuild = |s: &NurbsSurface, pts: Vec<_>, w: Option<Vec<f64>>| -> Result<NurbsSurface> {
        Ok(NurbsSurface::try_new(
            (s.u_degree(), s.v_degree()),
            (s.u_knots().clone(), s.v_knots().clone()),
            (s.n_u(), s.n_v()),
            pts,
            w,
        )?)
    };
    let fa = rebuild(&fa, pa, wa)?;
    let fb = rebuild(&fb, pb, wb)?;
    *a = unframe(fa, ta, ra, false);
    *b = unframe(fb, tb, rb, vb_rev);
    Ok(Repair {
        added_a: a.control_points().len().saturating_sub(na0),
        added_b: b.control_points().len().saturating_sub(nb0),
        max_move,
        g1: aligned,
    })
}
