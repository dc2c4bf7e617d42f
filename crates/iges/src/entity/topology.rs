//! Views of trimming, B-rep topology, structure and attribute entities.

use nalgebra::Point3;

use super::Cursor;
use crate::document::{EntityId, Value};
use crate::error::Result;

/// One curve of a 141 boundary: the model-space curve and its parameter-space images.
#[derive(Debug, Clone, PartialEq)]
pub struct BoundaryCurve {
    /// Model-space curve.
    pub curve: EntityId,
    /// SENSE: 1 as is, 2 reversed.
    pub sense: i64,
    /// Parameter-space curves.
    pub parameter_curves: Vec<EntityId>,
}

/// 141 boundary: a closed loop of curves on a surface.
#[derive(Debug, Clone, PartialEq)]
pub struct Boundary {
    /// TYPE: 0 model space only, 1 with parameter-space curves.
    pub kind: i64,
    /// PREF: preferred representation.
    pub preference: i64,
    /// The surface.
    pub surface: EntityId,
    /// The curves.
    pub curves: Vec<BoundaryCurve>,
}

impl Boundary {
    pub(crate) fn read(c: &mut Cursor) -> Result<Self> {
        let kind = c.int("TYPE")?;
        let preference = c.int("PREF")?;
        let surface = c.required("SPTR (surface)")?;
        let n = c.count("N (curves)", 3)?;
        let mut curves = Vec::with_capacity(n);
        for _ in 0..n {
            let curve = c.required("CRVPT (curve)")?;
            let sense = c.int("SENSE")?;
            let k = c.count("K (parameter curves)", 1)?;
            curves.push(BoundaryCurve { curve, sense, parameter_curves: c.pointers("PSCPT", k)? });
        }
        Ok(Self { kind, preference, surface, curves })
    }
}

/// 142 curve on a parametric surface.
#[derive(Debug, Clone, PartialEq)]
pub struct CurveOnSurface {
    /// CRTN: how the curve was created.
    pub creation: i64,
    /// The surface.
    pub surface: EntityId,
    /// The curve in the surface's parameter space (B).
    pub parameter_curve: Option<EntityId>,
    /// The curve in model space (C).
    pub model_curve: Option<EntityId>,
    /// PREF: 0 unspecified, 1 parameter space, 2 model space, 3 either.
    pub preference: i64,
}

impl CurveOnSurface {
    pub(crate) fn read(c: &mut Cursor) -> Result<Self> {
        Ok(Self {
            creation: c.int("CRTN")?,
            surface: c.required("SPTR (surface)")?,
            parameter_curve: c.pointer("BPTR (parameter curve)")?,
            model_curve: c.pointer("CPTR (model curve)")?,
            preference: c.int_or("PREF", 0)?,
        })
    }
}

/// 143 bounded surface.
#[derive(Debug, Clone, PartialEq)]
pub struct BoundedSurface {
    /// TYPE: 0 model space only, 1 with parameter-space curves.
    pub kind: i64,
    /// The surface.
    pub surface: EntityId,
    /// Its 141 boundaries.
    pub boundaries: Vec<EntityId>,
}

impl BoundedSurface {
    pub(crate) fn read(c: &mut Cursor) -> Result<Self> {
        let kind = c.int("TYPE")?;
        let surface = c.required("SPTR (surface)")?;
        let n = c.count("N (boundaries)", 1)?;
        Ok(Self { kind, surface, boundaries: c.pointers("BDPT", n)? })
    }
}

/// 144 trimmed surface.
#[derive(Debug, Clone, PartialEq)]
pub struct TrimmedSurface {
    /// The surface.
    pub surface: EntityId,
    /// N1 = 0: the outer boundary is the surface's own boundary.
    pub outer_is_domain: bool,
    /// The outer boundary (a 142), when N1 = 1.
    pub outer: Option<EntityId>,
    /// Inner boundaries (142s).
    pub inner: Vec<EntityId>,
}

impl TrimmedSurface {
    pub(crate) fn read(c: &mut Cursor) -> Result<Self> {
        let surface = c.required("PTS (surface)")?;
        let n1 = c.int("N1")?;
        let n2 = c.count("N2 (inner boundaries)", 1)?;
        let outer = c.pointer("PTO (outer boundary)")?;
        Ok(Self { surface, outer_is_domain: n1 == 0, outer, inner: c.pointers("PTI (inner boundary)", n2)? })
    }
}

/// 186 manifold solid B-rep object.
#[derive(Debug, Clone, PartialEq)]
pub struct ManifoldSolid {
    /// The outer shell (514).
    pub shell: EntityId,
    /// SOF: the shell's orientation agrees with its faces.
    pub same_orientation: bool,
    /// Void shells and their orientation flags.
    pub voids: Vec<(EntityId, bool)>,
}

impl ManifoldSolid {
    pub(crate) fn read(c: &mut Cursor) -> Result<Self> {
        let shell = c.required("SHELL")?;
        let same_orientation = c.int("SOF")? == 1;
        let n = c.count("N (void shells)", 2)?;
        let mut voids = Vec::with_capacity(n);
        for _ in 0..n {
            voids.push((c.required("VOID")?, c.int("VOF")? == 1));
        }
        Ok(Self { shell, same_orientation, voids })
    }
}

/// 308 subfigure definition.
#[derive(Debug, Clone, PartialEq)]
pub struct SubfigureDefinition {
    /// Nesting depth.
    pub depth: i64,
    /// Name.
    pub name: String,
    /// The entities of the subfigure.
    pub entities: Vec<EntityId>,
}

impl SubfigureDefinition {
    pub(crate) fn read(c: &mut Cursor) -> Result<Self> {
        let depth = c.int("DEPTH")?;
        let name = c.string("NAME")?;
        let n = c.count("N (entities)", 1)?;
        Ok(Self { depth, name, entities: c.pointers("DE", n)? })
    }
}

/// 314 colour definition (percentages of red, green, blue).
#[derive(Debug, Clone, PartialEq)]
pub struct Color {
    /// `[R, G, B]` in percent.
    pub rgb: [f64; 3],
    /// Colour name.
    pub name: String,
}

impl Color {
    pub(crate) fn read(c: &mut Cursor) -> Result<Self> {
        let rgb = [c.real("CC1")?, c.real("CC2")?, c.real("CC3")?];
        let name = if c.remaining() > 0 { c.string("CNAME")? } else { String::new() };
        Ok(Self { rgb, name })
    }
}

/// 402 associativity instance. Group forms (1, 7, 14, 15) list their members; other
/// forms keep their parameters as values.
#[derive(Debug, Clone, PartialEq)]
pub struct Associativity {
    /// Form number.
    pub form: i64,
    /// Members (group forms).
    pub members: Vec<EntityId>,
    /// Parameters after the entity type (other forms).
    pub values: Vec<Value>,
}

impl Associativity {
    pub(crate) fn read(c: &mut Cursor, form: i64) -> Result<Self> {
        if matches!(form, 1 | 7 | 14 | 15) {
            let n = c.count("N (members)", 1)?;
            return Ok(Self { form, members: c.pointers("member", n)?, values: Vec::new() });
        }
        let values = (c.i..c.e.param_count()).filter_map(|i| c.e.param(i)).map(|p| p.to_value()).collect();
        Ok(Self { form, members: Vec::new(), values })
    }
}

/// 406 property: form number and values.
#[derive(Debug, Clone, PartialEq)]
pub struct Property {
    /// Form number (e.g. 15 name, 16 drawing size).
    pub form: i64,
    /// The values after the count NP.
    pub values: Vec<Value>,
}

impl Property {
    pub(crate) fn read(c: &mut Cursor, form: i64) -> Result<Self> {
        let n = c.count("NP (values)", 1)?;
        let values = (c.i..c.i + n).filter_map(|i| c.e.param(i)).map(|p| p.to_value()).collect();
        Ok(Self { form, values })
    }
}

/// 408 singular subfigure instance.
#[derive(Debug, Clone, PartialEq)]
pub struct SubfigureInstance {
    /// The 308 definition.
    pub definition: EntityId,
    /// Translation.
    pub translation: Point3<f64>,
    /// Scale factor (default 1).
    pub scale: f64,
}

impl SubfigureInstance {
    pub(crate) fn read(c: &mut Cursor) -> Result<Self> {
        Ok(Self {
            definition: c.required("DE (definition)")?,
            translation: c.point("translation")?,
            scale: c.real_or("S", 1.0)?,
        })
    }
}

/// 502 vertex list.
#[derive(Debug, Clone, PartialEq)]
pub struct VertexList {
    /// The vertices.
    pub vertices: Vec<Point3<f64>>,
}

impl VertexList {
    pub(crate) fn read(c: &mut Cursor) -> Result<Self> {
        let n = c.count("N (vertices)", 3)?;
        Ok(Self { vertices: (0..n).map(|_| c.point("vertex")).collect::<Result<_>>()? })
    }
}

/// One edge of a 504 edge list.
#[derive(Debug, Clone, PartialEq)]
pub struct Edge {
    /// Model-space curve.
    pub curve: EntityId,
    /// Start vertex: its 502 list and 1-based index.
    pub start: (EntityId, i64),
    /// End vertex.
    pub end: (EntityId, i64),
}

/// 504 edge list.
#[derive(Debug, Clone, PartialEq)]
pub struct EdgeList {
    /// The edges.
    pub edges: Vec<Edge>,
}

impl EdgeList {
    pub(crate) fn read(c: &mut Cursor) -> Result<Self> {
        let n = c.count("N (edges)", 5)?;
        let mut edges = Vec::with_capacity(n);
        for _ in 0..n {
            let curve = c.required("CURV")?;
            let start = (c.required("SVP")?, c.int("SV")?);
            let end = (c.required("TVP")?, c.int("TV")?);
            edges.push(Edge { curve, start, end });
        }
        Ok(Self { edges })
    }
}

/// One edge use of a 508 loop.
#[derive(Debug, Clone, PartialEq)]
pub struct LoopEdge {
    /// TYPE: 0 edge, 1 vertex.
    pub kind: i64,
    /// The 504 edge list (or 502 vertex list).
    pub list: EntityId,
    /// 1-based index in the list.
    pub index: i64,
    /// OF: the edge's direction agrees with the loop.
    pub same_orientation: bool,
    /// Parameter-space curves: (isoparametric flag, curve).
    pub parameter_curves: Vec<(bool, EntityId)>,
}

/// 508 loop.
#[derive(Debug, Clone, PartialEq)]
pub struct Loop {
    /// The edge uses.
    pub edges: Vec<LoopEdge>,
}

impl Loop {
    pub(crate) fn read(c: &mut Cursor) -> Result<Self> {
        let n = c.count("N (edges)", 5)?;
        let mut edges = Vec::with_capacity(n);
        for _ in 0..n {
            let kind = c.int("TYPE")?;
            let list = c.required("EDGE")?;
            let index = c.int("NDX")?;
            let same_orientation = c.int("OF")? == 1;
            let k = c.count("K (parameter curves)", 2)?;
            let mut parameter_curves = Vec::with_capacity(k);
            for _ in 0..k {
                parameter_curves.push((c.int("ISOP")? == 1, c.required("CURV")?));
            }
            edges.push(LoopEdge { kind, list, index, same_orientation, parameter_curves });
        }
        Ok(Self { edges })
    }
}

/// 510 face.
#[derive(Debug, Clone, PartialEq)]
pub struct Face {
    /// The surface.
    pub surface: EntityId,
    /// OF: the first loop is the outer one.
    pub outer_first: bool,
    /// The 508 loops.
    pub loops: Vec<EntityId>,
}

impl Face {
    pub(crate) fn read(c: &mut Cursor) -> Result<Self> {
        let surface = c.required("SURF")?;
        let n = c.count("N (loops)", 1)?;
        let outer_first = c.int("OF")? == 1;
        Ok(Self { surface, outer_first, loops: c.pointers("LOOP", n)? })
    }
}

/// 514 shell.
#[derive(Debug, Clone, PartialEq)]
pub struct Shell {
    /// Faces and their orientation flags (true: the face normal agrees with the shell).
    pub faces: Vec<(EntityId, bool)>,
}

impl Shell {
    pub(crate) fn read(c: &mut Cursor) -> Result<Self> {
        let n = c.count("N (faces)", 2)?;
        let mut faces = Vec::with_capacity(n);
        for _ in 0..n {
            faces.push((c.required("FACE")?, c.int("OF")? == 1));
        }
        Ok(Self { faces })
    }
}
