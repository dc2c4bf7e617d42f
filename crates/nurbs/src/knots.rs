//! Knot vectors: validation, span search, multiplicities and the usual constructions.

use std::ops::{Index, RangeInclusive};

use crate::{Error, Result};

/// A non-decreasing sequence of finite knots `U = {u₀ ≤ u₁ ≤ … ≤ u_m}`.
///
/// A `KnotVector` alone does not know its degree; the curve or surface that owns it
/// checks the count (`m + 1 = n + p + 2` for `n + 1` control points of degree `p`)
/// and the multiplicities (at most `p + 1`). The valid parameter range of a degree-`p`
/// spline is `[u_p, u_{m-p}]`; for a clamped vector that is `[u₀, u_m]`.
///
/// # Examples
///
/// ```
/// use cadmorph_nurbs::KnotVector;
/// // The NURBS Book, Ex. 2.3: U = {0,0,0,1,2,3,4,4,5,5,5}, p = 2.
/// let u = KnotVector::try_new(vec![0., 0., 0., 1., 2., 3., 4., 4., 5., 5., 5.]).unwrap();
/// assert_eq!(u.find_span(2, 2.5), 4);
/// assert_eq!(u.multiplicity(4.0, 1e-12), 2);
/// assert!(u.is_clamped(2));
/// ```
#[derive(Debug, Clone, PartialEq)]
pub struct KnotVector(Vec<f64>);

impl KnotVector {
    /// Validates and wraps `knots`.
    ///
    /// # Errors
    ///
    /// [`Error::NotFinite`] for NaN or infinite knots, [`Error::DecreasingKnots`] where
    /// the sequence goes down, [`Error::EmptyDomain`] if all knots are equal or there
    /// are fewer than two.
    pub fn try_new(knots: Vec<f64>) -> Result<Self> {
        for (index, &value) in knots.iter().enumerate() {
            if !value.is_finite() {
                return Err(Error::NotFinite { what: "knot", index, value });
            }
            if index > 0 && value < knots[index - 1] {
                return Err(Error::DecreasingKnots { index, value, previous: knots[index - 1] });
            }
        }
        match (knots.first(), knots.last()) {
            (Some(&start), Some(&end)) if end > start => Ok(Self(knots)),
            (start, end) => Err(Error::EmptyDomain {
                start: start.copied().unwrap_or(f64::NAN),
                end: end.copied().unwrap_or(f64::NAN),
            }),
        }
    }

    /// Wraps `knots` without checking them. The caller guarantees what
    /// [`try_new`](Self::try_new) checks.
    pub fn new_unchecked(knots: Vec<f64>) -> Self {
        Self(knots)
    }

    /// Builds the flat vector from distinct values and their multiplicities (the
    /// IGES/STEP/OCCT form, `knots` + `mults`).
    ///
    /// # Errors
    ///
    /// [`Error::MultiplicityList`] if the lengths differ or a multiplicity is zero, and
    /// whatever [`try_new`](Self::try_new) reports.
    pub fn from_multiplicities(values: &[f64], mults: &[usize]) -> Result<Self> {
        if values.len() != mults.len() || mults.contains(&0) {
            return Err(Error::MultiplicityList { knots: values.len(), mults: mults.len() });
        }
        let total: usize = mults.iter().sum();
        if total > 1 << 24 {
            return Err(Error::MultiplicityList { knots: values.len(), mults: mults.len() });
        }
        let mut knots = Vec::with_capacity(total);
        for (&v, &m) in values.iter().zip(mults) {
            knots.extend(std::iter::repeat_n(v, m));
        }
        Self::try_new(knots)
    }

    /// The clamped uniform knot vector on `[0, 1]` for `n_control` control points of
    /// degree `p`: `p + 1` zeros, equally spaced interior knots, `p + 1` ones.
    ///
    /// # Panics
    ///
    /// If `n_control <= p`.
    pub fn clamped_uniform(p: usize, n_control: usize) -> Self {
        assert!(n_control > p, "need more than {p} control points, got {n_control}");
        let segments = n_control - p;
        let mut knots = vec![0.0; p + 1];
        knots.extend((1..segments).map(|i| i as f64 / segments as f64));
        knots.extend(std::iter::repeat_n(1.0, p + 1));
        Self(knots)
    }

    /// The uniform (unclamped) knot vector `0, 1, …, n_control + p` for `n_control`
    /// control points of degree `p`; its spline domain is `[p, n_control]`.
    ///
    /// # Panics
    ///
    /// If `n_control <= p`.
    pub fn uniform(p: usize, n_control: usize) -> Self {
        assert!(n_control > p, "need more than {p} control points, got {n_control}");
        Self((0..n_control + p + 1).map(|i| i as f64).collect())
    }

    /// The unclamped knot vector of a periodic spline of degree `p`, from one period of
    /// distinct knots `values[0] < … < values[k]` with interior multiplicities `mults`
    /// (the first and last multiplicity must be equal, as in OCCT).
    ///
    /// One period holds `Σ mults[..k]` control points; the returned vector has that many
    /// plus `p` (the first `p` control points repeated at the end) and its spline domain
    /// is `[values[0], values[k]]`.
    ///
    /// # Errors
    ///
    /// [`Error::MultiplicityList`] for mismatched lists, [`Error::Periodic`] if the end
    /// multiplicities differ or a multiplicity exceeds `p`.
    pub fn periodic(p: usize, values: &[f64], mults: &[usize]) -> Result<Self> {
        if values.len() != mults.len() || values.len() < 2 || mults.contains(&0) {
            return Err(Error::MultiplicityList { knots: values.len(), mults: mults.len() });
        }
        let k = values.len() - 1;
        if mults[0] != mults[k] {
            return Err(Error::Periodic { reason: "first and last knot multiplicities differ" });
        }
        if mults.iter().any(|&m| m > p) {
            return Err(Error::Periodic { reason: "a multiplicity exceeds the degree" });
        }
        let period = values[k] - values[0];
        // One period of knots, the first one counted once.
        let mut one: Vec<f64> = Vec::new();
        for i in 1..=k {
            one.extend(std::iter::repeat_n(values[i], mults[i]));
        }
        let n_period = one.len(); // = Σ mults[..k] = number of poles in a period
        if n_period == 0 || !period.is_finite() || period <= 0.0 {
            return Err(Error::Periodic { reason: "empty period" });
        }
        // Flat vector: u_p = values[0]; knots before it and after the period end
        // continue periodically.
        let n_ctrl = n_period + p;
        let len = n_ctrl + p + 1;
        let mut knots = vec![0.0; len];
        // Position p holds values[0] (its last copy among the mult copies).
        let at = |j: isize| -> f64 {
            // j-th knot after values[0] (j >= 1 → one[j-1]), periodic extension.
            let n = n_period as isize;
            let q = (j - 1).div_euclid(n);
            let r = (j - 1).rem_euclid(n) as usize;
            one[r] + q as f64 * period
        };
        for (i, knot) in knots.iter_mut().enumerate() {
            let j = i as isize - p as isize;
            *knot = if j == 0 { values[0] } else { at(j) };
        }
        Self::try_new(knots)
    }

    /// The knots as a slice.
    pub fn as_slice(&self) -> &[f64] {
        &self.0
    }

    /// Consumes the vector and returns the knots.
    pub fn into_vec(self) -> Vec<f64> {
        self.0
    }

    /// Number of knots, `m + 1`.
    #[allow(clippy::len_without_is_empty)]
    pub fn len(&self) -> usize {
        self.0.len()
    }

    /// The spline domain `[u_p, u_{m-p}]` for degree `p`.
    pub fn domain(&self, p: usize) -> RangeInclusive<f64> {
        self.0[p]..=self.0[self.0.len() - 1 - p]
    }

    /// Whether the first and last `p + 1` knots are equal (the spline interpolates its
    /// end control points).
    pub fn is_clamped(&self, p: usize) -> bool {
        let m = self.0.len() - 1;
        self.0[..=p].iter().all(|&k| k == self.0[0]) && self.0[m - p..].iter().all(|&k| k == self.0[m])
    }

    /// Index `i` of the knot span `[u_i, u_{i+1})` that holds `u`, for degree `p`
    /// (Piegl & Tiller A2.1). Parameters outside the domain are clamped to it, and the
    /// domain end belongs to the last non-empty span.
    pub fn find_span(&self, p: usize, u: f64) -> usize {
        find_span(&self.0, p, u)
    }

    /// The number of knots equal to `u` within `ptol`.
    pub fn multiplicity(&self, u: f64, ptol: f64) -> usize {
        self.0.iter().filter(|&&k| (k - u).abs() <= ptol).count()
    }

    /// Distinct knot values and their multiplicities (the IGES/STEP/OCCT form).
    pub fn distinct(&self) -> (Vec<f64>, Vec<usize>) {
        let mut values: Vec<f64> = Vec::new();
        let mut mults: Vec<usize> = Vec::new();
        for &k in &self.0 {
            if values.last() == Some(&k) {
                *mults.last_mut().expect("pushed with the value") += 1;
            } else {
                values.push(k);
                mults.push(1);
            }
        }
        (values, mults)
    }

    /// Checks the vector against a degree and a control-point count.
    pub(crate) fn check_for(&self, p: usize, n_control: usize, direction: &'static str) -> Result<()> {
        if p == 0 || p > crate::MAX_DEGREE {
            return Err(Error::Degree { degree: p });
        }
        if n_control < p + 1 {
            return Err(Error::TooFewControlPoints { degree: p, found: n_control });
        }
        if self.0.len() != n_control + p + 1 {
            return Err(Error::KnotCount {
                direction,
                expected: n_control + p + 1,
                found: self.0.len(),
                degree: p,
                control_points: n_control,
            });
        }
        let (values, mults) = self.distinct();
        for (value, multiplicity) in values.into_iter().zip(mults) {
            if multiplicity > p + 1 {
                return Err(Error::Multiplicity { value, multiplicity, max: p + 1 });
            }
        }
        let d = self.domain(p);
        if d.end() <= d.start() {
            return Err(Error::EmptyDomain { start: *d.start(), end: *d.end() });
        }
        Ok(())
    }

    /// The same knots mirrored: `ū_i = a + b − u_{m−i}` (used to reverse a spline).
    pub fn reversed(&self) -> Self {
        let a = self.0[0];
        let b = self.0[self.0.len() - 1];
        Self(self.0.iter().rev().map(|&k| a + b - k).collect())
    }
}

impl Index<usize> for KnotVector {
    type Output = f64;
    fn index(&self, i: usize) -> &f64 {
        &self.0[i]
    }
}

impl AsRef<[f64]> for KnotVector {
    fn as_ref(&self) -> &[f64] {
        &self.0
    }
}

/// Span search on a raw knot slice (Piegl & Tiller A2.1), by bisection.
///
/// Returns `i` with `u_i ≤ u < u_{i+1}` and `p ≤ i ≤ n`, where `n = knots.len() − p − 2`;
/// `u` at or beyond the domain end gives the last non-empty span, `u` before the start
/// gives `p`. NaN gives `p`.
pub(crate) fn find_span(knots: &[f64], p: usize, u: f64) -> usize {
    let n = knots.len() - p - 2;
    if u >= knots[n + 1] {
        // Last non-empty span.
        let mut i = n;
        while i > p && knots[i] == knots[n + 1] {
            i -= 1;
        }
        return i;
    }
    if u.is_nan() || u <= knots[p] {
        // First non-empty span.
        let mut i = p;
        while i < n && knots[i + 1] == knots[p] {
            i += 1;
        }
        return i;
    }
    let (mut low, mut high) = (p, n + 1);
    while high - low > 1 {
        let mid = (low + high) / 2;
        if u < knots[mid] {
            high = mid;
        } else {
            low = mid;
        }
    }
    low
}
