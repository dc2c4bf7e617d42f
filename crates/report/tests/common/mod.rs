//! What the report tests share: the README's main job (hull3 and the bow-dome FFD) in
//! memory, scenes of samples, a scratch folder, the repository's test tools.
#![allow(dead_code)]

use std::path::{Path, PathBuf};

use cadmorph::model::{MorphOptions, MorphOutcome};
use cadmorph::morph::{Ffd, Parameters};
use cadmorph::seam::SeamRefineOptions;
use cadmorph::Model;
use cadmorph_report::{Input, Scene};
use cadmorph_testkit::sample;

/// The bow-dome FFD of `samples/prm/bow_dome.prm`.
pub fn bow_dome() -> Ffd {
    let text = std::fs::read_to_string(sample("prm/bow_dome.prm")).unwrap();
    match Parameters::from_prm(&text).unwrap() {
        Parameters::Ffd(f) => f,
        _ => panic!("bow_dome.prm is an FFD"),
    }
}

/// hull3 before and after the README's main job (FFD bow dome, seams refined to
/// 1.45e-5 and 0.01 deg), and the outcome.
pub fn main_job() -> (Model, Model, MorphOutcome, Ffd) {
    let before = cadmorph::open(&sample("hull3.igs")).unwrap();
    let mut after = cadmorph::open(&sample("hull3.igs")).unwrap();
    let ffd = bow_dome();
    let opts = MorphOptions { refine: Some(SeamRefineOptions::new(1.45e-5, 0.01)), uniform_knots: None, repair: false };
    let outcome = after.morph(&ffd, &opts).unwrap();
    assert!(outcome.refinement.as_ref().unwrap().converged);
    (before, after, outcome, ffd)
}

/// The scene of `before` → `after` with the lattice of `ffd`.
pub fn scene(before: &Model, after: Option<&Model>, ffd: Option<&Ffd>) -> Scene {
    let bs = before.seams(200);
    let as_ = after.map(|m| m.seams(200));
    Scene::new(
        Input { model: before, seams: &bs, source: "before".into() },
        after.zip(as_.as_ref()).map(|(m, s)| Input { model: m, seams: s, source: "after".into() }),
        ffd,
        1e-7 * before.size(),
        0.01,
    )
    .unwrap()
}

/// A new empty folder under the system's temporary folder for test `name`.
pub fn scratch(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("cadmorph-report-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// `tests/report` of the repository (the browser and validator scripts).
pub fn tools() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../tests/report")
}

/// Runs `node SCRIPT ARGS` in `tests/report` (after `bash tests/report/setup.sh`);
/// panics with its output if it fails.
pub fn node(script: &str, args: &[&Path]) -> String {
    let tools = tools();
    assert!(
        tools.join("node_modules/playwright-core").is_dir(),
        "run `bash tests/report/setup.sh` first (scripts/test does)"
    );
    let out = std::process::Command::new("node")
        .arg(tools.join(script))
        .args(args)
        .current_dir(&tools)
        .output()
        .expect("node runs");
    let text = String::from_utf8_lossy(&out.stdout).into_owned();
    assert!(out.status.success(), "node {script} failed:\n{text}\n{}", String::from_utf8_lossy(&out.stderr));
    text
}

/// Decodes a PNG file into (width, height, RGB bytes).
pub fn read_png(path: &Path) -> (u32, u32, Vec<u8>) {
    let dec = png::Decoder::new(std::fs::File::open(path).unwrap());
    let mut r = dec.read_info().unwrap();
    let mut buf = vec![0; r.output_buffer_size()];
    let info = r.next_frame(&mut buf).unwrap();
    buf.truncate(info.buffer_size());
    let rgb = match info.color_type {
        png::ColorType::Rgb => buf,
        png::ColorType::Rgba => buf.chunks(4).flat_map(|c| [c[0], c[1], c[2]]).collect(),
        other => panic!("unexpected PNG colour type {other:?}"),
    };
    (info.width, info.height, rgb)
}
