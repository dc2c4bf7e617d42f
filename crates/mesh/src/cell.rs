//! Cells (elements) as the formats store them: a kind and the 0-based indices of its nodes,
//! in VTK's node order (VTK file formats, "Cell types" figure; Gmsh and UNV orders are
//! converted on reading).

/// The kind of a cell. The numbers are VTK cell type ids (VTK file formats, `VTK_TRIANGLE`
/// = 5 and so on).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum CellKind {
    /// A single node (VTK 1).
    Vertex,
    /// A two-node segment (VTK 3).
    Line,
    /// A three-node triangle (VTK 5).
    Triangle,
    /// A polygon with any number of nodes (VTK 7).
    Polygon,
    /// A four-node quadrilateral (VTK 9).
    Quad,
    /// A four-node tetrahedron (VTK 10).
    Tetra,
    /// An eight-node hexahedron (VTK 12).
    Hexahedron,
    /// A six-node wedge / prism (VTK 13).
    Wedge,
    /// A five-node pyramid (VTK 14).
    Pyramid,
}

impl CellKind {
    /// VTK's cell type id.
    pub fn vtk_id(self) -> u8 {
        match self {
            CellKind::Vertex => 1,
            CellKind::Line => 3,
            CellKind::Triangle => 5,
            CellKind::Polygon => 7,
            CellKind::Quad => 9,
            CellKind::Tetra => 10,
            CellKind::Hexahedron => 12,
            CellKind::Wedge => 13,
            CellKind::Pyramid => 14,
        }
    }

    /// The kind with VTK id `id`, if it is one of the linear kinds above.
    pub fn from_vtk_id(id: i64) -> Option<CellKind> {
        Some(match id {
            1 => CellKind::Vertex,
            3 => CellKind::Line,
            5 => CellKind::Triangle,
            7 => CellKind::Polygon,
            9 => CellKind::Quad,
            10 => CellKind::Tetra,
            12 => CellKind::Hexahedron,
            13 => CellKind::Wedge,
            14 => CellKind::Pyramid,
            _ => return None,
        })
    }

    /// Number of nodes, `None` for [`CellKind::Polygon`].
    pub fn n_nodes(self) -> Option<usize> {
        match self {
            CellKind::Vertex => Some(1),
            CellKind::Line => Some(2),
            CellKind::Triangle => Some(3),
            CellKind::Polygon => None,
            CellKind::Quad => Some(4),
            CellKind::Tetra => Some(4),
            CellKind::Hexahedron => Some(8),
            CellKind::Wedge => Some(6),
            CellKind::Pyramid => Some(5),
        }
    }

    /// Topological dimension (0 vertex, 1 line, 2 surface, 3 volume).
    pub fn dim(self) -> u8 {
        match self {
            CellKind::Vertex => 0,
            CellKind::Line => 1,
            CellKind::Triangle | CellKind::Polygon | CellKind::Quad => 2,
            _ => 3,
        }
    }

    /// The faces of a volume cell as node positions within the cell, each ordered so that
    /// its right-hand normal points out of the cell (VTK node order).
    pub fn faces(self) -> &'static [&'static [usize]] {
        match self {
            CellKind::Tetra => &[&[0, 2, 1], &[0, 1, 3], &[1, 2, 3], &[0, 3, 2]],
            CellKind::Pyramid => &[&[0, 3, 2, 1], &[0, 1, 4], &[1, 2, 4], &[2, 3, 4], &[3, 0, 4]],
            CellKind::Wedge => &[&[0, 1, 2], &[3, 5, 4], &[0, 3, 4, 1], &[1, 4, 5, 2], &[2, 5, 3, 0]],
            CellKind::Hexahedron => {
                &[&[0, 3, 2, 1], &[4, 5, 6, 7], &[0, 1, 5, 4], &[1, 2, 6, 5], &[2, 3, 7, 6], &[3, 0, 4, 7]]
            }
            _ => &[],
        }
    }
}

/// One cell: its kind and the 0-based indices of its nodes.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Cell {
    /// The kind.
    pub kind: CellKind,
    /// Node indices into the mesh's point list, in VTK order.
    pub nodes: Vec<usize>,
}

impl Cell {
    /// A cell of `kind` on `nodes`.
    pub fn new(kind: CellKind, nodes: Vec<usize>) -> Cell {
        Cell { kind, nodes }
    }
}
