//! Uniform cell grid over the centres of a compactly supported kernel: the neighbours of a
//! point within the support lie in the 3×3×3 cells around its own, and the three cells
//! along x are contiguous in the cell-sorted centre arrays, so a neighbourhood is nine
//! contiguous ranges. Used for the sparse matrix assembly and the bulk evaluation (no
//! allocation per point, loops the compiler vectorises).

use std::ops::Range;

use nalgebra::Point3;

/// Centres sorted by cell, in structure-of-arrays form.
#[derive(Debug, Clone)]
pub(crate) struct Grid {
    lo: [f64; 3],
    inv_h: f64,
    dims: [usize; 3],
    /// `start[c]..start[c + 1]` are the sorted centres of cell `c = (iz·ny + iy)·nx + ix`.
    start: Vec<u32>,
    /// Sorted position → original centre index.
    pub perm: Vec<u32>,
    pub x: Vec<f64>,
    pub y: Vec<f64>,
    pub z: Vec<f64>,
    /// Weights γ in sorted order (refreshed after each solve).
    pub g: [Vec<f64>; 3],
}

impl Grid {
    /// A grid with cells of side at least `support` (larger when the cell count would
    /// exceed a few per centre).
    pub fn new(centres: &[Point3<f64>], support: f64) -> Grid {
        let n = centres.len();
        let mut lo = [f64::INFINITY; 3];
        let mut hi = [f64::NEG_INFINITY; 3];
        for p in centres {
            for a in 0..3 {
                lo[a] = lo[a].min(p[a]);
                hi[a] = hi[a].max(p[a]);
            }
        }
        let mut h = support;
        let dims = loop {
            let d: [usize; 3] = std::array::from_fn(|a| ((hi[a] - lo[a]) / h).floor() as usize + 1);
            if (d[0] as f64) * (d[1] as f64) * (d[2] as f64) <= (4 * n + 64) as f64 {
                break d;
            }
            h *= 1.25;
        };
        let inv_h = 1.0 / h;
        let cell = |p: &Point3<f64>| -> usize {
            let i: [usize; 3] = std::array::from_fn(|a| (((p[a] - lo[a]) * inv_h) as usize).min(dims[a] - 1));
            (i[2] * dims[1] + i[1]) * dims[0] + i[0]
        };
        let n_cells = dims[0] * dims[1] * dims[2];
        let mut start = vec![0u32; n_cells + 1];
        let cells: Vec<usize> = centres.iter().map(cell).collect();
        for &c in &cells {
            start[c + 1] += 1;
        }
        for c in 0..n_cells {
            start[c + 1] += start[c];
        }
        let mut fill = start.clone();
        let mut perm = vec![0u32; n];
        for (i, &c) in cells.iter().enumerate() {
            perm[fill[c] as usize] = i as u32;
            fill[c] += 1;
        }
        let pick = |a: usize| perm.iter().map(|&i| centres[i as usize][a]).collect::<Vec<f64>>();
        let (x, y, z) = (pick(0), pick(1), pick(2));
        Grid { lo, inv_h, dims, start, perm, x, y, z, g: [vec![0.0; n], vec![0.0; n], vec![0.0; n]] }
    }

    /// Groups of sorted centres that lie close together, for a block preconditioner: the
    /// cubes of `s × s × s` cells (`s` chosen so a cube holds about `target` centres),
    /// shifted by half a cube along each axis when `staggered` (the second partition of
    /// an additive Schwarz preconditioner: centres on either side of a face of the first
    /// partition's cubes share a group there). A cube's centres are one group, and a
    /// group over `2 · target` is cut into runs of `target` (in cell order, so still
    /// compact). Returns the sorted positions in group order and the group bounds in it.
    pub fn blocks(&self, target: usize, staggered: bool) -> (Vec<u32>, Vec<usize>) {
        let n = self.x.len();
        let [nx, ny, nz] = self.dims;
        let per_cell = n as f64 / (nx * ny * nz) as f64;
        let s = ((target as f64 / per_cell.max(1e-300)).cbrt().round() as usize).max(1);
        let (inv_side, shift) = (self.inv_h / s as f64, if staggered { 0.5 } else { 0.0 });
        let keys: Vec<u64> = (0..n)
            .map(|i| {
                let c = [self.x[i], self.y[i], self.z[i]];
                let k: [u64; 3] =
                    std::array::from_fn(|a| ((c[a] - self.lo[a]) * inv_side + shift).floor().max(0.0) as u64);
                (k[2] << 42) | (k[1] << 21) | k[0]
            })
            .collect();
        let mut order: Vec<u32> = (0..n as u32).collect();
        order.sort_unstable_by_key(|&i| (keys[i as usize], i));
        let mut bounds = vec![0];
        let mut first = 0;
        for p in 1..=n {
            if p == n || keys[order[p] as usize] != keys[order[first] as usize] {
                let len = p - first;
                let pieces = if len > 2 * target { len.div_ceil(target) } else { 1 };
                bounds.extend((1..=pieces).map(|k| first + len * k / pieces));
                first = p;
            }
        }
        (order, bounds)
    }

    /// Copy the weights (original order) into sorted order.
    pub fn set_weights(&mut self, g: &[Vec<f64>; 3]) {
        for c in 0..3 {
            for (s, &i) in self.perm.iter().enumerate() {
                self.g[c][s] = g[c][i as usize];
            }
        }
    }

    /// Calls `f` with the (at most nine) ranges of sorted centres in the cells around `p`;
    /// every centre within one cell side of `p` is in one of them.
    #[inline]
    pub fn for_each_range(&self, p: [f64; 3], mut f: impl FnMut(Range<usize>)) {
        let mut lo = [0usize; 3];
        let mut hi = [0usize; 3];
        for a in 0..3 {
            let t = (p[a] - self.lo[a]) * self.inv_h;
            // Cells ix − 1 ..= ix + 1 clipped to the grid; `as i64` saturates (NaN → 0).
            let i = t.floor() as i64;
            let (l, h) = (i.saturating_sub(1).max(0), i.saturating_add(1).min(self.dims[a] as i64 - 1));
            if l > h || !t.is_finite() {
                return;
            }
            lo[a] = l as usize;
            hi[a] = h as usize;
        }
        let [nx, ny, _] = self.dims;
        for iz in lo[2]..=hi[2] {
            for iy in lo[1]..=hi[1] {
                let row = (iz * ny + iy) * nx;
                let (a, b) = (self.start[row + lo[0]] as usize, self.start[row + hi[0] + 1] as usize);
                if a < b {
                    f(a..b);
                }
            }
        }
    }
}
