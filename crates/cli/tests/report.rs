//! `cadmorph report`, `morph --report-html` and `campaign report` through the binary:
//! the files they write, what they refuse, and the VTU files read by meshio.

use std::path::{Path, PathBuf};
use std::process::Command;

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

fn cadmorph(args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_cadmorph")).args(args).current_dir(root()).output().expect("the binary runs")
}

fn ok(out: &std::process::Output) -> String {
    assert!(out.status.success(), "{}\n{}", String::from_utf8_lossy(&out.stdout), String::from_utf8_lossy(&out.stderr));
    String::from_utf8_lossy(&out.stdout).into_owned()
}

fn scratch(name: &str) -> PathBuf {
    let d = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join(format!("report-{name}"));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

#[test]
fn report_writes_the_page_and_the_exports() {
    let d = scratch("exports");
    let html = d.join("r.html");
    ok(&cadmorph(&[
        "report",
        "samples/hull3_defect.igs",
        "--ffd",
        "samples/prm/bow_dome.prm",
        "-o",
        s(&html),
        "--glb",
        s(&d.join("r.glb")),
        "--vtu-dir",
        s(&d),
        "--png-dir",
        s(&d),
    ]));
    let page = std::fs::read_to_string(&html).unwrap();
    assert!(page.len() < 5_000_000);
    assert!(page.contains("id=\"layer-lattice\"") && page.contains("Seams before"));
    for v in ["side", "plan", "front", "iso"] {
        let png = std::fs::read(d.join(format!("{v}_before.png"))).unwrap();
        assert_eq!(&png[1..4], b"PNG");
    }
    assert_eq!(&std::fs::read(d.join("r.glb")).unwrap()[..4], b"glTF");
    // 15x12 + 18x12 + 15x12 poles; a 5x4x4 lattice.
    let net = std::fs::read_to_string(d.join("net_before.vtu")).unwrap();
    assert!(net.contains("NumberOfPoints=\"576\" NumberOfCells=\"495\""), "{}", &net[..300]);
    let lattice = std::fs::read_to_string(d.join("lattice.vtu")).unwrap();
    assert!(lattice.contains("NumberOfPoints=\"80\" NumberOfCells=\"36\""));
}

#[test]
fn a_failed_report_writes_nothing() {
    let d = scratch("refused");
    let html = d.join("r.html");
    // An IDW parameter file is no lattice.
    let out =
        cadmorph(&["report", "samples/hull3.igs", "--ffd", "samples/pygem/parameters_idw_default.prm", "-o", s(&html)]);
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("does not hold FFD parameters"), "{err}");
    // A folder that does not exist for the pictures: refused before anything is written.
    let out = cadmorph(&["report", "samples/hull3.igs", "-o", s(&html), "--png-dir", s(&d.join("nope"))]);
    assert!(!out.status.success());
    assert!(String::from_utf8_lossy(&out.stderr).contains("is not a folder"));
    assert!(!html.exists());
    assert_eq!(std::fs::read_dir(&d).unwrap().count(), 0);
}

#[test]
fn morph_writes_its_report_with_the_output() {
    let d = scratch("morph");
    let (out, html) = (d.join("m.igs"), d.join("m.html"));
    let o = cadmorph(&[
        "morph",
        "samples/hull3.igs",
        "--ffd",
        "samples/prm/bow_dome.prm",
        "--refine-tol",
        "1.45e-5",
        "-o",
        s(&out),
        "--report-html",
        s(&html),
        "--json",
    ]);
    let json: serde_json::Value = serde_json::from_str(&ok(&o)).unwrap();
    assert!(String::from_utf8_lossy(&o.stderr).contains("written in"));
    let page = std::fs::read_to_string(&html).unwrap();
    assert!(out.exists());
    // The growth table: a row per round of the JSON's per_round, the last row the
    // refinement's final count as the JSON reports it.
    let r = &json["refinement"];
    let per_round = r["per_round"].as_array().unwrap();
    assert_eq!(per_round.len() as u64, r["rounds"].as_u64().unwrap() + 1);
    assert_eq!(per_round.last().unwrap()["control_points"], r["control_points_after"]);
    assert_eq!(per_round[0]["control_points"], r["control_points_before"]);
    let table = &page[page.find("<table class=\"growth\">").expect("growth table")..];
    let table = &table[..table.find("</table>").unwrap()];
    let counts: Vec<String> =
        table.split("<tr><td>").skip(1).map(|row| row.split("</td><td>").nth(1).unwrap().to_string()).collect();
    let want: Vec<String> = per_round.iter().map(|x| x["control_points"].to_string()).collect();
    assert_eq!(counts, want);
    assert!(page.contains("id=\"growth-plot\"><svg"));
    // `cadmorph report --after OUT --morph-json` shows the same growth.
    let js = d.join("m.json");
    std::fs::write(&js, serde_json::to_string(&json).unwrap()).unwrap();
    let html2 = d.join("r.html");
    ok(&cadmorph(&["report", "samples/hull3.igs", "--after", s(&out), "--morph-json", s(&js), "-o", s(&html2)]));
    let page2 = std::fs::read_to_string(&html2).unwrap();
    let table2 = &page2[page2.find("<table class=\"growth\">").expect("growth table")..];
    assert_eq!(&table2[..table2.find("</table>").unwrap()], table);
    // Both states, the refinement and the lattice.
    assert!(page.contains("Seams before") && page.contains("Seams after") && page.contains("Refinement"));
    assert!(page.contains("id=\"layer-lattice-moved\""));
}

#[test]
fn campaign_report_marks_the_variants() {
    let d = scratch("campaign");
    let c = "samples/campaigns/bow_dome.toml";
    // The first share of 2 of the 130 variants.
    ok(&cadmorph(&["campaign", "run", c, "--out", s(&d), "--shard", "0/65"]));
    let index = d.join("index.html");
    let said = ok(&cadmorph(&["campaign", "report", c, "--out", s(&d)]));
    assert!(said.contains("130 variants"), "{said}");
    let page = std::fs::read_to_string(&index).unwrap();
    assert!(page.contains("130 variants: 2 ok, 0 out of tolerance, 0 failed, 128 pending"), "{}", &page[..2000]);
    assert_eq!(page.matches("<img ").count(), 2);
    assert_eq!(page.matches("data-state=\"pending\"").count(), 128);
    assert!(page.contains("class=\"sortable\""));
    // Each of the 6 parameters against each of the 4 plotted results.
    assert_eq!(page.matches("<svg").count(), 24);
}

#[test]
#[ignore = "needs meshio: bash tests/mesh/setup.sh"]
fn meshio_reads_the_vtu_files() {
    let d = scratch("meshio");
    ok(&cadmorph(&[
        "report",
        "samples/hull3.igs",
        "--ffd",
        "samples/prm/bow_dome.prm",
        "-o",
        s(&d.join("r.html")),
        "--vtu-dir",
        s(&d),
    ]));
    let py = root().join("tests/mesh/.venv/bin/python");
    let script = "import meshio, sys, numpy as np\n\
        n = meshio.read(sys.argv[1]); l = meshio.read(sys.argv[2])\n\
        print(len(n.points), sum(len(c.data) for c in n.cells), n.cells[0].type)\n\
        print(len(l.points), sum(len(c.data) for c in l.cells), l.cells[0].type, float(np.abs(l.point_data['displacement']).max()))\n";
    let out = Command::new(py)
        .args(["-c", script, s(&d.join("net_before.vtu")), s(&d.join("lattice.vtu"))])
        .output()
        .expect("the mesh venv's python runs");
    let text = ok(&out);
    let lines: Vec<&str> = text.lines().collect();
    assert_eq!(lines[0], "576 495 quad");
    let f: Vec<&str> = lines[1].split(' ').collect();
    assert_eq!(&f[..3], &["80", "36", "hexahedron"]);
    // The largest displacement component of bow_dome.prm: 0.02 of the 62 m box length
    // along x (the others: 0.05 and 0.08 of 12 m).
    let max: f64 = f[3].parse().unwrap();
    assert!((max - 1.24).abs() < 1e-9, "{max}");
}
