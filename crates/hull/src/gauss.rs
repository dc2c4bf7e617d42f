//! Gauss–Legendre quadrature rules on an interval.

/// The `n`-point Gauss–Legendre rule on `[a, b]` as `(node, weight)` pairs: exact for
/// polynomials of degree `2n − 1`. Nodes are the roots of the Legendre polynomial
/// `P_n`, found by Newton's method from Tricomi's approximation (Numerical Recipes
/// §4.6 `gauleg`), to full double precision.
pub fn gauss_legendre(n: usize, a: f64, b: f64) -> Vec<(f64, f64)> {
    let n = n.max(1);
    let (mid, half) = (0.5 * (a + b), 0.5 * (b - a));
    let mut out = vec![(0.0, 0.0); n];
    for i in 0..n.div_ceil(2) {
        let mut z = (std::f64::consts::PI * (i as f64 + 0.75) / (n as f64 + 0.5)).cos();
        let mut dp = 1.0;
        for _ in 0..100 {
            // P_n(z) and P_n'(z) by the three-term recurrence.
            let (mut p1, mut p2) = (1.0, 0.0);
            for j in 0..n {
                let p3 = p2;
                p2 = p1;
                p1 = ((2 * j + 1) as f64 * z * p2 - j as f64 * p3) / (j + 1) as f64;
            }
            dp = n as f64 * (z * p1 - p2) / (z * z - 1.0);
            let step = p1 / dp;
            z -= step;
            if step.abs() <= 1e-16 {
                break;
            }
        }
        let w = 2.0 / ((1.0 - z * z) * dp * dp);
        out[i] = (mid - half * z, half * w);
        out[n - 1 - i] = (mid + half * z, half * w);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn integrates_polynomials_exactly() {
        for n in 1..12 {
            let rule = gauss_legendre(n, -0.5, 2.0);
            for k in 0..2 * n {
                let got: f64 = rule.iter().map(|&(x, w)| w * x.powi(k as i32)).sum();
                let exact = (2f64.powi(k as i32 + 1) - (-0.5f64).powi(k as i32 + 1)) / (k + 1) as f64;
                assert!((got - exact).abs() <= 1e-13 * exact.abs().max(1.0), "n {n} k {k}: {got} vs {exact}");
            }
        }
    }

    #[test]
    fn five_point_rule_matches_the_tabulated_one() {
        // Abramowitz & Stegun table 25.4, n = 5 on [−1, 1].
        let rule = gauss_legendre(5, -1.0, 1.0);
        assert!((rule[4].0 - 0.906_179_845_938_664).abs() < 1e-15);
        assert!((rule[4].1 - 0.236_926_885_056_189).abs() < 1e-15);
        assert!((rule[2].0).abs() < 1e-16 && (rule[2].1 - 0.568_888_888_888_889).abs() < 1e-15);
    }
}
