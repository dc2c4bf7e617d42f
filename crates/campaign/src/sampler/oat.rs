//! One-at-a-time designs: the base point, then each parameter through its levels while
//! the others stay at base (the classical OAT screening design; Saltelli et al., Global
//! Sensitivity Analysis: The Primer, 2008, §2.4).

use crate::space::Parameter;

/// The base point (every parameter at its [`base`](crate::space::Values::base)), then
/// for each parameter in order each of its levels other than its base value.
pub fn one_at_a_time(params: &[Parameter], levels: usize) -> Vec<Vec<f64>> {
    let base: Vec<f64> = params.iter().map(|p| p.values.base()).collect();
    let mut rows = vec![base.clone()];
    for (i, p) in params.iter().enumerate() {
        for v in p.values.levels(levels) {
            if v != base[i] {
                let mut r = base.clone();
                r[i] = v;
                rows.push(r);
            }
        }
    }
    rows
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::entry::Entry;
    use crate::space::Values;

    #[test]
    fn each_row_differs_from_base_in_one_parameter() {
        let p = |lo, hi| Parameter {
            name: "p".into(),
            entry: Entry::Control { component: 0, index: 0 },
            theta: 0,
            values: Values::Range { lo, hi },
        };
        let rows = one_at_a_time(&[p(0.0, 1.0), p(-1.0, 1.0), p(2.0, 4.0)], 3);
        // 3 levels with the midpoint as base: 2 more rows per parameter.
        assert_eq!(rows.len(), 1 + 3 * 2);
        assert_eq!(rows[0], vec![0.5, 0.0, 3.0]);
        for r in &rows[1..] {
            assert_eq!(r.iter().zip(&rows[0]).filter(|(a, b)| a != b).count(), 1);
        }
    }
}
