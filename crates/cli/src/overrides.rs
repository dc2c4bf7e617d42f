//! `--set NAME=VALUE`: entries of a parameter file overridden on the command line, for
//! parameter sweeps without a file per value. Names are those of the TOML form
//! (`docs/parameters.md`), whichever form the file is in: `mu_y[1,1,1]=0.05` (an FFD
//! displacement at lattice node i, j, k), `box_origin[0]=90`, `radius=0.3`,
//! `kernel=gaussian_spline`, `power=3`, `deformed_control_points[2,1]=0.4` (point 2, y).
//! The result is read again as a whole, so every check of the file applies to it.

use anyhow::{anyhow, bail, Context, Result};
use cadmorph::morph::Parameters;
use toml::{Table, Value};

/// One `--set` override: a name, its indices and the value's text.
#[derive(Debug, Clone, PartialEq)]
pub struct Set {
    /// The whole argument, for messages.
    pub text: String,
    /// The entry's name (`mu_y`).
    pub name: String,
    /// The indices in brackets (`[1, 1, 1]`), none for a plain value.
    pub index: Vec<usize>,
    /// The value as given.
    pub value: String,
}

/// Reads `NAME=VALUE`, `NAME[i]=VALUE` or `NAME[i,j,k]=VALUE` (clap value parser).
pub fn parse(s: &str) -> Result<Set, String> {
    let (lhs, value) = s.split_once('=').ok_or_else(|| format!("{s:?}: expected NAME=VALUE, e.g. mu_y[1,1,1]=0.05"))?;
    let lhs = lhs.trim();
    let (name, index) = match lhs.split_once('[') {
        Some((name, rest)) => {
            let inner =
                rest.strip_suffix(']').ok_or_else(|| format!("{s:?}: the index of {name} needs a closing ]"))?;
            let index = inner
                .split(',')
                .map(|i| {
                    i.trim().parse::<usize>().map_err(|_| format!("{s:?}: index {:?} is not a whole number", i.trim()))
                })
                .collect::<Result<Vec<_>, _>>()?;
            (name.trim(), index)
        }
        None => (lhs, Vec::new()),
    };
    if name.is_empty() || !name.chars().all(|c| c.is_ascii_alphanumeric() || c == '_') {
        return Err(format!("{s:?}: {name:?} is not a parameter name"));
    }
    Ok(Set { text: s.to_owned(), name: name.to_owned(), index, value: value.trim().to_owned() })
}

/// The value text as TOML: a number, a boolean, an array, or else a bare word as a string.
fn value(text: &str) -> Value {
    toml::from_str::<Table>(&format!("v = {text}"))
        .ok()
        .and_then(|mut t| t.remove("v"))
        .unwrap_or_else(|| Value::String(text.to_owned()))
}

fn as_usize(v: Option<&Value>) -> Option<usize> {
    v.and_then(Value::as_integer).and_then(|i| usize::try_from(i).ok())
}

/// Applies one override to the kind's table `t` (`kind`: `ffd`, `rbf` or `idw`).
fn apply_one(t: &mut Table, kind: &str, s: &Set) -> Result<()> {
    let names: Vec<String> = t.keys().cloned().collect();
    let optional: &[&str] = match kind {
        "rbf" => &["k"],
        "idw" => &["cutoff"],
        _ => &[],
    };
    if !t.contains_key(&s.name) && !optional.contains(&s.name.as_str()) {
        bail!("{kind} parameters have no {:?}; their names are {}", s.name, names.join(", "));
    }
    if kind == "ffd" && s.name == "n_control_points" {
        bail!("the lattice size cannot be set (its displacements would no longer fit); use `cadmorph ffd fit`");
    }
    let new = value(&s.value);
    let shape: Option<[usize; 3]> = t
        .get("n_control_points")
        .and_then(Value::as_array)
        .and_then(|a| Some([as_usize(a.first())?, as_usize(a.get(1))?, as_usize(a.get(2))?]));
    let slot = t.get_mut(&s.name);
    match (slot, s.index.as_slice()) {
        (Some(slot), []) => *slot = new,
        (None, []) => {
            t.insert(s.name.clone(), new);
        }
        (Some(Value::Array(a)), idx) => {
            // mu_* arrays are indexed by lattice node; others by position (and coordinate).
            let flat = match (s.name.starts_with("mu_"), idx, shape) {
                (true, [i, j, k], Some([l, m, n])) => {
                    if *i >= l || *j >= m || *k >= n {
                        bail!("node [{i},{j},{k}] is outside the {l}x{m}x{n} lattice (i < {l}, j < {m}, k < {n})");
                    }
                    vec![(i * m + j) * n + k]
                }
                (true, _, _) => bail!("{} takes a lattice node: {}[i,j,k]", s.name, s.name),
                (false, [p], _) => vec![*p],
                (false, [p, c], _) => vec![*p, *c],
                _ => bail!("{} takes one index, or a point and a coordinate ([p] or [p,c])", s.name),
            };
            let len = a.len();
            let first = a
                .get_mut(flat[0])
                .ok_or_else(|| anyhow!("index {} is past the {len} entries of {}", flat[0], s.name))?;
            match (first, flat.get(1)) {
                (slot, None) => *slot = new,
                (Value::Array(p), Some(&c)) => {
                    let n = p.len();
                    *p.get_mut(c)
                        .ok_or_else(|| anyhow!("coordinate {c} is past the {n} of a point (0, 1, 2: x, y, z)"))? = new;
                }
                _ => bail!("{}[{}] is not a point, so it takes one index", s.name, flat[0]),
            }
        }
        (_, _) => bail!("{} is a single value: give it without an index", s.name),
    }
    Ok(())
}

/// `params` with the overrides `sets` applied in order, read again as a whole.
///
/// # Errors
///
/// A name the parameters do not have, an index out of range, or a value the parameters
/// refuse, each naming the `--set` it comes from.
pub fn apply(params: Parameters, sets: &[Set]) -> Result<Parameters> {
    if sets.is_empty() {
        return Ok(params);
    }
    let mut doc: Table = toml::from_str(&params.to_toml()).context("the TOML form of the parameters")?;
    let kind = crate::params::kind_of(&params);
    for s in sets {
        let t = doc.get_mut(kind).and_then(Value::as_table_mut).context("the TOML form has its kind's table")?;
        apply_one(t, kind, s).with_context(|| format!("--set {}", s.text))?;
    }
    let text = toml::to_string(&doc).context("writing the overridden parameters")?;
    let list: Vec<&str> = sets.iter().map(|s| s.text.as_str()).collect();
    Parameters::from_toml(&text).with_context(|| format!("the parameters after --set {}", list.join(" --set ")))
}

#[cfg(test)]
mod tests {
    use super::*;

    const FFD: &str =
        "[ffd]\nn_control_points = [2, 3, 2]\nbox_origin = [0.0, 0.0, 0.0]\nbox_length = [1.0, 1.0, 1.0]\n";

    fn set(s: &str) -> Set {
        parse(s).unwrap()
    }

    #[test]
    fn a_lattice_node_is_set_in_c_order() {
        let p = Parameters::from_toml(FFD).unwrap();
        let Parameters::Ffd(f) = apply(p, &[set("mu_y[1,2,0]=0.05"), set("box_origin[2]=4")]).unwrap() else {
            panic!()
        };
        assert_eq!(f.mu().get(1, 2, 0), [0.0, 0.05, 0.0]);
        assert_eq!(f.mu().y.iter().filter(|v| **v != 0.0).count(), 1);
        assert_eq!(f.box_origin().z, 4.0);
    }

    #[test]
    fn bad_overrides_name_what_is_wrong() {
        let p = || Parameters::from_toml(FFD).unwrap();
        let e = format!("{:#}", apply(p(), &[set("mu_y[2,0,0]=1")]).unwrap_err());
        assert!(e.contains("outside the 2x3x2 lattice"), "{e}");
        let e = format!("{:#}", apply(p(), &[set("radius=0.3")]).unwrap_err());
        assert!(e.contains("no \"radius\"") && e.contains("box_origin"), "{e}");
        let e = format!("{:#}", apply(p(), &[set("box_length[0]=-1")]).unwrap_err());
        assert!(e.contains("--set box_length[0]=-1"), "{e}");
        assert!(parse("radius").is_err());
        assert!(parse("mu_y[1,x,1]=0").is_err());
    }

    #[test]
    fn rbf_radius_and_points() {
        let text = "[rbf]\nkernel = \"gaussian_spline\"\nradius = 0.5\noriginal_control_points = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0]]\ndeformed_control_points = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0]]\n";
        let p = Parameters::from_toml(text).unwrap();
        let Parameters::Rbf(r) = apply(p, &[set("radius=0.3"), set("deformed_control_points[1,2]=0.25")]).unwrap()
        else {
            panic!()
        };
        assert_eq!(r.kernel.radius(), 0.3);
        assert_eq!(r.deformed[1].z, 0.25);
    }
}
