//! Instances that edits left unused: an old curve an edge no longer points at, the
//! points of a surface rewritten with new ones, an analytic surface's placement after
//! the surface became a B-spline. Removed when the document is written, so an edited
//! file carries no dead geometry; instances the input itself left unreferenced (its
//! roots: products, contexts, representations, and whatever else the writer put there
//! unreferenced) are kept.

use std::collections::BTreeSet;

use crate::document::Document;
use crate::read::scan_instance;

impl Document {
    /// Positions of the instances orphaned by the edits so far: every instance that some
    /// instance of the input referenced, or that an edit added, and that nothing kept
    /// references any more (counting the references of other orphans as gone). Empty
    /// for an unedited document.
    pub(crate) fn orphans(&self) -> BTreeSet<usize> {
        let mut out = BTreeSet::new();
        if self.texts.is_empty() {
            return out;
        }
        let refs_of = |bytes: &[u8]| -> Vec<usize> {
            // Instances were scanned when parsed or edited: a failure here cannot happen,
            // and an instance that fails keeps all its references (nothing is removed).
            scan_instance(bytes)
                .map(|(_, refs)| refs.into_iter().filter_map(|id| self.index.get(id)).collect())
                .unwrap_or_default()
        };
        let n = self.instances.len();
        let mut referenced_before = vec![false; n];
        let mut count = vec![0usize; n];
        let mut now: Vec<Vec<usize>> = Vec::with_capacity(n);
        for k in 0..n {
            let current = refs_of(self.text(k));
            for &j in &current {
                count[j] += 1;
            }
            if k < self.n_original {
                if self.texts.contains_key(&k) {
                    let inst = &self.instances[k];
                    for j in refs_of(&self.source[inst.start..inst.end]) {
                        referenced_before[j] = true;
                    }
                } else {
                    for &j in &current {
                        referenced_before[j] = true;
                    }
                }
            }
            now.push(current);
        }
        let candidate = |k: usize, referenced_before: &[bool]| {
            (k >= self.n_original || referenced_before[k]) && !self.pinned.contains(&k)
        };
        let mut work: Vec<usize> = (0..n).filter(|&k| count[k] == 0 && candidate(k, &referenced_before)).collect();
        while let Some(k) = work.pop() {
            if !out.insert(k) {
                continue;
            }
            for &j in &now[k] {
                count[j] -= 1;
                if count[j] == 0 && candidate(j, &referenced_before) {
                    work.push(j);
                }
            }
        }
        out
    }
}
