//! `cadmorph ffd fit` and `cadmorph ffd show`: an FFD box fitted around a model or some of
//! its faces (PyGeM #135), written as a PyGeM `.prm` or TOML parameter file with zero
//! displacements; and the lattice of a parameter file, node by node.

use std::path::{Path, PathBuf};

use anyhow::{bail, Context, Result};
use cadmorph::morph::math::{Point3, Vector3};
use cadmorph::morph::{Ffd, Parameters};
use cadmorph::nurbs::Aabb;
use serde_json::json;

/// `ffd fit` and `ffd show`.
#[derive(clap::Subcommand)]
pub enum FfdCommand {
    /// Fit an axis-aligned FFD box around the control points of a model (or of the
    /// faces given with --around) and write it with zero displacements.
    Fit(FitArgs),
    /// Print the lattice of an FFD parameter file: box, nodes, displacements.
    Show(ShowArgs),
}

/// Arguments of `ffd fit`.
#[derive(clap::Args)]
#[command(after_help = "The box holds every control point of the chosen faces (so the morph moves all of \
                        them), widened on each side by the margin. Edit the displacements in the file, or \
                        give them on the command line: cadmorph morph IN -o OUT box.prm --set 'mu_y[1,1,1]=0.05'.")]
pub struct FitArgs {
    /// The IGES or STEP file.
    input: PathBuf,
    /// Lattice nodes per direction, LxMxN (each 2 to 64).
    #[arg(long, default_value = "3x3x3", value_parser = parse_lattice, value_name = "LxMxN")]
    lattice: [usize; 3],
    /// Space added on every side: a fraction of the faces' extent along that axis (`5%`,
    /// `0.05`), or a length in model units with a `u` after it (`2u`).
    #[arg(long, default_value = "5%", value_parser = parse_margin)]
    margin: Margin,
    /// Fit around these faces only: an index as `cadmorph info` numbers them (`2`), or the
    /// face entity (`DE 7`, `DE7`, `#531`). Repeat or give several.
    #[arg(long, num_args = 1.., value_name = "FACE")]
    around: Vec<String>,
    /// The parameter file to write: `.prm` (PyGeM) or `.toml`.
    #[arg(short, long)]
    output: PathBuf,
    /// Print JSON (schema `cadmorph.ffd_fit/1`).
    #[arg(long)]
    json: bool,
}

/// Arguments of `ffd show`.
#[derive(clap::Args)]
pub struct ShowArgs {
    /// An FFD parameter file (PyGeM `.prm` or `.toml`).
    file: PathBuf,
    /// Print JSON (schema `cadmorph.ffd_show/1`).
    #[arg(long)]
    json: bool,
}

/// The margin of a fitted box.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Margin {
    /// A fraction of the box's extent along each axis.
    Fraction(f64),
    /// A length in model units.
    Length(f64),
}

/// `4x3x3` to `[4, 3, 3]`.
pub fn parse_lattice(s: &str) -> Result<[usize; 3], String> {
    let parts: Vec<&str> = s.split(['x', 'X', '×']).collect();
    if parts.len() != 3 {
        return Err(format!("{s:?} is not a lattice: expected three counts like 4x3x3"));
    }
    let mut out = [0; 3];
    for (o, p) in out.iter_mut().zip(&parts) {
        let n: usize = p.trim().parse().map_err(|_| format!("{p:?} in {s:?} is not a whole number"))?;
        if !(2..=64).contains(&n) {
            return Err(format!("{n} nodes in {s:?}: each direction needs 2 to 64"));
        }
        *o = n;
    }
    Ok(out)
}

/// `5%`, `0.05` (fractions) or `2u` (model units).
pub fn parse_margin(s: &str) -> Result<Margin, String> {
    let t = s.trim();
    let (num, make): (&str, fn(f64) -> Margin) = if let Some(p) = t.strip_suffix('%') {
        (p, |v| Margin::Fraction(v / 100.0))
    } else if let Some(u) = t.strip_suffix('u') {
        (u, Margin::Length)
    } else {
        (t, Margin::Fraction)
    };
    let v: f64 = num.trim().parse().map_err(|_| format!("{s:?} is not a margin (examples: 5%, 0.05, 2u)"))?;
    if !v.is_finite() || v < 0.0 {
        return Err(format!("{s:?}: a margin is a finite number, 0 or more"));
    }
    Ok(make(v))
}

/// The faces `around` names, as indices into `faces` (all faces when empty).
pub fn select_faces(around: &[String], faces: &[cadmorph::brep::Face]) -> Result<Vec<usize>> {
    if around.is_empty() {
        return Ok((0..faces.len()).collect());
    }
    let squash = |s: &str| s.chars().filter(|c| !c.is_whitespace()).collect::<String>().to_ascii_uppercase();
    let mut out = Vec::new();
    for a in around.iter().flat_map(|a| a.split(',')).map(str::trim).filter(|a| !a.is_empty()) {
        let found = match a.parse::<usize>() {
            Ok(i) if i < faces.len() => Some(i),
            Ok(i) => {
                bail!("--around {a}: there is no face {i} (the file has faces 0 to {})", faces.len().saturating_sub(1))
            }
            Err(_) => faces.iter().position(|f| squash(&f.entity.to_string()) == squash(a)),
        };
        match found {
            Some(i) if !out.contains(&i) => out.push(i),
            Some(_) => {}
            None => {
                let known: Vec<String> =
                    faces.iter().enumerate().map(|(i, f)| crate::faces::label(i, &f.entity)).collect();
                bail!("--around {a:?} names no face: give an index or a face entity, one of {}", known.join(", "));
            }
        }
    }
    Ok(out)
}

/// The box around `b` widened by `margin` on every side; an axis along which the faces
/// are flat is widened by the margin of the largest axis, so the box never has a zero
/// length.
pub fn fitted_box(b: &Aabb, margin: Margin) -> (Point3<f64>, Vector3<f64>) {
    let extent = b.max - b.min;
    let largest = extent.max().max(f64::MIN_POSITIVE);
    let pad = extent.map(|e| match margin {
        Margin::Fraction(f) => f * if e > 1e-9 * largest { e } else { largest },
        Margin::Length(l) => l,
    });
    // A flat axis with a zero margin still needs a box of some thickness.
    let pad = pad.zip_map(&extent, |p, e| if e + 2.0 * p > 0.0 { p } else { 0.5e-3 * largest });
    (b.min - pad, extent + 2.0 * pad)
}

fn write_params(path: &Path, p: &Parameters) -> Result<()> {
    let text = match path.extension().and_then(|e| e.to_str()) {
        Some("toml") => p.to_toml(),
        Some("prm") => p.to_prm()?,
        _ => bail!("{}: the output must end in .prm (PyGeM) or .toml", path.display()),
    };
    cadmorph::model::write_atomic(path, text.as_bytes())?;
    Ok(())
}

/// Runs `ffd fit`.
pub fn fit(a: FitArgs) -> Result<()> {
    if !matches!(a.output.extension().and_then(|e| e.to_str()), Some("prm" | "toml")) {
        bail!("{}: the output must end in .prm (PyGeM) or .toml; nothing written", a.output.display());
    }
    let m = cadmorph::open(&a.input)?;
    crate::skipped::warn(&m.info().skipped);
    if m.patches().is_empty() {
        bail!("{} has no faces to fit a box around; nothing written", a.input.display());
    }
    let chosen = select_faces(&a.around, m.patches())?;
    let points = chosen.iter().flat_map(|&i| m.patches()[i].surface.control_points());
    let bbox = Aabb::from_points(points).context("the chosen faces have no control points")?;
    let (origin, length) = fitted_box(&bbox, a.margin);
    let ffd = Ffd::try_new(a.lattice, origin, length, Vector3::zeros())
        .with_context(|| format!("fitting the box around {}", a.input.display()))?;
    let params = Parameters::Ffd(ffd);
    write_params(&a.output, &params)?;
    let info = m.info();
    let unit = crate::units::words(info.metres_per_unit, &info.unit);
    let faces: Vec<_> =
        chosen.iter().map(|&i| crate::faces::json(i, &m.patches()[i].entity, &m.patches()[i].surface_entity)).collect();
    if a.json {
        return crate::schema::print(
            "ffd_fit",
            json!({
                "input": a.input.display().to_string(),
                "output": a.output.display().to_string(),
                "unit": crate::units::json(info.metres_per_unit, &info.unit),
                "faces": faces,
                "lattice": a.lattice,
                "control_point_box": { "min": [bbox.min.x, bbox.min.y, bbox.min.z], "max": [bbox.max.x, bbox.max.y, bbox.max.z] },
                "box_origin": [origin.x, origin.y, origin.z],
                "box_length": [length.x, length.y, length.z],
            }),
        );
    }
    let names: Vec<String> = chosen.iter().map(|&i| crate::faces::label(i, &m.patches()[i].entity)).collect();
    println!(
        "{} -> {}: {}x{}x{} lattice around {} face(s): {}",
        a.input.display(),
        a.output.display(),
        a.lattice[0],
        a.lattice[1],
        a.lattice[2],
        chosen.len(),
        names.join(", ")
    );
    println!(
        "  control points span x {:.6} .. {:.6}, y {:.6} .. {:.6}, z {:.6} .. {:.6} {unit}",
        bbox.min.x, bbox.max.x, bbox.min.y, bbox.max.y, bbox.min.z, bbox.max.z
    );
    println!(
        "  box origin ({:.6}, {:.6}, {:.6}), lengths ({:.6}, {:.6}, {:.6}) {unit}; all displacements 0",
        origin.x, origin.y, origin.z, length.x, length.y, length.z
    );
    Ok(())
}

/// Whether node `(i, j, k)` of an `[l, m, n]` lattice lies on a face of the box.
pub fn on_boundary([i, j, k]: [usize; 3], [l, m, n]: [usize; 3]) -> bool {
    i == 0 || j == 0 || k == 0 || i + 1 == l || j + 1 == m || k + 1 == n
}

/// Runs `ffd show`.
pub fn show(a: ShowArgs) -> Result<()> {
    let Parameters::Ffd(f) = crate::params::read(&a.file)? else {
        bail!(
            "{} holds {} parameters; `ffd show` shows FFD lattices",
            a.file.display(),
            crate::params::kind_of(&crate::params::read(&a.file)?)
        );
    };
    let shape = f.n_control_points();
    let [l, m, n] = shape;
    let (o, len, rot) = (f.box_origin(), f.box_length(), f.rot_angle());
    let (rest, moved) = (f.control_points(false), f.control_points(true));
    let mut nodes = Vec::with_capacity(l * m * n);
    for i in 0..l {
        for j in 0..m {
            for k in 0..n {
                let idx = f.mu().index(i, j, k);
                nodes.push(([i, j, k], f.mu().get(i, j, k), rest[idx], moved[idx]));
            }
        }
    }
    let moving = nodes.iter().filter(|(_, mu, _, _)| mu.iter().any(|c| *c != 0.0)).count();
    let boundary_moving =
        nodes.iter().filter(|(ijk, mu, _, _)| on_boundary(*ijk, shape) && mu.iter().any(|c| *c != 0.0)).count();
    if a.json {
        let list: Vec<_> = nodes
            .iter()
            .map(|(ijk, mu, p, q)| json!({ "index": ijk, "mu": mu, "rest": [p.x, p.y, p.z], "moved": [q.x, q.y, q.z], "boundary": on_boundary(*ijk, shape) }))
            .collect();
        return crate::schema::print(
            "ffd_show",
            json!({
                "file": a.file.display().to_string(),
                "lattice": shape,
                "box_origin": [o.x, o.y, o.z],
                "box_length": [len.x, len.y, len.z],
                "rot_angle_deg": [rot.x, rot.y, rot.z],
                "moving_nodes": moving,
                "moving_boundary_nodes": boundary_moving,
                "nodes": list,
            }),
        );
    }
    println!("{}: FFD lattice {l}x{m}x{n} ({} nodes, {moving} with a displacement, {boundary_moving} of them on the box faces)", a.file.display(), l * m * n);
    println!(
        "  box origin ({}, {}, {}), lengths ({}, {}, {}), rotation ({}, {}, {}) degrees",
        o.x, o.y, o.z, len.x, len.y, len.z, rot.x, rot.y, rot.z
    );
    println!("  mu: displacement in units of the box lengths (PyGeM's convention); B: a node on a box face");
    println!(
        "{:>3} {:>3} {:>3} {:>1} {:>9} {:>9} {:>9} {:>13} {:>13} {:>13} {:>13} {:>13} {:>13}",
        "i", "j", "k", "", "mu_x", "mu_y", "mu_z", "x", "y", "z", "x moved", "y moved", "z moved"
    );
    for (ijk, mu, p, q) in &nodes {
        println!(
            "{:>3} {:>3} {:>3} {:>1} {:>9.4} {:>9.4} {:>9.4} {:>13.6} {:>13.6} {:>13.6} {:>13.6} {:>13.6} {:>13.6}",
            ijk[0],
            ijk[1],
            ijk[2],
            if on_boundary(*ijk, shape) { "B" } else { "" },
            mu[0],
            mu[1],
            mu[2],
            p.x,
            p.y,
            p.z,
            q.x,
            q.y,
            q.z
        );
    }
    Ok(())
}

/// Runs `ffd`.
pub fn run(c: FfdCommand) -> Result<()> {
    match c {
        FfdCommand::Fit(a) => fit(a),
        FfdCommand::Show(a) => show(a),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lattices_and_margins() {
        assert_eq!(parse_lattice("4x3x3"), Ok([4, 3, 3]));
        assert!(parse_lattice("4x3").is_err());
        assert!(parse_lattice("1x3x3").is_err());
        assert_eq!(parse_margin("5%"), Ok(Margin::Fraction(0.05)));
        assert_eq!(parse_margin("0.1"), Ok(Margin::Fraction(0.1)));
        assert_eq!(parse_margin("2u"), Ok(Margin::Length(2.0)));
        assert!(parse_margin("-1%").is_err());
    }

    #[test]
    fn the_box_holds_the_points_with_the_margin() {
        let b = Aabb { min: Point3::new(0.0, 0.0, 1.0), max: Point3::new(10.0, 2.0, 1.0) };
        let (o, l) = fitted_box(&b, Margin::Fraction(0.1));
        assert_eq!(o, Point3::new(-1.0, -0.2, 0.0), "flat z takes the margin of the largest axis");
        assert_eq!(l, Vector3::new(12.0, 2.4, 2.0));
    }
}
