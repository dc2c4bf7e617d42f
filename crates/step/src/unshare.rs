//! Parts placed more than once, given their own copies.
//!
//! An assembly places one part by several occurrences (ISO 10303-44 §4.3:
//! `next_assembly_usage_occurrence`s of one `product_definition`, each with its own
//! `context_dependent_shape_representation` whose `representation_relationship_with_
//! transformation` places the part's shape representation; ISO 10303-43 §4.5.7 does the
//! same with `mapped_item`s of one `representation_map`). The placements share every
//! face, edge, curve and surface instance, so a morph that moves them differently cannot
//! be written into them. [`Document::unshare`] gives each placement that needs it a copy
//! of the part: the representation and everything its items reach (contexts and units
//! stay shared, so do the placement axes among its items, which the transformations
//! name), its relationship children (sub-assemblies) in turn, and for assembly
//! occurrences a `product_definition` of the same formation with its
//! `product_definition_shape` and `shape_definition_representation`, which the
//! occurrence's `next_assembly_usage_occurrence` then names (OCCT's reader takes a
//! component's shape from the related product definition, the placement from the
//! relationship). Styled items of the copied geometry are copied and listed where the
//! originals are, so the copy keeps its colours.
//!
//! Only placements that hold moved faces are copied; the placements that do not move keep
//! sharing the original. Nothing is renumbered: copies take fresh ids above the highest.

use std::collections::{BTreeSet, HashMap, HashSet};

use crate::document::Document;
use crate::error::{Error, Position, Result};
use crate::read::{scan_instance, scan_instance_at};
use crate::views::{Link, Occurrence};
use crate::EntityId;

/// Indexes of the product structure and presentation, as the document stands.
struct Graph {
    /// Representation → its `SHAPE_DEFINITION_REPRESENTATION`.
    sdr_of_rep: HashMap<u64, u64>,
    /// Representation relationship → its `CONTEXT_DEPENDENT_SHAPE_REPRESENTATION`.
    cdsr_of_link: HashMap<u64, u64>,
    /// Representation → its relationship children `(child, relationship)`, in walk order.
    children: HashMap<u64, Vec<(u64, u64)>>,
    /// Item → the `STYLED_ITEM`s that style it.
    styled: HashMap<u64, Vec<u64>>,
    /// Styled item → the presentation representations that list it.
    lists: HashMap<u64, Vec<u64>>,
    /// Contexts, units and everything they reach: shared by every copy.
    shared: HashSet<u64>,
}

/// A representation entered by the placement walk: the links taken to it (empty for a
/// root) and whether a moved face lies below.
struct Entry {
    /// The root representation of the walk that entered it.
    root: u64,
    prefix: Vec<Link>,
    moved: bool,
}

impl Document {
    /// Gives every placement of a repeated part that holds a face of `moved` its own copy
    /// of the part, so that each placement can be edited alone (see the module docs).
    /// `moved` names placed faces as [`Document::faces`] lists them: `(face, occurrence)`.
    /// Placements that move nothing keep sharing the original; a part placed once is left
    /// as it is. Afterwards [`Document::faces`] lists the same faces in the same order and
    /// at the same places, those of the copies under their new ids. Returns the number of
    /// copies made (0: the document is unchanged).
    ///
    /// # Errors
    ///
    /// The errors of [`Document::faces`] for malformed placements; [`Error::Limit`] when
    /// the copies would grow the document without bound; [`Error::Edit`] for a product
    /// structure that names a missing instance. After an error the document is unchanged.
    pub fn unshare(&mut self, moved: &HashSet<(EntityId, usize)>) -> Result<usize> {
        let run_moved = self.moved_runs(moved)?;
        if !run_moved.iter().any(|&m| m) {
            return Ok(0);
        }
        // All or nothing: a failure part-way leaves the document as it was.
        let before = self.clone();
        let result = self.unshare_runs(&run_moved);
        if result.is_err() {
            *self = before;
        }
        result
    }

    fn unshare_runs(&mut self, run_moved: &[bool]) -> Result<usize> {
        let limit = self.instances.len().saturating_mul(64).saturating_add(1 << 20);
        let mut copies = 0;
        loop {
            let (occs, plan) = self.unshare_plan(run_moved)?;
            let Some(links) = plan else { return Ok(copies) };
            let graph = Graph::of(self, &occs)?;
            for link in links {
                self.copy_for(link, &graph)?;
                copies += 1;
            }
            if self.instances.len() > limit {
                return Err(Error::Limit {
                    at: Position { line: 0, column: 0, id: None },
                    what: "copies of repeated parts beyond 64 times the file",
                });
            }
        }
    }

    /// For each placement run of the walk, whether it holds a face of `moved`.
    fn moved_runs(&self, moved: &HashSet<(EntityId, usize)>) -> Result<Vec<bool>> {
        let (ctx, units) = self.ctx()?;
        let mut seen: HashMap<u64, usize> = HashMap::new();
        let mut out = Vec::new();
        for occ in ctx.occurrences(units.length.metres)? {
            let mut m = false;
            for (f, _) in ctx.run_faces(&occ)? {
                let n = seen.entry(f.0).or_insert(0);
                m |= moved.contains(&(f, *n));
                *n += 1;
            }
            out.push(m);
        }
        Ok(out)
    }

    /// The placement walk as the document stands, and the links to redirect to fresh
    /// copies next: those of the first repeated representation that needs copies and
    /// whose entries pass through no other that does, or `None` when none does.
    ///
    /// Of a representation's entries one keeps the original (the unplaced root entry if
    /// there is one, else the first that moves nothing, else the first); if the keeper
    /// moves, every other entry gets a copy, else every moving one does.
    fn unshare_plan(&self, run_moved: &[bool]) -> Result<(Vec<Occurrence>, Option<Vec<Link>>)> {
        let (ctx, units) = self.ctx()?;
        let occs = ctx.occurrences(units.length.metres)?;
        if occs.len() != run_moved.len() {
            return Err(Error::Edit {
                at: Position { line: 0, column: 0, id: None },
                reason: format!("the copies changed the placements ({} runs, {} before)", occs.len(), run_moved.len()),
            });
        }
        let mut entries: Vec<Entry> = Vec::new();
        let mut at: HashMap<(u64, Vec<Link>), usize> = HashMap::new();
        let mut by_rep: HashMap<u64, Vec<usize>> = HashMap::new();
        for (occ, &m) in occs.iter().zip(run_moved) {
            for j in 0..=occ.path.len() {
                let rep = if j == 0 { occ.root.0 } else { occ.path[j - 1].rep.0 };
                let key = (rep, occ.path[..j].to_vec());
                let e = *at.entry(key).or_insert_with(|| {
                    entries.push(Entry { root: occ.root.0, prefix: occ.path[..j].to_vec(), moved: false });
                    by_rep.entry(rep).or_default().push(entries.len() - 1);
                    entries.len() - 1
                });
                entries[e].moved |= m;
            }
        }
        // Representations that need copies, with the links to redirect.
        let mut reps: Vec<u64> = by_rep.keys().copied().collect();
        reps.sort_by_key(|r| by_rep[r][0]);
        let mut needs: Vec<(u64, Vec<Link>)> = Vec::new();
        for rep in reps {
            let list = &by_rep[&rep];
            if list.len() < 2 || !list.iter().any(|&e| entries[e].moved) {
                continue;
            }
            let keeper = list
                .iter()
                .copied()
                .find(|&e| entries[e].prefix.is_empty())
                .or_else(|| list.iter().copied().find(|&e| !entries[e].moved))
                .unwrap_or(list[0]);
            let copy: Vec<Link> = list
                .iter()
                .copied()
                .filter(|&e| e != keeper && (entries[keeper].moved || entries[e].moved))
                .filter_map(|e| entries[e].prefix.last().copied())
                .collect();
            if !copy.is_empty() {
                needs.push((rep, copy));
            }
        }
        // The first whose entries pass through no other representation that needs
        // copies: its entries then end in distinct links (an ancestor placed twice is
        // copied first, and its copy brings its own links).
        let needy: HashSet<u64> = needs.iter().map(|(r, _)| *r).collect();
        let ready = needs.into_iter().find(|(rep, _)| {
            by_rep[rep].iter().all(|&e| {
                let p = &entries[e].prefix;
                let above = p.len().saturating_sub(1);
                p[..above].iter().all(|l| !needy.contains(&l.rep.0))
                    && (p.is_empty() || !needy.contains(&entries[e].root))
            })
        });
        let links = ready.map(|(_, links)| links);
        Ok((occs, links))
    }

    /// Redirects `link` (a relationship or a `MAPPED_ITEM`) to a fresh copy of the
    /// representation it leads to.
    fn copy_for(&mut self, link: Link, g: &Graph) -> Result<()> {
        let via = self.index.get(link.via.0).ok_or(Error::NoSuchInstance(link.via))?;
        let rep = link.rep.0;
        if !self.instances[via].complex && self.name_of(via) == "MAPPED_ITEM" {
            let (copy, _) = self.copy_tree(rep, false, g)?;
            let refs = self.refs_of(via)?;
            let map = *refs.first().ok_or_else(|| self.edit_error(via, "a MAPPED_ITEM without its map"))?;
            let mk = self.at(map)?;
            let new_map = self.fresh()?;
            let text = self.retarget(mk, new_map, &HashMap::from([(rep, format!("#{copy}"))]))?;
            self.put(new_map, text, false)?;
            let text = self.retarget(via, link.via.0, &HashMap::from([(map, format!("#{new_map}"))]))?;
            self.replace_instance_text(link.via, text)?;
            return Ok(());
        }
        let (copy, product) = self.copy_tree(rep, true, g)?;
        let text = self.retarget(via, link.via.0, &HashMap::from([(rep, format!("#{copy}"))]))?;
        self.replace_instance_text(link.via, text)?;
        if let (Some(&cdsr), Some((pd, new_pd))) = (g.cdsr_of_link.get(&link.via.0), product) {
            let nauo = self.usage_of(cdsr)?.1;
            let k = self.at(nauo)?;
            let text = self.retarget(k, nauo, &HashMap::from([(pd, format!("#{new_pd}"))]))?;
            self.replace_instance_text(EntityId(nauo), text)?;
        }
        Ok(())
    }

    /// Copies representation `rep` with everything its items reach (contexts, units and
    /// its own placement axes kept shared), its relationship children in turn, and with
    /// `product` its product definition. Returns the copy and `(old, new)` product
    /// definitions when one was copied.
    fn copy_tree(&mut self, rep: u64, product: bool, g: &Graph) -> Result<(u64, Option<(u64, u64)>)> {
        let rk = self.at(rep)?;
        // Everything the items reach, in file order.
        let mut seen: BTreeSet<usize> = BTreeSet::new();
        let mut work = Vec::new();
        for r in self.refs_of(rk)? {
            let k = self.at(r)?;
            if g.shared.contains(&r) || self.name_of(k).starts_with("AXIS2_PLACEMENT") {
                continue;
            }
            if seen.insert(k) {
                work.push(k);
            }
        }
        while let Some(k) = work.pop() {
            for r in self.refs_of(k)? {
                let j = self.at(r)?;
                if !g.shared.contains(&r) && seen.insert(j) {
                    work.push(j);
                }
            }
        }
        let mut map: HashMap<u64, String> = HashMap::with_capacity(seen.len() + 1);
        let mut plan = Vec::with_capacity(seen.len());
        for &k in &seen {
            let id = self.fresh()?;
            map.insert(self.instances[k].id, format!("#{id}"));
            plan.push((k, id));
        }
        let new_rep = self.fresh()?;
        map.insert(rep, format!("#{new_rep}"));
        for (k, id) in plan {
            let text = self.retarget(k, id, &map)?;
            self.put(id, text, false)?;
        }
        let text = self.retarget(rk, new_rep, &map)?;
        self.put(new_rep, text, false)?;
        // The part's product definition, so an assembly occurrence can name the copy.
        let mut pd_pair = None;
        if let (true, Some(&sdr)) = (product, g.sdr_of_rep.get(&rep)) {
            let sk = self.at(sdr)?;
            let pds = *self.refs_of(sk)?.first().ok_or_else(|| self.edit_error(sk, "a definition"))?;
            let pk = self.at(pds)?;
            let pd = *self.refs_of(pk)?.last().ok_or_else(|| self.edit_error(pk, "a product definition"))?;
            let dk = self.at(pd)?;
            let (new_pd, new_pds, new_sdr) = (self.fresh()?, self.fresh()?, self.fresh()?);
            let text = self.retarget(dk, new_pd, &HashMap::new())?;
            self.put(new_pd, text, false)?;
            let text = self.retarget(pk, new_pds, &HashMap::from([(pd, format!("#{new_pd}"))]))?;
            self.put(new_pds, text, false)?;
            let text = self.retarget(
                sk,
                new_sdr,
                &HashMap::from([(pds, format!("#{new_pds}")), (rep, format!("#{new_rep}"))]),
            )?;
            self.put(new_sdr, text, true)?;
            pd_pair = Some((pd, new_pd));
        }
        // Sub-assemblies: each child copied with its relationship and occurrence.
        for &(child, link) in g.children.get(&rep).map_or(&[][..], Vec::as_slice) {
            let (new_child, child_pd) = self.copy_tree(child, true, g)?;
            let lk = self.at(link)?;
            let new_link = self.fresh()?;
            let relink = HashMap::from([(rep, format!("#{new_rep}")), (child, format!("#{new_child}"))]);
            let text = self.retarget(lk, new_link, &relink)?;
            let cdsr = g.cdsr_of_link.get(&link).copied();
            self.put(new_link, text, cdsr.is_none())?;
            let Some(cdsr) = cdsr else { continue };
            let (pds, nauo) = self.usage_of(cdsr)?;
            let mut pds_map = HashMap::new();
            if let Some((a, b)) = pd_pair {
                pds_map.insert(a, format!("#{b}"));
            }
            if let Some((a, b)) = child_pd {
                pds_map.insert(a, format!("#{b}"));
            }
            let (new_nauo, new_pds, new_cdsr) = (self.fresh()?, self.fresh()?, self.fresh()?);
            let text = self.retarget(self.at(nauo)?, new_nauo, &pds_map)?;
            self.put(new_nauo, text, false)?;
            let text = self.retarget(self.at(pds)?, new_pds, &HashMap::from([(nauo, format!("#{new_nauo}"))]))?;
            self.put(new_pds, text, false)?;
            let text = self.retarget(
                self.at(cdsr)?,
                new_cdsr,
                &HashMap::from([(link, format!("#{new_link}")), (pds, format!("#{new_pds}"))]),
            )?;
            self.put(new_cdsr, text, true)?;
        }
        // Colours and other styles of the copied items, listed beside the originals.
        // Plain styled items first: an over-riding one names the style it overrides,
        // which its copy must name in the copy.
        let mut styled: Vec<u64> =
            seen.iter().flat_map(|&k| g.styled.get(&self.instances[k].id).into_iter().flatten().copied()).collect();
        styled.sort_by_key(|&si| self.index.get(si).is_some_and(|k| self.name_of(k) != "STYLED_ITEM"));
        let mut appends: HashMap<u64, HashMap<u64, String>> = HashMap::new();
        for si in styled {
            let new_si = self.fresh()?;
            let text = self.retarget(self.at(si)?, new_si, &map)?;
            map.insert(si, format!("#{new_si}"));
            self.put(new_si, text, true)?;
            for &list in g.lists.get(&si).map_or(&[][..], Vec::as_slice) {
                appends.entry(list).or_default().insert(si, format!("#{si},#{new_si}"));
            }
        }
        // One rewrite per presentation list, however many styles it gains.
        let mut lists: Vec<_> = appends.into_iter().collect();
        lists.sort_unstable_by_key(|(l, _)| *l);
        for (list, add) in lists {
            let text = self.retarget(self.at(list)?, list, &add)?;
            self.replace_instance_text(EntityId(list), text)?;
        }
        Ok((new_rep, pd_pair))
    }

    /// The `PRODUCT_DEFINITION_SHAPE` of a `CONTEXT_DEPENDENT_SHAPE_REPRESENTATION` and
    /// the occurrence (`NEXT_ASSEMBLY_USAGE_OCCURRENCE`) it defines.
    fn usage_of(&self, cdsr: u64) -> Result<(u64, u64)> {
        let ck = self.at(cdsr)?;
        let pds = *self.refs_of(ck)?.get(1).ok_or_else(|| self.edit_error(ck, "a product definition shape"))?;
        let pk = self.at(pds)?;
        let nauo = *self.refs_of(pk)?.last().ok_or_else(|| self.edit_error(pk, "an assembly usage occurrence"))?;
        Ok((pds, nauo))
    }

    fn at(&self, id: u64) -> Result<usize> {
        self.index.get(id).ok_or(Error::NoSuchInstance(EntityId(id)))
    }

    fn refs_of(&self, k: usize) -> Result<Vec<u64>> {
        Ok(scan_instance(self.text(k))?.1)
    }

    fn edit_error(&self, k: usize, expected: &str) -> Error {
        Error::Edit { at: self.position_of(k, 0), reason: format!("expected {expected} among its references") }
    }

    /// A fresh id above the highest in use.
    fn fresh(&mut self) -> Result<u64> {
        self.max_id = self.max_id.checked_add(1).ok_or(Error::Limit {
            at: Position { line: 0, column: 0, id: None },
            what: "no id left above the highest one",
        })?;
        Ok(self.max_id)
    }

    /// Adds instance text `text` (of id `id`, from [`fresh`](Self::fresh)); its
    /// references are checked when the copy is complete, by the caller's edits.
    fn put(&mut self, id: u64, text: String, pinned: bool) -> Result<()> {
        let (inst, _) = scan_instance(text.as_bytes())?;
        let k = self.instances.len();
        self.instances.push(inst);
        self.index.insert(id, k);
        self.texts.insert(k, text);
        if pinned {
            self.pinned.insert(k);
        }
        self.pristine.insert(k);
        self.views_changed();
        Ok(())
    }

    /// Instance `k`'s text renamed `#id`, every reference in `map` replaced by its text.
    fn retarget(&self, k: usize, id: u64, map: &HashMap<u64, String>) -> Result<String> {
        let text = self.text(k);
        let (_, refs) = scan_instance_at(text)?;
        let digits = |from: usize| text[from..].iter().take_while(|c| c.is_ascii_digit()).count();
        let name_end = text.iter().position(|&c| c == b'#').map_or(0, |p| p + 1 + digits(p + 1));
        let mut out = format!("#{id}").into_bytes();
        let mut cursor = name_end;
        for (r, off) in refs {
            if let Some(with) = map.get(&r) {
                out.extend_from_slice(&text[cursor..off]);
                out.extend_from_slice(with.as_bytes());
                cursor = off + 1 + digits(off + 1);
            }
        }
        out.extend_from_slice(&text[cursor..]);
        Ok(String::from_utf8_lossy(&out).into_owned())
    }
}

impl Graph {
    /// The indexes of `doc`, whose placement walk is `occs`.
    fn of(doc: &Document, occs: &[Occurrence]) -> Result<Self> {
        let mut g = Graph {
            sdr_of_rep: HashMap::new(),
            cdsr_of_link: HashMap::new(),
            children: HashMap::new(),
            styled: HashMap::new(),
            lists: HashMap::new(),
            shared: HashSet::new(),
        };
        let mut work = Vec::new();
        let mut presentation = Vec::new();
        for k in 0..doc.instances.len() {
            let name = doc.name_of(k);
            let id = doc.instances[k].id;
            if name.ends_with("_CONTEXT") {
                if g.shared.insert(id) {
                    work.push(k);
                }
                continue;
            }
            if doc.instances[k].complex {
                continue;
            }
            match name {
                "SHAPE_DEFINITION_REPRESENTATION" => {
                    if let Some(&rep) = doc.refs_of(k)?.get(1) {
                        g.sdr_of_rep.entry(rep).or_insert(id);
                    }
                }
                "CONTEXT_DEPENDENT_SHAPE_REPRESENTATION" => {
                    if let Some(&link) = doc.refs_of(k)?.first() {
                        g.cdsr_of_link.entry(link).or_insert(id);
                    }
                }
                // ISO 10303-46 §4.4.1 styled_item(name, styles, item); over_riding_styled_item
                // adds over_ridden_style after the item.
                "STYLED_ITEM" | "OVER_RIDING_STYLED_ITEM" => {
                    let refs = doc.refs_of(k)?;
                    let back = if name == "STYLED_ITEM" { 1 } else { 2 };
                    if let Some(&item) = refs.len().checked_sub(back).and_then(|i| refs.get(i)) {
                        g.styled.entry(item).or_default().push(id);
                    }
                }
                _ if name.ends_with("PRESENTATION_REPRESENTATION") || name == "DRAUGHTING_MODEL" => {
                    presentation.push(k);
                }
                _ => {}
            }
        }
        while let Some(k) = work.pop() {
            for r in doc.refs_of(k)? {
                if let Some(j) = doc.index.get(r) {
                    if g.shared.insert(r) {
                        work.push(j);
                    }
                }
            }
        }
        for k in presentation {
            for r in doc.refs_of(k)? {
                g.lists.entry(r).or_default().push(doc.instances[k].id);
            }
        }
        // Relationship children as the placement walk takes them.
        let mut have: HashSet<(u64, u64)> = HashSet::new();
        for occ in occs {
            let mut parent = occ.root.0;
            for l in &occ.path {
                let k = doc.at(l.via.0)?;
                let mapped = !doc.instances[k].complex && doc.name_of(k) == "MAPPED_ITEM";
                if !mapped && have.insert((l.via.0, l.rep.0)) {
                    g.children.entry(parent).or_default().push((l.rep.0, l.via.0));
                }
                parent = l.rep.0;
            }
        }
        Ok(g)
    }
}
