//! Full factorial designs: every combination of the parameters' levels (Box, Hunter &
//! Hunter, Statistics for Experimenters, ch. 5), the last parameter varying fastest.

use crate::space::Parameter;

/// Every combination of each parameter's [`levels`](crate::space::Values::levels).
pub fn full_factorial(params: &[Parameter], levels: usize) -> Vec<Vec<f64>> {
    let axes: Vec<Vec<f64>> = params.iter().map(|p| p.values.levels(levels)).collect();
    let mut rows = vec![Vec::new()];
    for axis in &axes {
        rows = rows.into_iter().flat_map(|r| axis.iter().map(move |&v| [r.as_slice(), &[v]].concat())).collect();
    }
    rows
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::entry::Entry;
    use crate::space::Values;

    #[test]
    fn counts_and_order() {
        let p = |lo, hi| Parameter {
            name: "p".into(),
            entry: Entry::Control { component: 0, index: 0 },
            theta: 0,
            values: Values::Range { lo, hi },
        };
        let mut s = p(0.0, 1.0);
        s.values = Values::Set(vec![5.0, 7.0]);
        let rows = full_factorial(&[p(0.0, 1.0), s], 3);
        assert_eq!(rows.len(), 6);
        assert_eq!(rows[0], vec![0.0, 5.0]);
        assert_eq!(rows[1], vec![0.0, 7.0]);
        assert_eq!(rows[5], vec![1.0, 7.0]);
    }
}
