//! Errors of the morph crate: parameter-file problems (with the line they are on) and
//! numeric failures (with the measured quantity).

/// Everything that can go wrong while building a deformation or reading its parameters.
///
/// Building a deformation may fail; applying one never does (see [`crate::Deformation`]).
/// Parameter-file errors name the 1-based line of the problem.
///
/// # Examples
///
/// ```
/// use cadmorph_morph::{prm, Error};
/// let text = "[Radial Basis Functions]\nbasis function: gaussian_splines\nradius: 0.5\n";
/// match prm::read(text) {
///     Err(Error::UnknownKernel { line, name }) => {
///         assert_eq!(line, 2);
///         assert_eq!(name, "gaussian_splines");
///     }
///     other => panic!("unexpected {other:?}"),
/// }
/// ```
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum Error {
    /// A line of a parameter file did not parse.
    #[error("line {line}: expected {expected}, found {found:?}")]
    Syntax {
        /// 1-based line number.
        line: usize,
        /// What the reader expected there.
        expected: &'static str,
        /// The offending text.
        found: String,
    },
    /// A required section is absent from a parameter file.
    #[error("missing section [{section}]")]
    MissingSection {
        /// Section name, as PyGeM spells it.
        section: &'static str,
    },
    /// A required key is absent from a section of a parameter file.
    #[error("line {line}: section [{section}] has no key {key:?}")]
    MissingKey {
        /// Line of the section header.
        line: usize,
        /// Section name.
        section: &'static str,
        /// The missing key.
        key: &'static str,
    },
    /// A section or key appears twice.
    #[error("line {line}: duplicate {what}, first given on line {first}")]
    Duplicate {
        /// Line of the second occurrence.
        line: usize,
        /// Line of the first occurrence.
        first: usize,
        /// What is duplicated (`section [..]`, `key ..`, `weight (i, j, k)`).
        what: String,
    },
    /// The RBF basis function name is not one cadmorph knows.
    #[error("line {line}: unknown basis function {name:?} (known: {})", crate::rbf::Kernel::NAMES.join(", "))]
    UnknownKernel {
        /// Line of the `basis function` key.
        line: usize,
        /// The name found.
        name: String,
    },
    /// A key that the basis function (or the section) does not take.
    #[error("line {line}: unknown parameter {name:?} for {context}")]
    UnknownParameter {
        /// Line of the key.
        line: usize,
        /// The key found.
        name: String,
        /// What it was given to (a kernel name or a section).
        context: String,
    },
    /// Two lists that must have the same length do not.
    #[error("line {line}: {what}: expected {expected}, found {found}")]
    CountMismatch {
        /// Line where the second list starts (0 when not read from a file).
        line: usize,
        /// What is being counted.
        what: &'static str,
        /// The count required.
        expected: usize,
        /// The count found.
        found: usize,
    },
    /// A lattice index lies outside the lattice.
    #[error("line {line}: lattice index ({}, {}, {}) outside the {}x{}x{} lattice", index[0], index[1], index[2], shape[0], shape[1], shape[2])]
    IndexOutOfRange {
        /// Line of the weight.
        line: usize,
        /// The index read.
        index: [usize; 3],
        /// Lattice size.
        shape: [usize; 3],
    },
    /// A numeric parameter is out of its domain (non-finite, non-positive length, lattice < 2, ...).
    #[error("{line_prefix}invalid {name} = {value}: {reason}", line_prefix = line.map(|l| format!("line {l}: ")).unwrap_or_default())]
    InvalidParameter {
        /// Line where it was read, if it came from a file.
        line: Option<usize>,
        /// Parameter name.
        name: &'static str,
        /// The value given.
        value: f64,
        /// Why it is rejected.
        reason: &'static str,
    },
    /// The RBF interpolation system is singular (duplicate control points, coplanar control
    /// points with the linear term, ...). `condition` is the 1-norm condition estimate
    /// (infinite when a pivot vanished).
    #[error("singular interpolation system (condition estimate {condition:e})")]
    SingularSystem {
        /// 1-norm condition number estimate.
        condition: f64,
    },
    /// The RBF interpolation system is too ill-conditioned for its solution to be trusted
    /// (for example a Gaussian radius far larger than the control-point spacing): the solved
    /// interpolant misses its own control points by more than
    /// [`crate::rbf::RbfOptions::max_residual`], or the condition estimate exceeds
    /// [`crate::rbf::RbfOptions::max_condition`].
    #[error("ill-conditioned interpolation system: condition estimate {condition:e} (limit {max_condition:e}), the solution misses its control points by {residual:e} of the largest displacement")]
    IllConditioned {
        /// 1-norm condition number estimate.
        condition: f64,
        /// Largest miss at a control point, relative to the largest displacement.
        residual: f64,
        /// The condition limit in force.
        max_condition: f64,
    },
    /// A size derived from the input would need more memory than the budget allows
    /// ([`crate::budget`]); nothing was allocated.
    #[error("{what} would need {} of memory, over the budget of {}", crate::budget::human_bytes(*needed), crate::budget::human_bytes(*limit as u128))]
    TooLarge {
        /// The parameter or structure whose size is refused (`FFD lattice 100000x100000x100000`).
        what: String,
        /// Bytes it would need (`u128::MAX` when even the product overflows).
        needed: u128,
        /// The budget in force, in bytes.
        limit: u64,
    },
    /// An FFD lattice larger than one deformation evaluates: a dimension over
    /// [`crate::ffd::MAX_NODES_PER_AXIS`] (the Bernstein degree `f64` holds), or a node
    /// count over [`crate::ffd::MAX_NODES`] (the work per deformed point).
    #[error("{}", lattice_message(*line, shape, *axis, *limit))]
    LatticeTooLarge {
        /// Line of the lattice size, if it came from a file.
        line: Option<usize>,
        /// The lattice size asked for.
        shape: [usize; 3],
        /// The dimension over its limit (0 = x, 1 = y, 2 = z), or `None` for the node count.
        axis: Option<usize>,
        /// The limit exceeded.
        limit: usize,
    },
    /// A parameter file is not valid UTF-8.
    #[error("byte {offset} (line {line}): not valid UTF-8 text")]
    Encoding {
        /// 0-based byte offset of the first invalid byte.
        offset: usize,
        /// 1-based line it is on.
        line: usize,
    },
    /// Two RBF centres coincide (within a relative 1e-12 of the model size), so the
    /// interpolation system is singular.
    #[error("RBF centres {first} and {second} coincide at ({}, {}, {}): the interpolation system is singular", point[0], point[1], point[2])]
    CoincidentCentres {
        /// 0-based index of the first centre.
        first: usize,
        /// 0-based index of the second centre.
        second: usize,
        /// Where they are.
        point: [f64; 3],
    },
    /// A constrained morph has no solution: the displacements it may change cannot meet
    /// the constraints (all fixed, a change out of reach, contradicting constraints).
    #[error("constraint cannot be met: {0}")]
    Infeasible(String),
    /// A TOML parameter document did not parse or did not describe valid parameters.
    #[error("TOML line {line}, column {column}: {message}")]
    Toml {
        /// 1-based line (0 when unknown).
        line: usize,
        /// 1-based column (0 when unknown).
        column: usize,
        /// The parser's message.
        message: String,
    },
}

/// `Result` with this crate's [`Error`].
pub type Result<T, E = Error> = std::result::Result<T, E>;

/// `line 4: FFD lattice 200x200x200: nodes in all = 8000000, over the limit of 262144 (...)`.
fn lattice_message(line: Option<usize>, shape: &[usize; 3], axis: Option<usize>, limit: usize) -> String {
    let at = line.map(|l| format!("line {l}: ")).unwrap_or_default();
    let [l, m, n] = *shape;
    let (name, value, why) = match axis {
        Some(a) => (
            format!("n control points {}", ["x", "y", "z"][a.min(2)]),
            shape[a.min(2)] as u128,
            "Bernstein polynomials of a higher degree overflow f64",
        ),
        None => {
            ("nodes in all".to_owned(), l as u128 * m as u128 * n as u128, "each deformed point sums over every node")
        }
    };
    format!("{at}FFD lattice {l}x{m}x{n}: {name} = {value}, over the limit of {limit} ({why})")
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Prints every message once so their wording can be reviewed (`cargo test -- --nocapture`).
    #[test]
    fn messages_name_line_and_quantity() {
        let all = [
            Error::Syntax { line: 3, expected: "a number", found: "x".into() },
            Error::MissingSection { section: "Box info" },
            Error::MissingKey { line: 2, section: "Box info", key: "box length x" },
            Error::Duplicate { line: 9, first: 4, what: "key \"radius\"".into() },
            Error::UnknownKernel { line: 5, name: "gaussian_splines".into() },
            Error::UnknownParameter { line: 6, name: "q".into(), context: "gaussian_spline".into() },
            Error::CountMismatch { line: 7, what: "deformed control points", expected: 8, found: 9 },
            Error::IndexOutOfRange { line: 8, index: [3, 0, 0], shape: [3, 2, 2] },
            Error::InvalidParameter { line: Some(4), name: "radius", value: -1.0, reason: "must be positive" },
            Error::SingularSystem { condition: f64::INFINITY },
            Error::IllConditioned { condition: 1e20, residual: 4.0, max_condition: 1e16 },
            Error::Toml { line: 1, column: 2, message: "expected `=`".into() },
        ];
        for e in &all {
            let msg = e.to_string();
            println!("{msg}");
            assert!(!msg.is_empty());
        }
        assert!(all[0].to_string().starts_with("line 3:"));
        assert!(all[4].to_string().contains("thin_plate_spline"));
        assert!(all[6].to_string().contains("expected 8, found 9"));
        assert!(all[9].to_string().contains("inf"));
        assert!(all[10].to_string().contains("1e20"));
    }
}
