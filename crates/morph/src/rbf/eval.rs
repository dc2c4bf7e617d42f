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
/// Sixteen: the thin-plate term with its logarithm is a long dependency chain per pair, and
/// four AVX2 vectors of points per centre give the out-of-order core more independent work
/// (measured: about 8% less CPU time per pair than eight lanes on the AMD EPYC bench machine).
pub(crate) const LANES: usize = 16;

/// Centres and weights in structure-of-arrays form.
#[derive(Debug, Clone, Default)]
pub(crate) struct Centres {
    pub x: Vec<f64>,
    pub y: Vec<f64>,
    pub z: Vec<f64>,
    /// γ for the x, y, z displacement components.
    pub g: [Vec<f64>; 3],
}

/// `ln x` for finite `x ≥ 0`, branch-free so that it vectorises (the C library's `log` is
/// a scalar call).
///
/// The range reduction is fdlibm's `__ieee754_log` (as in FreeBSD and musl) with the
/// branches replaced by arithmetic: `x = 2ᵏ·m` with `m ∈ [√2/2, √2)` by an integer
/// addition on the bit pattern (the carry out of the mantissa bumps the exponent exactly
/// when the mantissa is at least √2). Then, with `f = m − 1` (exact) and `s = f/(2 + f)`,
/// `ln m = 2s + s·R(s²) = f + s·(R(s²) − f)`, where `R` is fdlibm's degree-14 minimax
/// polynomial (error below 2⁻⁵⁸·⁴⁵); the second form keeps the exact `f` as the leading
/// term, so the rounding of the division only touches the small correction. `k·ln 2` is
/// added in one fused multiply-add. Subnormal `x` is scaled by 2⁵⁴ first, so it is handled like the
/// normal numbers.
///
/// Measured against `f64::ln` on 2·10⁶ random inputs (10⁶ random bit patterns over all
/// binades, normal and subnormal, and 10⁶ uniform in (0, 4]), on dense samples around 1
/// and √2 and on subnormals (test `ln_fast_matches_ln`): never more than one ulp from
/// `f64::ln`, largest relative error 2.2·10⁻¹⁶. `ln_fast(0)` is a finite (meaningless)
/// number, so that `0 · ln_fast(0) = 0` and `r² ln r` needs no branch at r = 0. Infinite,
/// NaN and negative inputs give meaningless values.
// The complete function (subnormals included); the thin-plate sums clamp their argument
// and call `ln_fast_normal`.
#[cfg_attr(not(test), allow(dead_code))]
#[inline(always)]
pub(crate) fn ln_fast(x: f64) -> f64 {
    // Subnormals (and zero): scale into the normal range and remember the 54.
    let tiny = x < f64::MIN_POSITIVE;
    let x = if tiny { x * 18_014_398_509_481_984.0 } else { x };
    ln_reduced(x, if tiny { EXPONENT_BIAS + 54.0 } else { EXPONENT_BIAS })
}

/// [`ln_fast`] for `x ≥ f64::MIN_POSITIVE` (no subnormal scaling; used where the caller
/// clamps its argument, two operations fewer per value). Same accuracy on that range.
#[inline(always)]
pub(crate) fn ln_fast_normal(x: f64) -> f64 {
    ln_reduced(x, EXPONENT_BIAS)
}

/// 2⁵² + 1023: subtracted from `2⁵² + biased exponent` to get the exponent as a float.
const EXPONENT_BIAS: f64 = 4_503_599_627_370_496.0 + 1023.0;

/// The body of [`ln_fast`] for a normal `x`; `bias` is [`EXPONENT_BIAS`] plus the power of
/// two `x` was scaled by.
#[inline(always)]
fn ln_reduced(x: f64, bias: f64) -> f64 {
    const LN2: f64 = std::f64::consts::LN_2;
    const LG1: f64 = f64::from_bits(0x3FE5_5555_5555_5593);
    const LG2: f64 = f64::from_bits(0x3FD9_9999_9997_FA04);
    const LG3: f64 = f64::from_bits(0x3FD2_4924_9422_9359);
    const LG4: f64 = f64::from_bits(0x3FCC_71C5_1D8E_78AF);
    const LG5: f64 = f64::from_bits(0x3FC7_4664_96CB_03DE);
    const LG6: f64 = f64::from_bits(0x3FC3_9A09_D078_C69F);
    const LG7: f64 = f64::from_bits(0x3FC2_F112_DF3E_5244);
    const SQRT_HALF_HI: u64 = 0x3FE6_A09E_0000_0000; // the upper word of √2/2
                                                     // Shift the mantissa range [1, 2) to [√2/2, √2): adding 1.0's exponent minus √2/2's
                                                     // upper word carries into the exponent exactly when the mantissa is ≥ √2.
    let u = x.to_bits().wrapping_add(0x3FF0_0000_0000_0000 - SQRT_HALF_HI);
    // The exponent as an exact float: put it in the mantissa of 2⁵² and subtract.
    let k = f64::from_bits((u >> 52) | 0x4330_0000_0000_0000) - bias;
    let m = f64::from_bits((u & 0x000F_FFFF_FFFF_FFFF) + SQRT_HALF_HI);
    let f = m - 1.0;
    let s = f / (2.0 + f);
    let z = s * s;
    let w = z * z;
    // R(z) = z·(LG1 + w·(LG3 + w·(LG5 + w·LG7))) + w·(LG2 + w·(LG4 + w·LG6)), two chains.
    let odd = w.mul_add(w.mul_add(LG7, LG5), LG3);
    let even = w.mul_add(w.mul_add(LG6, LG4), LG2);
    let r = z.mul_add(w.mul_add(odd, LG1), w * even);
    let ln_m = s.mul_add(r - f, f);
    // k·ln 2 in one fused step: the product is exact inside the FMA, and ln 2's own
    // rounding (3·10⁻¹⁷ relative) stays far below half an ulp.
    k.mul_add(LN2, ln_m)
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
        Kernel::ThinPlate { radius, k: 2 } | Kernel::Polyharmonic { radius, k: 2 } => {
            let s = 1.0 / (radius * radius);
            // (r/R)² ln(r/R) = ½ a ln a with a = r²/R² (the ½ is applied to the sums).
            // Below the smallest normal number a·ln a is below 10⁻³⁰⁵ in magnitude: clamping
            // there (instead of scaling subnormals) changes no sum, and a = 0 still gives 0.
            let sums = run(c, px, py, pz, move |r2| {
                let a = r2 * s;
                a * ln_fast_normal(a.max(f64::MIN_POSITIVE))
            });
            sums.map(|comp| comp.map(|v| 0.5 * v))
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

    /// Largest relative error of [`ln_fast`] against `f64::ln` over `xs`, and the largest
    /// distance in ulps (units in the last place).
    fn max_err(xs: impl Iterator<Item = f64>) -> (f64, u64) {
        xs.map(|v| {
            let (a, b) = (ln_fast(v), v.ln());
            assert!(a.is_finite(), "{v}: {a}");
            let ulps = if a.signum() == b.signum() { a.to_bits().abs_diff(b.to_bits()) } else { u64::MAX };
            ((a - b).abs() / b.abs().max(f64::MIN_POSITIVE), ulps)
        })
        .fold((0.0, 0), |(e, u), (f, v)| (e.max(f), u.max(v)))
    }

    #[test]
    fn ln_fast_matches_ln() {
        let mut state = 0x2545_F491_4F6C_DD1Du64;
        let mut next = move || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            state
        };
        // Random bit patterns of positive finite numbers: every binade, subnormals included.
        let all =
            max_err((0..1_000_000).map(|_| f64::from_bits(next() % 0x7FF0_0000_0000_0000).max(f64::from_bits(1))));
        // Uniform in (0, 4], where the thin-plate arguments r²/R² mostly lie.
        let unit = max_err((0..1_000_000).map(|_| 4.0 * ((next() >> 11) as f64 + 1.0) / (1u64 << 53) as f64));
        // Around 1 (where ln is small and the relative error hardest) and √2 (the range split).
        let one =
            max_err((1..20_000).flat_map(|i| [1.0 + i as f64 * 1e-9, 1.0 - i as f64 * 1e-9, 1.0 + i as f64 * 1e-5]));
        let split = max_err((-5000..5000).map(|i| std::f64::consts::SQRT_2 * (1.0 + i as f64 * f64::EPSILON)));
        // Subnormals: the smallest, powers of two, and a spread.
        let subnormal = max_err(
            (0..52).map(|b| f64::from_bits(1u64 << b)).chain((1..10_000).map(|i| f64::from_bits(i * 450_359_962_737))),
        );
        for (what, e) in [("all", all), ("unit", unit), ("one", one), ("split", split), ("subnormal", subnormal)] {
            // Measured: at most one ulp, relative error at most 2.2e-16 (see ln_fast).
            assert!(e.1 <= 1 && e.0 <= 2.3e-16, "{what}: relative error {:e}, {} ulp", e.0, e.1);
        }
        // The unclamped variant on normal numbers: the same values.
        for v in [f64::MIN_POSITIVE, 1e-300, 0.3, 1.0 + 1e-12, 7.0, 1e300, f64::MAX] {
            assert_eq!(ln_fast_normal(v), ln_fast(v));
        }
        for v in [1.0, 2.0, 0.5, 4.0, 1024.0] {
            assert_eq!(ln_fast(v), v.ln());
        }
        assert_eq!(ln_fast(f64::MAX), f64::MAX.ln());
        // r = 0: a finite value, so that the thin-plate term a·ln a is exactly 0.
        assert!(ln_fast(0.0).is_finite());
        assert_eq!(0.0 * ln_fast(0.0), 0.0);
        let tps = Kernel::ThinPlate { radius: 0.5, k: 2 };
        let c = Centres {
            x: vec![0.0; 4],
            y: vec![0.0; 4],
            z: vec![0.0; 4],
            g: [vec![1.0; 4], vec![1.0; 4], vec![1.0; 4]],
        };
        let zero = [0.0; LANES];
        assert_eq!(dense_sums(&tps, &c, &zero, &zero, &zero), [[0.0; LANES]; 3]);
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
        let px: [f64; LANES] =
            std::array::from_fn(|i| [0.0, 0.3, 0.5, 0.1, 0.9, 0.2, 0.7, 0.4][i % 8] + 0.01 * i as f64);
        let py: [f64; LANES] = std::array::from_fn(|i| [0.1, 0.2, 0.5, 0.6, 0.8, 0.3, 0.1, 0.9][i % 8]);
        let pz: [f64; LANES] =
            std::array::from_fn(|i| [0.5, 0.0, 0.5, 0.2, 0.4, 0.9, 0.6, 0.3][i % 8] - 0.02 * i as f64);
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
