//! VTK XML unstructured grids (`.vtu`, ASCII) of the control nets and the FFD lattice,
//! for ParaView.
//!
//! - [`net_vtu`]: every face's control net as quadrilaterals (`VTK_QUAD`), with the cell
//!   data `face` (the face's index, as in the seam tables).
//! - [`lattice_vtu`]: the FFD lattice as hexahedra (`VTK_HEXAHEDRON`) at its original
//!   points, with the point data `displacement` (moved − original): ParaView's "Warp By
//!   Vector" shows the moved lattice.

use std::fmt::Write;

use crate::scene::{Lattice, ModelView};

const VTK_QUAD: u8 = 9;
const VTK_HEXAHEDRON: u8 = 12;

fn grid(points: &[[f64; 3]], cells: &[Vec<usize>], kind: u8, point_data: &str, cell_data: &str) -> String {
    let mut s = String::from("<?xml version=\"1.0\"?>\n<VTKFile type=\"UnstructuredGrid\" version=\"1.0\" byte_order=\"LittleEndian\" header_type=\"UInt64\">\n<UnstructuredGrid>\n");
    let _ = writeln!(s, "<Piece NumberOfPoints=\"{}\" NumberOfCells=\"{}\">", points.len(), cells.len());
    s.push_str(point_data);
    s.push_str(cell_data);
    s.push_str("<Points><DataArray type=\"Float64\" NumberOfComponents=\"3\" format=\"ascii\">\n");
    for p in points {
        let _ = writeln!(s, "{:e} {:e} {:e}", p[0], p[1], p[2]);
    }
    s.push_str("</DataArray></Points>\n<Cells><DataArray type=\"Int64\" Name=\"connectivity\" format=\"ascii\">\n");
    for c in cells {
        let line: Vec<String> = c.iter().map(|i| i.to_string()).collect();
        let _ = writeln!(s, "{}", line.join(" "));
    }
    s.push_str("</DataArray>\n<DataArray type=\"Int64\" Name=\"offsets\" format=\"ascii\">\n");
    let mut off = 0;
    for c in cells {
        off += c.len();
        let _ = write!(s, "{off} ");
    }
    s.push_str("\n</DataArray>\n<DataArray type=\"UInt8\" Name=\"types\" format=\"ascii\">\n");
    for _ in cells {
        let _ = write!(s, "{kind} ");
    }
    s.push_str("\n</DataArray></Cells>\n</Piece>\n</UnstructuredGrid>\n</VTKFile>\n");
    s
}

/// The control nets of `state` as a `.vtu` document.
pub fn net_vtu(state: &ModelView) -> String {
    let (mut points, mut cells, mut face) = (Vec::new(), Vec::new(), Vec::new());
    for (k, f) in state.faces.iter().enumerate() {
        let base = points.len();
        points.extend_from_slice(&f.net);
        let nv = f.net_v;
        for i in 0..f.net_u.saturating_sub(1) {
            for j in 0..nv.saturating_sub(1) {
                let a = base + i * nv + j;
                cells.push(vec![a, a + nv, a + nv + 1, a + 1]);
                face.push(k);
            }
        }
    }
    let mut cd = String::from("<CellData Scalars=\"face\"><DataArray type=\"Int32\" Name=\"face\" format=\"ascii\">\n");
    for k in &face {
        let _ = write!(cd, "{k} ");
    }
    cd.push_str("\n</DataArray></CellData>\n");
    grid(&points, &cells, VTK_QUAD, "", &cd)
}

/// The lattice `l` as a `.vtu` document.
pub fn lattice_vtu(l: &Lattice) -> String {
    let [nl, m, n] = l.shape;
    let id = |i: usize, j: usize, k: usize| (i * m + j) * n + k;
    let mut cells = Vec::new();
    for i in 0..nl.saturating_sub(1) {
        for j in 0..m.saturating_sub(1) {
            for k in 0..n.saturating_sub(1) {
                cells.push(vec![
                    id(i, j, k),
                    id(i + 1, j, k),
                    id(i + 1, j + 1, k),
                    id(i, j + 1, k),
                    id(i, j, k + 1),
                    id(i + 1, j, k + 1),
                    id(i + 1, j + 1, k + 1),
                    id(i, j + 1, k + 1),
                ]);
            }
        }
    }
    let mut pd = String::from(
        "<PointData Vectors=\"displacement\"><DataArray type=\"Float64\" Name=\"displacement\" NumberOfComponents=\"3\" format=\"ascii\">\n",
    );
    for (a, b) in l.original.iter().zip(&l.moved) {
        let _ = writeln!(pd, "{:e} {:e} {:e}", b[0] - a[0], b[1] - a[1], b[2] - a[2]);
    }
    pd.push_str("</DataArray></PointData>\n");
    grid(&l.original, &cells, VTK_HEXAHEDRON, &pd, "")
}
