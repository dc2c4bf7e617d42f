//! The entry of the deformation a campaign parameter is bound to: one FFD lattice
//! displacement `mu_y[1,2,0]` (PyGeM's `array_mu_y[1, 2, 0]`, paper §2.1.1 eq. (2)) or one
//! component of an RBF or IDW control-point displacement `d_z[3]` (paper eq. (3)–(5), (9)).

use std::fmt;

use cadmorph::morph::Parameters;

/// One scalar of a deformation's parameter vector θ (layout of
/// [`LinearInParameters`](cadmorph::morph::LinearInParameters): `θ[c · n_nodes + node]`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Entry {
    /// FFD lattice displacement of node `(i, j, k)` along box axis `component` (0 = x),
    /// in units of the box length.
    Lattice {
        /// 0, 1, 2 for `mu_x`, `mu_y`, `mu_z`.
        component: usize,
        /// Lattice index `[i, j, k]`.
        node: [usize; 3],
    },
    /// RBF or IDW displacement of control point `index` along `component` (model units):
    /// the control point's deformed position is its original one plus this.
    Control {
        /// 0, 1, 2 for `d_x`, `d_y`, `d_z`.
        component: usize,
        /// 0-based control point.
        index: usize,
    },
}

const AXES: [char; 3] = ['x', 'y', 'z'];

impl Entry {
    /// Parses `mu_x[i,j,k]` or `d_x[n]` (any of x, y, z; spaces allowed inside the
    /// brackets). Returns what was expected on failure.
    pub fn parse(text: &str) -> Result<Entry, String> {
        let expected = "an entry `mu_x[i,j,k]` (FFD; mu_y, mu_z too) or `d_x[n]` (RBF/IDW control point n; d_y, d_z)";
        let t = text.trim();
        let (head, rest) = t.split_once('[').ok_or_else(|| format!("expected {expected}, found {t:?}"))?;
        let inner = rest.strip_suffix(']').ok_or_else(|| format!("expected {expected}, found {t:?}"))?;
        let numbers: Result<Vec<usize>, _> = inner.split(',').map(|s| s.trim().parse::<usize>()).collect();
        let numbers = numbers.map_err(|_| format!("expected non-negative integer indices in {t:?}"))?;
        let axis = |prefix: &str| {
            head.trim().strip_prefix(prefix).and_then(|a| AXES.iter().position(|&c| a.len() == 1 && a.starts_with(c)))
        };
        if let Some(component) = axis("mu_") {
            if let [i, j, k] = numbers[..] {
                return Ok(Entry::Lattice { component, node: [i, j, k] });
            }
            return Err(format!("a lattice entry has three indices [i,j,k], found {t:?}"));
        }
        if let Some(component) = axis("d_") {
            if let [index] = numbers[..] {
                return Ok(Entry::Control { component, index });
            }
            return Err(format!("a control-point entry has one index [n], found {t:?}"));
        }
        Err(format!("expected {expected}, found {t:?}"))
    }

    /// The index of this entry in the parameter vector θ of `params`, or why it does not
    /// exist there (a lattice node outside the lattice, a control point past the last, an
    /// FFD entry for an RBF).
    pub fn theta_index(&self, params: &Parameters) -> Result<usize, String> {
        match (self, params) {
            (Entry::Lattice { component, node }, Parameters::Ffd(ffd)) => {
                let [l, m, n] = ffd.n_control_points();
                let [i, j, k] = *node;
                if i >= l || j >= m || k >= n {
                    return Err(format!(
                        "lattice node [{i},{j},{k}] does not exist: the lattice has {l} x {m} x {n} nodes \
                         (indices up to [{},{},{}])",
                        l - 1,
                        m - 1,
                        n - 1
                    ));
                }
                Ok(component * l * m * n + (i * m + j) * n + k)
            }
            (Entry::Control { component, index }, Parameters::Rbf(p)) => control(*component, *index, p.original.len()),
            (Entry::Control { component, index }, Parameters::Idw(p)) => control(*component, *index, p.original.len()),
            (Entry::Lattice { .. }, _) => Err("a lattice entry mu_*[i,j,k] needs an FFD deformation".into()),
            (Entry::Control { .. }, Parameters::Ffd(_)) => {
                Err("a control-point entry d_*[n] needs an RBF or IDW deformation; FFD entries are mu_*[i,j,k]".into())
            }
        }
    }
}

fn control(component: usize, index: usize, n: usize) -> Result<usize, String> {
    if index >= n {
        return Err(format!("control point {index} does not exist: the deformation has {n} (0 to {})", n.max(1) - 1));
    }
    Ok(component * n + index)
}

impl fmt::Display for Entry {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Entry::Lattice { component, node: [i, j, k] } => write!(f, "mu_{}[{i},{j},{k}]", AXES[*component]),
            Entry::Control { component, index } => write!(f, "d_{}[{index}]", AXES[*component]),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parses_and_prints_both_kinds() {
        assert_eq!(Entry::parse("mu_y[1, 2,0]"), Ok(Entry::Lattice { component: 1, node: [1, 2, 0] }));
        assert_eq!(Entry::parse(" d_z[3] "), Ok(Entry::Control { component: 2, index: 3 }));
        assert_eq!(Entry::parse("mu_y[1,2,0]").unwrap().to_string(), "mu_y[1,2,0]");
        for bad in ["mu_w[1,2,0]", "mu_y[1,2]", "d_x[1,2]", "mu_y[1,-2,0]", "mu_y 1 2 0", "muy[1,2,0]", "mu_xy[0,0,0]"]
        {
            assert!(Entry::parse(bad).is_err(), "{bad}");
        }
    }

    #[test]
    fn theta_index_follows_the_c_order_layout() {
        let ffd = cadmorph::morph::Ffd::unit([5, 4, 4]);
        let p = Parameters::Ffd(ffd);
        let e = Entry::Lattice { component: 1, node: [1, 2, 3] };
        assert_eq!(e.theta_index(&p), Ok(80 + (4 + 2) * 4 + 3));
        let err = Entry::Lattice { component: 0, node: [5, 0, 0] }.theta_index(&p).unwrap_err();
        assert!(err.contains("5 x 4 x 4"), "{err}");
        assert!(Entry::Control { component: 0, index: 0 }.theta_index(&p).is_err());
    }
}
