//! Vectorised sums `Σⱼ γⱼ φ(‖x − cⱼ‖)` over all centres for a block of points.
//!
//! Each kernel is written as a function of the squared distance ([`Phi`]) so that no square
//! root is taken where none is needed, and the thin-plate logarithm uses [`ln_minus`], a
//! branch-free `ln` that the compiler vectorises (the C library's `log` is a scalar call).
//! The loops run inside `crate::simd::dispatch`, which compiles them for AVX-512 or AVX2/FMA when the
//! CPU has them.

use nalgebra::Point3;

use super::grid::Grid;
use super::Kernel;

/// Centres taken together by the dense sums (one SIMD lane each: two AVX2 vectors).
/// The sums run across the centres for one point at a time, so a point's coordinates and
/// its accumulators stay in registers and the centres stream from cache. Measured on the
/// AMD EPYC bench machine (thin plate, 1000 centres, one core), this layout costs 0.19 s
/// per 10⁸ pairs against 0.26 s for the previous sixteen points per centre, which spilled
/// most of its registers. Four lanes leave too little independent work for the long
/// logarithm chain (0.26 s), sixteen spill again (0.23 s). The thin-plate loop written out
/// in AVX2 intrinsics was no faster (0.75 against 0.70 s per 4·10⁸ pairs) and was not kept.
const CW: usize = 8;

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
    ln_reduced(x, if tiny { EXPONENT_BIAS + 54.0 } else { EXPONENT_BIAS }, 0.0)
}

/// `ln x − c` for normal or zero `x` (no subnormal scaling): the thin-plate sums take the
/// logarithm of r² itself and subtract `c = ln R²` inside, off the dependency chain (one
/// rounding of `f − c`, an absolute error of half an ulp of `max(|f|, |c|)`). `ln_minus(0, c)`
/// is finite, so `0 · ln_minus(0, c) = 0`; a subnormal `x` gives a meaningless finite value,
/// which the thin-plate term multiplies by `x < 10⁻³⁰⁷`.
#[inline(always)]
pub(crate) fn ln_minus(x: f64, c: f64) -> f64 {
    ln_reduced(x, EXPONENT_BIAS, c)
}

/// 2⁵² + 1023: subtracted from `2⁵² + biased exponent` to get the exponent as a float.
const EXPONENT_BIAS: f64 = 4_503_599_627_370_496.0 + 1023.0;

/// The body of [`ln_fast`] for a normal `x`, less `c`; `bias` is [`EXPONENT_BIAS`] plus the
/// power of two `x` was scaled by.
#[inline(always)]
fn ln_reduced(x: f64, bias: f64, c: f64) -> f64 {
    const LN2: f64 = std::f64::consts::LN_2;
    const LG1: f64 = f64::from_bits(0x3FE5_5555_5555_5593);
    const LG2: f64 = f64::from_bits(0x3FD9_9999_9997_FA04);
    const LG3: f64 = f64::from_bits(0x3FD2_4924_9422_9359);
    const LG4: f64 = f64::from_bits(0x3FCC_71C5_1D8E_78AF);
    const LG5: f64 = f64::from_bits(0x3FC7_4664_96CB_03DE);
    const LG6: f64 = f64::from_bits(0x3FC3_9A09_D078_C69F);
    const LG7: f64 = f64::from_bits(0x3FC2_F112_DF3E_5244);
    // The upper word of √2/2. Shift the mantissa range [1, 2) to [√2/2, √2): adding 1.0's
    // exponent minus √2/2's upper word carries into the exponent exactly when the mantissa
    // is ≥ √2.
    const SQRT_HALF_HI: u64 = 0x3FE6_A09E_0000_0000;
    let u = x.to_bits().wrapping_add(0x3FF0_0000_0000_0000 - SQRT_HALF_HI);
    // The exponent as an exact float: put it in the mantissa of 2⁵² and subtract.
    let k = f64::from_bits((u >> 52) | 0x4330_0000_0000_0000) - bias;
    let m = f64::from_bits((u & 0x000F_FFFF_FFFF_FFFF) + SQRT_HALF_HI);
    let f = m - 1.0;
    // m + 1 is 2 + f, formed beside f rather than after it (the sums are latency-bound).
    let s = f / (m + 1.0);
    let z = s * s;
    // R(z) = z·P(z), P of degree 6 by Estrin's scheme (depth three instead of six).
    let w = z * z;
    let p01 = z.mul_add(LG2, LG1);
    let p23 = z.mul_add(LG4, LG3);
    let p45 = z.mul_add(LG6, LG5);
    let q0 = w.mul_add(p23, p01);
    let q1 = w.mul_add(LG7, p45);
    let p = (w * w).mul_add(q1, q0);
    // ln m = f + s·(R − f): the exact f leads, the division's rounding only touches the
    // small correction.
    let ln_m = s.mul_add(z.mul_add(p, -f), f - c);
    // k·ln 2 in one fused step: the product is exact inside the FMA, and ln 2's own
    // rounding (3·10⁻¹⁷ relative) stays far below half an ulp.
    k.mul_add(LN2, ln_m)
}

/// A kernel as the sums see it: `φ(r) = scale · value(r²)`, with `value` branch-free so that
/// it vectorises (the `scale` is applied once to each finished sum).
pub(crate) trait Phi: Copy {
    /// `φ(r) / scale` from `r²`.
    fn value(self, r2: f64) -> f64;
}

/// `r² (ln r² − ln R²)`, i.e. `(r/R)² ln(r/R)` with scale `1/(2R²)`.
#[derive(Clone, Copy)]
struct ThinPlate {
    ln_r2: f64,
}

impl Phi for ThinPlate {
    #[inline(always)]
    fn value(self, r2: f64) -> f64 {
        r2 * ln_minus(r2, self.ln_r2)
    }
}

/// `(r/R)³`.
#[derive(Clone, Copy)]
struct Cubic {
    inv: f64,
}

impl Phi for Cubic {
    #[inline(always)]
    fn value(self, r2: f64) -> f64 {
        let a = r2.sqrt() * self.inv;
        a * a * a
    }
}

/// `√(r² + R²)`, or its reciprocal when `INVERSE`.
#[derive(Clone, Copy)]
struct MultiQuadric<const INVERSE: bool> {
    r2: f64,
}

impl<const INVERSE: bool> Phi for MultiQuadric<INVERSE> {
    #[inline(always)]
    fn value(self, r2: f64) -> f64 {
        let q = (r2 + self.r2).sqrt();
        if INVERSE {
            1.0 / q
        } else {
            q
        }
    }
}

/// Wendland's compactly supported functions of `a = r/s`: the factor `max(1 − a, 0)` zeroes
/// the centres beyond the support without a branch.
/// `C` is the smoothness: 0, 2 or 4.
#[derive(Clone, Copy)]
struct Wendland<const C: u8> {
    inv: f64,
}

impl<const C: u8> Phi for Wendland<C> {
    #[inline(always)]
    fn value(self, r2: f64) -> f64 {
        let a = r2.sqrt() * self.inv;
        let t = (1.0 - a).max(0.0);
        match C {
            0 => t * t,
            2 => {
                let t2 = t * t;
                t2 * t2 * (4.0 * a + 1.0)
            }
            _ => {
                let t3 = t * t * t;
                t3 * t3 * (35.0 * a * a + 18.0 * a + 3.0) * (1.0 / 3.0)
            }
        }
    }
}

/// Any kernel through [`Kernel::eval`] (scalar: the Gaussian's `exp` and the other powers).
#[derive(Clone, Copy)]
struct Scalar(Kernel);

impl Phi for Scalar {
    #[inline(always)]
    fn value(self, r2: f64) -> f64 {
        self.0.eval(r2.sqrt())
    }
}

/// Something to run with a kernel's [`Phi`] form.
pub(crate) trait WithPhi {
    /// What the run gives back.
    type Output;
    /// Run with `phi`, whose values are `φ / scale`.
    fn run<P: Phi>(self, phi: P, scale: f64) -> Self::Output;
}

/// Calls `job` with the vectorised form of `kernel` (one match for every bulk loop).
pub(crate) fn with_phi<J: WithPhi>(kernel: &Kernel, job: J) -> J::Output {
    match *kernel {
        Kernel::ThinPlate { radius, k: 2 } | Kernel::Polyharmonic { radius, k: 2 } => {
            let r2 = radius * radius;
            job.run(ThinPlate { ln_r2: r2.ln() }, 0.5 / r2)
        }
        Kernel::Polyharmonic { radius, k: 3 } => job.run(Cubic { inv: 1.0 / radius }, 1.0),
        Kernel::MultiQuadratic { radius } => job.run(MultiQuadric::<false> { r2: radius * radius }, 1.0),
        Kernel::InverseMultiQuadratic { radius } => job.run(MultiQuadric::<true> { r2: radius * radius }, 1.0),
        Kernel::BeckertWendlandC2 { radius: s } | Kernel::WendlandC2 { support: s } => {
            job.run(Wendland::<2> { inv: 1.0 / s }, 1.0)
        }
        Kernel::WendlandC0 { support } => job.run(Wendland::<0> { inv: 1.0 / support }, 1.0),
        Kernel::WendlandC4 { support } => job.run(Wendland::<4> { inv: 1.0 / support }, 1.0),
        k => job.run(Scalar(k), 1.0),
    }
}

/// `out[i] = [Σⱼ γⱼᶜ φ(‖pᵢ − cⱼ‖)]` over all centres (dense kernels).
pub(crate) fn dense_sums(kernel: &Kernel, c: &Centres, pts: &[Point3<f64>], out: &mut [[f64; 3]]) {
    with_phi(kernel, SumsJob { centres: Source::All(c), pts, out })
}

/// `out[i] = [Σⱼ γⱼᶜ φ(‖pᵢ − cⱼ‖)]` for a compactly supported kernel, over the centres
/// of the grid cells around each point (no allocation, branch-free kernel: the factor
/// `max(1 − r/s, 0)` zeroes the centres beyond the support).
pub(crate) fn grid_sums(kernel: &Kernel, grid: &Grid, pts: &[Point3<f64>], out: &mut [[f64; 3]]) {
    with_phi(kernel, SumsJob { centres: Source::Grid(grid), pts, out })
}

/// The centres a sum runs over.
enum Source<'a> {
    All(&'a Centres),
    Grid(&'a Grid),
}

struct SumsJob<'a> {
    centres: Source<'a>,
    pts: &'a [Point3<f64>],
    out: &'a mut [[f64; 3]],
}

impl WithPhi for SumsJob<'_> {
    type Output = ();

    fn run<P: Phi>(self, phi: P, scale: f64) {
        let SumsJob { centres, pts, out } = self;
        match centres {
            Source::All(c) => crate::simd::dispatch(DenseSimd { c, pts, out: &mut *out, phi }),
            Source::Grid(grid) => crate::simd::dispatch(GridSums { grid, pts, out: &mut *out, phi }),
        }
        if scale != 1.0 {
            out.iter_mut().for_each(|o| *o = o.map(|v| v * scale));
        }
    }
}

/// The sum loop, compiled inside `pulp`'s target-feature function: its body must be in
/// `with_simd` itself (a closure body would stay a separate function without AVX2/FMA).
struct DenseSimd<'a, P> {
    c: &'a Centres,
    pts: &'a [Point3<f64>],
    out: &'a mut [[f64; 3]],
    phi: P,
}

impl<P: Phi> pulp::WithSimd for DenseSimd<'_, P> {
    type Output = ();

    #[inline(always)]
    fn with_simd<S: pulp::Simd>(self, _simd: S) {
        let DenseSimd { c, pts, out, phi } = self;
        let n = c.x.len();
        let full = n / CW * CW;
        let (cx, cy, cz) = (&c.x[..n], &c.y[..n], &c.z[..n]);
        let (gx, gy, gz) = (&c.g[0][..n], &c.g[1][..n], &c.g[2][..n]);
        for (p, o) in pts.iter().zip(out.iter_mut()) {
            let mut acc = [[0.0; CW]; 3];
            let blocks = cx[..full]
                .chunks_exact(CW)
                .zip(cy[..full].chunks_exact(CW))
                .zip(cz[..full].chunks_exact(CW))
                .zip(gx[..full].chunks_exact(CW).zip(gy[..full].chunks_exact(CW)).zip(gz[..full].chunks_exact(CW)));
            for (((bx, by), bz), ((wx, wy), wz)) in blocks {
                for l in 0..CW {
                    let (u, v, w) = (p.x - bx[l], p.y - by[l], p.z - bz[l]);
                    let f = phi.value(u.mul_add(u, v.mul_add(v, w * w)));
                    acc[0][l] = f.mul_add(wx[l], acc[0][l]);
                    acc[1][l] = f.mul_add(wy[l], acc[1][l]);
                    acc[2][l] = f.mul_add(wz[l], acc[2][l]);
                }
            }
            let mut tail = [0.0; 3];
            for j in full..n {
                let (u, v, w) = (p.x - cx[j], p.y - cy[j], p.z - cz[j]);
                let f = phi.value(u.mul_add(u, v.mul_add(v, w * w)));
                tail[0] = f.mul_add(gx[j], tail[0]);
                tail[1] = f.mul_add(gy[j], tail[1]);
                tail[2] = f.mul_add(gz[j], tail[2]);
            }
            for (k, t) in tail.iter().enumerate() {
                o[k] = t + acc[k].iter().sum::<f64>();
            }
        }
    }
}

/// `out[i] = φ(‖p − cᵢ‖)` for every centre: a column of the interpolation matrix.
pub(crate) fn kernel_column(kernel: &Kernel, c: &Centres, p: Point3<f64>, out: &mut [f64]) {
    with_phi(kernel, Column { c, p, out })
}

struct Column<'a> {
    c: &'a Centres,
    p: Point3<f64>,
    out: &'a mut [f64],
}

impl WithPhi for Column<'_> {
    type Output = ();

    fn run<P: Phi>(self, phi: P, scale: f64) {
        crate::simd::dispatch(ColumnSimd { col: self, phi, scale })
    }
}

struct ColumnSimd<'a, P> {
    col: Column<'a>,
    phi: P,
    scale: f64,
}

impl<P: Phi> pulp::WithSimd for ColumnSimd<'_, P> {
    type Output = ();

    #[inline(always)]
    fn with_simd<S: pulp::Simd>(self, _simd: S) {
        let ColumnSimd { col: Column { c, p, out }, phi, scale } = self;
        let n = out.len();
        for (((o, &x), &y), &z) in out.iter_mut().zip(&c.x[..n]).zip(&c.y[..n]).zip(&c.z[..n]) {
            let (u, v, w) = (p.x - x, p.y - y, p.z - z);
            *o = scale * phi.value(u.mul_add(u, v.mul_add(v, w * w)));
        }
    }
}

/// The grid sum loop (see [`DenseSimd`] on why it is a `WithSimd` type).
struct GridSums<'a, P> {
    grid: &'a Grid,
    pts: &'a [Point3<f64>],
    out: &'a mut [[f64; 3]],
    phi: P,
}

/// Centres handled together (independent accumulators, so that the sum vectorises).
const CL: usize = 4;

impl<P: Phi> pulp::WithSimd for GridSums<'_, P> {
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
                        let f = phi.value(u.mul_add(u, v.mul_add(v, w * w)));
                        acc[0][l] = f.mul_add(gx[j], acc[0][l]);
                        acc[1][l] = f.mul_add(gy[j], acc[1][l]);
                        acc[2][l] = f.mul_add(gz[j], acc[2][l]);
                    }
                }
                for j in full..cx.len() {
                    let (u, v, w) = (p.x - cx[j], p.y - cy[j], p.z - cz[j]);
                    let f = phi.value(u.mul_add(u, v.mul_add(v, w * w)));
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
        // The variant without subnormal scaling, on normal numbers: the same values, and
        // less c the same values as subtracting afterwards (to the one rounding of f − c).
        for v in [f64::MIN_POSITIVE, 1e-300, 0.3, 1.0 + 1e-12, 7.0, 1e300, f64::MAX] {
            assert_eq!(ln_minus(v, 0.0), ln_fast(v));
            for c in [-1.3862943611198906, 0.5, 3.0] {
                let (a, b) = (ln_minus(v, c), v.ln() - c);
                assert!((a - b).abs() <= 4.0 * f64::EPSILON * b.abs().max(c.abs()), "{v} {c}: {a} vs {b}");
            }
        }
        assert!(ln_minus(0.0, -1.3862943611198906).is_finite());
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
        let mut out = [[1.0; 3]; 3];
        dense_sums(&tps, &c, &[Point3::origin(); 3], &mut out);
        assert_eq!(out, [[0.0; 3]; 3]);
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
            Kernel::WendlandC0 { support: 0.7 },
            Kernel::BeckertWendlandC2 { radius: 0.7 },
            Kernel::ThinPlate { radius: 0.7, k: 3 },
        ];
        // Enough centres for full SIMD blocks and a tail.
        let m = 2 * CW + 3;
        let c = Centres {
            x: (0..m).map(|j| [0.0, 0.3, 0.9][j % 3] + 0.011 * j as f64).collect(),
            y: (0..m).map(|j| [0.1, 0.2, 0.8][j % 3] - 0.007 * j as f64).collect(),
            z: (0..m).map(|j| [0.5, 0.0, 0.4][j % 3] + 0.003 * j as f64).collect(),
            g: [
                (0..m).map(|j| [1.0, -2.0, 0.5][j % 3] * (1.0 + 0.1 * j as f64)).collect(),
                (0..m).map(|j| [0.0, 1.0, 1.0][j % 3] - 0.05 * j as f64).collect(),
                (0..m).map(|j| [3.0, 0.0, -1.0][j % 3]).collect(),
            ],
        };
        // Points at centres too (r = 0).
        let pts: Vec<Point3<f64>> = (0..20)
            .map(|i| {
                Point3::new(
                    [0.0, 0.3, 0.5, 0.1, 0.9, 0.2, 0.7, 0.4][i % 8] + 0.01 * i as f64,
                    [0.1, 0.2, 0.5, 0.6, 0.8, 0.3, 0.1, 0.9][i % 8],
                    [0.5, 0.0, 0.5, 0.2, 0.4, 0.9, 0.6, 0.3][i % 8] - 0.02 * i as f64,
                )
            })
            .chain([Point3::new(c.x[0], c.y[0], c.z[0]), Point3::new(c.x[m - 1], c.y[m - 1], c.z[m - 1])])
            .collect();
        crate::simd::for_each_isa(|isa| sums_match(isa, &kernels, &c, &pts, m));
    }

    /// The dense sums and kernel columns of [`sums_match_scalar_kernels`] against the scalar
    /// kernel, in one instruction set.
    fn sums_match(isa: &str, kernels: &[Kernel], c: &Centres, pts: &[Point3<f64>], m: usize) {
        for &k in kernels {
            let mut s = vec![[0.0; 3]; pts.len()];
            dense_sums(&k, c, pts, &mut s);
            let mut col = vec![0.0; m];
            for (i, p) in pts.iter().enumerate() {
                kernel_column(&k, c, *p, &mut col);
                for comp in 0..3 {
                    let mut e = 0.0;
                    let mut mag = 0.0;
                    for j in 0..m {
                        let r = ((p.x - c.x[j]).powi(2) + (p.y - c.y[j]).powi(2) + (p.z - c.z[j]).powi(2)).sqrt();
                        let phi = k.eval(r);
                        assert!((col[j] - phi).abs() <= 1e-14 * (1.0 + phi.abs()), "{isa} {k:?}: {} vs {phi}", col[j]);
                        e += c.g[comp][j] * phi;
                        mag += (c.g[comp][j] * phi).abs();
                    }
                    assert!((s[i][comp] - e).abs() < 1e-14 * (1.0 + mag), "{isa} {k:?}: {} vs {e}", s[i][comp]);
                }
            }
        }
    }
}
