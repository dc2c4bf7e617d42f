//! Bad meshes get an error that names the file and the line, byte offset or index of the
//! problem; nothing panics, and a failed write leaves no file behind.

use std::path::{Path, PathBuf};

use cadmorph_mesh::format::foam::PolyMesh;
use cadmorph_mesh::format::{gmsh::Msh, stl::Stl, unv::Unv, vtk::VtkLegacy};
use cadmorph_mesh::{Cell, CellKind, Error, MeshFile};
use cadmorph_morph::math::Point3;

fn temp(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("cadmorph-mesh-bad-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    d
}

/// Two unit hexahedra side by side, written as a fresh ASCII polyMesh in `dir`.
fn two_hexes(dir: &Path) -> PolyMesh {
    let mut pts = Vec::new();
    for z in 0..2 {
        for y in 0..2 {
            for x in 0..3 {
                pts.push(Point3::new(x as f64, y as f64, z as f64));
            }
        }
    }
    let id = |x: usize, y: usize, z: usize| x + 3 * y + 6 * z;
    let hex = |x: usize| {
        Cell::new(
            CellKind::Hexahedron,
            vec![
                id(x, 0, 0),
                id(x + 1, 0, 0),
                id(x + 1, 1, 0),
                id(x, 1, 0),
                id(x, 0, 1),
                id(x + 1, 0, 1),
                id(x + 1, 1, 1),
                id(x, 1, 1),
            ],
        )
    };
    let m = PolyMesh::from_cells(pts, &[hex(0), hex(1)]).unwrap();
    m.write(dir).unwrap();
    m
}

fn replace_in(path: &Path, from: &str, to: &str) {
    let t = std::fs::read_to_string(path).unwrap();
    assert!(t.contains(from), "{from:?} not in {}", path.display());
    std::fs::write(path, t.replacen(from, to, 1)).unwrap();
}

fn message(e: &Error) -> String {
    let m = e.to_string();
    eprintln!("{m}");
    m
}

#[test]
fn polymesh_errors_name_file_and_position() {
    let dir = temp("poly");
    let good = two_hexes(&dir);
    assert_eq!(good.n_cells(), 2);
    assert_eq!(good.n_internal_faces(), 1);
    let q = cadmorph_mesh::quality::Quality::of(&PolyMesh::read(&dir).unwrap());
    assert!(q.ok() && (q.total_volume - 2.0).abs() < 1e-14);

    // A face point out of range.
    let d = temp("poly-face");
    two_hexes(&d);
    replace_in(&d.join("faces"), "4(1 4 10 7)", "4(1 4 10 99)");
    let e = PolyMesh::read(&d).unwrap_err();
    let m = message(&e);
    assert!(m.contains("faces") && m.contains("face 0") && m.contains("point 99"), "{m}");

    // An owner label beyond nCells.
    let d = temp("poly-owner");
    two_hexes(&d);
    replace_in(&d.join("owner"), "\n(\n0\n", "\n(\n7\n");
    let m = message(&PolyMesh::read(&d).unwrap_err());
    assert!(m.contains("owner") && m.contains("cell 7"), "{m}");

    // A neighbour list that is too short for its count: the line is named.
    let d = temp("poly-nei");
    two_hexes(&d);
    replace_in(&d.join("neighbour"), "\n1\n(\n1\n)", "\n2\n(\n1\n)");
    let m = message(&PolyMesh::read(&d).unwrap_err());
    assert!(m.contains("neighbour") && m.contains("line"), "{m}");

    // Dangling boundary faces: the patch covers fewer faces than there are.
    let d = temp("poly-dangling");
    two_hexes(&d);
    replace_in(&d.join("boundary"), "nFaces          10", "nFaces          9");
    let m = message(&PolyMesh::read(&d).unwrap_err());
    assert!(m.contains("dangling"), "{m}");

    // A NaN point.
    let d = temp("poly-nan");
    two_hexes(&d);
    replace_in(&d.join("points"), "(1 0 0)", "(nan 0 0)");
    let m = message(&PolyMesh::read(&d).unwrap_err());
    assert!(m.contains("point 1") && m.contains("not finite"), "{m}");

    // Truncated binary points.
    let d = temp("poly-trunc");
    two_hexes(&d);
    let mut bin = b"FoamFile { version 2.0; format binary; class vectorField; arch \"LSB;label=32;scalar=64\"; object points; }\n12\n(".to_vec();
    bin.extend_from_slice(&[0u8; 100]);
    std::fs::write(d.join("points"), &bin).unwrap();
    let m = message(&PolyMesh::read(&d).unwrap_err());
    assert!(m.contains("byte") && m.contains("12 points"), "{m}");
    for x in [
        dir,
        temp("poly-face"),
        temp("poly-owner"),
        temp("poly-nei"),
        temp("poly-dangling"),
        temp("poly-nan"),
        temp("poly-trunc"),
    ] {
        let _ = std::fs::remove_dir_all(x);
    }
}

#[test]
fn file_format_errors_name_the_line() {
    let m = message(&Stl::parse(&[0u8; 90]).unwrap_err());
    assert!(m.contains("byte 84") && m.contains("0 triangles"), "{m}");
    let mut bin = vec![0u8; 80];
    bin.extend_from_slice(&3u32.to_le_bytes());
    bin.extend_from_slice(&[0u8; 60]);
    let m = message(&Stl::parse(&bin).unwrap_err());
    assert!(m.contains("3 triangles"), "{m}");
    let m = message(&Stl::parse(b"solid x\n facet normal 0 0 1\n  outer loop\n   vertex 0 0\n").unwrap_err());
    assert!(m.contains("line 4"), "{m}");
    let m =
        message(&Unv::parse("    -1\n  2411\n         1         1         1        11\n   0.0   0.0\n").unwrap_err());
    assert!(m.contains("line"), "{m}");
    let msh = "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n1\n1 0 0 0\n$EndNodes\n$Elements\n1\n1 1 2 0 0 1 5\n$EndElements\n";
    let m = message(&Msh::parse(msh).unwrap_err());
    assert!(m.contains("line 10") && m.contains("node tag 5"), "{m}");
    let m = message(
        &VtkLegacy::parse("# vtk DataFile Version 3.0\nt\nASCII\nDATASET POLYDATA\nPOINTS 2 float\n0 0 0 1 0\n")
            .unwrap_err(),
    );
    assert!(m.contains("a coordinate") && m.contains("end of file"), "{m}");
    let m = message(&MeshFile::read(Path::new("/nonexistent/mesh.unv")).unwrap_err());
    assert!(m.contains("/nonexistent/mesh.unv"), "{m}");
}

#[test]
fn a_failed_write_leaves_nothing() {
    let d = temp("write");
    std::fs::create_dir_all(&d).unwrap();
    // The target's directory is a file: the write fails and no temporary is left.
    let blocker = d.join("file");
    std::fs::write(&blocker, b"x").unwrap();
    let target = blocker.join("out.stl");
    assert!(cadmorph_mesh::atomic::write_atomic(&target, b"data").is_err());
    let left: Vec<_> = std::fs::read_dir(&d).unwrap().map(|e| e.unwrap().file_name()).collect();
    assert_eq!(left.len(), 1, "{left:?}");
    let _ = std::fs::remove_dir_all(d);
}

/// Found by the `mesh_formats` fuzz target: an empty Gmsh file indexed its first line.
/// Every single-file reader refuses empty and blank input with an error.
#[test]
fn empty_files_are_errors_not_panics() {
    use cadmorph_mesh::format::{dyna::KeywordFile, elmer::ElmerNodes, mdpa::Mdpa, obj::Obj, vtu::Vtu};
    for text in ["", "\n", "   \r\n\n"] {
        let e = Msh::parse(text).unwrap_err();
        assert!(message(&e).contains("MeshFormat"), "{}", message(&e));
        let _ = VtkLegacy::parse(text).unwrap_err();
        let _ = Unv::parse(text);
        let _ = Obj::parse(text);
        let _ = KeywordFile::parse(text);
        let _ = Mdpa::parse(text);
        let _ = ElmerNodes::parse(text);
        let _ = Stl::parse(text.as_bytes());
        let _ = Vtu::parse(text.as_bytes()).unwrap_err();
    }
}

/// Found by the `mesh_formats` fuzz target: a base64 block header claiming 2⁶⁴ − 16 bytes
/// overflowed the length arithmetic (a panic in debug builds). Such counts are refused.
#[test]
fn vtu_block_counts_beyond_the_file_are_refused() {
    use cadmorph_mesh::format::vtu::Vtu;
    for (compressor, data) in [
        ("", "8P////////8AAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAA="),
        (" compressor=\"vtkZLibDataCompressor\"", "AgAAAAAAAADw/////////wgAAAAAAAAA8P////////8="),
    ] {
        let xml = format!(
            r#"<?xml version="1.0"?>
<VTKFile type="UnstructuredGrid" version="1.0" byte_order="LittleEndian" header_type="UInt64"{compressor}>
<UnstructuredGrid><Piece NumberOfPoints="1" NumberOfCells="0">
<Points><DataArray type="Float64" NumberOfComponents="3" format="binary">{data}</DataArray></Points>
<Cells><DataArray type="Int64" Name="connectivity" format="ascii"></DataArray>
<DataArray type="Int64" Name="offsets" format="ascii"></DataArray>
<DataArray type="UInt8" Name="types" format="ascii"></DataArray></Cells>
</Piece></UnstructuredGrid></VTKFile>
"#
        );
        let e = Vtu::parse(xml.as_bytes()).unwrap_err();
        eprintln!("{}", message(&e));
    }
}

/// Found by the `mesh_formats` fuzz target (issue 13 run): appended raw data whose UInt64
/// block header says 2⁶⁴ − 1 bytes overflowed `header + count` (a panic in debug builds, a
/// wrapped range in release). Refused as a block longer than the data.
#[test]
fn vtu_appended_raw_block_count_near_two_to_the_64_is_refused() {
    use cadmorph_mesh::format::vtu::Vtu;
    let mut xml = br#"<?xml version="1.0"?>
<VTKFile type="UnstructuredGrid" version="1.0" byte_order="LittleEndian" header_type="UInt64">
<UnstructuredGrid><Piece NumberOfPoints="1" NumberOfCells="0">
<Points><DataArray type="Float64" NumberOfComponents="3" format="appended" offset="0"/></Points>
<Cells><DataArray type="Int64" Name="connectivity" format="ascii"></DataArray>
<DataArray type="Int64" Name="offsets" format="ascii"></DataArray>
<DataArray type="UInt8" Name="types" format="ascii"></DataArray></Cells>
</Piece></UnstructuredGrid>
<AppendedData encoding="raw">
_"#
    .to_vec();
    xml.extend_from_slice(&[0xff; 8]);
    xml.extend_from_slice(&[0x41; 24]);
    xml.extend_from_slice(b"\n</AppendedData>\n</VTKFile>\n");
    let e = Vtu::parse(&xml).unwrap_err();
    let m = message(&e);
    assert!(m.contains("bytes of data, but the block is shorter"), "{m}");
}

/// Found by the `mesh_formats` fuzz target (issue 13 run): a legacy VTK cell count of
/// 2⁶⁴ − 1 was allocated for (an abort on allocation) before the list was read. Refused at
/// its line.
#[test]
fn legacy_vtk_cell_counts_beyond_the_file_are_refused() {
    for kw in ["LINES", "CELLS", "POLYGONS"] {
        let text = format!(
            "# vtk DataFile Version 4.2\nhuge\nASCII\nDATASET POLYDATA\nPOINTS 1 float\n0 0 0\n{kw} 18446744073709551615 0\n"
        );
        let e = VtkLegacy::parse(&text).unwrap_err();
        let m = message(&e);
        assert!(m.contains("line 7") && m.contains("a cell count the file can hold"), "{kw}: {m}");
    }
}

/// Found by the `mesh_formats` fuzz target: an MSH 2.2 element record with a huge tag
/// count overflowed `3 + ntags` (and a negative count would have been read as huge).
#[test]
fn msh_tag_counts_the_record_cannot_hold_are_refused() {
    for ntags in ["9223372036854775807", "-1", "5"] {
        let text = format!(
            "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n1\n1 0 0 0\n$EndNodes\n$Elements\n1\n1 15 {ntags} 1\n$EndElements\n"
        );
        let e = Msh::parse(&text).unwrap_err();
        assert!(message(&e).contains("ntags"), "{}", message(&e));
    }
}
