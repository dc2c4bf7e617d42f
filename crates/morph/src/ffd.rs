//! Free-form deformation on a Bernstein lattice (paper §2.1.1, eq. (1)–(2)), as PyGeM's
//! `FFD` defines it.

use nalgebra::{Matrix3, Point3, Vector3};
use rayon::prelude::*;

use crate::deformation::{check_params, for_each_chunk, ChunkHook, ParamWeights, PARALLEL_CHUNK, PARALLEL_MIN_POINTS};
use crate::{affine::rotation_matrix, Deformation, Error, LinearInParameters, Result};

/// Default tolerance, in reference (unit-box) coordinates, within which a point outside the
/// closed box still counts as on its face. It absorbs the rounding of `ψ` (a few ulps of the
/// box size), so that a point lying on a face or corner in model coordinates moves like its
/// neighbours just inside. PyGeM has no such tolerance, and its face points may stay behind
/// when rounding puts them a hair outside (PyGeM issue 272).
pub const FACE_TOL: f64 = 1e-12;

/// The most lattice nodes along one axis: the Bernstein polynomials of degree `n − 1`
/// have binomial coefficients up to `C(n − 1, (n − 1)/2)`, which stays finite in `f64`
/// to degree 1029 only (beyond, every deformed point came out NaN and the morph failed on
/// a "folded" Jacobian).
pub const MAX_NODES_PER_AXIS: usize = 1024;

/// The most lattice nodes in all (64 × 64 × 64): every deformed point sums over every
/// node, so a 200 × 200 × 200 lattice (192 MB, within the memory budget) costs 24 million
/// products per point, minutes for a model of a few thousand control points.
pub const MAX_NODES: usize = 1 << 18;

/// Lattice displacements μ of an L×M×N FFD, in units of the box length along each rotated
/// box axis: PyGeM's `array_mu_x`, `array_mu_y`, `array_mu_z`.
///
/// Each component is stored flat in C order, `index(i, j, k) = (i·M + j)·N + k`, like
/// `array_mu_x.ravel()`.
#[derive(Debug, Clone, PartialEq)]
pub struct Displacements {
    shape: [usize; 3],
    /// μ along the box x axis, C order.
    pub x: Vec<f64>,
    /// μ along the box y axis, C order.
    pub y: Vec<f64>,
    /// μ along the box z axis, C order.
    pub z: Vec<f64>,
}

impl Displacements {
    /// All-zero displacements for an `[L, M, N]` lattice.
    pub fn zeros(shape: [usize; 3]) -> Self {
        let n = shape[0] * shape[1] * shape[2];
        Displacements { shape, x: vec![0.0; n], y: vec![0.0; n], z: vec![0.0; n] }
    }

    /// Displacements from three flat C-order arrays.
    ///
    /// # Errors
    ///
    /// [`Error::CountMismatch`] when an array does not hold L·M·N values.
    pub fn try_from_arrays(shape: [usize; 3], x: Vec<f64>, y: Vec<f64>, z: Vec<f64>) -> Result<Self> {
        let n = shape[0] * shape[1] * shape[2];
        for (what, len) in [("mu_x values", x.len()), ("mu_y values", y.len()), ("mu_z values", z.len())] {
            if len != n {
                return Err(Error::CountMismatch { line: 0, what, expected: n, found: len });
            }
        }
        Ok(Displacements { shape, x, y, z })
    }

    /// Lattice size `[L, M, N]`.
    pub fn shape(&self) -> [usize; 3] {
        self.shape
    }

    /// Flat index of lattice node `(i, j, k)`.
    ///
    /// # Panics
    ///
    /// If the index lies outside the lattice.
    pub fn index(&self, i: usize, j: usize, k: usize) -> usize {
        let [l, m, n] = self.shape;
        assert!(i < l && j < m && k < n, "lattice index ({i}, {j}, {k}) outside {l}x{m}x{n}");
        (i * m + j) * n + k
    }

    /// The displacement of node `(i, j, k)` as `[μx, μy, μz]`.
    pub fn get(&self, i: usize, j: usize, k: usize) -> [f64; 3] {
        let f = self.index(i, j, k);
        [self.x[f], self.y[f], self.z[f]]
    }

    /// Set the displacement of node `(i, j, k)`.
    pub fn set(&mut self, i: usize, j: usize, k: usize, mu: [f64; 3]) {
        let f = self.index(i, j, k);
        self.x[f] = mu[0];
        self.y[f] = mu[1];
        self.z[f] = mu[2];
    }

    fn len(&self) -> usize {
        self.x.len()
    }
}

/// Free-form deformation with an L×M×N Bernstein lattice, exactly as PyGeM's `FFD`:
///
/// ```text
/// ψ(x)  = diag(1/ℓ) Rᵀ (x − o)                       model → unit box
/// T̂(u)  = u + Σₗ Σₘ Σₙ bₗ(u₁) bₘ(u₂) bₙ(u₃) μₗₘₙ      eq. (2), Bernstein bᵢ of degree L−1, M−1, N−1
/// φ(x)  = ψ⁻¹(T̂(ψ(x))) = x + R diag(ℓ) Σ b μ          eq. (1), for u in the closed unit box
/// ```
///
/// with `o` = `box_origin`, `ℓ` = `box_length`, and `R = Rx·Ry·Rz` from `rot_angle` in
/// degrees ([`rotation_matrix`]). Points outside the closed box do not move; points on a
/// face, edge or corner (to [`FACE_TOL`] in unit-box coordinates, see
/// [`Ffd::with_face_tol`]) move like their neighbours inside.
///
/// For many displacement sets on the same points, [`Ffd::bind`] precomputes the Bernstein
/// weights (offline) so that each new μ costs one product ([`BoundFfd::deform_with`]).
///
/// # Examples
///
/// ```
/// use cadmorph_morph::{Deformation, Ffd};
/// use cadmorph_morph::math::{Point3, Vector3};
/// let mut ffd = Ffd::try_new([2, 2, 2], Point3::origin(), Vector3::new(2.0, 1.0, 1.0), Vector3::zeros())?;
/// // Move the corner node (1, 1, 1) by a tenth of the box along x.
/// ffd.mu_mut().set(1, 1, 1, [0.1, 0.0, 0.0]);
/// let p = ffd.deform_point(&Point3::new(2.0, 1.0, 1.0)); // the corner itself
/// assert!((p.x - 2.2).abs() < 1e-15);
/// let q = ffd.deform_point(&Point3::new(3.0, 1.0, 1.0)); // outside: unchanged
/// assert_eq!(q, Point3::new(3.0, 1.0, 1.0));
/// # Ok::<(), cadmorph_morph::Error>(())
/// ```
#[derive(Debug, Clone, PartialEq)]
pub struct Ffd {
    box_origin: Point3<f64>,
    box_length: Vector3<f64>,
    rot_angle: Vector3<f64>,
    mu: Displacements,
    face_tol: f64,
    // Derived: frame = R·diag(ℓ) (unit box → model), inverse = diag(1/ℓ)·Rᵀ.
    frame: Matrix3<f64>,
    inverse: Matrix3<f64>,
}

impl Ffd {
    /// An FFD with zero displacements.
    ///
    /// # Errors
    ///
    /// [`Error::InvalidParameter`] when a lattice dimension is below 2, a box length is not
    /// positive and finite, or the origin or an angle is not finite;
    /// [`Error::TooLarge`] when the lattice's displacements would not fit the memory
    /// [budget](crate::budget); [`Error::LatticeTooLarge`] when a dimension exceeds
    /// [`MAX_NODES_PER_AXIS`] or all of them [`MAX_NODES`].
    pub fn try_new(
        n_control_points: [usize; 3],
        box_origin: Point3<f64>,
        box_length: Vector3<f64>,
        rot_angle_deg: Vector3<f64>,
    ) -> Result<Self> {
        for &n in &n_control_points {
            if n < 2 {
                return Err(Error::InvalidParameter {
                    line: None,
                    name: "n control points",
                    value: n as f64,
                    reason: "each lattice dimension must be at least 2",
                });
            }
        }
        let [l, m, n] = n_control_points;
        // Three μ components per node, checked before the allocation and without wrapping.
        crate::budget::check(&format!("FFD lattice {l}x{m}x{n}"), &[l, m, n, 3], std::mem::size_of::<f64>())?;
        if let Some(axis) = n_control_points.iter().position(|&k| k > MAX_NODES_PER_AXIS) {
            return Err(Error::LatticeTooLarge {
                line: None,
                shape: n_control_points,
                axis: Some(axis),
                limit: MAX_NODES_PER_AXIS,
            });
        }
        // Within MAX_NODES_PER_AXIS each, the product does not wrap.
        if l * m * n > MAX_NODES {
            return Err(Error::LatticeTooLarge { line: None, shape: n_control_points, axis: None, limit: MAX_NODES });
        }
        let mut ffd = Ffd {
            box_origin,
            box_length,
            rot_angle: rot_angle_deg,
            mu: Displacements::zeros(n_control_points),
            face_tol: FACE_TOL,
            frame: Matrix3::identity(),
            inverse: Matrix3::identity(),
        };
        ffd.set_box(box_origin, box_length, rot_angle_deg)?;
        Ok(ffd)
    }

    /// The unit box `[0, 1]³` with an `n` lattice and zero displacements (PyGeM's default
    /// `FFD(n)`).
    ///
    /// # Panics
    ///
    /// If a lattice dimension is below 2.
    pub fn unit(n_control_points: [usize; 3]) -> Self {
        Ffd::try_new(n_control_points, Point3::origin(), Vector3::repeat(1.0), Vector3::zeros())
            .expect("lattice dimensions must be at least 2")
    }

    /// Move, resize or rotate the box (μ unchanged).
    ///
    /// # Errors
    ///
    /// As [`Ffd::try_new`].
    pub fn set_box(
        &mut self,
        box_origin: Point3<f64>,
        box_length: Vector3<f64>,
        rot_angle_deg: Vector3<f64>,
    ) -> Result<()> {
        for &l in box_length.iter() {
            if !(l.is_finite() && l > 0.0) {
                return Err(Error::InvalidParameter {
                    line: None,
                    name: "box length",
                    value: l,
                    reason: "must be positive and finite",
                });
            }
        }
        for &v in box_origin.iter() {
            if !v.is_finite() {
                return Err(Error::InvalidParameter {
                    line: None,
                    name: "box origin",
                    value: v,
                    reason: "must be finite",
                });
            }
        }
        for &v in rot_angle_deg.iter() {
            if !v.is_finite() {
                return Err(Error::InvalidParameter {
                    line: None,
                    name: "rotation angle",
                    value: v,
                    reason: "must be finite",
                });
            }
        }
        let r = rotation_matrix(&rot_angle_deg);
        self.box_origin = box_origin;
        self.box_length = box_length;
        self.rot_angle = rot_angle_deg;
        self.frame = r * Matrix3::from_diagonal(&box_length);
        self.inverse = Matrix3::from_diagonal(&box_length.map(|l| 1.0 / l)) * r.transpose();
        Ok(())
    }

    /// The same FFD with another face tolerance (unit-box coordinates, default
    /// [`FACE_TOL`]); `0.0` reproduces PyGeM's strict test.
    ///
    /// # Tolerance
    ///
    /// A point whose unit-box coordinates lie in `[−tol, 1 + tol]` is clamped onto the closed
    /// box and moves; `tol · box_length` is the distance in model units.
    pub fn with_face_tol(mut self, tol: f64) -> Self {
        self.face_tol = tol.max(0.0);
        self
    }

    /// Lattice size `[L, M, N]`.
    pub fn n_control_points(&self) -> [usize; 3] {
        self.mu.shape
    }
    /// Box origin `o` (the lattice node `(0, 0, 0)` and the centre of rotation).
    pub fn box_origin(&self) -> Point3<f64> {
        self.box_origin
    }
    /// Box lengths `ℓ` along the rotated box axes.
    pub fn box_length(&self) -> Vector3<f64> {
        self.box_length
    }
    /// Rotation angles about x, y, z in degrees.
    pub fn rot_angle(&self) -> Vector3<f64> {
        self.rot_angle
    }
    /// The box rotation `R = Rx·Ry·Rz`.
    pub fn rotation(&self) -> Matrix3<f64> {
        rotation_matrix(&self.rot_angle)
    }
    /// The displacements μ.
    pub fn mu(&self) -> &Displacements {
        &self.mu
    }
    /// The displacements μ, for editing.
    pub fn mu_mut(&mut self) -> &mut Displacements {
        &mut self.mu
    }

    /// Replace all displacements.
    ///
    /// # Errors
    ///
    /// [`Error::CountMismatch`] when `mu` has another lattice shape.
    pub fn set_mu(&mut self, mu: Displacements) -> Result<()> {
        if mu.shape != self.mu.shape {
            return Err(Error::CountMismatch {
                line: 0,
                what: "lattice nodes",
                expected: self.mu.len(),
                found: mu.len(),
            });
        }
        self.mu = mu;
        Ok(())
    }

    /// The lattice control points `P + μ` (when `deformed`) or `P`, in model coordinates,
    /// in C order of `(i, j, k)` (PyGeM `control_points`).
    pub fn control_points(&self, deformed: bool) -> Vec<Point3<f64>> {
        let [l, m, n] = self.mu.shape;
        let mut out = Vec::with_capacity(l * m * n);
        for i in 0..l {
            for j in 0..m {
                for k in 0..n {
                    let mut u =
                        Vector3::new(i as f64 / (l - 1) as f64, j as f64 / (m - 1) as f64, k as f64 / (n - 1) as f64);
                    if deformed {
                        u += Vector3::from(self.mu.get(i, j, k));
                    }
                    out.push(self.box_origin + self.frame * u);
                }
            }
        }
        out
    }

    /// Unit-box coordinates of `p`, clamped onto the box, or `None` when `p` is outside.
    #[inline(always)]
    fn reference(&self, p: &Point3<f64>) -> Option<Vector3<f64>> {
        let u = self.inverse * (p - self.box_origin);
        let t = self.face_tol;
        if u.iter().all(|&c| c >= -t && c <= 1.0 + t) {
            Some(u.map(|c| c.clamp(0.0, 1.0)))
        } else {
            None
        }
    }

    /// Bind a point set: precompute which points lie in the box and their Bernstein
    /// weights (offline phase, paper §2.1.1). See [`BoundFfd`].
    pub fn bind(&self, points: &[Point3<f64>]) -> BoundFfd {
        let [l, m, n] = self.mu.shape;
        let stride = l + m + n;
        let mut inside = Vec::new();
        let mut basis = Vec::new();
        for (idx, p) in points.iter().enumerate() {
            if let Some(u) = self.reference(p) {
                inside.push(idx);
                let start = basis.len();
                basis.resize(start + stride, 0.0);
                let b = &mut basis[start..];
                bernstein(l - 1, u.x, &mut b[..l]);
                bernstein(m - 1, u.y, &mut b[l..l + m]);
                bernstein(n - 1, u.z, &mut b[l + m..]);
            }
        }
        BoundFfd { shape: self.mu.shape, frame: self.frame, points: points.to_vec(), inside, basis }
    }

    /// The displacement `R diag(ℓ) Σ b(u) μ` at unit-box coordinates `u`.
    fn displacement_at(&self, u: &Vector3<f64>) -> Vector3<f64> {
        let [l, m, n] = self.mu.shape;
        let mut bx = vec![0.0; l];
        let mut by = vec![0.0; m];
        let mut bz = vec![0.0; n];
        bernstein(l - 1, u.x, &mut bx);
        bernstein(m - 1, u.y, &mut by);
        bernstein(n - 1, u.z, &mut bz);
        self.frame * contract(&self.mu, &bx, &by, &bz)
    }

    /// Deform `points` on the calling thread. The points are taken [`SUB`] at a time: the
    /// ones inside the box are gathered (with their unit-box coordinates) into
    /// structure-of-arrays scratch on the stack, and only those go through the Bernstein
    /// values and the lattice sum, one SIMD vector of points at a time inside one `pulp`
    /// dispatch. On x86-64 with AVX2/FMA the gathering is vectorised too ([`v3`]); elsewhere
    /// it is a branch-free scalar loop.
    /// Deforms `points` on this thread; returns the index of the first point with a
    /// non-finite coordinate (such points are outside every box and stay as they are).
    /// The check is fused into the gathering of the points inside the box: a group of
    /// points all inside is finite, so only groups with a point outside are looked at.
    fn deform_serial(&self, points: &mut [Point3<f64>], power: Option<&PowerForm>) -> Option<usize> {
        let [l, m, n] = self.mu.shape;
        if l.max(m).max(n) > 33 {
            // Beyond the binomial table: point by point.
            let mut bad = None;
            for (i, p) in points.iter_mut().enumerate() {
                if bad.is_none() && !(p.x.is_finite() && p.y.is_finite() && p.z.is_finite()) {
                    bad = Some(i);
                }
                *p = self.deform_point(p);
            }
            return bad;
        }
        #[cfg(target_arch = "x86_64")]
        if let Some(simd) = pulp::x86::V3::try_new() {
            return pulp::Simd::vectorize(simd, v3::Deform { simd, ffd: self, power, points });
        }
        crate::simd::dispatch(DeformSimd { ffd: self, power, points })
    }
}

/// Points gathered per pass of [`Ffd::deform_serial`].
const SUB: usize = 256;
/// Widest SIMD vector of `f64` handled (AVX-512 has 8 lanes).
const MAX_W: usize = 8;

/// Scratch of one pass of [`Ffd::deform_serial`]: the unit-box coordinates of the points
/// inside (structure of arrays, with room for a whole vector past the last), their indices
/// in the pass, and their model-space displacements.
struct Pass<V> {
    u: [[f64; SUB + MAX_W]; 3],
    idx: [u64; SUB + MAX_W],
    d: [[f64; SUB + MAX_W]; 3],
    bernstein: [[V; 33]; 3],
}

impl<V: Copy> Pass<V> {
    fn new(zero: V) -> Self {
        Pass {
            u: [[0.0; SUB + MAX_W]; 3],
            idx: [0; SUB + MAX_W],
            d: [[0.0; SUB + MAX_W]; 3],
            bernstein: [[zero; 33]; 3],
        }
    }
}

/// The displacements `R diag(ℓ) Σ b(u) μ` of the first `count` gathered points of `pass`, one
/// SIMD vector at a time, into `pass.d` (the last vector padded with the box centre).
#[inline(always)]
fn displace_gathered<S: pulp::Simd>(
    simd: S,
    ffd: &Ffd,
    power: Option<&PowerForm>,
    pass: &mut Pass<S::f64s>,
    count: usize,
) {
    let w = S::F64_LANES;
    let padded = count.div_ceil(w) * w;
    for ua in pass.u.iter_mut() {
        ua[count..padded].fill(0.5);
    }
    let f = ffd.frame;
    let mut fm = [[simd.splat_f64s(0.0); 3]; 3];
    for r in 0..3 {
        for c in 0..3 {
            fm[r][c] = simd.splat_f64s(f[(r, c)]);
        }
    }
    for start in (0..padded).step_by(w) {
        let uvw = [
            S::as_simd_f64s(&pass.u[0][start..start + w]).0[0],
            S::as_simd_f64s(&pass.u[1][start..start + w]).0[0],
            S::as_simd_f64s(&pass.u[2][start..start + w]).0[0],
        ];
        let acc = match power {
            Some(power) => power.eval(simd, uvw),
            None => displacement_simd(simd, &ffd.mu, uvw, &mut pass.bernstein),
        };
        for (r, dr) in pass.d.iter_mut().enumerate() {
            let v = simd.mul_add_f64s(
                fm[r][0],
                acc[0],
                simd.mul_add_f64s(fm[r][1], acc[1], simd.mul_f64s(fm[r][2], acc[2])),
            );
            S::as_mut_simd_f64s(&mut dr[start..start + w]).0[0] = v;
        }
    }
}

/// The lattice sum of a lattice with at most three nodes along each axis (Bernstein degree
/// ≤ 2: the common small lattices) in power form, `Σ c_abc uᵃ vᵇ wᶜ`, evaluated by nested
/// Horner steps: `3·(LM(N−1) + L(M−1) + L − 1)` fused multiply-adds per vector (78 for
/// 3×3×3) instead of the Bernstein form's `3·(LMN + LM + L)` (117) plus the basis values.
///
/// At these degrees the change of basis costs little accuracy: each coefficient is a sum of
/// at most 27 terms with integer weights of magnitude ≤ 2 per axis. Against the Bernstein
/// form on random lattices the values differ by at most 6.2·10⁻¹⁵ of the largest |μ|
/// (28 ulps, 3×3×3; test `power_form_matches_bernstein_form`), and PyGeM's outputs are still
/// matched to 1·10⁻¹⁵. Higher degrees keep the Bernstein form, whose power form would lose
/// accuracy as 2ᵈ per axis.
struct PowerForm {
    shape: [usize; 3],
    /// `coef[component][(a·M + b)·N + c]`.
    coef: [[f64; 27]; 3],
}

impl PowerForm {
    fn new(mu: &Displacements) -> Option<PowerForm> {
        let [l, m, n] = mu.shape;
        if [l, m, n].iter().any(|d| !(2..=3).contains(d)) {
            return None;
        }
        // Per axis, the coefficient of tᵃ in the Bernstein polynomial i of degree d:
        // C(d, i) C(d − i, a − i) (−1)^(a − i) for a ≥ i, else 0.
        let to_power = |nodes: usize| -> [[f64; 3]; 3] {
            let d = nodes - 1;
            std::array::from_fn(|a| {
                std::array::from_fn(|i| {
                    if a > d || i > a {
                        0.0
                    } else {
                        let sign = if (a - i) % 2 == 0 { 1.0 } else { -1.0 };
                        sign * BINOM[d][i] * BINOM[d - i][a - i]
                    }
                })
            })
        };
        let (tx, ty, tz) = (to_power(l), to_power(m), to_power(n));
        let mut coef = [[0.0; 27]; 3];
        for (comp, src) in [&mu.x, &mu.y, &mu.z].into_iter().enumerate() {
            for a in 0..l {
                for b in 0..m {
                    for c in 0..n {
                        let mut sum = 0.0;
                        for i in 0..=a {
                            for j in 0..=b {
                                for k in 0..=c {
                                    sum += tx[a][i] * ty[b][j] * tz[c][k] * src[(i * m + j) * n + k];
                                }
                            }
                        }
                        coef[comp][(a * m + b) * n + c] = sum;
                    }
                }
            }
        }
        Some(PowerForm { shape: mu.shape, coef })
    }

    #[inline(always)]
    fn eval<S: pulp::Simd>(&self, simd: S, uvw: [S::f64s; 3]) -> [S::f64s; 3] {
        match self.shape {
            [2, 2, 2] => self.eval_fixed::<S, 2, 2, 2>(simd, uvw),
            [3, 3, 3] => self.eval_fixed::<S, 3, 3, 3>(simd, uvw),
            [2, 2, 3] => self.eval_fixed::<S, 2, 2, 3>(simd, uvw),
            [2, 3, 2] => self.eval_fixed::<S, 2, 3, 2>(simd, uvw),
            [3, 2, 2] => self.eval_fixed::<S, 3, 2, 2>(simd, uvw),
            [2, 3, 3] => self.eval_fixed::<S, 2, 3, 3>(simd, uvw),
            [3, 2, 3] => self.eval_fixed::<S, 3, 2, 3>(simd, uvw),
            [3, 3, 2] => self.eval_fixed::<S, 3, 3, 2>(simd, uvw),
            shape => unreachable!("PowerForm::new builds only 2 or 3 nodes per axis, not {shape:?}"),
        }
    }

    #[inline(always)]
    fn eval_fixed<S: pulp::Simd, const L: usize, const M: usize, const N: usize>(
        &self,
        simd: S,
        [u, v, w]: [S::f64s; 3],
    ) -> [S::f64s; 3] {
        let mut out = [simd.splat_f64s(0.0); 3];
        for (o, coef) in out.iter_mut().zip(&self.coef) {
            let mut r = simd.splat_f64s(0.0);
            for a in (0..L).rev() {
                let mut q = simd.splat_f64s(0.0);
                for b in (0..M).rev() {
                    let base = (a * M + b) * N;
                    let mut p = simd.splat_f64s(coef[base + N - 1]);
                    for c in (0..N - 1).rev() {
                        p = simd.mul_add_f64s(p, w, simd.splat_f64s(coef[base + c]));
                    }
                    q = if b == M - 1 { p } else { simd.mul_add_f64s(q, v, p) };
                }
                r = if a == L - 1 { q } else { simd.mul_add_f64s(r, u, q) };
            }
            *o = r;
        }
        out
    }
}

/// Add the displacements of `pass` to the gathered points of `sub`.
#[inline(always)]
fn scatter<V>(pass: &Pass<V>, count: usize, sub: &mut [Point3<f64>]) {
    for (q, &i) in pass.idx[..count].iter().enumerate() {
        let p = &mut sub[i as usize];
        p.x += pass.d[0][q];
        p.y += pass.d[1][q];
        p.z += pass.d[2][q];
    }
}

/// The whole FFD of a slice, compiled inside `pulp`'s target-feature function (the portable
/// path: scalar gathering).
struct DeformSimd<'a> {
    ffd: &'a Ffd,
    power: Option<&'a PowerForm>,
    points: &'a mut [Point3<f64>],
}

impl pulp::WithSimd for DeformSimd<'_> {
    type Output = Option<usize>;

    #[inline(always)]
    fn with_simd<S: pulp::Simd>(self, simd: S) -> Option<usize> {
        let DeformSimd { ffd, power, points } = self;
        let mut bad = usize::MAX;
        let w = S::F64_LANES;
        assert!(w <= MAX_W && SUB.is_multiple_of(w), "unsupported SIMD width {w}");
        let (o, inv, t) = (ffd.box_origin, ffd.inverse, ffd.face_tol);
        let mut pass = Pass::new(simd.splat_f64s(0.0));
        for (k, sub) in points.chunks_mut(SUB).enumerate() {
            // Gather the points inside the (tolerance-widened) box.
            let mut count = 0;
            for (q, p) in sub.iter().enumerate() {
                let e = [p.x - o.x, p.y - o.y, p.z - o.z];
                // Branch-free: every point is written at `count`, which only advances for
                // the inside ones (a branch here would be mispredicted for random points).
                let mut ok = true;
                for (a, ua) in pass.u.iter_mut().enumerate() {
                    let v = inv[(a, 0)] * e[0] + inv[(a, 1)] * e[1] + inv[(a, 2)] * e[2];
                    ok &= (v >= -t) & (v <= 1.0 + t);
                    // max/min (vmaxsd/vminsd), not clamp: no NaN propagation to preserve here,
                    // since the point only counts as inside when `ok`.
                    #[allow(clippy::manual_clamp)]
                    let clamped = v.max(0.0).min(1.0);
                    ua[count] = clamped;
                }
                pass.idx[count] = q as u64;
                count += ok as usize;
                if !ok && bad == usize::MAX && !(p.x.is_finite() && p.y.is_finite() && p.z.is_finite()) {
                    bad = k * SUB + q;
                }
            }
            if count > 0 {
                displace_gathered(simd, ffd, power, &mut pass, count);
                scatter(&pass, count, sub);
            }
        }
        (bad != usize::MAX).then_some(bad)
    }
}

/// The AVX2/FMA path of [`Ffd::deform_serial`]: four points are mapped to the unit box and
/// tested at once, and the ones inside are packed to the front of the scratch with one lane
/// permutation (`vpermd`, indexed by the 4-bit inside mask) instead of a scalar loop.
#[cfg(target_arch = "x86_64")]
mod v3 {
    use super::*;
    use pulp::x86::V3;
    use pulp::{f64x4, u64x4, Simd};

    /// For each 4-bit mask of lanes, the 32-bit lane indices that move the selected 64-bit
    /// lanes to the front, in order (the rest are don't-cares).
    const COMPRESS: [[u32; 8]; 16] = {
        let mut t = [[0u32; 8]; 16];
        let mut m = 0;
        while m < 16 {
            let (mut k, mut l) = (0, 0);
            while l < 4 {
                if (m >> l) & 1 == 1 {
                    t[m][2 * k] = 2 * l as u32;
                    t[m][2 * k + 1] = 2 * l as u32 + 1;
                    k += 1;
                }
                l += 1;
            }
            m += 1;
        }
        t
    };

    pub(super) struct Deform<'a> {
        pub simd: V3,
        pub ffd: &'a Ffd,
        pub power: Option<&'a PowerForm>,
        pub points: &'a mut [Point3<f64>],
    }

    /// The box as splatted vectors (no closures here: a closure body would not be compiled
    /// with the AVX2 target features).
    struct BoxV {
        origin: [f64x4; 3],
        inverse: [[f64x4; 3]; 3],
        lo: f64x4,
        hi: f64x4,
    }

    impl pulp::WithSimd for Deform<'_> {
        type Output = Option<usize>;

        #[inline(always)]
        fn with_simd<S: Simd>(self, _: S) -> Option<usize> {
            let Deform { simd, ffd, power, points } = self;
            let mut bad = usize::MAX;
            let (o, inv, t) = (ffd.box_origin, ffd.inverse, ffd.face_tol);
            let mut b = BoxV {
                origin: [simd.splat_f64x4(o.x), simd.splat_f64x4(o.y), simd.splat_f64x4(o.z)],
                inverse: [[simd.splat_f64x4(0.0); 3]; 3],
                lo: simd.splat_f64x4(-t),
                hi: simd.splat_f64x4(1.0 + t),
            };
            for r in 0..3 {
                for c in 0..3 {
                    b.inverse[r][c] = simd.splat_f64x4(inv[(r, c)]);
                }
            }
            let mut pass = Pass::new(simd.splat_f64x4(0.0));
            for (k, sub) in points.chunks_mut(SUB).enumerate() {
                let mut count = 0;
                let mut finite = simd.splat_f64x4(0.0);
                // Four points are twelve coordinates: three vector loads, then a 3 × 4
                // transpose in six shuffles (Point3<f64> is three packed f64).
                let flat: &[f64] = bytemuck::cast_slice(sub);
                for (g, twelve) in flat.chunks_exact(12).enumerate() {
                    let load = |k: usize| -> f64x4 {
                        let v: [f64; 4] = twelve[4 * k..4 * k + 4].try_into().unwrap();
                        pulp::cast(v)
                    };
                    let c = transpose(simd, load(0), load(1), load(2));
                    count += gather(simd, &b, &mut pass, count, 4 * g, c, &mut finite);
                }
                let rest = &sub[sub.len() / 4 * 4..];
                if !rest.is_empty() {
                    // Missing lanes of the short last group are NaN: never inside.
                    let mut c = [[f64::NAN; 4]; 3];
                    for (l, p) in rest.iter().enumerate() {
                        c[0][l] = p.x;
                        c[1][l] = p.y;
                        c[2][l] = p.z;
                    }
                    // (Their x · 0 is NaN too: the scan below reads only the real points.)
                    let first = sub.len() - rest.len();
                    count += gather(simd, &b, &mut pass, count, first, c.map(pulp::cast), &mut finite);
                }
                if bad == usize::MAX {
                    let f: [f64; 4] = pulp::cast(finite);
                    if f.iter().any(|v| *v != 0.0) {
                        if let Some(q) =
                            sub.iter().position(|p| !(p.x.is_finite() && p.y.is_finite() && p.z.is_finite()))
                        {
                            bad = k * SUB + q;
                        }
                        finite = simd.splat_f64x4(0.0);
                    }
                }
                if count > 0 {
                    displace_gathered(simd, ffd, power, &mut pass, count);
                    scatter(&pass, count, sub);
                }
            }
            (bad != usize::MAX).then_some(bad)
        }
    }

    /// `[x₀ y₀ z₀ x₁], [y₁ z₁ x₂ y₂], [z₂ x₃ y₃ z₃]` → `[x₀ x₁ x₂ x₃], [y…], [z…]`.
    #[inline(always)]
    fn transpose(simd: V3, a: f64x4, b: f64x4, c: f64x4) -> [f64x4; 3] {
        let (a, b, c) = (pulp::cast(a), pulp::cast(b), pulp::cast(c));
        let p = simd.avx._mm256_blend_pd::<0b1100>(a, b); // x₀ y₀ | x₂ y₂
        let q = simd.avx._mm256_permute2f128_pd::<0x21>(a, c); // z₀ x₁ | z₂ x₃
        let r = simd.avx._mm256_blend_pd::<0b1100>(b, c); // y₁ z₁ | y₃ z₃
        [
            pulp::cast(simd.avx._mm256_shuffle_pd::<0b1010>(p, q)),
            pulp::cast(simd.avx._mm256_shuffle_pd::<0b0101>(p, r)),
            pulp::cast(simd.avx._mm256_shuffle_pd::<0b1010>(q, r)),
        ]
    }

    /// Map four points (`c`, lane = point) to the unit box and append the ones inside to
    /// `pass` at `count`, their indices in the pass starting at `first`; returns how many
    /// were inside. `finite` stays zero while every coordinate seen is finite (NaN and ±∞
    /// never compare inside, so such points are left as they are).
    #[inline(always)]
    fn gather(
        simd: V3,
        b: &BoxV,
        pass: &mut Pass<f64x4>,
        count: usize,
        first: usize,
        c: [f64x4; 3],
        finite: &mut f64x4,
    ) -> usize {
        let e =
            [simd.sub_f64x4(c[0], b.origin[0]), simd.sub_f64x4(c[1], b.origin[1]), simd.sub_f64x4(c[2], b.origin[2])];
        let mut u = [simd.splat_f64x4(0.0); 3];
        let mut inside = simd.splat_m64x4(pulp::m64::new(true));
        for r in 0..3 {
            let a = &b.inverse[r];
            u[r] = simd.mul_add_f64x4(a[0], e[0], simd.mul_add_f64x4(a[1], e[1], simd.mul_f64x4(a[2], e[2])));
            let ok =
                simd.and_m64x4(simd.greater_than_or_equal_f64s(u[r], b.lo), simd.less_than_or_equal_f64s(u[r], b.hi));
            inside = simd.and_m64x4(inside, ok);
        }
        let bits = simd.avx._mm256_movemask_pd(pulp::cast(inside)) as usize;
        // x · 0 is ±0 for finite x, NaN for NaN and ±∞: one fused multiply-add per
        // coordinate vector into the caller's accumulator, looked at once per pass.
        for r in 0..3 {
            *finite = simd.mul_add_f64x4(c[r], simd.splat_f64x4(0.0), *finite);
        }
        if bits == 0 {
            return 0;
        }
        let perm: pulp::u32x8 = pulp::cast(COMPRESS[bits]);
        let (zero, one) = (simd.splat_f64x4(0.0), simd.splat_f64x4(1.0));
        for r in 0..3 {
            let clamped = simd.max_f64x4(simd.min_f64x4(u[r], one), zero);
            let packed: [f64; 4] =
                pulp::cast(simd.avx2._mm256_permutevar8x32_epi32(pulp::cast(clamped), pulp::cast(perm)));
            pass.u[r][count..count + 4].copy_from_slice(&packed);
        }
        let lanes = u64x4(first as u64, first as u64 + 1, first as u64 + 2, first as u64 + 3);
        let idx: [u64; 4] = pulp::cast(simd.avx2._mm256_permutevar8x32_epi32(pulp::cast(lanes), pulp::cast(perm)));
        pass.idx[count..count + 4].copy_from_slice(&idx);
        bits.count_ones() as usize
    }
}

/// `Σₗₘₙ bₗ(u) bₘ(v) bₙ(t) μₗₘₙ` for one SIMD vector of points with unit-box coordinates
/// `uvw` (lane = point), contracted one dimension at a time: over k for each (i, j), then
/// over j, then over i, i.e. `3·(LMN + LM + L)` fused multiply-adds per vector.
/// `scratch` holds the Bernstein values (set up once by the caller, not per vector).
#[inline(always)]
fn displacement_simd<S: pulp::Simd>(
    simd: S,
    mu: &Displacements,
    uvw: [S::f64s; 3],
    scratch: &mut [[S::f64s; 33]; 3],
) -> [S::f64s; 3] {
    let [l, m, n] = mu.shape;
    let [bx, by, bz] = scratch;
    bernstein_into(simd, uvw[0], &mut bx[..l]);
    bernstein_into(simd, uvw[1], &mut by[..m]);
    let (bx, by) = (&bx[..l], &by[..m]);
    // The k sum with the k extent known at compile time keeps the z values in registers.
    match n {
        2 => lattice_sum_simd(simd, mu, bx, by, &bernstein_fixed::<S, 2>(simd, uvw[2])),
        3 => lattice_sum_simd(simd, mu, bx, by, &bernstein_fixed::<S, 3>(simd, uvw[2])),
        4 => lattice_sum_simd(simd, mu, bx, by, &bernstein_fixed::<S, 4>(simd, uvw[2])),
        5 => lattice_sum_simd(simd, mu, bx, by, &bernstein_fixed::<S, 5>(simd, uvw[2])),
        6 => lattice_sum_simd(simd, mu, bx, by, &bernstein_fixed::<S, 6>(simd, uvw[2])),
        7 => lattice_sum_simd(simd, mu, bx, by, &bernstein_fixed::<S, 7>(simd, uvw[2])),
        8 => lattice_sum_simd(simd, mu, bx, by, &bernstein_fixed::<S, 8>(simd, uvw[2])),
        _ => {
            bernstein_simd(simd, n - 1, uvw[2], &mut bz[..n]);
            lattice_sum_simd(simd, mu, bx, by, &bz[..n])
        }
    }
}

/// The lattice sum of [`displacement_simd`]. Inlined into the match arms of the caller,
/// where `bz` is an array of 2..=8 values, its length is a constant: the k loop unrolls and
/// the z values stay in registers.
#[inline(always)]
fn lattice_sum_simd<S: pulp::Simd>(
    simd: S,
    mu: &Displacements,
    bx: &[S::f64s],
    by: &[S::f64s],
    bz: &[S::f64s],
) -> [S::f64s; 3] {
    let n = bz.len();
    let zero = simd.splat_f64s(0.0);
    let mut acc = [zero; 3];
    // The (i, j) rows of μ in order, n values each (no index arithmetic or bounds checks).
    let mut rows = mu.x.chunks_exact(n).zip(mu.y.chunks_exact(n)).zip(mu.z.chunks_exact(n));
    for &bxi in bx {
        let mut row = [zero; 3];
        for (&byj, ((mx, my), mz)) in by.iter().zip(rows.by_ref()) {
            let mut s = [zero; 3];
            for (k, &b) in bz.iter().enumerate() {
                s[0] = simd.mul_add_f64s(b, simd.splat_f64s(mx[k]), s[0]);
                s[1] = simd.mul_add_f64s(b, simd.splat_f64s(my[k]), s[1]);
                s[2] = simd.mul_add_f64s(b, simd.splat_f64s(mz[k]), s[2]);
            }
            for c in 0..3 {
                row[c] = simd.mul_add_f64s(byj, s[c], row[c]);
            }
        }
        for c in 0..3 {
            acc[c] = simd.mul_add_f64s(bxi, row[c], acc[c]);
        }
    }
    acc
}

/// [`bernstein`] across the lanes of a SIMD vector (`deg ≤ 32`); the same operations in
/// the same order, so the values are those of [`bernstein`].
#[inline(always)]
fn bernstein_simd<S: pulp::Simd>(simd: S, deg: usize, t: S::f64s, out: &mut [S::f64s]) {
    let one = simd.splat_f64s(1.0);
    let mut tp = one;
    for o in out.iter_mut() {
        *o = tp;
        tp = simd.mul_f64s(tp, t);
    }
    let s = simd.sub_f64s(one, t);
    let mut sp = one;
    for i in (0..=deg).rev() {
        out[i] = simd.mul_f64s(out[i], simd.mul_f64s(simd.splat_f64s(BINOM[deg][i]), sp));
        sp = simd.mul_f64s(sp, s);
    }
}

/// [`bernstein_simd`] with the number of values `N` (degree `N − 1`) known at compile time,
/// so that the loops unroll and the values stay in registers; the same operations.
#[inline(always)]
fn bernstein_fixed<S: pulp::Simd, const N: usize>(simd: S, t: S::f64s) -> [S::f64s; N] {
    // The loops of `bernstein_simd` with constant trip counts written out here: calling it
    // on an array of N was 30% slower for 6×6×6 (the loops did not unroll).
    let one = simd.splat_f64s(1.0);
    let mut out = [one; N];
    let mut tp = one;
    for o in out.iter_mut() {
        *o = tp;
        tp = simd.mul_f64s(tp, t);
    }
    let s = simd.sub_f64s(one, t);
    let mut sp = one;
    for i in (0..N).rev() {
        out[i] = simd.mul_f64s(out[i], simd.mul_f64s(simd.splat_f64s(BINOM[N - 1][i]), sp));
        sp = simd.mul_f64s(sp, s);
    }
    out
}

/// The Bernstein values of degree `out.len() − 1` into `out`, through [`bernstein_fixed`] for
/// up to eight values.
#[inline(always)]
fn bernstein_into<S: pulp::Simd>(simd: S, t: S::f64s, out: &mut [S::f64s]) {
    match out.len() {
        2 => out.copy_from_slice(&bernstein_fixed::<S, 2>(simd, t)),
        3 => out.copy_from_slice(&bernstein_fixed::<S, 3>(simd, t)),
        4 => out.copy_from_slice(&bernstein_fixed::<S, 4>(simd, t)),
        5 => out.copy_from_slice(&bernstein_fixed::<S, 5>(simd, t)),
        6 => out.copy_from_slice(&bernstein_fixed::<S, 6>(simd, t)),
        7 => out.copy_from_slice(&bernstein_fixed::<S, 7>(simd, t)),
        8 => out.copy_from_slice(&bernstein_fixed::<S, 8>(simd, t)),
        n => bernstein_simd(simd, n - 1, t, out),
    }
}

/// Points handled together by the vectorised lattice sums.
const LANES: usize = 8;

/// `Σₗₘₙ bx[l] by[m] bz[n] μₗₘₙ` for `LANES` points at once (lane = point).
fn lattice_sum_lanes(
    mu: &Displacements,
    bx: &[[f64; LANES]],
    by: &[[f64; LANES]],
    bz: &[[f64; LANES]],
) -> [[f64; LANES]; 3] {
    crate::simd::dispatch(LatticeSum { mu, bx, by, bz })
}

/// The lattice sum, compiled inside `pulp`'s target-feature function (the body must sit in
/// `with_simd` itself to get AVX2).
struct LatticeSum<'a> {
    mu: &'a Displacements,
    bx: &'a [[f64; LANES]],
    by: &'a [[f64; LANES]],
    bz: &'a [[f64; LANES]],
}

impl pulp::WithSimd for LatticeSum<'_> {
    type Output = [[f64; LANES]; 3];

    #[inline(always)]
    fn with_simd<S: pulp::Simd>(self, _simd: S) -> Self::Output {
        let LatticeSum { mu, bx, by, bz } = self;
        lattice_sum_body(mu, bx, by, bz)
    }
}

/// The lattice sum's body (inlined into a `pulp` dispatch by its callers).
#[inline(always)]
fn lattice_sum_body(
    mu: &Displacements,
    bx: &[[f64; LANES]],
    by: &[[f64; LANES]],
    bz: &[[f64; LANES]],
) -> [[f64; LANES]; 3] {
    {
        let [_, m, n] = mu.shape;
        let mut acc = [[0.0; LANES]; 3];
        for (i, bxi) in bx.iter().enumerate() {
            for (j, byj) in by.iter().enumerate() {
                let base = (i * m + j) * n;
                let (mx, my, mz) = (&mu.x[base..base + n], &mu.y[base..base + n], &mu.z[base..base + n]);
                // Contract over k first, then scale by bx·by: 3N + 4 operations per (i, j).
                let mut sx = [0.0; LANES];
                let mut sy = [0.0; LANES];
                let mut sz = [0.0; LANES];
                for (k, bzk) in bz.iter().enumerate() {
                    let (a, b, c) = (mx[k], my[k], mz[k]);
                    for lane in 0..LANES {
                        sx[lane] = bzk[lane].mul_add(a, sx[lane]);
                        sy[lane] = bzk[lane].mul_add(b, sy[lane]);
                        sz[lane] = bzk[lane].mul_add(c, sz[lane]);
                    }
                }
                for lane in 0..LANES {
                    let w = bxi[lane] * byj[lane];
                    acc[0][lane] = w.mul_add(sx[lane], acc[0][lane]);
                    acc[1][lane] = w.mul_add(sy[lane], acc[1][lane]);
                    acc[2][lane] = w.mul_add(sz[lane], acc[2][lane]);
                }
            }
        }
        acc
    }
}

/// `Σₗₘₙ bx[l] by[m] bz[n] μₗₘₙ` for one point.
fn contract(mu: &Displacements, bx: &[f64], by: &[f64], bz: &[f64]) -> Vector3<f64> {
    let [_, m, n] = mu.shape;
    let mut acc = Vector3::zeros();
    for (i, &bi) in bx.iter().enumerate() {
        for (j, &bj) in by.iter().enumerate() {
            let w = bi * bj;
            let base = (i * m + j) * n;
            for (k, &bk) in bz.iter().enumerate() {
                let f = base + k;
                acc += w * bk * Vector3::new(mu.x[f], mu.y[f], mu.z[f]);
            }
        }
    }
    acc
}

/// Binomial coefficients `C(n, k)` for `n ≤ 32` (Pascal's triangle, built at compile time;
/// all below 2⁵³, so exact as `f64`, which saves the integer conversion in the loops).
const BINOM: [[f64; 33]; 33] = {
    let mut t = [[0u64; 33]; 33];
    let mut f = [[0.0; 33]; 33];
    let mut n = 0;
    while n <= 32 {
        t[n][0] = 1;
        f[n][0] = 1.0;
        let mut k = 1;
        while k <= n {
            t[n][k] = t[n - 1][k - 1] + if k < n { t[n - 1][k] } else { 0 };
            f[n][k] = t[n][k] as f64;
            k += 1;
        }
        n += 1;
    }
    f
};

/// Bernstein polynomials of degree `deg` at `t`: `out[i] = C(deg, i) tⁱ (1 − t)^(deg − i)`.
#[inline]
pub(crate) fn bernstein(deg: usize, t: f64, out: &mut [f64]) {
    debug_assert_eq!(out.len(), deg + 1);
    let s = 1.0 - t;
    // out[i] = tⁱ first, then multiply by C(deg, i) (1 − t)^(deg − i) from the top down.
    let mut tp = 1.0;
    for o in out.iter_mut() {
        *o = tp;
        tp *= t;
    }
    let mut sp = 1.0;
    if deg <= 32 {
        for i in (0..=deg).rev() {
            out[i] *= BINOM[deg][i] * sp;
            sp *= s;
        }
        return;
    }
    let mut binom = 1.0;
    for i in (0..=deg).rev() {
        out[i] *= binom * sp;
        sp *= s;
        // C(deg, i − 1) = C(deg, i) · i / (deg − i + 1), the ratio first: near the middle
        // of degree 1023, C · i overflows where C · (i / (deg − i + 1)) does not.
        binom *= i as f64 / (deg - i + 1) as f64;
    }
}

/// Derivatives of the Bernstein polynomials: `d/dt bᵢ = deg (b_{i−1}^{deg−1} − bᵢ^{deg−1})`.
fn bernstein_deriv(deg: usize, t: f64, out: &mut [f64]) {
    let mut lower = vec![0.0; deg];
    bernstein(deg - 1, t, &mut lower);
    let d = deg as f64;
    for i in 0..=deg {
        let left = if i > 0 { lower[i - 1] } else { 0.0 };
        let right = if i < deg { lower[i] } else { 0.0 };
        out[i] = d * (left - right);
    }
}

impl Deformation for Ffd {
    fn deform_point(&self, p: &Point3<f64>) -> Point3<f64> {
        match self.reference(p) {
            Some(u) => p + self.displacement_at(&u),
            None => *p,
        }
    }

    fn deform(&self, points: &mut [Point3<f64>]) {
        // The check is fused into the kernel (see `deform_serial`): ignoring it costs nothing.
        let _ = self.deform_checked(points);
    }

    fn deform_chunks(&self, points: &mut [Point3<f64>], before: &ChunkHook<'_>) {
        let power = PowerForm::new(&self.mu);
        for_each_chunk(points, before, |c| {
            self.deform_serial(c, power.as_ref());
        });
    }

    /// Every finite point deformed; the points with a non-finite coordinate stay as they
    /// are (they lie outside every box), the first is reported.
    fn deform_checked(&self, points: &mut [Point3<f64>]) -> Result<(), usize> {
        let power = PowerForm::new(&self.mu);
        let bad = if points.len() >= PARALLEL_MIN_POINTS {
            points
                .par_chunks_mut(PARALLEL_CHUNK)
                .enumerate()
                .filter_map(|(i, c)| self.deform_serial(c, power.as_ref()).map(|k| i * PARALLEL_CHUNK + k))
                .min()
        } else {
            self.deform_serial(points, power.as_ref())
        };
        bad.map_or(Ok(()), Err)
    }

    /// `I + R diag(ℓ) (Σ μ ⊗ ∇ᵤb) diag(1/ℓ) Rᵀ` inside the closed box (one-sided on its
    /// faces), `I` outside.
    fn jacobian(&self, p: &Point3<f64>) -> Option<Matrix3<f64>> {
        let Some(u) = self.reference(p) else {
            return Some(Matrix3::identity());
        };
        let [l, m, n] = self.mu.shape;
        let (mut bx, mut by, mut bz) = (vec![0.0; l], vec![0.0; m], vec![0.0; n]);
        let (mut dx, mut dy, mut dz) = (vec![0.0; l], vec![0.0; m], vec![0.0; n]);
        bernstein(l - 1, u.x, &mut bx);
        bernstein(m - 1, u.y, &mut by);
        bernstein(n - 1, u.z, &mut bz);
        bernstein_deriv(l - 1, u.x, &mut dx);
        bernstein_deriv(m - 1, u.y, &mut dy);
        bernstein_deriv(n - 1, u.z, &mut dz);
        let mut g = Matrix3::zeros(); // g[c][a] = ∂(Σ b μᶜ)/∂u_a
        for i in 0..l {
            for j in 0..m {
                for k in 0..n {
                    let f = (i * m + j) * n + k;
                    let grad = Vector3::new(dx[i] * by[j] * bz[k], bx[i] * dy[j] * bz[k], bx[i] * by[j] * dz[k]);
                    let mu = Vector3::new(self.mu.x[f], self.mu.y[f], self.mu.z[f]);
                    g += mu * grad.transpose();
                }
            }
        }
        Some(Matrix3::identity() + self.frame * g * self.inverse)
    }
}

impl LinearInParameters for Ffd {
    /// `3 · L·M·N`: `[μx (C order), μy, μz]`, PyGeM's `array_mu_*.ravel()` one after another.
    fn n_params(&self) -> usize {
        3 * self.mu.len()
    }
    fn params(&self) -> Vec<f64> {
        [self.mu.x.as_slice(), &self.mu.y, &self.mu.z].concat()
    }
    fn set_params(&mut self, theta: &[f64]) -> Result<()> {
        check_params(theta, self.n_params())?;
        let n = self.mu.len();
        self.mu.x.copy_from_slice(&theta[..n]);
        self.mu.y.copy_from_slice(&theta[n..2 * n]);
        self.mu.z.copy_from_slice(&theta[2 * n..]);
        Ok(())
    }
    fn param_weights(&self, p: &Point3<f64>) -> ParamWeights {
        let [l, m, n] = self.mu.shape;
        let mut weights = Vec::new();
        if let Some(u) = self.reference(p) {
            let (mut bx, mut by, mut bz) = (vec![0.0; l], vec![0.0; m], vec![0.0; n]);
            bernstein(l - 1, u.x, &mut bx);
            bernstein(m - 1, u.y, &mut by);
            bernstein(n - 1, u.z, &mut bz);
            weights.reserve(l * m * n);
            for i in 0..l {
                for j in 0..m {
                    for k in 0..n {
                        weights.push(((i * m + j) * n + k, bx[i] * by[j] * bz[k]));
                    }
                }
            }
        }
        ParamWeights { n_nodes: self.mu.len(), weights, frame: self.frame }
    }
}

/// An FFD bound to a point set: which points lie in the box and their Bernstein weights,
/// computed once by [`Ffd::bind`] (offline). Each new set of displacements then costs one
/// product with the precomputed weights ([`BoundFfd::deform_with`], online).
///
/// The weight matrix `B` (points × L·M·N nodes, paper eq. (2)) is kept in its Kronecker
/// factors, `B[p, (l,m,n)] = bx[p,l] · by[p,m] · bz[p,n]`: `L+M+N` numbers per point
/// instead of `L·M·N`, so binding a million points to a 6×6×6 lattice takes 144 MB, not 1.7 GB.
///
/// # Examples
///
/// ```
/// use cadmorph_morph::{Deformation, Ffd, Displacements};
/// use cadmorph_morph::math::Point3;
/// let mut ffd = Ffd::unit([3, 3, 3]);
/// let pts = vec![Point3::new(0.5, 0.5, 0.5), Point3::new(0.1, 0.9, 0.2), Point3::new(2.0, 0.0, 0.0)];
/// let bound = ffd.bind(&pts);
/// assert_eq!(bound.n_inside(), 2);
/// let mut mu = Displacements::zeros([3, 3, 3]);
/// mu.set(1, 1, 1, [0.0, 0.0, 0.3]);
/// let mut out = vec![Point3::origin(); 3];
/// bound.deform_with(&mu, &mut out).unwrap();
/// ffd.set_mu(mu).unwrap();
/// assert!((out[0] - ffd.deform_point(&pts[0])).norm() < 1e-15);
/// assert_eq!(out[2], pts[2]);
/// ```
#[derive(Debug, Clone)]
pub struct BoundFfd {
    shape: [usize; 3],
    frame: Matrix3<f64>,
    points: Vec<Point3<f64>>,
    inside: Vec<usize>,
    basis: Vec<f64>,
}

impl BoundFfd {
    /// Number of bound points.
    pub fn len(&self) -> usize {
        self.points.len()
    }
    /// Whether no point is bound.
    pub fn is_empty(&self) -> bool {
        self.points.is_empty()
    }
    /// Number of bound points inside the closed box (the ones that move).
    pub fn n_inside(&self) -> usize {
        self.inside.len()
    }

    /// Write `φ_μ(points)` into `out` (online phase: one product with the stored weights).
    ///
    /// # Errors
    ///
    /// [`Error::CountMismatch`] when `out` does not have one slot per bound point or `mu`
    /// another lattice shape.
    pub fn deform_with(&self, mu: &Displacements, out: &mut [Point3<f64>]) -> Result<()> {
        if out.len() != self.points.len() {
            return Err(Error::CountMismatch {
                line: 0,
                what: "output points",
                expected: self.points.len(),
                found: out.len(),
            });
        }
        if mu.shape != self.shape {
            let n = self.shape[0] * self.shape[1] * self.shape[2];
            return Err(Error::CountMismatch { line: 0, what: "lattice nodes", expected: n, found: mu.len() });
        }
        out.copy_from_slice(&self.points);
        let [l, m, n] = self.shape;
        let stride = l + m + n;
        // Eight rows at a time through the vectorised lattice sum.
        const ROWS: usize = 512;
        let frame = self.frame;
        let mut moved = vec![[0.0; 3]; self.inside.len()];
        moved.par_chunks_mut(ROWS).enumerate().for_each(|(chunk, ms)| {
            let (mut bx, mut by, mut bz) = (vec![[0.0; LANES]; l], vec![[0.0; LANES]; m], vec![[0.0; LANES]; n]);
            for (block, mb) in ms.chunks_mut(LANES).enumerate() {
                for lane in 0..mb.len() {
                    let row = chunk * ROWS + block * LANES + lane;
                    let b = &self.basis[row * stride..(row + 1) * stride];
                    for i in 0..l {
                        bx[i][lane] = b[i];
                    }
                    for j in 0..m {
                        by[j][lane] = b[l + j];
                    }
                    for k in 0..n {
                        bz[k][lane] = b[l + m + k];
                    }
                }
                let acc = lattice_sum_lanes(mu, &bx, &by, &bz);
                for (lane, d) in mb.iter_mut().enumerate() {
                    let v = frame * Vector3::new(acc[0][lane], acc[1][lane], acc[2][lane]);
                    *d = [v.x, v.y, v.z];
                }
            }
        });
        for (&idx, d) in self.inside.iter().zip(moved) {
            out[idx] += Vector3::from(d);
        }
        Ok(())
    }

    /// `∂φ(points[i])/∂μ` in compact form (see [`ParamWeights`]).
    ///
    /// # Panics
    ///
    /// If `i` is not below [`BoundFfd::len`].
    pub fn param_weights(&self, i: usize) -> ParamWeights {
        assert!(i < self.points.len(), "point {i} of {}", self.points.len());
        let [l, m, n] = self.shape;
        let stride = l + m + n;
        let mut weights = Vec::new();
        if let Ok(row) = self.inside.binary_search(&i) {
            let b = &self.basis[row * stride..(row + 1) * stride];
            for a in 0..l {
                for c in 0..m {
                    for d in 0..n {
                        weights.push(((a * m + c) * n + d, b[a] * b[l + c] * b[l + m + d]));
                    }
                }
            }
        }
        ParamWeights { n_nodes: l * m * n, weights, frame: self.frame }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bernstein_partition_of_unity_and_values() {
        for deg in 1..8 {
            let mut b = vec![0.0; deg + 1];
            for t in [0.0, 0.25, 0.5, 0.9, 1.0] {
                bernstein(deg, t, &mut b);
                let s: f64 = b.iter().sum();
                assert!((s - 1.0).abs() < 1e-14);
            }
        }
        let mut b = [0.0; 4];
        bernstein(3, 0.5, &mut b);
        assert_eq!(b, [0.125, 0.375, 0.375, 0.125]);
        bernstein(3, 1.0, &mut b);
        assert_eq!(b, [0.0, 0.0, 0.0, 1.0]);
        // The table and the recurrence used above degree 32 agree.
        let mut big = vec![0.0; 34];
        bernstein(33, 0.3, &mut big);
        assert!((big.iter().sum::<f64>() - 1.0).abs() < 1e-13);
        assert_eq!(BINOM[32][16], 601_080_390.0);
    }

    #[test]
    fn bernstein_derivative_matches_difference() {
        let (deg, t, h) = (4, 0.37, 1e-6);
        let (mut d, mut p, mut q) = (vec![0.0; 5], vec![0.0; 5], vec![0.0; 5]);
        bernstein_deriv(deg, t, &mut d);
        bernstein(deg, t + h, &mut p);
        bernstein(deg, t - h, &mut q);
        for i in 0..=deg {
            assert!((d[i] - (p[i] - q[i]) / (2.0 * h)).abs() < 1e-8);
        }
    }

    /// A small deterministic generator (xorshift64*) for test inputs, in `[0, 1)`.
    fn uniform(state: &mut u64) -> f64 {
        *state ^= *state >> 12;
        *state ^= *state << 25;
        *state ^= *state >> 27;
        (state.wrapping_mul(0x2545_F491_4F6C_DD1D) >> 11) as f64 / (1u64 << 53) as f64
    }

    /// The FFD written out directly: `p + frame · Σᵢⱼₖ C·uⁱ(1−u)^… μᵢⱼₖ`, binomials and
    /// powers computed afresh for every term.
    fn naive_deform(ffd: &Ffd, p: &Point3<f64>) -> Point3<f64> {
        let [l, m, n] = ffd.mu.shape;
        let u = ffd.inverse * (p - ffd.box_origin);
        let t = ffd.face_tol;
        if u.iter().any(|&c| c < -t || c > 1.0 + t) {
            return *p;
        }
        let u = u.map(|c| c.clamp(0.0, 1.0));
        let choose = |n: usize, k: usize| (1..=k).fold(1.0, |a, i| a * (n + 1 - i) as f64 / i as f64);
        let b = |deg: usize, i: usize, x: f64| choose(deg, i) * x.powi(i as i32) * (1.0 - x).powi((deg - i) as i32);
        let mut acc = Vector3::zeros();
        for i in 0..l {
            for j in 0..m {
                for k in 0..n {
                    let w = b(l - 1, i, u.x) * b(m - 1, j, u.y) * b(n - 1, k, u.z);
                    acc += w * Vector3::from(ffd.mu.get(i, j, k));
                }
            }
        }
        p + ffd.frame * acc
    }

    #[test]
    fn vectorised_deform_matches_direct_bernstein_sum() {
        let mut state = 0x9E37_79B9_7F4A_7C15;
        // Shapes on the compile-time k paths (2..=8), beyond them, and past the binomial table.
        for shape in
            [[2, 2, 2], [3, 3, 3], [3, 2, 3], [2, 3, 2], [6, 6, 6], [4, 3, 5], [3, 9, 7], [5, 2, 11], [2, 3, 34]]
        {
            let mut ffd = Ffd::try_new(
                shape,
                Point3::new(-1.0, 2.0, 0.5),
                Vector3::new(2.0, 1.5, 3.0),
                Vector3::new(10.0, -25.0, 40.0),
            )
            .unwrap();
            for f in 0..ffd.mu.len() {
                ffd.mu.x[f] = 0.2 * uniform(&mut state) - 0.1;
                ffd.mu.y[f] = 0.2 * uniform(&mut state) - 0.1;
                ffd.mu.z[f] = 0.2 * uniform(&mut state) - 0.1;
            }
            // Points in and around the box (unit-box coordinates in [−0.2, 1.2]), some on
            // faces and corners; more than one parallel chunk, and a ragged tail.
            let mut pts: Vec<Point3<f64>> = (0..9001)
                .map(|q| {
                    let mut u = Vector3::from_fn(|_, _| 1.4 * uniform(&mut state) - 0.2);
                    if q % 7 == 0 {
                        u.x = (q % 2) as f64;
                    }
                    if q % 11 == 0 {
                        u = Vector3::new(1.0, 0.0, 1.0);
                    }
                    ffd.box_origin + ffd.frame * u
                })
                .collect();
            pts.push(ffd.box_origin);
            let fast = ffd.deformed(&pts);
            let (mut moved, mut stayed) = (0, 0);
            for (p, q) in pts.iter().zip(&fast) {
                let r = naive_deform(&ffd, p);
                assert!((q - r).amax() <= 1e-12 * p.coords.amax().max(1.0), "{shape:?} at {p}: {q} vs {r}");
                let one = ffd.deform_point(p);
                assert!((q - one).amax() <= 1e-12 * p.coords.amax().max(1.0), "{shape:?} at {p}: {q} vs {one}");
                if q == p {
                    stayed += 1;
                } else {
                    moved += 1;
                }
            }
            assert!(moved > 1000 && stayed > 1000, "{shape:?}: {moved} moved, {stayed} stayed");
        }
    }

    #[test]
    fn portable_scalar_and_avx2_paths_agree() {
        use pulp::WithSimd;
        let mut state = 0x853C_49E6_748F_EA9B;
        for shape in [[3, 3, 3], [2, 3, 2], [4, 3, 5]] {
            let mut ffd = Ffd::try_new(
                shape,
                Point3::new(0.5, -2.0, 1.0),
                Vector3::new(1.0, 2.0, 0.5),
                Vector3::new(-30.0, 5.0, 60.0),
            )
            .unwrap();
            for f in 0..ffd.mu.len() {
                ffd.mu.x[f] = 0.2 * uniform(&mut state) - 0.1;
                ffd.mu.y[f] = 0.2 * uniform(&mut state) - 0.1;
                ffd.mu.z[f] = 0.2 * uniform(&mut state) - 0.1;
            }
            // A ragged count: a short last group of four and a short last pass.
            let pts: Vec<Point3<f64>> = (0..1003)
                .map(|_| ffd.box_origin + ffd.frame * Vector3::from_fn(|_, _| 1.4 * uniform(&mut state) - 0.2))
                .collect();
            let power = PowerForm::new(&ffd.mu);
            let run = |which: u8| {
                let mut out = pts.clone();
                let points = &mut out[..];
                let op = DeformSimd { ffd: &ffd, power: power.as_ref(), points };
                // The three paths must agree on the points and on the first non-finite one.
                let bad = match which {
                    0 => op.with_simd(pulp::Scalar::new()),
                    1 => pulp::Arch::new().dispatch(op),
                    _ => ffd.deform_serial(&mut out, power.as_ref()),
                };
                assert_eq!(bad, None);
                out
            };
            let (scalar, portable, best) = (run(0), run(1), run(2));
            for (i, p) in pts.iter().enumerate() {
                let one = ffd.deform_point(p);
                for q in [scalar[i], portable[i], best[i]] {
                    assert!((q - one).amax() <= 1e-13, "{shape:?} at {p}: {q} vs {one}");
                    assert_eq!(q == *p, one == *p, "{shape:?} at {p}: inside or not");
                }
            }
        }
    }

    #[test]
    fn power_form_matches_bernstein_form() {
        let mut state = 0x2545_F491_4F6C_DD1D;
        let shapes = [[2, 2, 2], [3, 3, 3], [2, 2, 3], [2, 3, 2], [3, 2, 2], [2, 3, 3], [3, 2, 3], [3, 3, 2]];
        for shape in shapes {
            let mut mu = Displacements::zeros(shape);
            for f in 0..mu.len() {
                mu.x[f] = 2.0 * uniform(&mut state) - 1.0;
                mu.y[f] = 2.0 * uniform(&mut state) - 1.0;
                mu.z[f] = 1e3 * (2.0 * uniform(&mut state) - 1.0);
            }
            let power = PowerForm::new(&mu).unwrap();
            let simd = pulp::Scalar::new();
            let mut scratch = [[0.0; 33]; 3];
            let mut worst = [0.0f64; 3];
            for _ in 0..20_000 {
                let uvw = [uniform(&mut state), uniform(&mut state), uniform(&mut state)];
                let a = power.eval(simd, uvw);
                let b = displacement_simd(simd, &mu, uvw, &mut scratch);
                for c in 0..3 {
                    worst[c] = worst[c].max((a[c] - b[c]).abs());
                }
            }
            // Relative to the largest |μ| of each component (1 and 1000): within 64 ulps.
            assert!(worst[0] <= 64.0 * f64::EPSILON && worst[1] <= 64.0 * f64::EPSILON, "{shape:?}: {worst:?}");
            assert!(worst[2] <= 64.0 * f64::EPSILON * 1e3, "{shape:?}: {worst:?}");
        }
        assert!(PowerForm::new(&Displacements::zeros([4, 3, 3])).is_none());
    }

    #[test]
    fn lattice_rejects_small_dimensions() {
        let e = Ffd::try_new([1, 2, 2], Point3::origin(), Vector3::repeat(1.0), Vector3::zeros()).unwrap_err();
        assert!(matches!(e, Error::InvalidParameter { name: "n control points", .. }));
        let e = Ffd::try_new([2, 2, 2], Point3::origin(), Vector3::new(1.0, 0.0, 1.0), Vector3::zeros()).unwrap_err();
        assert!(matches!(e, Error::InvalidParameter { name: "box length", .. }));
    }
}

#[cfg(test)]
mod checked_tests {
    use super::*;
    use pulp::WithSimd;

    /// The fused check finds the first non-finite point on every path (AVX2 groups of
    /// four, the short last group, the portable gather, point by point for big lattices),
    /// leaves those points as they are and deforms every other one as `deform_point` does.
    #[test]
    fn deform_checked_reports_the_first_non_finite_point_and_moves_the_rest() {
        let mut ffd = Ffd::unit([3, 3, 3]);
        for (i, m) in ffd.mu_mut().x.iter_mut().enumerate() {
            *m = 0.01 * (i as f64).sin();
        }
        let n = 5003;
        let pts: Vec<Point3<f64>> = (0..n)
            .map(|i| {
                let t = i as f64;
                Point3::new(
                    -0.1 + 1.2 * (t * 0.37).fract(),
                    -0.1 + 1.2 * (t * 0.61).fract(),
                    -0.1 + 1.2 * (t * 0.83).fract(),
                )
            })
            .collect();
        for (bad_at, value) in [(3001usize, f64::NAN), (5002, f64::INFINITY), (7, f64::NEG_INFINITY), (4999, f64::NAN)]
        {
            let mut p = pts.clone();
            p[bad_at].y = value;
            p[bad_at].z = value;
            if bad_at + 1500 < n {
                p[bad_at + 1500].x = f64::NAN; // a later one is not the one named
            }
            let expect: Vec<Point3<f64>> = p.iter().map(|q| ffd.deform_point(q)).collect();
            let mut got = p.clone();
            assert_eq!(ffd.deform_checked(&mut got), Err(bad_at));
            for (k, (a, b)) in got.iter().zip(&expect).enumerate() {
                let same = (a - b).norm() <= 1e-14
                    || (a.coords.iter().zip(b.coords.iter()).all(|(x, y)| x.to_bits() == y.to_bits()));
                assert!(same, "point {k}: {a:?} vs {b:?}");
            }
            // Small slices run on one thread, through each SIMD path.
            let mut one = p[bad_at.saturating_sub(3)..(bad_at + 3).min(n)].to_vec();
            assert_eq!(ffd.deform_checked(&mut one), Err(bad_at - bad_at.saturating_sub(3)));
            let power = PowerForm::new(&ffd.mu);
            let mut portable = p.clone();
            let r = pulp::Arch::new().dispatch(DeformSimd { ffd: &ffd, power: power.as_ref(), points: &mut portable });
            assert_eq!(r, Some(bad_at));
            let mut scalar = p.clone();
            let r = DeformSimd { ffd: &ffd, power: power.as_ref(), points: &mut scalar }.with_simd(pulp::Scalar::new());
            assert_eq!(r, Some(bad_at));
        }
        let mut clean = pts.clone();
        assert_eq!(ffd.deform_checked(&mut clean), Ok(()));
    }
}
