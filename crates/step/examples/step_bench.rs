//! Writes the generated STEP benchmark files and times cadmorph's STEP reader on files, for
//! `benches/step_vs_foxtrot.sh`.
//!
//!     cargo run --release -p cadmorph-step --example step_bench -- --write DIR
//!     cargo run --release -p cadmorph-step --example step_bench -- --repeat 5 FILE...
//!
//! `--write DIR` writes `hull3_200x150.stp` and `faces300.stp` (the files of the criterion
//! bench `parse`, from `benches/generate.rs`) to `DIR`. Each timed file is read into memory
//! once (the file read is not timed), then timed best of `--repeat` runs two ways:
//! `Document::parse` alone (`parse_s`), and `Document::parse` + the world-coordinate NURBS
//! surface of every face (`parse_world_s`, what the criterion bench `parse_world` does).
//! One JSON line per file: bytes, both times, the face and pole counts and a checksum (the
//! sum of x + y + z over every world pole), so that runs can be compared.

#[path = "../benches/generate.rs"]
mod generate;

use std::hint::black_box;
use std::time::Instant;

use cadmorph_step::Document;

/// Parse `bytes` and build the world NURBS of every face: (faces, poles, checksum).
fn parse_world(bytes: &[u8]) -> (usize, usize, f64) {
    let doc = Document::parse(bytes).expect("parses");
    let faces = doc.faces().expect("faces");
    let (mut poles, mut checksum) = (0, 0.0);
    for world in doc.faces_nurbs(&faces) {
        let world = world.expect("world NURBS");
        for p in world.surface.control_points() {
            checksum += p.x + p.y + p.z;
        }
        poles += world.surface.control_points().len();
    }
    (faces.len(), poles, checksum)
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let mut repeat = 5usize;
    let mut files = Vec::new();
    let mut i = 0;
    while i < args.len() {
        match args[i].as_str() {
            "--write" => {
                let dir = std::path::Path::new(args.get(i + 1).expect("--write DIR"));
                std::fs::create_dir_all(dir).expect("create the output directory");
                std::fs::write(dir.join("hull3_200x150.stp"), generate::hull3()).expect("write");
                std::fs::write(dir.join("faces300.stp"), generate::faces300()).expect("write");
                i += 2;
            }
            "--repeat" => {
                repeat = args.get(i + 1).expect("--repeat N").parse().expect("a count");
                i += 2;
            }
            f => {
                files.push(f.to_string());
                i += 1;
            }
        }
    }
    for f in files {
        let bytes = std::fs::read(&f).expect("read the file");
        let (mut parse_s, mut world_s) = (f64::INFINITY, f64::INFINITY);
        let mut counts = (0, 0, 0.0);
        for _ in 0..repeat.max(1) {
            let t = Instant::now();
            let doc = Document::parse(black_box(&bytes)).expect("parses");
            black_box(doc.len());
            drop(doc);
            parse_s = parse_s.min(t.elapsed().as_secs_f64());
            let t = Instant::now();
            counts = parse_world(black_box(&bytes));
            world_s = world_s.min(t.elapsed().as_secs_f64());
        }
        let (faces, poles, checksum) = counts;
        let mb = bytes.len() as f64 / 1e6;
        println!(
            "{{\"file\": {f:?}, \"bytes\": {}, \"faces\": {faces}, \"poles\": {poles}, \"parse_s\": {parse_s:.9}, \"parse_world_s\": {world_s:.9}, \"parse_mb_per_s\": {:.1}, \"parse_world_mb_per_s\": {:.1}, \"checksum\": {checksum:.9}}}",
            bytes.len(),
            mb / parse_s,
            mb / world_s
        );
    }
}
