//! `cadmorph mesh …`: morph and check surface and volume meshes (crate `cadmorph-mesh`).
//!
//! ```text
//! cadmorph mesh morph IN -o OUT --ffd|--rbf|--idw PARAMS [--allow-degrade] [--json]
//! cadmorph mesh check IN [--json] [--histograms DIR [--after OUT]]
//! ```
//!
//! `IN`/`OUT` are an OpenFOAM case or `polyMesh` directory, or a `.unv`, `.k`, `.mdpa`,
//! `.nodes` file; `OUT` is written in the format of `IN`, only after the morph passed the
//! quality check (volume meshes), atomically.

use std::path::{Path, PathBuf};

use anyhow::{bail, Context, Result};
use cadmorph::mesh::morph::morph_file;
use cadmorph::mesh::quality::Quality;
use cadmorph::mesh::MeshFile;
use cadmorph::model::write_atomic;
use cadmorph::morph::{Deformation, Parameters};
use cadmorph_report::histogram::{histogram_png, histogram_svg, quality_samples};
use clap::{Args, Subcommand};

/// `cadmorph mesh` subcommands.
#[derive(Subcommand)]
pub enum MeshCommand {
    /// Move every node of a mesh by an FFD, RBF or IDW; volume meshes are checked before
    /// and after, and a morph that inverts cells is refused.
    Morph(MorphArgs),
    /// Mesh quality as OpenFOAM's checkMesh reports it.
    Check {
        /// Mesh file or OpenFOAM case / polyMesh directory.
        input: PathBuf,
        /// Print JSON instead of a table.
        #[arg(long)]
        json: bool,
        /// Also write histograms of the per-face and per-cell quality (non-orthogonality,
        /// aspect ratio, cell volume, skewness) into this folder, each as NAME.svg and
        /// NAME.png.
        #[arg(long)]
        histograms: Option<PathBuf>,
        /// The morphed mesh to draw as "after" in the histograms (INPUT is "before").
        #[arg(long, requires = "histograms")]
        after: Option<PathBuf>,
    },
    /// Tessellate every face of an IGES or STEP model, trims included, into one
    /// watertight triangle mesh: shared edges sampled once, so no vertex is duplicated
    /// and none lies inside another face's edge (what snappyHexMesh wants). STL output
    /// has one solid per face, OBJ one group per face, named by the face's index and
    /// entity (`face3_DE123`, `face3_531` for STEP #531).
    FromCad {
        /// The IGES or STEP model.
        input: PathBuf,
        /// The mesh: .stl (ASCII, a solid per face) or .obj (a group per face).
        #[arg(short, long)]
        output: PathBuf,
        /// Largest distance from the triangles to the CAD surfaces, in model units
        /// (default 1e-3 of the model's size).
        #[arg(long)]
        tol: Option<f64>,
        /// Largest angle between a triangle and the surface, degrees.
        #[arg(long, default_value_t = 15.0)]
        angle: f64,
        /// Print what was made as JSON.
        #[arg(long)]
        json: bool,
    },
}

/// Arguments of `cadmorph mesh morph`.
#[derive(Args)]
pub struct MorphArgs {
    /// Mesh file or OpenFOAM case / polyMesh directory.
    pub input: PathBuf,
    /// Output (same format as the input).
    #[arg(short, long)]
    pub output: PathBuf,
    /// FFD parameters (PyGeM .prm or TOML).
    #[arg(long, group = "law")]
    pub ffd: Option<PathBuf>,
    /// RBF parameters (PyGeM .prm or TOML).
    #[arg(long, group = "law")]
    pub rbf: Option<PathBuf>,
    /// IDW parameters (PyGeM .prm or TOML).
    #[arg(long, group = "law")]
    pub idw: Option<PathBuf>,
    /// Write even if the morph inverts or degrades cells (the report says where).
    #[arg(long)]
    pub allow_degrade: bool,
    /// Print the before/after quality as JSON.
    #[arg(long)]
    pub json: bool,
}

fn law(path: &Path, expect: &str) -> Result<Box<dyn Deformation + Send>> {
    let text = std::fs::read_to_string(path).with_context(|| format!("reading {}", path.display()))?;
    let is_toml = path.extension().is_some_and(|e| e == "toml");
    let params = if is_toml { Parameters::from_toml(&text) } else { Parameters::from_prm(&text) }
        .with_context(|| format!("reading {}", path.display()))?;
    let kind = match params {
        Parameters::Ffd(_) => "ffd",
        Parameters::Rbf(_) => "rbf",
        Parameters::Idw(_) => "idw",
    };
    if kind != expect {
        bail!("{} holds {kind} parameters, but --{expect} was given", path.display());
    }
    params.build().with_context(|| format!("building the morph of {}", path.display()))
}

/// `cadmorph mesh from-cad`.
fn from_cad(input: &Path, output: &Path, tol: Option<f64>, angle: f64, json: bool) -> Result<()> {
    use cadmorph::mesh::from_cad::{tessellate_faces, to_obj, to_stl, MeshTolerance};
    let ext = output.extension().and_then(|e| e.to_str()).map(str::to_ascii_lowercase);
    let obj = match ext.as_deref() {
        Some("stl") => false,
        Some("obj") => true,
        _ => bail!("{}: the mesh is written as .stl or .obj", output.display()),
    };
    let m = cadmorph::open(input)?;
    let size = m.size();
    let chord = tol.unwrap_or(1e-3 * size);
    let faces = cadmorph::bounded_faces(&m)?;
    let w = tessellate_faces(&faces.faces, &faces.natural, faces.join, size, MeshTolerance { chord, angle_deg: angle })
        .with_context(|| format!("tessellating {}", input.display()))?;
    // Region names OpenFOAM takes as words (snappyHexMesh names its patches after them):
    // `face3_DE123` (IGES), `face3_531` (STEP #531).
    let names: Vec<String> = m
        .patches()
        .iter()
        .enumerate()
        .map(|(i, f)| {
            format!("face{i}_{}", f.entity.to_string().chars().filter(char::is_ascii_alphanumeric).collect::<String>())
        })
        .collect();
    let bytes = if obj { to_obj(&w, &names) } else { to_stl(&w, &names)? };
    write_atomic(output, &bytes).with_context(|| format!("writing {}", output.display()))?;
    // Mesh edges with one triangle: the open borders of the model.
    let mut uses: std::collections::HashMap<(usize, usize), u32> = std::collections::HashMap::new();
    for t in &w.triangles {
        for k in 0..3 {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            *uses.entry((a.min(b), a.max(b))).or_default() += 1;
        }
    }
    let border = uses.values().filter(|&&n| n == 1).count();
    let non_manifold = uses.values().filter(|&&n| n > 2).count();
    if json {
        return crate::schema::print(
            "mesh_from_cad",
            serde_json::json!({
                "input": input.display().to_string(),
                "output": output.display().to_string(),
                "faces": m.patches().len(),
                "points": w.points.len(),
                "triangles": w.triangles.len(),
                "chord_tolerance": chord,
                "angle_tolerance_deg": angle,
                "border_edges": border,
                "non_manifold_edges": non_manifold,
            }),
        );
    }
    println!(
        "{}: {} faces → {} points, {} triangles (chord {chord:e}, angle {angle}°); {} border edges, {} edges with more than two triangles",
        output.display(),
        m.patches().len(),
        w.points.len(),
        w.triangles.len(),
        border,
        non_manifold
    );
    Ok(())
}

/// Run a `cadmorph mesh` subcommand.
pub fn run(cmd: MeshCommand) -> Result<()> {
    match cmd {
        MeshCommand::FromCad { input, output, tol, angle, json } => from_cad(&input, &output, tol, angle, json),
        MeshCommand::Check { input, json, histograms, after } => {
            let read = |path: &Path| -> Result<_> {
                let file = MeshFile::read(path).with_context(|| format!("reading {}", path.display()))?;
                let Some(mesh) = file.volume_mesh()? else {
                    bail!("{} has no volume cells to check", path.display());
                };
                Ok(mesh)
            };
            let mesh = read(&input)?;
            let q = Quality::of(&mesh);
            if let Some(dir) = &histograms {
                let before = quality_samples(&mesh);
                let after = after.as_deref().map(|p| read(p).map(|m| quality_samples(&m))).transpose()?;
                std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
                for (k, (name, values)) in before.iter().enumerate() {
                    let other = after.as_ref().map(|a| a[k].1.as_slice());
                    if values.iter().chain(other.into_iter().flatten()).all(|v| !v.is_finite()) {
                        eprintln!("{}: no {name} values (no internal faces?): no histogram", input.display());
                        continue;
                    }
                    let svg = histogram_svg(name, values, other, 30, 720, 440)?;
                    let file: String = name
                        .split(" (")
                        .next()
                        .unwrap_or(name)
                        .chars()
                        .map(|c| if c.is_ascii_alphanumeric() { c } else { '_' })
                        .collect();
                    let path = dir.join(format!("{file}.svg"));
                    write_atomic(&path, svg.as_bytes()).with_context(|| format!("writing {}", path.display()))?;
                    let png = histogram_png(name, values, other, 30, 720, 440)?;
                    let path = dir.join(format!("{file}.png"));
                    write_atomic(&path, &png).with_context(|| format!("writing {}", path.display()))?;
                }
            }
            if json {
                println!("{}", serde_json::to_string_pretty(&q)?);
            } else {
                print!("{}", q.table());
            }
            if !q.ok() {
                bail!("{}: failed {} mesh check(s)", input.display(), q.failed.len());
            }
            Ok(())
        }
        MeshCommand::Morph(a) => {
            let (path, kind) = match (&a.ffd, &a.rbf, &a.idw) {
                (Some(p), _, _) => (p, "ffd"),
                (_, Some(p), _) => (p, "rbf"),
                (_, _, Some(p)) => (p, "idw"),
                _ => bail!("one of --ffd, --rbf, --idw is needed"),
            };
            let d = law(path, kind)?;
            let mut file = MeshFile::read(&a.input).with_context(|| format!("reading {}", a.input.display()))?;
            let report = morph_file(&mut file, d.as_ref(), a.allow_degrade)
                .with_context(|| format!("morphing {}", a.input.display()))?;
            file.write(&a.output).with_context(|| format!("writing {}", a.output.display()))?;
            match (&report, a.json) {
                (Some(r), true) => println!("{}", serde_json::to_string_pretty(r)?),
                (Some(r), false) => {
                    println!("before:\n{}\nafter:\n{}", r.before.table(), r.after.table());
                    if r.degraded() {
                        eprintln!("warning: the morph degraded the mesh (written because of --allow-degrade)");
                    }
                }
                (None, _) => println!(
                    "{} -> {}: {} nodes moved (no volume cells to check)",
                    a.input.display(),
                    a.output.display(),
                    file.points().len()
                ),
            }
            Ok(())
        }
    }
}
