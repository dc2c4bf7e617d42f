//! glTF export checked by the Khronos glTF validator (npm `gltf-validator`, run by
//! `tests/report/validate_gltf.js`): no errors for the defect hull, the morphed main job
//! with its lattice, and the STEP solid. Needs `bash tests/report/setup.sh`, hence
//! `#[ignore]`. The structure (named nodes, colours) is checked here without it.

mod common;

use cadmorph_report::gltf::to_glb;
use cadmorph_testkit::sample;
use common::{main_job, node, scene, scratch};

fn json_chunk(glb: &[u8]) -> serde_json::Value {
    assert_eq!(&glb[0..4], b"glTF");
    assert_eq!(u32::from_le_bytes(glb[8..12].try_into().unwrap()) as usize, glb.len());
    let n = u32::from_le_bytes(glb[12..16].try_into().unwrap()) as usize;
    assert_eq!(&glb[16..20], b"JSON");
    serde_json::from_slice(&glb[20..20 + n]).unwrap()
}

#[test]
fn nodes_are_named_by_face_and_coloured() {
    let m = cadmorph::open(&sample("hull3_defect.igs")).unwrap();
    let glb = to_glb(&scene(&m, None, None)).unwrap();
    let j = json_chunk(&glb);
    let names: Vec<&str> = j["nodes"].as_array().unwrap().iter().map(|n| n["name"].as_str().unwrap()).collect();
    let faces: Vec<String> = m.patches().iter().map(|p| p.entity.to_string()).collect();
    assert_eq!(&names[..3], &faces.iter().map(|s| s.as_str()).collect::<Vec<_>>()[..]);
    assert_eq!(names[3], "seams");
    for mesh in j["meshes"].as_array().unwrap() {
        assert!(mesh["primitives"][0]["attributes"]["COLOR_0"].is_number());
    }
}

#[test]
#[ignore = "needs the Khronos glTF validator: bash tests/report/setup.sh"]
fn khronos_validator_finds_no_errors() {
    let dir = scratch("gltf");
    let (before, after, _, ffd) = main_job();
    let cases = [
        ("defect", scene(&cadmorph::open(&sample("hull3_defect.igs")).unwrap(), None, None)),
        ("main_job", scene(&before, Some(&after), Some(&ffd))),
        ("mixed_solid", scene(&cadmorph::open(&sample("mixed_solid.stp")).unwrap(), None, None)),
    ];
    for (name, sc) in cases {
        let path = dir.join(format!("{name}.glb"));
        std::fs::write(&path, to_glb(&sc).unwrap()).unwrap();
        let report: serde_json::Value = serde_json::from_str(&node("validate_gltf.js", &[&path])).unwrap();
        let issues = &report["issues"];
        assert_eq!(issues["numErrors"], 0, "{name}: {issues}");
        assert!(report["info"]["totalTriangleCount"].as_u64().unwrap() > 1000, "{name}: {}", report["info"]);
        println!(
            "{name}: {} errors, {} warnings, {} triangles",
            issues["numErrors"], issues["numWarnings"], report["info"]["totalTriangleCount"]
        );
    }
    let _ = std::fs::remove_dir_all(&dir);
}
