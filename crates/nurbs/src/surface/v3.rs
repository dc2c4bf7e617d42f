//! The AVX2/FMA path of [`NurbsSurface::eval_d1`]: a control point is one 4-lane vector
//! `(x, y, z, ·)` (rational: `(wx, wy, wz, w)`), so each term of the tensor contraction
//! `Σₖ Σₗ Nₖ(u) Nₗ(v) Pₖₗ` and of its two partials is one packed fused multiply-add
//! instead of three scalar multiplies and adds. Run through pulp's `V3` (x86-64-v3:
//! AVX2, FMA), picked at run time; the scalar path of `surface.rs` is the fallback and
//! the reference the tests compare this one with.

use nalgebra::{Point3, Vector3};
use pulp::x86::V3;
use pulp::{f64x4, Simd};

use super::{basis_d1_pair, NurbsSurface, SurfacePointD1};

/// One `eval_d1` evaluation for [`pulp::Simd::vectorize`]: the surface, the parameters,
/// and the degrees. With `D > 0` both degrees are the constant `D` (`p` and `q` are then
/// ignored), so that the bicubic case compiles with constant loop bounds and its basis
/// arrays live in registers; `D = 0` takes `p` and `q`.
pub(super) struct D1<'a, const N: usize, const D: usize> {
    pub simd: V3,
    pub surface: &'a NurbsSurface,
    pub u: f64,
    pub v: f64,
    pub p: usize,
    pub q: usize,
}

impl<const N: usize, const D: usize> pulp::WithSimd for D1<'_, N, D> {
    type Output = SurfacePointD1;

    #[inline(always)]
    fn with_simd<S: Simd>(self, _: S) -> SurfacePointD1 {
        let D1 { simd, surface: s, u, v, p, q } = self;
        let (p, q) = if D > 0 { (D, D) } else { (p, q) };
        let su = crate::knots::find_span(s.u_knots.as_slice(), p, u);
        let sv = crate::knots::find_span(s.v_knots.as_slice(), q, v);
        let ((nu, dnu), (nv, dnv)) = basis_d1_pair::<N>(s, (su, sv), (u, v), (p, q));
        let (i0, j0) = (su - p, sv - q);
        let flat: &[f64] = bytemuck::cast_slice(&s.control_points);
        let zero = simd.splat_f64x4(0.0);
        let (mut a, mut au, mut av) = (zero, zero, zero);
        match &s.weights {
            None => {
                for k in 0..=p {
                    let row = row(flat, 3 * ((i0 + k) * s.n_v + j0), q);
                    let (mut t0, mut t1) = (zero, zero);
                    for l in 0..=q {
                        let c = load(row, 3 * l);
                        t0 = simd.mul_add_f64x4(simd.splat_f64x4(nv[l]), c, t0);
                        t1 = simd.mul_add_f64x4(simd.splat_f64x4(dnv[l]), c, t1);
                    }
                    a = simd.mul_add_f64x4(simd.splat_f64x4(nu[k]), t0, a);
                    au = simd.mul_add_f64x4(simd.splat_f64x4(dnu[k]), t0, au);
                    av = simd.mul_add_f64x4(simd.splat_f64x4(nu[k]), t1, av);
                }
                let [x, y, z, _]: [f64; 4] = pulp::cast(a);
                let [xu, yu, zu, _]: [f64; 4] = pulp::cast(au);
                let [xv, yv, zv, _]: [f64; 4] = pulp::cast(av);
                SurfacePointD1 {
                    point: Point3::new(x, y, z),
                    du: Vector3::new(xu, yu, zu),
                    dv: Vector3::new(xv, yv, zv),
                }
            }
            Some(w) => {
                let one = simd.splat_f64x4(1.0);
                for k in 0..=p {
                    let idx = (i0 + k) * s.n_v + j0;
                    let row = row(flat, 3 * idx, q);
                    let w = &w[idx..idx + q + 1];
                    let (mut t0, mut t1) = (zero, zero);
                    for l in 0..=q {
                        // (x, y, z, 1) · w
                        let c: f64x4 = pulp::cast(
                            simd.avx._mm256_blend_pd::<0b1000>(pulp::cast(load(row, 3 * l)), pulp::cast(one)),
                        );
                        let h = simd.mul_f64x4(c, simd.splat_f64x4(w[l]));
                        t0 = simd.mul_add_f64x4(simd.splat_f64x4(nv[l]), h, t0);
                        t1 = simd.mul_add_f64x4(simd.splat_f64x4(dnv[l]), h, t1);
                    }
                    a = simd.mul_add_f64x4(simd.splat_f64x4(nu[k]), t0, a);
                    au = simd.mul_add_f64x4(simd.splat_f64x4(dnu[k]), t0, au);
                    av = simd.mul_add_f64x4(simd.splat_f64x4(nu[k]), t1, av);
                }
                let [x, y, z, sw]: [f64; 4] = pulp::cast(a);
                let [xu, yu, zu, wu]: [f64; 4] = pulp::cast(au);
                let [xv, yv, zv, wv]: [f64; 4] = pulp::cast(av);
                let pt = Vector3::new(x, y, z) / sw;
                SurfacePointD1 {
                    point: Point3::from(pt),
                    du: (Vector3::new(xu, yu, zu) - pt * wu) / sw,
                    dv: (Vector3::new(xv, yv, zv) - pt * wv) / sw,
                }
            }
        }
    }
}

/// The `q + 1` control points of a row of the net from `flat[start]` on, with one value
/// more when there is one (so that every point can be loaded as four values).
#[inline(always)]
fn row(flat: &[f64], start: usize, q: usize) -> &[f64] {
    let end = start + 3 * (q + 1);
    flat.get(start..end + 1).unwrap_or(&flat[start..end])
}

/// The control point whose `x` is `row[i]` as `(x, y, z, ·)`: four contiguous values
/// (the last lane is the next point's `x`, or zero past the end of the net).
#[inline(always)]
fn load(row: &[f64], i: usize) -> f64x4 {
    match row.get(i..i + 4) {
        Some(four) => pulp::cast::<[f64; 4], f64x4>(four.try_into().expect("four values")),
        None => f64x4(row[i], row[i + 1], row[i + 2], 0.0),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::surface::{basis_d1, basis_d1_cubic};
    use crate::KnotVector;
    use rand::{Rng, SeedableRng};
    use rand_xorshift::XorShiftRng;

    /// A clamped knot vector of degree `p` for `n` control points on `[a, b]`, with random
    /// interior knots, some of them repeated (up to multiplicity `p`).
    fn knots(rng: &mut XorShiftRng, p: usize, n: usize) -> KnotVector {
        let (a, b) = (rng.gen_range(-2.0..0.0), rng.gen_range(0.5..3.0));
        let mut inner = Vec::new();
        while inner.len() < n - p - 1 {
            let x = rng.gen_range(a..b);
            let m = rng.gen_range(1..=p).min(n - p - 1 - inner.len());
            inner.extend(std::iter::repeat_n(x, m));
        }
        inner.sort_by(f64::total_cmp);
        let mut k = vec![a; p + 1];
        k.extend(inner);
        k.extend(vec![b; p + 1]);
        KnotVector::try_new(k).expect("sorted")
    }

    fn surface(rng: &mut XorShiftRng, p: usize, q: usize, rational: bool) -> NurbsSurface {
        let (n_u, n_v) = (p + 1 + rng.gen_range(0..6), q + 1 + rng.gen_range(0..6));
        let pts = (0..n_u * n_v)
            .map(|_| Point3::new(rng.gen_range(-10.0..10.0), rng.gen_range(-10.0..10.0), rng.gen_range(-10.0..10.0)))
            .collect();
        let w = rational.then(|| (0..n_u * n_v).map(|_| rng.gen_range(0.2..4.0)).collect());
        NurbsSurface::new((p, q), (knots(rng, p, n_u), knots(rng, q, n_v)), (n_u, n_v), pts, w)
    }

    fn close(a: &SurfacePointD1, b: &SurfacePointD1, scale: f64) -> bool {
        let tol = 1e-11 * scale;
        (a.point - b.point).norm() <= tol && (a.du - b.du).norm() <= tol && (a.dv - b.dv).norm() <= tol
    }

    /// The AVX2 path (dispatched by `eval_d1`, and its generic-degree form forced for the
    /// bicubic case too) against the scalar path and against A3.6 + A4.4, on random
    /// surfaces of degrees 1..=5 in each direction, rational or not, at random parameters,
    /// the knots and the ends of the domain.
    #[test]
    fn avx2_path_matches_scalar_path() {
        let Some(simd) = V3::try_new() else {
            eprintln!("no AVX2/FMA on this CPU: only the scalar path runs here");
            return;
        };
        let mut rng = XorShiftRng::seed_from_u64(21);
        let mut checked = 0;
        for p in 1..=5 {
            for q in 1..=5 {
                for rational in [false, true] {
                    for _ in 0..4 {
                        let s = surface(&mut rng, p, q, rational);
                        let (ud, vd) = crate::Surface::domain(&s);
                        let mut us: Vec<f64> = (0..12).map(|_| rng.gen_range(ud.clone())).collect();
                        let mut vs: Vec<f64> = (0..12).map(|_| rng.gen_range(vd.clone())).collect();
                        us.extend(s.u_knots().as_slice());
                        vs.extend(s.v_knots().as_slice());
                        for (&u, &v) in us.iter().zip(vs.iter().cycle()) {
                            let scalar = s.eval_d1_scalar(u, v);
                            let general = s.derivs_general(u, v, 1);
                            let scale = 1.0 + scalar.point.coords.norm() + scalar.du.norm() + scalar.dv.norm();
                            let fast = s.eval_d1(u, v);
                            let forced = if p.max(q) <= 3 {
                                pulp::Simd::vectorize(simd, D1::<4, 0> { simd, surface: &s, u, v, p, q })
                            } else {
                                pulp::Simd::vectorize(simd, D1::<8, 0> { simd, surface: &s, u, v, p, q })
                            };
                            for (name, d) in [("dispatched", fast), ("generic", forced)] {
                                assert!(
                                    close(&d, &scalar, scale),
                                    "{name} p={p} q={q} rational={rational} at ({u}, {v}): {d:?} vs {scalar:?}"
                                );
                            }
                            assert!((scalar.du - general[(1, 0)]).norm() <= 1e-10 * scale);
                            assert!((scalar.dv - general[(0, 1)]).norm() <= 1e-10 * scale);
                            checked += 1;
                        }
                    }
                }
            }
        }
        assert!(checked > 1000);
    }

    /// The unrolled cubic basis is the generic one, bit for bit.
    #[test]
    fn cubic_basis_is_the_generic_one() {
        let mut rng = XorShiftRng::seed_from_u64(3);
        for _ in 0..200 {
            let n = 4 + rng.gen_range(0..8);
            let k = knots(&mut rng, 3, n);
            let kv = k.as_slice();
            let inv = super::super::inverse_denominators(kv, 3);
            for _ in 0..20 {
                let u = rng.gen_range(kv[0]..=kv[kv.len() - 1]);
                let span = crate::knots::find_span(kv, 3, u);
                assert_eq!(basis_d1_cubic(kv, &inv, span, u), basis_d1::<4>(kv, &inv, span, u, 3));
            }
        }
    }
}
