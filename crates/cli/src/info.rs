//! `cadmorph info`: format and schema, units, bounding box and model size, entity counts
//! with their type names, faces (numbered as every subcommand numbers them), curves, and
//! the faces left out with the reason.

use std::path::{Path, PathBuf};

use anyhow::Result;
use cadmorph::nurbs::Aabb;
use cadmorph::Format;
use serde_json::{json, Value};

/// Arguments of `info`.
#[derive(clap::Args)]
pub struct Args {
    /// An IGES or STEP file.
    file: PathBuf,
    /// Print JSON (schema `cadmorph.info/1`, see `cadmorph schema`).
    #[arg(long)]
    json: bool,
}

/// The application protocol a STEP file names in its header (`FILE_SCHEMA`), e.g.
/// `AUTOMOTIVE_DESIGN { 1 0 10303 214 3 1 1 }`; `None` for IGES or a header without one.
fn step_schema(path: &Path, format: Format) -> Option<String> {
    if format != Format::Step {
        return None;
    }
    let bytes = std::fs::read(path).ok()?;
    let head = String::from_utf8_lossy(&bytes[..bytes.len().min(1 << 16)]).into_owned();
    let at = head.find("FILE_SCHEMA")?;
    let rest = &head[at..];
    let open = rest.find('\'')?;
    let close = rest[open + 1..].find('\'')?;
    Some(rest[open + 1..open + 1 + close].trim().to_owned())
}

/// Cells `count  name` laid out in as many columns as fit in 100 characters.
fn wrapped(cells: &[String]) -> String {
    let width = cells.iter().map(String::len).max().unwrap_or(0) + 3;
    let per_row = (100 / width.max(1)).max(1);
    let mut out = String::new();
    for row in cells.chunks(per_row) {
        let line: Vec<String> = row.iter().map(|c| format!("{c:<width$}")).collect();
        out.push_str("  ");
        out.push_str(line.concat().trim_end());
        out.push('\n');
    }
    out
}

/// Runs `info`.
pub fn run(a: Args) -> Result<()> {
    let m = cadmorph::open(&a.file)?;
    let i = m.info();
    let unit = crate::units::words(i.metres_per_unit, &i.unit);
    let schema = step_schema(&a.file, i.format);
    let boxes = m
        .patches()
        .iter()
        .map(|p| p.surface.bounding_box())
        .chain(m.free_curves().iter().map(|c| c.curve.bounding_box()));
    let bbox = boxes.reduce(|x, y| x.union(&y));
    let size = bbox.map_or(0.0, |b: Aabb| b.diagonal());
    let mut counts: Vec<(&String, &usize)> = i.entity_counts.iter().collect();
    counts.sort_by(|x, y| y.1.cmp(x.1).then(x.0.cmp(y.0)));
    if a.json {
        let faces: Vec<Value> = m
            .patches()
            .iter()
            .zip(&i.patches)
            .enumerate()
            .map(|(k, (p, pi))| {
                let mut f = crate::faces::json(k, &p.entity, &p.surface_entity);
                f["type"] = json!(pi.kind);
                f["degrees"] = json!([pi.u_degree, pi.v_degree]);
                f["poles"] = json!([pi.n_u, pi.n_v]);
                f["rational"] = json!(pi.rational);
                f["trimmed"] = json!(pi.trimmed);
                f["analytic"] = json!(pi.analytic);
                f["reversed"] = json!(pi.reversed);
                f
            })
            .collect();
        let curves: Vec<Value> = m
            .free_curves()
            .iter()
            .map(|c| {
                json!({
                    "entity": crate::faces::entity(&c.entity),
                    "degree": c.curve.degree(),
                    "poles": c.curve.control_points().len(),
                    "rational": c.curve.is_rational(),
                })
            })
            .collect();
        let body = json!({
            "file": a.file.display().to_string(),
            "format": i.format.to_string(),
            "file_schema": schema,
            "unit": crate::units::json(i.metres_per_unit, &i.unit),
            "bounding_box": bbox.map(|b| json!({ "min": [b.min.x, b.min.y, b.min.z], "max": [b.max.x, b.max.y, b.max.z] })),
            "model_size": size,
            "entity_counts": counts.iter().map(|(k, v)| json!({
                "type": k,
                "name": crate::entity_names::display(i.format, k),
                "count": v,
            })).collect::<Vec<_>>(),
            "unknown_entities": i.unknown_entities,
            "faces": faces,
            "curves": curves,
            "skipped": i.skipped.iter().map(|s| json!({ "entity": crate::faces::entity(&s.entity), "reason": s.reason })).collect::<Vec<_>>(),
        });
        return crate::schema::print("info", body);
    }
    println!("{}", a.file.display());
    match &schema {
        Some(s) => println!("  format: {} ({s})", i.format),
        None => println!("  format: {}", i.format),
    }
    println!("  unit: {unit} (the file says {:?}; {} m per unit)", i.unit, i.metres_per_unit);
    match bbox {
        Some(b) => {
            println!(
                "  bounding box: x {:.6} .. {:.6}, y {:.6} .. {:.6}, z {:.6} .. {:.6} {unit}",
                b.min.x, b.max.x, b.min.y, b.max.y, b.min.z, b.max.z
            );
            println!("  model size (box diagonal): {size:.6} {unit}");
        }
        None => println!("  bounding box: none (no faces or curves)"),
    }
    let total: usize = i.entity_counts.values().sum();
    println!("entities ({total} in {} types):", counts.len());
    let cells: Vec<String> =
        counts.iter().map(|(k, v)| format!("{v:>5}  {}", crate::entity_names::display(i.format, k))).collect();
    print!("{}", wrapped(&cells));
    if i.unknown_entities > 0 {
        println!("  kept verbatim without a typed view: {}", i.unknown_entities);
    }
    if i.patches.is_empty() {
        println!("faces: none");
    } else {
        println!(
            "faces ({}; index (entity) is the numbering of `seams`, `ffd fit --around` and JSON):",
            i.patches.len()
        );
        println!(
            "{:<20} {:<12} {:<28} {:>7} {:>8} {:>9} {:>8} {:>9}",
            "face", "surface", "type", "degree", "poles", "rational", "trimmed", "analytic"
        );
        for (k, (p, pi)) in m.patches().iter().zip(&i.patches).enumerate() {
            println!(
                "{:<20} {:<12} {:<28} {:>7} {:>8} {:>9} {:>8} {:>9}",
                crate::faces::label(k, &p.entity),
                p.surface_entity.to_string(),
                type_name(&pi.kind),
                format!("{}x{}", pi.u_degree, pi.v_degree),
                format!("{}x{}", pi.n_u, pi.n_v),
                yes(pi.rational),
                yes(pi.trimmed),
                yes(pi.analytic),
            );
        }
    }
    if !m.free_curves().is_empty() {
        println!("curves bounding no face ({}):", m.free_curves().len());
        println!("{:<16} {:>7} {:>7} {:>9}", "curve", "degree", "poles", "rational");
        for c in m.free_curves() {
            println!(
                "{:<16} {:>7} {:>7} {:>9}",
                c.entity.to_string(),
                c.curve.degree(),
                c.curve.control_points().len(),
                yes(c.curve.is_rational())
            );
        }
    }
    if !i.skipped.is_empty() {
        println!("faces left out ({}), kept in the file as they are:", i.skipped.len());
        for s in &i.skipped {
            println!("  {}: {}", s.entity, s.reason);
        }
    }
    Ok(())
}

/// `IGES 128` as `128 B-spline surface`; STEP names as they are.
fn type_name(kind: &str) -> String {
    match kind.strip_prefix("IGES ") {
        Some(n) => crate::entity_names::display(Format::Iges, n),
        None => kind.to_owned(),
    }
}

fn yes(b: bool) -> &'static str {
    if b {
        "yes"
    } else {
        "no"
    }
}
