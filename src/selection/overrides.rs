//! User overrides of the selection: pairs always kept (`--keep_pairs`), pairs and images never
//! selected (`--forbid_pairs`, `--forbid_images`).
//!
//! Overrides change the network ([`crate::flow::network::SelectionProblem::restrict`]), never
//! the costs, so the result stays an exact min-cost flow and is easy to explain:
//! - a forbidden image leaves the network with all its pairs; the search criteria count only the
//!   images that remain;
//! - a forbidden pair's arc leaves the network;
//! - a kept pair's arc leaves the network too, and the pair (with both its images) is added to
//!   whatever the flow selects. The flow optimises the rest of the graph: the criteria and the
//!   selection curve describe the flow's part, before the kept pairs are added.
//!
//! Files hold one entry per line (`name1 name2` for pairs, as `colmap matches_importer
//! --match_type pairs` reads them; one image name per line for images); blank lines and lines
//! starting with `#` are skipped.

use crate::colmap::database::Image;
use crate::flow::network::ArcRule;
use crate::scene::view_graph::ViewGraph;
use anyhow::{bail, Context, Result};
use serde::Serialize;
use std::collections::HashMap;
use std::path::{Path, PathBuf};

/// One list file as read: each entry with its 1-based line number.
#[derive(Clone, Debug)]
pub struct NameList {
    pub path: PathBuf,
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
    pub keep_pairs: Option<NameList>,
    pub forbid_pairs: Option<NameList>,
    pub forbid_images: Option<NameList>,
}

/// The overrides as listed in the report, by image name.
#[derive(Clone, Debug, Default, Serialize)]
pub struct Listed {
    pub keep_pairs: Vec<[String; 2]>,
    pub forbid_pairs: Vec<[String; 2]>,
    /// Forbidden pairs that are no view-graph edge: never selected anyway.
    pub forbid_pairs_not_in_view_graph: usize,
    pub forbid_images: Vec<String>,
    /// Pairs taken out of the network because one of their images is forbidden.
    pub pairs_of_forbidden_images: usize,
}

/// Overrides resolved against a view graph.
#[derive(Clone, Debug)]
pub struct Resolved {
    /// Indexed like `ViewGraph::edges`.
    pub edges: Vec<ArcRule>,
    /// Indexed like `ViewGraph::image_ids`.
    pub forbidden_vertices: Vec<bool>,
    pub listed: Listed,
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
        let ids: HashMap<&str, u32> = images
            .iter()
            .map(|im| (im.name.as_str(), im.image_id))
            .collect();
        let vertex = |id: u32| graph.image_ids.binary_search(&id).ok();
        let edge_index: HashMap<(usize, usize), usize> = graph
            .edges
            .iter()
            .enumerate()
            .map(|(k, e)| ((e.i as usize, e.j as usize), k))
            .collect();
        let lookup = |list: &NameList, line: usize, name: &str| -> Result<u32> {
            ids.get(name).copied().with_context(|| {
                format!(
                    "{} line {line}: no image named `{name}` in the database",
                    list.path.display()
                )
            })
        };
        // The edge of a pair entry, or None when it is no view-graph edge.
        let edge_of = |list: &NameList, line: usize, names: &[String]| -> Result<Option<usize>> {
            let a = lookup(list, line, &names[0])?;
            let b = lookup(list, line, &names[1])?;
            if a == b {
                bail!(
                    "{} line {line}: `{}` is paired with itself",
                    list.path.display(),
                    names[0]
                );
            }
            Ok(match (vertex(a), vertex(b)) {
                (Some(x), Some(y)) => edge_index.get(&(x.min(y), x.max(y))).copied(),
                _ => None,
            })
        };

        let mut edges = vec![ArcRule::Free; graph.edges.len()];
        let mut forbidden_vertices = vec![false; graph.num_vertices()];
        let mut listed = Listed::default();
        if let Some(list) = &self.forbid_images {
            for (line, names) in &list.entries {
                if let Some(v) = vertex(lookup(list, *line, &names[0])?) {
                    forbidden_vertices[v] = true;
                }
                listed.forbid_images.push(names[0].clone());
            }
        }
        for (k, e) in graph.edges.iter().enumerate() {
            if forbidden_vertices[e.i as usize] || forbidden_vertices[e.j as usize] {
                edges[k] = ArcRule::Removed;
                listed.pairs_of_forbidden_images += 1;
            }
        }
        if let Some(list) = &self.forbid_pairs {
            for (line, names) in &list.entries {
                match edge_of(list, *line, names)? {
                    Some(k) => edges[k] = ArcRule::Removed,
                    None => listed.forbid_pairs_not_in_view_graph += 1,
                }
                listed
                    .forbid_pairs
                    .push([names[0].clone(), names[1].clone()]);
            }
        }
        if let Some(list) = &self.keep_pairs {
            for (line, names) in &list.entries {
                let where_ = format!("{} line {line}", list.path.display());
                let Some(k) = edge_of(list, *line, names)? else {
                    bail!(
                        "{where_}: `{}` `{}` is not a verified pair with at least {min_num_matches} inliers, so it cannot be kept",
                        names[0], names[1]
                    );
                };
                if edges[k] == ArcRule::Removed {
                    bail!(
                        "{where_}: `{}` `{}` is kept but also forbidden (--forbid_pairs or --forbid_images)",
                        names[0], names[1]
                    );
                }
                edges[k] = ArcRule::Fixed;
                listed.keep_pairs.push([names[0].clone(), names[1].clone()]);
            }
        }
        Ok(Resolved {
            edges,
            forbidden_vertices,
            listed,
        })
    }
}
