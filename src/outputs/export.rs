//! Views of a database's view graph for other tools: Graphviz DOT and GraphML (`export`), and the
//! kept pairs as a COLMAP pair list (`prune --pairs_out`).
//!
//! `export` formats the plan of the database's last prune
//! ([`crate::selection::pipeline::last_plan`]: its priors and costs recomputed with the recorded
//! parameters, so they are the ones that drove the selection) with kept/removed as the database
//! records it ([`crate::colmap::database::Database::invalidated_pair_ids`]).

use crate::colmap::ids::pair_id;
use crate::named::Named;
use crate::selection::pipeline::Plan;
use std::collections::{BTreeMap, HashSet};
use std::fmt::Write;

/// The graph file format `export` writes (`--format`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Format {
    /// Graphviz DOT (removed pairs dashed).
    Dot,
    /// GraphML (networkx.read_graphml, Gephi, Cytoscape).
    Graphml,
}

impl Named for Format {
    const ALL: &'static [Format] = &[Format::Dot, Format::Graphml];

    fn name(self) -> &'static str {
        match self {
            Format::Dot => "dot",
            Format::Graphml => "graphml",
        }
    }

    fn help(self) -> &'static str {
        match self {
            Format::Dot => "Graphviz DOT (removed pairs dashed)",
            Format::Graphml => "GraphML (networkx.read_graphml, Gephi, Cytoscape)",
        }
    }
}

/// A typed attribute value, written as each format wants it.
#[derive(Clone, Debug)]
enum Value {
    Int(i64),
    Float(f64),
    Bool(bool),
}

impl Value {
    fn graphml_type(&self) -> &'static str {
        match self {
            Value::Int(_) => "long",
            Value::Float(_) => "double",
            Value::Bool(_) => "boolean",
        }
    }

    fn text(&self) -> String {
        match self {
            Value::Int(v) => v.to_string(),
            Value::Float(v) => v.to_string(),
            Value::Bool(v) => v.to_string(),
        }
    }
}

/// Named attribute values of a node or an edge, in output order.
type Attrs = Vec<(String, Value)>;

/// Nodes (id = image name) and edges (names of both ends) with their attributes, in order.
struct Graph {
    nodes: Vec<(String, Attrs)>,
    edges: Vec<(String, String, Attrs)>,
}

/// What an export wrote, for the command's summary.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Exported {
    /// Nodes written: the view graph's images.
    pub images: usize,
    /// Edges written: the view graph's pairs, kept or removed.
    pub pairs: usize,
    /// Edges the database still has valid (not in `vgsel_backup`).
    pub pairs_kept: usize,
}

/// The view graph of `plan` in `format`, each pair marked removed when its pair_id is in
/// `removed` (the database's own record of the prune) and kept otherwise.
pub fn export(plan: &Plan, removed: &HashSet<u64>, format: Format) -> (String, Exported) {
    let graph = build(plan, removed);
    let exported = Exported {
        images: graph.nodes.len(),
        pairs: graph.edges.len(),
        pairs_kept: graph.edges.iter().filter(|e| is_kept(&e.2)).count(),
    };
    let text = match format {
        Format::Dot => dot(&graph),
        Format::Graphml => graphml(&graph),
    };
    (text, exported)
}

fn edge_pair_id(plan: &Plan, pair: usize) -> u64 {
    let p = &plan.pairs[pair];
    pair_id(p.image_id1, p.image_id2)
}

fn build(plan: &Plan, removed: &HashSet<u64>) -> Graph {
    let names: BTreeMap<u32, &str> = plan
        .images
        .iter()
        .map(|im| (im.image_id, im.name.as_str()))
        .collect();
    let scored =
        |raw: &[crate::priors::PriorValues], fitness: &[crate::priors::PriorValues], k: usize| {
            raw.iter()
                .zip(fitness)
                .flat_map(|(r, f)| {
                    [
                        (r.prior.name().to_string(), Value::Float(r.values[k])),
                        (
                            format!("{}_score", f.prior.name()),
                            Value::Float(f.values[k]),
                        ),
                    ]
                })
                .collect::<Vec<_>>()
        };
    let nodes = names
        .iter()
        .map(|(&id, &name)| {
            let mut attrs = vec![("image_id".to_string(), Value::Int(id as i64))];
            if let Ok(v) = plan.graph.image_ids.binary_search(&id) {
                attrs.extend(scored(&plan.image_priors, &plan.costs.image_fitness, v));
                attrs.push(("cost".to_string(), Value::Float(plan.costs.image_costs[v])));
            }
            (name.to_string(), attrs)
        })
        .collect();
    let edges = plan
        .graph
        .edges
        .iter()
        .enumerate()
        .map(|(k, e)| {
            let pair = &plan.pairs[e.pair];
            let mut attrs = vec![(
                "num_inliers".to_string(),
                Value::Int(pair.inliers.len() as i64),
            )];
            attrs.extend(scored(&plan.pair_priors, &plan.costs.pair_fitness, k));
            attrs.push(("cost".to_string(), Value::Float(plan.costs.pair_costs[k])));
            let kept = !removed.contains(&edge_pair_id(plan, e.pair));
            attrs.push(("kept".to_string(), Value::Bool(kept)));
            (
                names[&pair.image_id1].to_string(),
                names[&pair.image_id2].to_string(),
                attrs,
            )
        })
        .collect();
    Graph { nodes, edges }
}

fn is_kept(attrs: &[(String, Value)]) -> bool {
    attrs
        .iter()
        .any(|(k, v)| k == "kept" && matches!(v, Value::Bool(true)))
}

fn dot_quote(s: &str) -> String {
    format!("\"{}\"", s.replace('\\', "\\\\").replace('"', "\\\""))
}

fn dot_attrs(attrs: &[(String, Value)], extra: &str) -> String {
    let list: Vec<String> = attrs
        .iter()
        .map(|(k, v)| format!("{k}={}", dot_quote(&v.text())))
        .collect();
    format!("[{}{extra}]", list.join(", "))
}

/// Removed edges are drawn dashed and grey, so `dot -Tsvg` shows the selection at a glance.
fn dot(graph: &Graph) -> String {
    let mut s = String::from("graph view_graph {\n  node [shape=box];\n");
    for (name, attrs) in &graph.nodes {
        let _ = writeln!(s, "  {} {};", dot_quote(name), dot_attrs(attrs, ""));
    }
    for (a, b, attrs) in &graph.edges {
        let style = if is_kept(attrs) {
            ""
        } else {
            ", style=dashed, color=gray"
        };
        let _ = writeln!(
            s,
            "  {} -- {} {};",
            dot_quote(a),
            dot_quote(b),
            dot_attrs(attrs, style)
        );
    }
    s + "}\n"
}

fn xml_escape(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
}

fn graphml(graph: &Graph) -> String {
    let mut s = String::from(
        "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n\
         <graphml xmlns=\"http://graphml.graphdrawing.org/xmlns\">\n",
    );
    // Keys in first-seen order, one per (domain, name).
    let mut keys: Vec<(&str, String, &'static str)> = Vec::new();
    let nodes = graph.nodes.iter().map(|n| ("node", &n.1));
    let edges = graph.edges.iter().map(|e| ("edge", &e.2));
    for (domain, attrs) in nodes.chain(edges) {
        for (name, value) in attrs {
            if !keys.iter().any(|(d, n, _)| *d == domain && n == name) {
                keys.push((domain, name.clone(), value.graphml_type()));
            }
        }
    }
    let key_id = |domain: &str, name: &str| {
        keys.iter()
            .position(|(d, n, _)| *d == domain && n == name)
            .expect("declared key")
    };
    for (k, (domain, name, ty)) in keys.iter().enumerate() {
        let _ = writeln!(
            s,
            "  <key id=\"d{k}\" for=\"{domain}\" attr.name=\"{}\" attr.type=\"{ty}\"/>",
            xml_escape(name)
        );
    }
    s += "  <graph id=\"view_graph\" edgedefault=\"undirected\">\n";
    let data = |domain: &str, attrs: &[(String, Value)]| -> String {
        attrs
            .iter()
            .map(|(name, v)| {
                format!(
                    "      <data key=\"d{}\">{}</data>\n",
                    key_id(domain, name),
                    xml_escape(&v.text())
                )
            })
            .collect()
    };
    for (name, attrs) in &graph.nodes {
        let _ = write!(
            s,
            "    <node id=\"{}\">\n{}    </node>\n",
            xml_escape(name),
            data("node", attrs)
        );
    }
    for (a, b, attrs) in &graph.edges {
        let _ = write!(
            s,
            "    <edge source=\"{}\" target=\"{}\">\n{}    </edge>\n",
            xml_escape(a),
            xml_escape(b),
            data("edge", attrs)
        );
    }
    s + "  </graph>\n</graphml>\n"
}

/// The selected view-graph edges as `name1 name2` lines (image_id order within a line), the
/// format of `colmap matches_importer --match_type pairs`.
pub fn pairs_list(plan: &Plan) -> String {
    let names: BTreeMap<u32, &str> = plan
        .images
        .iter()
        .map(|im| (im.image_id, im.name.as_str()))
        .collect();
    plan.selected_pairs()
        .iter()
        .map(|p| format!("{} {}\n", names[&p.image_id1], names[&p.image_id2]))
        .collect()
}
