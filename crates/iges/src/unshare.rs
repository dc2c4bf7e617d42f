//! Copies of subfigure definitions, so that a part placed several times can be moved a
//! different way at each place.
//!
//! A 308 subfigure definition (IGES 5.3 §4.74) placed by several 408 singular subfigure
//! instances (§4.137) holds one set of surfaces for all its places: a morph that moves
//! the places differently cannot be written into it. [`Document::unshare_subfigures`]
//! gives each instance whose placement moves its own copy of the definition: the
//! definition and every entity its records reach through pointers (groups, faces,
//! surfaces, trims, curves, B-rep topology), appended after the entities read, with the
//! pointers between them renumbered to the copies. Transformation matrices (124), colours (314) and
//! properties (406) stay shared, as do nested definitions: a nested 408 copied with its
//! container points to the same nested 308, which is then instanced once more and is
//! copied in its turn. Entity types without a typed view (whose pointers are not known)
//! are shared, never copied.
//!
//! The copies are written by the document's own writer: directory entries after those
//! read, from the original's directory lines with their own parameter pointer, line
//! count and sequence numbers; parameter records after those read.

use std::collections::{BTreeMap, HashMap, HashSet};

use crate::document::{Document, EntityId, PBlock, Value};
use crate::entity::View;
use crate::{Error, Result};

/// Entity types a copy shares with the original: the morph rewrites none of them.
const SHARED_TYPES: [u32; 4] = [0, 124, 314, 406];

impl Document {
    /// Gives each placement that holds one of the `moved` faces (face entity and
    /// [`FaceRef::occurrence`](crate::FaceRef::occurrence), as
    /// [`try_faces`](Self::try_faces) lists them) its own copies of the 308 definitions
    /// on its chain of 408 instances, where another instance shares them: a moving
    /// instance of a definition several instances place gets a copy (the first keeps the
    /// original when all of them move), instances whose placements do not move keep
    /// sharing it. Nested definitions are handled level by level: a copied container's
    /// nested instances place the nested definitions once more, and are separated in
    /// their turn where they move. Returns the number of definitions copied (0 leaves the
    /// document untouched).
    ///
    /// Afterwards [`try_faces`](Self::try_faces) lists the same faces at the same places
    /// in the same order; those of the copies are new entities.
    ///
    /// # Errors
    ///
    /// Those of [`try_faces`](Self::try_faces) and of reading the records copied;
    /// [`Error::Subfigure`] when the copies would grow the file past 16 times its
    /// entities (and at least 100000): definitions nested and instanced beyond reason.
    /// On an error the document is left as it was.
    pub fn unshare_subfigures(&mut self, moved: &HashSet<(EntityId, u32)>) -> Result<usize> {
        // Each moved placement as its chain of instances (outermost first) and face.
        let mut paths: Vec<(Vec<EntityId>, EntityId)> = Vec::new();
        if moved.is_empty() {
            return Ok(0);
        }
        for (f, chain) in self.faces_with_instances()? {
            if !chain.is_empty() && moved.contains(&(f.face, f.occurrence)) {
                paths.push((chain, f.face));
            }
        }
        if paths.is_empty() {
            return Ok(0);
        }
        // All or nothing: a record that fails to read half-way leaves the document as it was.
        let before = self.clone();
        let r = self.unshare_paths(paths);
        if r.is_err() {
            *self = before;
        }
        r
    }

    /// [`unshare_subfigures`](Self::unshare_subfigures) of the moved placements `paths`.
    fn unshare_paths(&mut self, mut paths: Vec<(Vec<EntityId>, EntityId)>) -> Result<usize> {
        let limit = (self.entities.len() * 16).max(100_000);
        let mut copies = 0;
        loop {
            // The 408 instances of each 308, in entity order.
            let mut instances: BTreeMap<EntityId, Vec<EntityId>> = BTreeMap::new();
            for e in self.entities.iter().filter(|e| e.entity_type() == 408) {
                if let Ok(View::SubfigureInstance(i)) = self.view(e.id()) {
                    instances.entry(i.definition).or_default().push(e.id());
                }
            }
            // How deep each instance on a moved path is (0: placed at the top).
            let mut depth: HashMap<EntityId, usize> = HashMap::new();
            for (chain, _) in &paths {
                for (k, &i) in chain.iter().enumerate() {
                    let d = depth.entry(i).or_insert(k);
                    *d = (*d).min(k);
                }
            }
            // The outermost definition shared by a moving instance and another one: an
            // inner definition is separated only once its containers are, or an
            // instance inside a shared container would carry unmoved placements along.
            let shared = instances
                .into_iter()
                .filter_map(|(def, insts)| {
                    let moving: Vec<EntityId> = insts.iter().copied().filter(|i| depth.contains_key(i)).collect();
                    let level = moving.iter().map(|i| depth[i]).min()?;
                    (insts.len() > 1).then(|| {
                        // All moving: the first keeps the original.
                        let skip = usize::from(moving.len() == insts.len());
                        (level, def, moving[skip..].to_vec())
                    })
                })
                .min_by_key(|c| (c.0, c.1));
            let Some((_, def, to_copy)) = shared else {
                return Ok(copies);
            };
            for inst in to_copy {
                let map = self.copy_closure(def)?;
                self.repoint(inst, &HashMap::from([(def, map[&def])]))?;
                copies += 1;
                // The moved placements through this instance now run through the copy.
                for (chain, face) in &mut paths {
                    if let Some(at) = chain.iter().position(|&i| i == inst) {
                        for i in &mut chain[at + 1..] {
                            *i = map.get(i).copied().unwrap_or(*i);
                        }
                        *face = map.get(face).copied().unwrap_or(*face);
                    }
                }
                if self.entities.len() > limit {
                    return Err(Error::Subfigure {
                        de: def.0,
                        reason: format!(
                            "copying its instances would pass {limit} entities (definitions nested and instanced beyond reason)"
                        ),
                    });
                }
            }
        }
    }

    /// The entities entity `id`'s record points to (its typed view's pointers; none for
    /// types without one).
    fn pointees(&self, id: EntityId) -> Result<Vec<EntityId>> {
        let Some(slots) = self.pointer_slots(id)? else { return Ok(Vec::new()) };
        let e = self.entity(id)?;
        Ok(slots
            .iter()
            .filter_map(|&i| e.param(i)?.as_integer())
            .filter(|&v| v != 0)
            .map(|v| EntityId(v.unsigned_abs() as u32))
            .collect())
    }

    /// Appends a copy of `root` and of everything its records reach (but the shared
    /// types, entities without a view, and the definitions nested 408s place), pointers
    /// among them renumbered; returns each copied entity's copy.
    fn copy_closure(&mut self, root: EntityId) -> Result<HashMap<EntityId, EntityId>> {
        let mut order = vec![root];
        let mut seen = HashSet::from([root]);
        let mut k = 0;
        while k < order.len() {
            let id = order[k];
            k += 1;
            if self.entity(id)?.entity_type() == 408 {
                continue;
            }
            for p in self.pointees(id)? {
                let Ok(e) = self.entity(p) else { continue };
                let t = e.entity_type();
                if SHARED_TYPES.contains(&t) || !crate::entity::is_known_type(t) {
                    continue;
                }
                if seen.insert(p) {
                    order.push(p);
                }
            }
        }
        let first_new = self.entities.len();
        let map: HashMap<EntityId, EntityId> =
            order.iter().enumerate().map(|(j, &id)| (id, EntityId::from_index(first_new + j))).collect();
        for &id in &order {
            let k = self.index_of(id)?;
            let mut e = self.entities[k].clone();
            e.id = map[&id];
            e.template = Some(e.template.unwrap_or(k));
            e.d_line = 0;
            self.entities.push(e);
            self.p_blocks.push(PBlock::Entity(self.entities.len() - 1));
        }
        for &id in &order {
            self.repoint_as(id, map[&id], &map)?;
        }
        Ok(map)
    }

    /// Rewrites entity `id`'s pointers (those of its typed view and of its additional
    /// pointer groups) through `map`.
    fn repoint(&mut self, id: EntityId, map: &HashMap<EntityId, EntityId>) -> Result<()> {
        self.repoint_as(id, id, map)
    }

    /// Writes `target`'s record as `source`'s values with their pointers mapped by `map`
    /// (`target` is `source` or its fresh copy, which is always written).
    fn repoint_as(&mut self, source: EntityId, target: EntityId, map: &HashMap<EntityId, EntityId>) -> Result<()> {
        let slots = match self.pointer_slots(source)? {
            Some(s) => s,
            None if source == target => return Ok(()),
            // A copy is always written, its record as the original's.
            None => Vec::new(),
        };
        let mut values = self.entity(source)?.values();
        for &i in &slots {
            if let Some(Value::Integer(n)) = values.get_mut(i) {
                if let Some(to) = u32::try_from(n.unsigned_abs()).ok().and_then(|a| map.get(&EntityId(a))) {
                    *n = n.signum() * i64::from(to.0);
                }
            }
        }
        self.write_values(target, values, source != target)
    }
}
