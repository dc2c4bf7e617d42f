//! The lossless core of the line-oriented formats (UNV, LS-DYNA, Kratos, Elmer, OpenFOAM
//! ASCII points): the file's text is kept as read, and each node remembers the line its
//! coordinates are on. Writing reproduces the text byte for byte, except the lines of
//! nodes whose coordinates changed, which are formatted anew.

use std::ops::Range;

use nalgebra::Point3;

/// A text file with node coordinate records at known places.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct NodeLines {
    /// The file as read.
    pub text: String,
    /// For each node, the byte range of its record in `text` (the part that is replaced
    /// when the node moves) and its coordinates as read.
    pub records: Vec<(Range<usize>, Point3<f64>)>,
}

impl NodeLines {
    /// Number of node records read.
    pub fn len(&self) -> usize {
        self.records.len()
    }

    /// The text with every node whose point differs (bitwise) from the one read, or every
    /// node when `all` is set, replaced by `format(index, point, original record)`.
    pub fn write(
        &self,
        points: &[Point3<f64>],
        all: bool,
        mut format: impl FnMut(usize, &Point3<f64>, &str) -> String,
    ) -> String {
        let mut out = String::with_capacity(self.text.len() + self.text.len() / 8);
        let mut at = 0;
        for (i, (range, orig)) in self.records.iter().enumerate() {
            // A point list shorter than the file's (not possible through `MeshFile`, which
            // refuses a changed count) keeps the missing records as read.
            let Some(p) = points.get(i) else { break };
            let same = p.iter().zip(orig.iter()).all(|(a, b)| a.to_bits() == b.to_bits());
            if all || !same {
                out.push_str(&self.text[at..range.start]);
                out.push_str(&format(i, p, &self.text[range.clone()]));
                at = range.end;
            }
        }
        out.push_str(&self.text[at..]);
        out
    }
}
