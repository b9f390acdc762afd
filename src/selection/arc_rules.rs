//! The arc rules: which pair arcs of the paper's network are fixed (kept whatever the flow
//! selects) or removed before the flow runs, besides the costs. Four sources, applied in this
//! order: the model check's evidence (`--model`: the pairs that glued a ghosted model's copies
//! are removed, and the pairs that link clean models placed in one frame are kept, whatever an
//! earlier model blamed; see [`crate::check::repair::loop_evidence`]), the user's overrides
//! (`--forbid_images`, `--forbid_pairs`, which win over the models', then `--keep_pairs`),
//! close neighbours in a capture sequence (`--keep_neighbours`), and the fitness floor
//! (`--min_pair_fitness`, lowered as far as the search needs). The pairs the view graph does
//! not corroborate (`--min_backbone_tracks`) are no arc rule: the flow may select them, the
//! track completion's forests do not add them.
//!
//! Rules change the network ([`crate::flow::network::SelectionProblem::restrict`]), never
//! the costs, so the result stays an exact min-cost flow and is easy to explain:
//! - a forbidden image leaves the network with all its pairs; the search criteria count only the
//!   images that remain;
//! - a forbidden pair's arc, or one below the floor, leaves the network;
//! - a kept pair's arc leaves the network too, and the pair (with both its images) is added to
//!   whatever the flow selects. The flow optimises the rest of the graph: the criteria and the
//!   selection curve describe the flow's part, before the kept pairs are added.
//!
//! Files hold one entry per line (`name1 name2` for pairs, as `colmap matches_importer
//! --match_type pairs` reads them; one image name per line for images); blank lines and lines
//! starting with `#` are skipped.

use crate::check::resection::PairMatches;
use crate::check::CheckSettings;
use crate::colmap::database::Image;
use crate::flow::network::ArcRule;
use crate::flow::search::FlowRule;
use crate::scene::view_graph::ViewGraph;
use crate::selection::capture_order::CaptureOrder;
use anyhow::{bail, Context, Result};
use serde::Serialize;
use std::collections::{BTreeMap, BTreeSet, HashMap};
use std::path::{Path, PathBuf};

/// The arc rules a prune was asked for (part of [`crate::selection::parameters::Parameters`]).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ArcRules {
    /// Pairs of images at most this many positions apart in the order are kept whatever the
    /// flow selects (0: none).
    pub keep_neighbours: u32,
    /// `--keep_pairs`: the file of pairs always kept.
    pub keep_pairs: Option<PathBuf>,
    /// `--forbid_pairs`: the file of pairs never selected.
    pub forbid_pairs: Option<PathBuf>,
    /// `--forbid_images`: the file of images never selected.
    pub forbid_images: Option<PathBuf>,
    /// `--model`: mappers' outputs on this database; the pairs the check blames in any of them
    /// (that glued a ghost, or that a wrong model refused) are never selected, and the pairs
    /// that link clean models are kept.
    pub model: Vec<PathBuf>,
    /// `--earlier_model`: the repair loop's earlier mapper outputs whose blame is not taken
    /// (the full database's, where its ghost is not `model`'s evidence): their ghosts refute
    /// what `model`'s check would place where they had it, and find them again in a model.
    pub earlier_model: Vec<PathBuf>,
    /// How the check judges `model`'s folders (`prune`'s check options).
    pub check: CheckSettings,
}

/// One list file as read: each entry with its 1-based line number.
#[derive(Clone, Debug)]
pub struct NameList {
    /// The file read, for error messages and the run record.
    pub path: PathBuf,
    /// (line number, names): two names per pair-list entry, one per image-list entry.
    pub entries: Vec<(usize, Vec<String>)>,
}

impl NameList {
    /// Reads a pair list (`pairs = true`: two whitespace-separated names a line) or an image list
    /// (the whole trimmed line is the name, so names may contain spaces).
    pub fn read(path: &Path, pairs: bool) -> Result<NameList> {
        let text = std::fs::read_to_string(path)
            .with_context(|| format!("cannot read {}", path.display()))?;
        let mut entries = Vec::new();
        for (k, line) in text.lines().enumerate() {
            let line = line.trim();
            if line.is_empty() || line.starts_with('#') {
                continue;
            }
            let names: Vec<String> = if pairs {
                line.split_whitespace().map(str::to_string).collect()
            } else {
                vec![line.to_string()]
            };
            if names.len() != if pairs { 2 } else { 1 } {
                bail!(
                    "{} line {}: expected two image names `name1 name2`, found {}",
                    path.display(),
                    k + 1,
                    names.len()
                );
            }
            entries.push((k + 1, names));
        }
        Ok(NameList {
            path: path.to_path_buf(),
            entries,
        })
    }
}

/// The override files given on the command line (each optional).
#[derive(Clone, Debug, Default)]
pub struct Overrides {
    /// `--keep_pairs`: pairs added to the selection whatever the flow does.
    pub keep_pairs: Option<NameList>,
    /// `--forbid_pairs`: pairs never selected.
    pub forbid_pairs: Option<NameList>,
    /// `--forbid_images`: images taken out of the network with all their pairs.
    pub forbid_images: Option<NameList>,
    /// `--model`: what the model check says of each folder, in the order given.
    pub model: Vec<ModelFolder>,
}

/// What the model check says of one `--model` folder: two pair lists whose path is the folder.
#[derive(Clone, Debug)]
pub struct ModelFolder {
    /// The pairs that glued its ghosted models: never selected.
    pub blamed: NameList,
    /// The pairs that link its clean models: kept.
    pub links: NameList,
    /// The matches that held its misplaced images where the mapper put them: dropped from
    /// the pairs kept.
    pub dropped: Vec<PairMatches>,
    /// The pairs that place an image no model registered: kept unless a folder blamed them.
    pub rejoin: NameList,
}

/// The overrides as listed in the report, by image name.
#[derive(Clone, Debug, Default, Serialize)]
pub struct Listed {
    /// Kept pairs, names as given in the file.
    pub keep_pairs: Vec<[String; 2]>,
    /// Forbidden pairs, names as given in the file (view-graph edges or not).
    pub forbid_pairs: Vec<[String; 2]>,
    /// Forbidden pairs that are no view-graph edge: never selected anyway.
    pub forbid_pairs_not_in_view_graph: usize,
    /// Forbidden image names, as given (isolated images included).
    pub forbid_images: Vec<String>,
    /// Pairs taken out of the network because one of their images is forbidden.
    pub pairs_of_forbidden_images: usize,
    /// Pairs the model check blamed (`--model`), never selected; absent without `--model`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub model_conflicts: Option<Vec<[String; 2]>>,
    /// Pairs that link clean models (`--model`), kept unless the user forbade them; absent
    /// without `--model`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub model_links: Option<Vec<[String; 2]>>,
    /// Pairs that place an image no model registered (`--model`), kept unless a folder blamed
    /// them or the user forbade them; absent without `--model`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub model_rejoins: Option<Vec<[String; 2]>>,
}

/// Overrides resolved against a view graph.
#[derive(Clone, Debug)]
pub struct Resolved {
    /// Indexed like `ViewGraph::edges`.
    pub edges: Vec<ArcRule>,
    /// Indexed like `ViewGraph::image_ids`.
    pub forbidden_vertices: Vec<bool>,
    /// What was resolved, by name, for the report.
    pub listed: Listed,
    /// Per edge, the matches `--model` drops from the pair if it is kept, as the pair's
    /// inliers hold them (keypoint of its first image_id first).
    pub dropped: BTreeMap<usize, BTreeSet<[u32; 2]>>,
}

impl Overrides {
    /// Checks every name against `images` and every kept pair against `graph`. Errors name the
    /// file and line: an unknown image, a kept pair that is no view-graph edge (fewer than
    /// `min_num_matches` inliers, or never verified), a kept pair also forbidden.
    pub fn resolve(
        &self,
        images: &[Image],
        graph: &ViewGraph,
        min_num_matches: usize,
    ) -> Result<Resolved> {
        let names = Names::new(images, graph);
        let mut resolved = Resolved {
            edges: vec![ArcRule::Free; graph.edges.len()],
            forbidden_vertices: vec![false; graph.num_vertices()],
            listed: Listed::default(),
            dropped: BTreeMap::new(),
        };
        if !self.model.is_empty() {
            resolved.apply_model_evidence(&self.model, &names)?;
        }
        if let Some(list) = &self.forbid_images {
            resolved.forbid_images(list, &names, graph)?;
        }
        if let Some(list) = &self.forbid_pairs {
            resolved.forbid_pairs(list, &names)?;
        }
        if let Some(list) = &self.keep_pairs {
            resolved.keep_pairs(list, &names, min_num_matches)?;
        }
        Ok(resolved)
    }
}

/// Image names and pairs of names looked up in the view graph, for the override files.
struct Names<'a> {
    ids: HashMap<&'a str, u32>,
    graph: &'a ViewGraph,
    edge_index: HashMap<(usize, usize), usize>,
}

impl<'a> Names<'a> {
    fn new(images: &'a [Image], graph: &'a ViewGraph) -> Names<'a> {
        Names {
            ids: images
                .iter()
                .map(|im| (im.name.as_str(), im.image_id))
                .collect(),
            graph,
            edge_index: graph
                .edges
                .iter()
                .enumerate()
                .map(|(k, e)| ((e.i as usize, e.j as usize), k))
                .collect(),
        }
    }

    /// The view-graph vertex of an image_id, if it has one.
    fn vertex(&self, id: u32) -> Option<usize> {
        self.graph.image_ids.binary_search(&id).ok()
    }

    /// The image_id of the image named on `line` of `list`.
    fn image(&self, list: &NameList, line: usize, name: &str) -> Result<u32> {
        self.ids.get(name).copied().with_context(|| {
            format!(
                "{} line {line}: no image named `{name}` in the database",
                list.path.display()
            )
        })
    }

    /// The edge of a pair entry, or None when it is no view-graph edge.
    fn edge(&self, list: &NameList, line: usize, names: &[String]) -> Result<Option<usize>> {
        let a = self.image(list, line, &names[0])?;
        let b = self.image(list, line, &names[1])?;
        if a == b {
            bail!(
                "{} line {line}: `{}` is paired with itself",
                list.path.display(),
                names[0]
            );
        }
        Ok(self.edge_between(a, b))
    }

    /// The edge between images `a` and `b` (image_ids), or None when it is no view-graph edge.
    fn edge_between(&self, a: u32, b: u32) -> Option<usize> {
        match (self.vertex(a), self.vertex(b)) {
            (Some(x), Some(y)) => self.edge_index.get(&(x.min(y), x.max(y))).copied(),
            _ => None,
        }
    }
}

impl Resolved {
    /// `--forbid_images`: the images and every pair of theirs leave the network.
    fn forbid_images(&mut self, list: &NameList, names: &Names, graph: &ViewGraph) -> Result<()> {
        for (line, entry) in &list.entries {
            if let Some(v) = names.vertex(names.image(list, *line, &entry[0])?) {
                self.forbidden_vertices[v] = true;
            }
            self.listed.forbid_images.push(entry[0].clone());
        }
        for (k, e) in graph.edges.iter().enumerate() {
            if self.forbidden_vertices[e.i as usize] || self.forbidden_vertices[e.j as usize] {
                self.edges[k] = ArcRule::Removed;
                self.listed.pairs_of_forbidden_images += 1;
            }
        }
        Ok(())
    }

    /// `--forbid_pairs`: the pairs' arcs leave the network.
    fn forbid_pairs(&mut self, list: &NameList, names: &Names) -> Result<()> {
        for (line, entry) in &list.entries {
            match names.edge(list, *line, entry)? {
                Some(k) => self.edges[k] = ArcRule::Removed,
                None => self.listed.forbid_pairs_not_in_view_graph += 1,
            }
            self.listed
                .forbid_pairs
                .push([entry[0].clone(), entry[1].clone()]);
        }
        Ok(())
    }

    /// `--model`, folder by folder in the order given: the pairs a folder's ghosted models
    /// blame leave the network and the pairs that link its clean models are fixed (those that
    /// are edges), over what earlier folders said. A ghost's blame falls on every pair across
    /// its split, true links included, and a later placement without conflict tells them
    /// apart; a later ghost blames links that glued it again. Each pair listed once.
    fn apply_model_evidence(&mut self, folders: &[ModelFolder], names: &Names) -> Result<()> {
        let mut listed = [(Vec::new(), BTreeSet::new()), (Vec::new(), BTreeSet::new())];
        for folder in folders {
            for (list, rule, slot) in [
                (&folder.blamed, ArcRule::Removed, 0),
                (&folder.links, ArcRule::Fixed, 1),
            ] {
                let (out, seen) = &mut listed[slot];
                for (line, entry) in &list.entries {
                    if let Some(k) = names.edge(list, *line, entry)? {
                        self.edges[k] = rule;
                    }
                    let pair = [entry[0].clone(), entry[1].clone()];
                    if seen.insert(pair.clone()) {
                        out.push(pair);
                    }
                }
            }
        }
        let [(blamed, _), (linked, _)] = listed;
        self.listed.model_conflicts = Some(blamed);
        self.listed.model_links = Some(linked);
        // An image the mapper lost is placed from its matches, which may be a ghost's: its
        // pairs are kept only where no run blamed them, and never over a link's decision.
        let mut rejoins = BTreeSet::new();
        for folder in folders {
            let list = &folder.rejoin;
            for (line, entry) in &list.entries {
                match names.edge(list, *line, entry)? {
                    Some(k) if self.edges[k] == ArcRule::Free => self.edges[k] = ArcRule::Fixed,
                    _ => continue,
                }
                rejoins.insert([entry[0].clone(), entry[1].clone()]);
            }
        }
        self.listed.model_rejoins = Some(rejoins.into_iter().collect());
        for (folder, pair) in folders
            .iter()
            .flat_map(|f| f.dropped.iter().map(move |p| (f, p)))
        {
            let id = |name: &str| {
                let id = names.ids.get(name).copied();
                id.with_context(|| {
                    format!(
                        "--model {}: no image named `{name}` in the database",
                        folder.links.path.display()
                    )
                })
            };
            let (a, b) = (id(&pair.images[0])?, id(&pair.images[1])?);
            if let Some(k) = names.edge_between(a, b) {
                let oriented = pair
                    .matches
                    .iter()
                    .map(|&[x, y]| if a < b { [x, y] } else { [y, x] });
                self.dropped.entry(k).or_default().extend(oriented);
            }
        }
        Ok(())
    }

    /// `--keep_pairs`: the pairs are fixed; each must be an edge and not forbidden.
    fn keep_pairs(&mut self, list: &NameList, names: &Names, min_num_matches: usize) -> Result<()> {
        for (line, entry) in &list.entries {
            let where_ = format!("{} line {line}", list.path.display());
            let Some(k) = names.edge(list, *line, entry)? else {
                bail!(
                    "{where_}: `{}` `{}` is not a verified pair with at least {min_num_matches} inliers, so it cannot be kept",
                    entry[0], entry[1]
                );
            };
            if self.edges[k] == ArcRule::Removed {
                bail!(
                    "{where_}: `{}` `{}` is kept but also forbidden (as a pair or by one of its images)",
                    entry[0], entry[1]
                );
            }
            self.edges[k] = ArcRule::Fixed;
            self.listed
                .keep_pairs
                .push([entry[0].clone(), entry[1].clone()]);
        }
        Ok(())
    }
}

/// Fixes every free edge whose images are at most `window` positions apart in `order`, so the
/// pair is kept whatever the flow selects; forbidden pairs stay forbidden. Returns how many.
/// Why: in a capture known to be a sequence, close neighbours see the same things, so their
/// verified pairs are true, and keeping them all gives a walk between look-alike objects the
/// redundancy a mapper needs to cross it in one piece (docs/cli.md).
pub fn keep_neighbours(
    rules: &mut [ArcRule],
    graph: &ViewGraph,
    order: &CaptureOrder,
    window: u32,
) -> usize {
    if window == 0 {
        return 0;
    }
    let mut kept = 0;
    for (rule, e) in rules.iter_mut().zip(&graph.edges) {
        if *rule == ArcRule::Free && order.within(e.i, e.j, window) {
            *rule = ArcRule::Fixed;
            kept += 1;
        }
    }
    kept
}

/// Removes every free edge whose value (a fitness, −cost) is below `min`. Returns how many.
pub fn remove_below(
    rules: &mut [ArcRule],
    values: impl IntoIterator<Item = f64>,
    min: f64,
) -> usize {
    let mut removed = 0;
    for (rule, value) in rules.iter_mut().zip(values) {
        if *rule == ArcRule::Free && value < min {
            *rule = ArcRule::Removed;
            removed += 1;
        }
    }
    removed
}

/// The cost model's `min_pair_fitness` (`floor`), lowered where needed so that the image
/// criterion's share of images keep a pair above it, and at least half as many pairs as the
/// pair criterion asks for reach it, counting only the pairs the flow may use (`rules`: not
/// those removed, forbidden or blamed by `--model`). On scenes where the priors score every
/// pair low (real photos where few triangles close within the loop tolerance) a fixed floor
/// left the flow too few pairs for `colmap mapper` to start a model (docs/priors.md); so did a
/// floor that counted the pairs a ghosted model blamed, where they were most of those above it
/// (the twin design, docs/check.md). It falls to 0 only under `zero`'s rule. With a fixed
/// flow it is applied as given.
pub fn fitness_floor(
    floor: f64,
    rule: &FlowRule,
    graph: &ViewGraph,
    rules: &[ArcRule],
    pair_costs: &[f64],
    zero: ZeroFitness,
) -> f64 {
    let FlowRule::Criteria(criteria) = rule else {
        return floor;
    };
    let n = graph.num_vertices();
    if floor <= 0.0 || n == 0 {
        return floor;
    }
    // The k-th largest of some values (k >= 1, at most their count); without any (every
    // image forbidden) nothing lowers the floor.
    let kth = |mut values: Vec<f64>, k: usize| {
        if values.is_empty() {
            return f64::INFINITY;
        }
        let k = k.clamp(1, values.len());
        *values
            .select_nth_unstable_by(k - 1, |a, b| b.total_cmp(a))
            .1
    };
    // The edges the flow may use, with their fitness (−cost).
    let usable = || {
        (graph.edges.iter().zip(rules).zip(pair_costs))
            .filter(|((_, rule), _)| **rule != ArcRule::Removed)
            .map(|((e, _), cost)| (e, -cost))
    };
    // Each image's best pair fitness: the wanted-th best image sets the highest usable floor.
    let mut best = vec![0.0f64; n];
    for (e, fitness) in usable() {
        for v in [e.i as usize, e.j as usize] {
            best[v] = best[v].max(fitness);
        }
    }
    let images = (criteria.min_image_fraction * n as f64).ceil() as usize;
    let pairs = (criteria.min_pairs_per_image * n as f64 / 2.0).ceil() as usize;
    let fitness = usable().map(|(_, fitness)| fitness);
    let lowest_scored = fitness.clone().filter(|&f| f > 0.0).reduce(f64::min);
    let lowered = floor
        .min(kth(best, images))
        .min(kth(fitness.collect(), pairs));
    match (zero, lowest_scored) {
        (ZeroFitness::Out, Some(lowest)) if lowered <= 0.0 => lowest,
        _ => lowered,
    }
}

/// Whether a lowered [`fitness_floor`] may let in the pairs the priors score 0.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ZeroFitness {
    /// Never: a pair scored 0 has nothing for it, and where such pairs are most of the graph
    /// (`disambiguation-global`'s geometric mean on a twin matching: 151 of 237 pairs, 54 of
    /// them false) letting them in left a search that could not meet its pair target, which
    /// then kept every pair. A plain prune; where no pair scores above 0 the floor is 0 anyway.
    Out,
    /// Yes: with `--model` the check has taken out the pairs that glued a mapper run's copies,
    /// and the pairs it left are what the next turn rebuilds from (the twin's turn from its
    /// full model: every one of the 151 left, 17 of 18 cameras right, the bound; only the 75
    /// scored above 0: 14 of 15).
    In,
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::colmap::database::VerifiedPair;
    use crate::flow::search::Criteria;
    use crate::scene::testing::{images, pair};

    /// Four images whose neighbours are verified pairs (edges 1-2, 2-3, 3-4).
    fn four_in_a_row() -> (Vec<Image>, ViewGraph) {
        let images = images(4);
        let pairs: Vec<VerifiedPair> = (1..4).map(|a| pair(a, a + 1, vec![[0, 0]; 20])).collect();
        let graph = ViewGraph::build(&images, &pairs, 15);
        (images, graph)
    }

    /// A pair list read from `path`, one entry a line.
    fn list(path: &str, entries: Vec<Vec<String>>) -> NameList {
        NameList {
            path: PathBuf::from(path),
            entries: entries
                .into_iter()
                .enumerate()
                .map(|(k, e)| (k + 1, e))
                .collect(),
        }
    }

    /// A `--model` folder's blamed pairs and links.
    fn folder(path: &str, blamed: Vec<Vec<String>>, links: Vec<Vec<String>>) -> ModelFolder {
        ModelFolder {
            blamed: list(path, blamed),
            links: list(path, links),
            dropped: Vec::new(),
            rejoin: list(path, Vec::new()),
        }
    }

    /// The matches folders drop are resolved per edge, turned to the pair's stored order (the
    /// first image_id's keypoint first) and merged; a pair that is no edge drops nothing; an
    /// unknown image is an error naming the folder.
    #[test]
    fn matches_the_model_check_drops_are_resolved_per_edge_in_the_pairs_order() {
        let (images, graph) = four_in_a_row();
        let name = |id: u32| images[id as usize - 1].name.clone();
        let drop = |a: u32, b: u32, matches: Vec<[u32; 2]>| PairMatches {
            images: [name(a), name(b)],
            matches,
        };
        let mut first = folder("sparse", vec![], vec![]);
        first.dropped = vec![drop(3, 2, vec![[7, 1]]), drop(1, 4, vec![[1, 1]])];
        let mut second = folder("sparse2", vec![], vec![]);
        second.dropped = vec![drop(2, 3, vec![[2, 8], [1, 7]])];
        let overrides = Overrides {
            model: vec![first, second],
            ..Overrides::default()
        };
        let resolved = overrides.resolve(&images, &graph, 15).unwrap();
        let want: BTreeMap<usize, BTreeSet<[u32; 2]>> =
            [(1, [[1, 7], [2, 8]].into_iter().collect())].into();
        assert_eq!(resolved.dropped, want);
        assert_eq!(resolved.edges, [ArcRule::Free; 3]);
        let mut unknown = folder("sparse3", vec![], vec![]);
        unknown.dropped = vec![PairMatches {
            images: ["nope.png".into(), name(1)],
            matches: vec![[0, 0]],
        }];
        let overrides = Overrides {
            model: vec![unknown],
            ..Overrides::default()
        };
        let e = overrides.resolve(&images, &graph, 15).unwrap_err();
        assert_eq!(
            e.to_string(),
            "--model sparse3: no image named `nope.png` in the database"
        );
    }

    /// The model check's pairs leave the network like forbidden pairs, and are listed once
    /// each whichever folders blamed them; a blamed pair that is no view-graph edge is listed and
    /// changes nothing.
    #[test]
    fn pairs_the_model_check_blames_are_never_selected() {
        let (images, graph) = four_in_a_row();
        let name = |id: u32| images[id as usize - 1].name.clone();
        let overrides = Overrides {
            model: vec![
                folder(
                    "sparse",
                    vec![vec![name(2), name(3)], vec![name(1), name(4)]],
                    vec![],
                ),
                folder(
                    "sparse2",
                    vec![vec![name(1), name(4)], vec![name(3), name(4)]],
                    vec![],
                ),
            ],
            ..Overrides::default()
        };
        let resolved = overrides.resolve(&images, &graph, 15).unwrap();
        assert_eq!(
            resolved.edges,
            [ArcRule::Free, ArcRule::Removed, ArcRule::Removed]
        );
        let listed = resolved.listed.model_conflicts.unwrap();
        assert_eq!(
            listed,
            [[name(2), name(3)], [name(1), name(4)], [name(3), name(4)]]
        );
        assert!(Overrides::default()
            .resolve(&images, &graph, 15)
            .unwrap()
            .listed
            .model_conflicts
            .is_none());
    }

    /// A pair that links clean models is kept even where an earlier folder blamed it, and is
    /// listed; a later folder's blame, and the user's `--forbid_pairs`, win over it.
    #[test]
    fn pairs_that_link_clean_models_are_kept_unless_the_user_forbids_them() {
        let (images, graph) = four_in_a_row();
        let name = |id: u32| images[id as usize - 1].name.clone();
        let mut overrides = Overrides {
            model: vec![
                folder(
                    "sparse",
                    vec![vec![name(2), name(3)], vec![name(3), name(4)]],
                    vec![],
                ),
                folder("sparse2", vec![], vec![vec![name(3), name(2)]]),
            ],
            ..Overrides::default()
        };
        let resolved = overrides.resolve(&images, &graph, 15).unwrap();
        assert_eq!(
            resolved.edges,
            [ArcRule::Free, ArcRule::Fixed, ArcRule::Removed]
        );
        assert_eq!(resolved.listed.model_links.unwrap(), [[name(3), name(2)]]);
        // A later folder's blame wins over an earlier folder's link.
        let mut later = overrides.clone();
        later
            .model
            .push(folder("sparse3", vec![vec![name(2), name(3)]], vec![]));
        let resolved = later.resolve(&images, &graph, 15).unwrap();
        assert_eq!(resolved.edges[1], ArcRule::Removed);
        overrides.forbid_pairs = Some(list("forbid.txt", vec![vec![name(2), name(3)]]));
        let resolved = overrides.resolve(&images, &graph, 15).unwrap();
        assert_eq!(resolved.edges[1], ArcRule::Removed);
    }

    /// The pairs that place an image the mapper lost are kept where no folder decided them,
    /// whichever folder placed it: a pair any folder blamed stays out (its matches may be a
    /// ghost's), and the user's `--forbid_pairs` wins. Only the pairs kept are listed.
    #[test]
    fn pairs_that_place_a_lost_image_are_kept_unless_a_ghost_blamed_them() {
        let (images, graph) = four_in_a_row();
        let name = |id: u32| images[id as usize - 1].name.clone();
        let mut placed = folder("sparse2", vec![], vec![]);
        placed.rejoin = list(
            "sparse2",
            vec![
                vec![name(1), name(2)],
                vec![name(2), name(3)],
                vec![name(1), name(4)],
            ],
        );
        let mut overrides = Overrides {
            model: vec![
                placed,
                folder("sparse3", vec![vec![name(2), name(3)]], vec![]),
            ],
            ..Overrides::default()
        };
        let resolved = overrides.resolve(&images, &graph, 15).unwrap();
        assert_eq!(
            resolved.edges,
            [ArcRule::Fixed, ArcRule::Removed, ArcRule::Free]
        );
        assert_eq!(resolved.listed.model_rejoins.unwrap(), [[name(1), name(2)]]);
        overrides.forbid_pairs = Some(list("forbid.txt", vec![vec![name(2), name(1)]]));
        let resolved = overrides.resolve(&images, &graph, 15).unwrap();
        assert_eq!(resolved.edges[0], ArcRule::Removed);
    }

    #[test]
    fn the_floor_is_lowered_only_as_far_as_the_criteria_need() {
        // A path 1-2-3-4-5: pair fitnesses 0.9, 0.8, 0.2, 0.1.
        let images = images(5);
        let pairs: Vec<VerifiedPair> = (1..5).map(|a| pair(a, a + 1, vec![[0, 0]; 20])).collect();
        let graph = ViewGraph::build(&images, &pairs, 15);
        let costs = [-0.9, -0.8, -0.2, -0.1];
        let rule = |fraction: f64, per_image: f64, fixed: Option<u64>| match fixed {
            Some(f) => FlowRule::Fixed(f),
            None => FlowRule::Criteria(Criteria {
                min_image_fraction: fraction,
                min_pairs_per_image: per_image,
                min_pair_fraction: 0.0,
                min_pairs_each: 0.0,
            }),
        };
        // The disambiguation preset's floor.
        let preset = 0.6;
        let free = [ArcRule::Free; 4];
        let floor =
            |rule: FlowRule| fitness_floor(preset, &rule, &graph, &free, &costs, ZeroFitness::Out);
        // Best pair per image: 0.9, 0.9, 0.8, 0.2, 0.1. Three images reach the preset's floor
        // (0.6) already, and half of 0.4 pairs per image x 5 images is one pair.
        assert_eq!(floor(rule(0.6, 0.4, None)), preset);
        // Four images need the floor at 0.2, all five at 0.1.
        assert_eq!(floor(rule(0.8, 0.4, None)), 0.2);
        assert_eq!(floor(rule(1.0, 0.4, None)), 0.1);
        // Half of 1.2 pairs per image x 5 images is 3 pairs: the third best is 0.2.
        assert_eq!(floor(rule(0.6, 1.2, None)), 0.2);
        // A fixed flow takes the floor as given.
        assert_eq!(floor(rule(1.0, 1.2, Some(3))), preset);
        // A pair the rules removed (forbidden, or blamed by a model) keeps no image: without
        // 1-2 (0.9), image 1 has no pair, and of the rest three images reach 0.6 no more: 2 and
        // 3 (0.8) only. The third best image is 4 (0.2).
        let blamed = [
            ArcRule::Removed,
            ArcRule::Free,
            ArcRule::Free,
            ArcRule::Free,
        ];
        let floor =
            |zero| fitness_floor(preset, &rule(0.6, 0.4, None), &graph, &blamed, &costs, zero);
        assert_eq!(floor(ZeroFitness::Out), 0.2);
    }

    #[test]
    fn a_plain_prune_never_lowers_the_floor_to_pairs_scored_zero() {
        // A path 1-2-3-4-5: pair fitnesses 0.9, 0, 0, 0.5; every image wanted. Image 3 has only
        // pairs scored 0, so meeting the image criterion would need the floor at 0.
        let images = images(5);
        let pairs: Vec<VerifiedPair> = (1..5).map(|a| pair(a, a + 1, vec![[0, 0]; 20])).collect();
        let graph = ViewGraph::build(&images, &pairs, 15);
        let rule = FlowRule::Criteria(Criteria {
            min_image_fraction: 1.0,
            min_pairs_per_image: 0.0,
            min_pair_fraction: 0.0,
            min_pairs_each: 0.0,
        });
        let free = [ArcRule::Free; 4];
        let floor = |costs: &[f64], zero| fitness_floor(0.6, &rule, &graph, &free, costs, zero);
        let costs = [-0.9, 0.0, 0.0, -0.5];
        // Without model evidence it stops at the lowest pair scored above 0 ...
        assert_eq!(floor(&costs, ZeroFitness::Out), 0.5);
        // ... with it, at 0.
        assert_eq!(floor(&costs, ZeroFitness::In), 0.0);
        // Where no pair scores above 0 nothing ranks them: 0 either way.
        assert_eq!(floor(&[0.0; 4], ZeroFitness::Out), 0.0);
    }
}
