//! Entities that edits left unused: the axis and generatrix of a 120 that became a 128,
//! the points and directions of a 190–198, the parameter curves of 142s, 141s and 508s
//! dropped with their surface's parameter space, the base of a 140 that became a
//! B-spline. When the document is written they are marked as Null entities (type 0,
//! IGES 5.3 §4.2: "ignored by processors"), so the file carries no dead geometry while
//! every DE number, and so every pointer of the rest of the file, stays as it was.
//! (Removing them would renumber the directory, and so every pointer of every entity,
//! including those of entity types this crate does not read.)
//!
//! The rule, as for STEP (`cadmorph-step`'s `write/orphans.rs`): an entity is orphaned
//! when an edit removed a pointer to it, it is physically dependent (status digits 3–4
//! `01` or `03`, §2.2.4.4.9: it exists only as part of its parents), and nothing that is
//! kept points to it any more; the entities it pointed to are then considered in turn.
//! Independent entities are never touched, nor anything the input itself left unused.
//! Copies an edit appended (`Document::unshare_subfigures`) have no input to respect: a
//! dependent copy nothing kept points to is an orphan.
//! "Points to" is counted generously: the pointers a record's [`View`] reads, those of
//! its additional pointer groups (back pointers, properties), and for entity types
//! without a view every integer parameter that is a DE number, as well as the
//! directory's pointer fields, so that no entity a record might reference is marked (a
//! count or degree that happens to equal a DE number is no pointer where the view says
//! so); the pointers an edit removed are read precisely, from the old and new [`View`]s.

use std::collections::BTreeSet;

use crate::document::{Document, EntityId, Param};
use crate::entity::View;

/// The pointers of a view, precisely; `None` for views whose pointers are not listed
/// here (then every DE-like integer of the record is taken).
fn view_pointers(v: &View) -> Option<Vec<EntityId>> {
    let mut out = Vec::new();
    match v {
        View::CircularArc(_)
        | View::ConicArc(_)
        | View::CopiousData(_)
        | View::Line(_)
        | View::ParametricSplineCurve(_)
        | View::ParametricSplineSurface(_)
        | View::Direction(_)
        | View::TransformationMatrix(_)
        | View::BSplineCurve(_)
        | View::BSplineSurface(_)
        | View::Color(_)
        | View::VertexList(_) => {}
        View::CompositeCurve(c) => out.extend(&c.curves),
        View::Plane(p) => out.extend(p.boundary),
        View::Point(p) => out.extend(p.symbol),
        View::RuledSurface(r) => out.extend([r.curve1, r.curve2]),
        View::SurfaceOfRevolution(r) => out.extend([r.axis, r.generatrix]),
        View::TabulatedCylinder(t) => out.push(t.directrix),
        View::OffsetSurface(o) => out.push(o.surface),
        View::Boundary(b) => {
            out.push(b.surface);
            for c in &b.curves {
                out.push(c.curve);
                out.extend(&c.parameter_curves);
            }
        }
        View::CurveOnSurface(c) => {
            out.push(c.surface);
            out.extend(c.parameter_curve);
            out.extend(c.model_curve);
        }
        View::BoundedSurface(b) => {
            out.push(b.surface);
            out.extend(&b.boundaries);
        }
        View::TrimmedSurface(t) => {
            out.push(t.surface);
            out.extend(t.outer);
            out.extend(&t.inner);
        }
        View::PlaneSurface(p) => out.extend([Some(p.location), Some(p.normal), p.reference].into_iter().flatten()),
        View::CylindricalSurface(c) => out.extend([Some(c.location), Some(c.axis), c.reference].into_iter().flatten()),
        View::ConicalSurface(c) => out.extend([Some(c.location), Some(c.axis), c.reference].into_iter().flatten()),
        View::SphericalSurface(s) => out.extend([Some(s.center), s.axis, s.reference].into_iter().flatten()),
        View::ToroidalSurface(t) => out.extend([Some(t.center), Some(t.axis), t.reference].into_iter().flatten()),
        View::EdgeList(l) => {
            for e in &l.edges {
                out.extend([e.curve, e.start.0, e.end.0]);
            }
        }
        View::Loop(l) => {
            for e in &l.edges {
                out.push(e.list);
                out.extend(e.parameter_curves.iter().map(|p| p.1));
            }
        }
        View::Face(f) => {
            out.push(f.surface);
            out.extend(&f.loops);
        }
        View::Shell(s) => out.extend(s.faces.iter().map(|f| f.0)),
        View::ManifoldSolid(m) => {
            out.push(m.shell);
            out.extend(m.voids.iter().map(|v| v.0));
        }
        View::SubfigureDefinition(s) => out.extend(&s.entities),
        View::SubfigureInstance(s) => out.push(s.definition),
        _ => return None,
    }
    Some(out)
}

/// Every DE number entity `k` of `doc` might point to: the pointers its typed view reads
/// and those of the additional pointer groups after them (§2.2.4.5.2), or, for a record
/// without a view (or one that does not read, or a 402 or 406, whose views read most
/// forms' values untyped), each integer parameter that names an entity; and the directory's pointer fields (§2.2.4.4: structure, line font, level,
/// view, transformation matrix, label display, colour; negated where they point).
fn generous_pointers(doc: &Document, k: usize, out: &mut Vec<usize>) {
    let e = &doc.entities[k];
    let mut add = |n: i64| {
        if let Ok(n) = u32::try_from(n) {
            if let Ok(j) = doc.index_of(EntityId(n)) {
                out.push(j);
            }
        }
    };
    // 402 and 406 views read most forms' values without knowing which are pointers.
    let slots = if matches!(e.entity_type(), 402 | 406) { Ok(None) } else { doc.pointer_slots(e.id) };
    match slots {
        // A typed view's pointers, and the additional pointer groups after them.
        Ok(Some(slots)) => {
            for i in slots {
                if let Some(Param::Integer(n)) = e.param(i) {
                    add(n);
                }
            }
        }
        _ => {
            for p in e.params().skip(1) {
                if let Param::Integer(n) = p {
                    add(n);
                }
            }
        }
    }
    let d = &e.directory;
    add(-d.structure);
    add(-d.line_font);
    add(-d.level);
    add(d.view);
    add(d.transform);
    add(d.label_display);
    add(-d.color);
}

/// The precise pointers of entity `id` in `doc`, or every DE-like integer when its view
/// does not read or is not listed.
fn precise_pointers(doc: &Document, id: EntityId) -> Vec<usize> {
    let Ok(k) = doc.index_of(id) else { return Vec::new() };
    match doc.view(id).ok().as_ref().and_then(view_pointers) {
        Some(ids) => ids.into_iter().filter_map(|p| doc.index_of(p).ok()).collect(),
        None => {
            let mut out = Vec::new();
            generous_pointers(doc, k, &mut out);
            out
        }
    }
}

impl Document {
    /// Indices of the entities orphaned by the edits (see the module docs); empty for an
    /// unedited document.
    pub(crate) fn orphans(&self) -> BTreeSet<usize> {
        let mut out = BTreeSet::new();
        let rewritten: Vec<usize> = (0..self.entities.len()).filter(|&k| self.entities[k].is_rewritten()).collect();
        if !self.edited || rewritten.is_empty() {
            return out;
        }
        // The input as read: the old records of the rewritten entities.
        let Ok(original) = Document::parse(&self.src.bytes) else { return out };
        // Entities appended by an edit (copies) come after those read.
        if original.entities.len() > self.entities.len() {
            return out;
        }
        let n = self.entities.len();
        let mut count = vec![0usize; n];
        let mut now: Vec<Vec<usize>> = Vec::with_capacity(n);
        for k in 0..n {
            let mut p = Vec::new();
            generous_pointers(self, k, &mut p);
            for &j in &p {
                count[j] += 1;
            }
            now.push(p);
        }
        let dependent = |k: usize| self.entities[k].directory.status.subordinate & 1 == 1;
        let mut work = Vec::new();
        for &k in &rewritten {
            let id = self.entities[k].id;
            let new: BTreeSet<usize> = precise_pointers(self, id).into_iter().collect();
            for j in precise_pointers(&original, id) {
                if !new.contains(&j) && j != k {
                    work.push(j);
                }
            }
        }
        // Copies an edit appended have no input to respect: any that nothing kept points
        // to any more is an orphan.
        work.extend((original.entities.len()..n).filter(|&k| self.entities[k].template.is_some()));
        while let Some(j) = work.pop() {
            if out.contains(&j) || count[j] != 0 || !dependent(j) {
                continue;
            }
            out.insert(j);
            for &i in &now[j] {
                count[i] -= 1;
            }
            // What the orphan pointed to may now be orphaned too: by its own record, read
            // precisely (it was not edited, or its new record is what is current).
            work.extend(precise_pointers(self, self.entities[j].id));
        }
        out
    }
}
