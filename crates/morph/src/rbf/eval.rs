//! Vectorised sums `Σⱼ γⱼ φ(‖x − cⱼ‖)` over all centres for a block of points.
//!
//! Each kernel is written as a function of the squared distance so that no square root is
//! taken where none is needed, and the thin-plate logarithm uses [`ln_fast`], which the
//! compiler vectorises (the C library's `log` is a scalar call). The loops run inside
//! `pulp::Arch::dispatch`, which compiles them for AVX2/FMA when the CPU has them.

use nalgebra::Point3;

use super::grid::Grid;
use super::Kernel;

/// Points evaluated together (one SIMD-friendly lane each).
pub(crate) const LANES: usize = 8;

/// Centres and weights in structure-of-arrays form.
#[derive(Debug, Clone, Default)]
pub(crate) struct Centres {
    pub x: Vec<f64>,
    pub y: Vec<f64>,
    pub z: Vec<f64>,
    /// γ for the x, y, z displacement components.
    pub g: [Vec<f64>; 3],
}

/// `ln x` for `x ≥ 0` finite, accurate to a few ulps, branch-free so that it vectorises.
/// `ln_fast(0)` is a finite (meaningless) number so that `0 · ln_fast(0) = 0`.
#[inline(always)]
pub(crate) fn ln_fast(x: f64) -> f64 {
    const LN2_HI: f64 = f64::from_bits(0x3FE6_2E42_FEE0_0000); // fdlibm ln2_hi: 32 trailing zero bits
    const LN2_LO: f64 = f64::from_bits(0x3DEA_39EF_3579_3C76); // fdlibm ln2_lo = ln 2 − ln2_hi
    let bits = x.to_bits();
    // Exponent field as an exact float: put it in the mantissa of 2⁵² and subtract 2⁵².
    let e = f64::from_bits((bits >> 52) | 0x4330_0000_0000_0000) - 4_503_599_627_370_496.0 - 1023.0;
    let m = f64::from_bits((bits & 0x000F_FFFF_FFFF_FFFF) | 0x3FF0_0000_0000_0000); // [1, 2)
    let big = m > std::f64::consts::SQRT_2;
    let m = if big { 0.5 * m } else { m };
    let e = if big { e + 1.0 } else { e };
    // ln m = 2 atanh(s), s = (m − 1)/(m + 1), |s| ≤ 0.1716: nine terms reach 1e-16.
    // (`mul_add` is one FMA instruction inside the AVX2/FMA dispatch below.)
    let s = (m - 1.0) / (m + 1.0);
    let s2 = s * s;
    let mut p: f64 = 1.0 / 19.0;
    for c in [1.0 / 17.0, 1.0 / 15.0, 1.0 / 13.0, 1.0 / 11.0, 1.0 / 9.0, 1.0 / 7.0, 1.0 / 5.0, 1.0 / 3.0] {
        p = p.mul_add(s2, c);
    }
    let ln_m = (2.0 * s * s2).mul_add(p, 2.0 * s);
    e.mul_add(LN2_HI, e.mul_add(LN2_LO, ln_m))
}

/// `[Σⱼ γⱼᶜ φ(‖pₗ − cⱼ‖)]` for the `LANES` points `(px, py, pz)`, c = x, y, z.
pub(crate) fn dense_sums(
    kernel: &Kernel,
    c: &Centres,
    px: &[f64; LANES],
    py: &[f64; LANES],
    pz: &[f64; LANES],
) -> [[f64; LANES]; 3] {
    match *kernel {
        Kernel::ThinPlate { radius, k: 2 } => {
            let s = 1.0 / (radius * radius);
            // (r/R)² ln(r/R) = ½ a ln a with a = r²/R².
            run(c, px, py, pz, move |r2| {
                let a = r2 * s;
                0.5 * a * ln_fast(a)
            })
        }
        Kernel::Polyharmonic { radius, k: 2 } => {
            let s = 1.0 / (radius * radius);
            run(c, px, py, pz, move |r2| {
                let a = r2 * s;
                0.5 * a * ln_fast(a)
            })
        }
        Kernel::Polyharmonic { radius, k: 3 } => {
            let s = 1.0 / radius;
            run(c, px, py, pz, move |r2| {
                let a = r2.sqrt() * s;
                a * a * a
            })
        }
        Kernel::MultiQuadratic { radius } => {
            let r2r = radius * radius;
            run(c, px, py, pz, move |r2| (r2 + r2r).sqrt())
        }
        Kernel::InverseMultiQuadratic { radius } => {
            let r2r = radius * radius;
            run(c, px, py, pz, move |r2| 1.0 / (r2 + r2r).sqrt())
        }
        Kernel::BeckertWendlandC2 { radius: s } | Kernel::WendlandC2 { support: s } => {
            let inv = 1.0 / s;
            run(c, px, py, pz, move |r2| {
                let a = r2.sqrt() * inv;
                let t = (1.0 - a).max(0.0);
                let t2 = t * t;
                t2 * t2 * (4.0 * a + 1.0)
            })
        }
        ref k => {
            let k = *k;
            run(c, px, py, pz, move |r2| k.eval(r2.sqrt()))
        }
    }
}

/// The sum loop, compiled inside `pulp`'s target-feature function: its body must be in
/// `with_simd` itself (a closure body would stay a separate function without AVX2/FMA).
struct Sums<'a, F> {
    c: &'a Centres,
    px: &'a [f64; LANES],
    py: &'a [f64; LANES],
    pz: &'a [f64; LANES],
    phi: F,
}

impl<F: Fn(f64) -> f64> pulp::WithSimd for Sums<'_, F> {
    type Output = [[f64; LANES]; 3];

    #[inline(always)]
    fn with_simd<S: pulp::Simd>(self, _simd: S) -> Self::Output {
        let Sums { c, px, py, pz, phi } = self;
        let mut acc = [[0.0; LANES]; 3];
        let n = c.x.len();
        let (cx, cy, cz) = (&c.x[..n], &c.y[..n], &c.z[..n]);
        let (gx, gy, gz) = (&c.g[0][..n], &c.g[1][..n], &c.g[2][..n]);
        for j in 0..n {
            let (a, b, d) = (cx[j], cy[j], cz[j]);
            let (wx, wy, wz) = (gx[j], gy[j], gz[j]);
            for lane in 0..LANES {
                let (u, v, w) = (px[lane] - a, py[lane] - b, pz[lane] - d);
                let r2 = u.mul_add(u, v.mul_add(v, w * w));
                let f = phi(r2);
                acc[0][lane] = f.mul_add(wx, acc[0][lane]);
                acc[1][lane] = f.mul_add(wy, acc[1][lane]);
                acc[2][lane] = f.mul_add(wz, acc[2][lane]);
            }
        }
        acc
    }
}

#[inline(always)]
fn run<F: Fn(f64) -> f64>(
    c: &Centres,
    px: &[f64; LANES],
    py: &[f64; LANES],
    pz: &[f64; LANES],
    phi: F,
) -> [[f64; LANES]; 3] {
    pulp::Arch::new().dispatch(Sums { c, px, py, pz, phi })
}

/// `out[i] = [Σⱼ γⱼᶜ φ(‖pᵢ − cⱼ‖)]` for a compactly supported kernel, over the centres
/// of the grid cells around each point (no allocation, branch-free kernel: the factor
/// `max(1 − r/s, 0)` zeroes the centres beyond the support).
pub(crate) fn grid_sums(kernel: &Kernel, grid: &Grid, pts: &[Point3<f64>], out: &mut [[f64; 3]]) {
    match *kernel {
        Kernel::BeckertWendlandC2 { radius: s } | Kernel::WendlandC2 { support: s } => {
            let inv = 1.0 / s;
            run_grid(grid, pts, out, move |r2| {
                let a = r2.sqrt() * inv;
                let t = (1.0 - a).max(0.0);
                let t2 = t * t;
                t2 * t2 * (4.0 * a + 1.0)
            })
        }
        Kernel::WendlandC0 { support: s } => {
            let inv = 1.0 / s;
            run_grid(grid, pts, out, move |r2| {
                let t = (1.0 - r2.sqrt() * inv).max(0.0);
                t * t
            })
        }
        Kernel::WendlandC4 { support: s } => {
            let inv = 1.0 / s;
            run_grid(grid, pts, out, move |r2| {
                let a = r2.sqrt() * inv;
                let t = (1.0 - a).max(0.0);
                let t3 = t * t * t;
                t3 * t3 * (35.0 * a * a + 18.0 * a + 3.0) * (1.0 / 3.0)
            })
        }
        ref k => {
            let k = *k;
            run_grid(grid, pts, out, move |r2| k.eval(r2.sqrt()))
        }
    }
}

#[inline(always)]
fn run_grid<F: Fn(f64) -> f64>(grid: &Grid, pts: &[Point3<f64>], out: &mut [[f64; 3]], phi: F) {
    pulp::Arch::new().dispatch(GridSums { grid, pts, out, phi })
}

struct GridSums<'a, F> {
    grid: &'a Grid,
    pts: &'a [Point3<f64>],
    out: &'a mut [[f64; 3]],
    phi: F,
}

/// Centres handled together (independent accumulators, so that the sum vectorises).
const CL: usize = 4;

impl<F: Fn(f64) -> f64> pulp::WithSimd for GridSums<'_, F> {
    type Output = ();

    #[inline(always)]
    fn with_simd<S: pulp::Simd>(self, _simd: S) {
        let GridSums { grid, pts, out, phi } = self;
        for (p, o) in pts.iter().zip(out.iter_mut()) {
            let mut acc = [[0.0; CL]; 3];
            let mut tail = [0.0; 3];
            grid.for_each_range([p.x, p.y, p.z], |r| {
                let (cx, cy, cz) = (&grid.x[r.clone()], &grid.y[r.clone()], &grid.z[r.clone()]);
                let (gx, gy, gz) = (&grid.g[0][r.clone()], &grid.g[1][r.clone()], &grid.g[2][r]);
                let full = cx.len() / CL * CL;
                for j0 in (0..full).step_by(CL) {
                    for l in 0..CL {
                        let j = j0 + l;
                        let (u, v, w) = (p.x - cx[j], p.y - cy[j], p.z - cz[j]);
                        let f = phi(u.mul_add(u, v.mul_add(v, w * w)));
                        acc[0][l] = f.mul_add(gx[j], acc[0][l]);
                        acc[1][l] = f.mul_add(gy[j], acc[1][l]);
                        acc[2][l] = f.mul_add(gz[j], acc[2][l]);
                    }
                }
                for j in full..cx.len() {
                    let (u, v, w) = (p.x - cx[j], p.y - cy[j], p.z - cz[j]);
                    let f = phi(u.mul_add(u, v.mul_add(v, w * w)));
                    tail[0] = f.mul_add(gx[j], tail[0]);
                    tail[1] = f.mul_add(gy[j], tail[1]);
                    tail[2] = f.mul_add(gz[j], tail[2]);
                }
            });
            for c in 0..3 {
                o[c] = tail[c] + acc[c].iter().sum::<f64>();
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ln_fast_is_accurate() {
        let mut x = 1e-300;
        while x < 1e300 {
            for f in [
                1.0,
                1.234_567,
                std::f64::consts::SQRT_2 * (1.0 - 1e-9),
                std::f64::consts::SQRT_2 * (1.0 + 1e-9),
                1.9999,
            ] {
                let v = x * f;
                let (a, b) = (ln_fast(v), v.ln());
                assert!((a - b).abs() <= 4.0 * f64::EPSILON * b.abs().max(1.0), "{v}: {a} vs {b}");
            }
            x *= 7.3;
        }
        for v in [1.0, 2.0, 0.5, std::f64::consts::E] {
            assert!((ln_fast(v) - v.ln()).abs() <= 2.0 * f64::EPSILON);
        }
        assert_eq!(0.0 * ln_fast(0.0), 0.0);
    }

    #[test]
    fn sums_match_scalar_kernels() {
        let kernels = [
            Kernel::ThinPlate { radius: 0.7, k: 2 },
            Kernel::Polyharmonic { radius: 0.7, k: 2 },
            Kernel::Polyharmonic { radius: 0.7, k: 3 },
            Kernel::MultiQuadratic { radius: 0.7 },
            Kernel::InverseMultiQuadratic { radius: 0.7 },
            Kernel::WendlandC2 { support: 0.7 },
            Kernel::Gaussian { radius: 0.7 },
            Kernel::WendlandC4 { support: 0.7 },
        ];
        let c = Centres {
            x: vec![0.0, 0.3, 0.9],
            y: vec![0.1, 0.2, 0.8],
            z: vec![0.5, 0.0, 0.4],
            g: [vec![1.0, -2.0, 0.5], vec![0.0, 1.0, 1.0], vec![3.0, 0.0, -1.0]],
        };
        let px = [0.0, 0.3, 0.5, 0.1, 0.9, 0.2, 0.7, 0.4];
        let py = [0.1, 0.2, 0.5, 0.6, 0.8, 0.3, 0.1, 0.9];
        let pz = [0.5, 0.0, 0.5, 0.2, 0.4, 0.9, 0.6, 0.3];
        for k in kernels {
            let s = dense_sums(&k, &c, &px, &py, &pz);
            for lane in 0..LANES {
                for comp in 0..3 {
                    let mut e = 0.0;
                    for j in 0..3 {
                        let r =
                            ((px[lane] - c.x[j]).powi(2) + (py[lane] - c.y[j]).powi(2) + (pz[lane] - c.z[j]).powi(2))
                                .sqrt();
                        e += c.g[comp][j] * k.eval(r);
                    }
                    assert!((s[comp][lane] - e).abs() < 1e-13 * (1.0 + e.abs()), "{k:?}: {} vs {e}", s[comp][lane]);
                }
            }
        }
    }
}
