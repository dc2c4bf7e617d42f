//! `blade deform --plots`, `blade build --plots` and `mesh check --histograms` through
//! the binary: the SVG files they write and what is in them.

use std::path::{Path, PathBuf};
use std::process::Command;

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

fn cadmorph(args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_cadmorph")).args(args).current_dir(root()).output().expect("the binary runs")
}

fn ok(out: &std::process::Output) {
    assert!(out.status.success(), "{}\n{}", String::from_utf8_lossy(&out.stdout), String::from_utf8_lossy(&out.stderr));
}

fn scratch(name: &str) -> PathBuf {
    let d = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join(format!("plots-{name}"));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn has_line(svg: &str, text: &str) -> bool {
    svg.lines().any(|l| l.trim() == text)
}

#[test]
fn blade_plots_write_every_law_and_the_sections() {
    let d = scratch("blade");
    let plots = d.join("plots");
    let p = plots.to_str().unwrap();
    ok(&cadmorph(&[
        "blade",
        "deform",
        "samples/blade/deform.prm",
        "-o",
        d.join("d.prm").to_str().unwrap(),
        "--plots",
        p,
    ]));
    for law in ["chord", "pitch", "rake", "skew", "camber"] {
        let svg = std::fs::read_to_string(plots.join(format!("law_{law}.svg"))).unwrap();
        assert!(has_line(&svg, &format!("{law} law")) && has_line(&svg, "deformed control points"), "{law}");
        assert!(svg.matches("<circle").count() >= 4, "{law}: control points drawn");
        let (w, h, _) =
            cadmorph_report::chart::decode_png(&std::fs::read(plots.join(format!("law_{law}.png"))).unwrap()).unwrap();
        assert_eq!((w, h), (720, 480), "{law}");
    }
    ok(&cadmorph(&[
        "blade",
        "build",
        "samples/blade/tutorial.toml",
        "-o",
        d.join("b.stp").to_str().unwrap(),
        "--plots",
        p,
    ]));
    let svg = std::fs::read_to_string(plots.join("profiles.svg")).unwrap();
    let labels = svg.lines().filter(|l| l.trim().starts_with("r = ")).count();
    assert!(labels >= 2, "one legend entry per section, found {labels}");
    let (_, _, rgb) = cadmorph_report::chart::decode_png(&std::fs::read(plots.join("profiles.png")).unwrap()).unwrap();
    // The outlines in colour (the sections of this table coincide: the last one's
    // colour covers the others), over white, grey grid lines and black text.
    let coloured = rgb.chunks(3).filter(|c| c.iter().max().unwrap() - c.iter().min().unwrap() > 60).count();
    assert!(coloured > 1000, "sections drawn: {coloured} coloured pixels");
}

#[test]
fn mesh_histograms_before_and_after() {
    let d = scratch("mesh");
    let h = d.join("h");
    let out = cadmorph(&[
        "mesh",
        "check",
        "crates/cli/tests/data/one_hex.unv",
        "--histograms",
        h.to_str().unwrap(),
        "--after",
        "crates/cli/tests/data/one_hex.unv",
    ]);
    ok(&out);
    // One cell, no internal face: no non-orthogonality histogram, and the command says so.
    assert!(String::from_utf8_lossy(&out.stderr).contains("no non-orthogonality"));
    assert!(!h.join("non_orthogonality.svg").exists());
    for name in ["aspect_ratio", "cell_volume", "skewness"] {
        let svg = std::fs::read_to_string(h.join(format!("{name}.svg"))).unwrap();
        assert!(has_line(&svg, "before") && has_line(&svg, "after"), "{name}");
        // The PNG of the same histogram: decoded, the bars of both colours drawn.
        let png = std::fs::read(h.join(format!("{name}.png"))).unwrap();
        let (w, hh, rgb) = cadmorph_report::chart::decode_png(&png).unwrap();
        assert_eq!((w, hh), (720, 440), "{name}");
        let near =
            |c: [u8; 3]| rgb.chunks(3).filter(|p| (0..3).all(|k| (p[k] as i32 - c[k] as i32).abs() <= 2)).count();
        assert!(near([31, 119, 180]) > 100 && near([214, 39, 40]) > 100, "{name}: bars drawn");
    }
    // --after needs --histograms.
    assert!(!cadmorph(&["mesh", "check", "crates/cli/tests/data/one_hex.unv", "--after", "x.unv"]).status.success());
}
