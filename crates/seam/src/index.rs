//! A bounding-box index for pairing boundaries: which boxes overlap a given box, in
//! `O(log n + k)` per query instead of a scan of all `n` (an R*-tree, `rstar`).

use cadmorph_nurbs::Aabb;
use rstar::primitives::{GeomWithData, Rectangle};
use rstar::{RTree, AABB};

type Entry = GeomWithData<Rectangle<[f64; 3]>, usize>;

/// Boxes by their index in the list they were built from.
pub(crate) struct BoxIndex {
    tree: RTree<Entry>,
}

fn corners(b: &Aabb) -> ([f64; 3], [f64; 3]) {
    ([b.min.x, b.min.y, b.min.z], [b.max.x, b.max.y, b.max.z])
}

impl BoxIndex {
    /// The index of `boxes` (bulk-loaded); box `k` is reported as `k`. Boxes with a
    /// non-finite corner are left out (they can overlap nothing sensibly).
    pub(crate) fn new<'a>(boxes: impl IntoIterator<Item = &'a Aabb>) -> Self {
        let entries = boxes
            .into_iter()
            .enumerate()
            .filter(|(_, b)| b.min.iter().chain(b.max.iter()).all(|x| x.is_finite()))
            .map(|(k, b)| {
                let (lo, hi) = corners(b);
                GeomWithData::new(Rectangle::from_corners(lo, hi), k)
            })
            .collect();
        Self { tree: RTree::bulk_load(entries) }
    }

    /// Indices of the boxes that intersect `b` (touching counts), in no order.
    pub(crate) fn overlapping(&self, b: &Aabb) -> Vec<usize> {
        let (lo, hi) = corners(b);
        let mut out: Vec<usize> =
            self.tree.locate_in_envelope_intersecting(&AABB::from_corners(lo, hi)).map(|e| e.data).collect();
        out.sort_unstable();
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use cadmorph_nurbs::math::Point3;

    fn unit_at(x: f64) -> Aabb {
        Aabb { min: Point3::new(x, 0.0, 0.0), max: Point3::new(x + 1.0, 1.0, 1.0) }
    }

    #[test]
    fn finds_exactly_the_overlapping_boxes() {
        // Boxes [k, k + 1] along x: box k touches k - 1 and k + 1 and nothing else.
        let boxes: Vec<Aabb> = (0..50).map(|k| unit_at(k as f64)).collect();
        let index = BoxIndex::new(&boxes);
        for (k, b) in boxes.iter().enumerate() {
            let brute: Vec<usize> = (0..boxes.len()).filter(|&j| boxes[j].intersection(b).is_some()).collect();
            assert_eq!(index.overlapping(b), brute, "box {k}");
        }
        assert_eq!(index.overlapping(&unit_at(10.5)), vec![10, 11]);
    }

    #[test]
    fn non_finite_boxes_are_left_out() {
        let mut boxes = vec![unit_at(0.0), unit_at(0.5)];
        boxes[1].max.x = f64::NAN;
        assert_eq!(BoxIndex::new(&boxes).overlapping(&unit_at(0.0)), vec![0]);
    }
}
