//! Model-space curves: those that bound faces and the others.

use cadmorph_nurbs::math::Matrix4;
use cadmorph_nurbs::NurbsCurve;

use crate::EntityRef;

/// A model-space curve bounding a face: a trimming curve (IGES 142 model curve of a 144,
/// 141 boundary curve of a 143), an edge of a 504 list used by a 508 loop of a 510 face,
/// or a STEP `EDGE_CURVE` of a face's loop. One per face that uses it: an edge shared by
/// two faces comes twice, with the same [`edge`](Self::edge).
#[derive(Debug, Clone, PartialEq)]
pub struct BoundCurve {
    /// Index of the face it bounds, into the faces it was asked for.
    pub face: usize,
    /// The entity that names it in reports: the IGES 142 (or the 141 curve), the 504 edge
    /// list, the STEP `EDGE_CURVE`.
    pub label: EntityRef,
    /// The topological edge, when the file has one (STEP `EDGE_CURVE` at its occurrence,
    /// IGES 504 list with the edge's 1-based index in `edge_index`): two faces
    /// with the same edge are adjacent along it. `None` for trimming curves, whose
    /// partners are found from geometry.
    pub edge: Option<EntityRef>,
    /// For an IGES 504 edge, its 1-based index in the list (`0` otherwise).
    pub edge_index: u32,
    /// What [`CadDocument::set_bound_curve`](crate::CadDocument::set_bound_curve)
    /// rewrites (the IGES curve entity, the STEP `EDGE_CURVE`); `None` when the curve
    /// cannot be rewritten alone (one piece of a composite curve that is not a member
    /// entity of its own).
    pub target: Option<EntityRef>,
    /// Which piece of the entity's curve this is (composite curves give several).
    pub piece: usize,
    /// The curve in world coordinates and model units.
    pub curve: NurbsCurve,
    /// The part of the curve's domain that bounds the face (between the edge's vertices).
    pub range: (f64, f64),
    /// File coordinates of the curve entity to world coordinates (see
    /// [`Face::placement`](crate::Face::placement)).
    pub placement: Matrix4<f64>,
}

/// A model-space curve that bounds no face (an IGES 126 that is not subordinate, the
/// model-space curve of a 142 whose face is not converted).
#[derive(Debug, Clone, PartialEq)]
pub struct FreeCurve {
    /// The curve entity.
    pub entity: EntityRef,
    /// The curve in world coordinates and model units (its control points are what a
    /// morph moves).
    pub curve: NurbsCurve,
}
