//! The order the network's pair arcs follow (`prune --order`), and how sequential a selection is
//! in it.
//!
//! Why it matters: the paper's network orients every pair arc from the lower to the higher image,
//! and with every cost negative each unit of flow is the longest cheap chain in that order. When
//! the order is the capture order of a sequence (a walk, an orbit), the chains run along the
//! sequence, consecutive frames are selected and copies of a duplicated structure are rarely
//! joined; in an arbitrary order the same costs keep false pairs at about their base rate
//! (docs/priors.md). COLMAP numbers images in the sorted order of their names, so `image_id` is
//! the capture order only when the names sort that way.
//!
//! Orders:
//! - `image_id`: COLMAP's numbering (the paper's network as is).
//! - `name`: file names in natural order (`img2` before `img10`), for frames named by a counter.
//! - `exif`: EXIF DateTimeOriginal (and SubSecTimeOriginal) of the image files, for photos from
//!   one camera clock; images without it follow in name order.
//! - `graph`: derived from the view graph alone, for sets whose names and times say nothing. It
//!   assumes the capture is one walk or orbit whose consecutive frames share more inliers than
//!   other pairs: the maximum spanning tree by inlier count is then mostly that walk, and its
//!   depth-first order from one end of the tree's longest path follows it (side branches are
//!   visited before the main line, smallest first, so they cost a short detour, not a jump).

use crate::colmap::database::{Image, VerifiedPair};
use crate::named::Named;
use crate::scene::view_graph::ViewGraph;
use anyhow::{bail, Context, Result};
use serde::{Deserialize, Serialize};
use std::cmp::Ordering;
use std::collections::HashMap;
use std::path::{Path, PathBuf};

/// Which order orients the pair arcs.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Order {
    /// COLMAP's image_id (the paper's network as is).
    #[default]
    ImageId,
    /// File names in natural order (digit runs compared as numbers).
    Name,
    /// EXIF DateTimeOriginal of the image files (needs --image_path); images without it last.
    Exif,
    /// Derived from the view graph: depth-first along its maximum spanning tree by inliers.
    Graph,
}

impl Named for Order {
    const ALL: &'static [Order] = &[Order::ImageId, Order::Name, Order::Exif, Order::Graph];

    fn name(self) -> &'static str {
        match self {
            Order::ImageId => "image_id",
            Order::Name => "name",
            Order::Exif => "exif",
            Order::Graph => "graph",
        }
    }

    fn help(self) -> &'static str {
        match self {
            Order::ImageId => "COLMAP's image_id (the paper's network as is)",
            Order::Name => "File names in natural order (digit runs compared as numbers)",
            Order::Exif => {
                "EXIF DateTimeOriginal of the image files (needs --image_path); images without it last"
            }
            Order::Graph => {
                "Derived from the view graph: depth-first along its maximum spanning tree by inliers"
            }
        }
    }
}

/// What `prune` is told about the order.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Input {
    /// The order asked for.
    pub order: Order,
    /// The image folder, for `Order::Exif`.
    pub image_path: Option<PathBuf>,
    /// The order is a capture sequence in which images at most this many positions apart see
    /// the same things (`--sequence_window`); 0: it says nothing about overlap.
    pub sequence_window: u32,
}

/// The order as computed: each view-graph vertex's position.
#[derive(Clone, Debug, PartialEq)]
pub struct CaptureOrder {
    /// The order it was computed as.
    pub order: Order,
    /// Position of each vertex, a permutation of `0..n`.
    pub rank: Vec<u32>,
    /// With `Order::Exif`: images whose file has no usable DateTimeOriginal.
    pub images_without_time: usize,
}

/// Pairs within this many positions count as sequential in the report.
pub const SEQUENTIAL_WINDOW: u32 = 5;

impl CaptureOrder {
    /// Whether vertices `i` and `j` are at most `window` positions apart.
    pub fn within(&self, i: u32, j: u32, window: u32) -> bool {
        self.rank[i as usize].abs_diff(self.rank[j as usize]) <= window
    }

    /// Share of the given edges (vertex pairs) whose ends are at most `window` positions apart;
    /// None without edges.
    pub fn share_within(
        &self,
        edges: impl Iterator<Item = (u32, u32)>,
        window: u32,
    ) -> Option<f64> {
        let (mut near, mut all) = (0usize, 0usize);
        for (i, j) in edges {
            all += 1;
            near += usize::from(self.within(i, j, window));
        }
        (all > 0).then(|| near as f64 / all as f64)
    }

    /// Values indexed by vertex, rearranged to be indexed by position in the order.
    pub fn by_rank<T: Clone>(&self, per_vertex: &[T]) -> Vec<T> {
        let mut out = per_vertex.to_vec();
        for (v, &r) in self.rank.iter().enumerate() {
            out[r as usize] = per_vertex[v].clone();
        }
        out
    }

    /// Values indexed by position in the order, rearranged to be indexed by vertex.
    pub fn by_vertex<T: Clone>(&self, per_rank: &[T]) -> Vec<T> {
        self.rank
            .iter()
            .map(|&r| per_rank[r as usize].clone())
            .collect()
    }
}

/// Computes `input.order` on the view graph's vertices.
pub fn compute(
    input: &Input,
    graph: &ViewGraph,
    images: &[Image],
    pairs: &[VerifiedPair],
) -> Result<CaptureOrder> {
    let name_of: HashMap<u32, &str> = images
        .iter()
        .map(|im| (im.image_id, im.name.as_str()))
        .collect();
    let names: Vec<&str> = graph.image_ids.iter().map(|id| name_of[id]).collect();
    let by_name = |a: &usize, b: &usize| natural_cmp(names[*a], names[*b]);
    let n = graph.num_vertices();
    let mut images_without_time = 0;
    let sequence: Vec<usize> = match input.order {
        Order::ImageId => (0..n).collect(),
        Order::Name => {
            let mut s: Vec<usize> = (0..n).collect();
            s.sort_by(by_name);
            s
        }
        Order::Exif => {
            let Some(dir) = &input.image_path else {
                bail!("--order exif reads the image files: give their folder with --image_path")
            };
            let times = names
                .iter()
                .map(|name| exif_time(&dir.join(name)))
                .collect::<Result<Vec<_>>>()?;
            images_without_time = times.iter().filter(|t| t.is_none()).count();
            if images_without_time == n {
                bail!(
                    "no image under {} has an EXIF DateTimeOriginal: use another --order",
                    dir.display()
                );
            }
            let mut s: Vec<usize> = (0..n).collect();
            // None sorts after every time; equal times by name.
            s.sort_by(|a, b| match (&times[*a], &times[*b]) {
                (Some(x), Some(y)) => x.cmp(y).then_with(|| by_name(a, b)),
                (x, y) => y.is_some().cmp(&x.is_some()).then_with(|| by_name(a, b)),
            });
            s
        }
        Order::Graph => {
            let weights: Vec<usize> = graph
                .edges
                .iter()
                .map(|e| pairs[e.pair].inliers.len())
                .collect();
            spanning_tree_order(graph, &weights)
        }
    };
    let mut rank = vec![0u32; n];
    for (position, &v) in sequence.iter().enumerate() {
        rank[v] = position as u32;
    }
    Ok(CaptureOrder {
        order: input.order,
        rank,
        images_without_time,
    })
}

/// Natural order of names: runs of digits compare as numbers (`f2` < `f10`), the rest
/// character by character; names equal that way fall back to plain comparison.
pub fn natural_cmp(a: &str, b: &str) -> Ordering {
    let (mut x, mut y) = (a.as_bytes(), b.as_bytes());
    loop {
        match (x.first(), y.first()) {
            (None, None) => return a.cmp(b),
            (None, Some(_)) => return Ordering::Less,
            (Some(_), None) => return Ordering::Greater,
            (Some(c), Some(d)) if c.is_ascii_digit() && d.is_ascii_digit() => {
                let digits = |s: &[u8]| s.iter().take_while(|c| c.is_ascii_digit()).count();
                let (p, q) = (digits(x), digits(y));
                let trim = |s: &[u8]| {
                    let zeros = s.iter().take_while(|&&c| c == b'0').count();
                    s[zeros..].to_vec()
                };
                let (u, v) = (trim(&x[..p]), trim(&y[..q]));
                let by_value = u.len().cmp(&v.len()).then_with(|| u.cmp(&v));
                if by_value != Ordering::Equal {
                    return by_value;
                }
                (x, y) = (&x[p..], &y[q..]);
            }
            (Some(c), Some(d)) => {
                if c != d {
                    return c.cmp(d);
                }
                (x, y) = (&x[1..], &y[1..]);
            }
        }
    }
}

/// Year, month, day, hour, minute, second, nanosecond: ordered as time is.
pub type CaptureTime = (u16, u8, u8, u8, u8, u8, u32);

/// EXIF capture time of an image file as (date-time fields, nanoseconds): DateTimeOriginal with
/// SubSecTimeOriginal. None when the file has no EXIF or no valid DateTimeOriginal; an error
/// when the file cannot be read.
pub fn exif_time(path: &Path) -> Result<Option<CaptureTime>> {
    let file = std::fs::File::open(path)
        .with_context(|| format!("--order exif: cannot open image {}", path.display()))?;
    let Ok(exif) = exif::Reader::new().read_from_container(&mut std::io::BufReader::new(file))
    else {
        return Ok(None);
    };
    let ascii = |tag| match exif.get_field(tag, exif::In::PRIMARY).map(|f| &f.value) {
        Some(exif::Value::Ascii(v)) => v.first().cloned(),
        _ => None,
    };
    let Some(Ok(mut t)) =
        ascii(exif::Tag::DateTimeOriginal).map(|v| exif::DateTime::from_ascii(&v))
    else {
        return Ok(None);
    };
    if let Some(sub) = ascii(exif::Tag::SubSecTimeOriginal) {
        // A malformed sub-second field only loses the sub-second part.
        let _ = t.parse_subsec(&sub);
    }
    Ok(Some((
        t.year,
        t.month,
        t.day,
        t.hour,
        t.minute,
        t.second,
        t.nanosecond.unwrap_or(0),
    )))
}

/// Depth-first order of the maximum spanning forest (by `weights`, one per graph edge), each
/// tree from one end of its longest path, children with smaller subtrees first; trees in the
/// order of their lowest vertex.
fn spanning_tree_order(graph: &ViewGraph, weights: &[usize]) -> Vec<usize> {
    let n = graph.num_vertices();
    // Kruskal: heaviest edges first, ties by edge index for determinism.
    let mut by_weight: Vec<usize> = (0..graph.edges.len()).collect();
    by_weight.sort_by_key(|&k| (std::cmp::Reverse(weights[k]), k));
    let mut parent: Vec<usize> = (0..n).collect();
    fn find(parent: &mut [usize], mut v: usize) -> usize {
        while parent[v] != v {
            parent[v] = parent[parent[v]];
            v = parent[v];
        }
        v
    }
    let mut tree = vec![Vec::new(); n];
    for k in by_weight {
        let (i, j) = (graph.edges[k].i as usize, graph.edges[k].j as usize);
        let (a, b) = (find(&mut parent, i), find(&mut parent, j));
        if a != b {
            parent[a] = b;
            tree[i].push(j);
            tree[j].push(i);
        }
    }
    for children in &mut tree {
        children.sort_unstable();
    }
    let mut placed = vec![false; n];
    let mut sequence = Vec::with_capacity(n);
    for start in 0..n {
        if placed[start] {
            continue;
        }
        // The farthest vertex from any vertex is one end of the tree's longest path.
        let root = *farthest(&tree, start).last().unwrap();
        let order = farthest(&tree, root);
        // Subtree sizes with `root` as the root: children come after their parent in `order`.
        let mut up = vec![usize::MAX; n];
        for &v in &order {
            for &w in &tree[v] {
                if w != up[v] {
                    up[w] = v;
                }
            }
        }
        let mut size = vec![1usize; n];
        for &v in order.iter().rev() {
            if v != root {
                size[up[v]] += size[v];
            }
        }
        let mut stack = vec![root];
        while let Some(v) = stack.pop() {
            placed[v] = true;
            sequence.push(v);
            let mut children: Vec<usize> =
                tree[v].iter().copied().filter(|&w| w != up[v]).collect();
            // Popped smallest first: pushed largest first.
            children.sort_by_key(|&w| (std::cmp::Reverse(size[w]), std::cmp::Reverse(w)));
            stack.extend(children);
        }
    }
    sequence
}

/// The vertices of `start`'s tree in breadth-first order (so the last is a farthest one).
fn farthest(tree: &[Vec<usize>], start: usize) -> Vec<usize> {
    let mut seen = vec![false; tree.len()];
    seen[start] = true;
    let mut order = vec![start];
    let mut k = 0;
    while k < order.len() {
        let v = order[k];
        k += 1;
        for &w in &tree[v] {
            if !seen[w] {
                seen[w] = true;
                order.push(w);
            }
        }
    }
    order
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Images named by `names` (image_id = position + 1) and pairs (by image_id) with the given
    /// inlier counts.
    fn scene(names: &[&str], pairs: &[(u32, u32, usize)]) -> (Vec<Image>, Vec<VerifiedPair>) {
        let images = names
            .iter()
            .enumerate()
            .map(|(k, name)| Image {
                image_id: k as u32 + 1,
                name: name.to_string(),
                camera_id: 1,
            })
            .collect();
        let pairs = pairs
            .iter()
            .map(|&(a, b, inliers)| {
                crate::scene::testing::pair(a.min(b), a.max(b), vec![[0, 0]; inliers])
            })
            .collect();
        (images, pairs)
    }

    /// The image names in the computed order.
    fn sequence(order: &CaptureOrder, graph: &ViewGraph, images: &[Image]) -> Vec<String> {
        let mut v: Vec<usize> = (0..graph.num_vertices()).collect();
        v.sort_by_key(|&k| order.rank[k]);
        v.iter()
            .map(|&k| {
                let id = graph.image_ids[k];
                images
                    .iter()
                    .find(|im| im.image_id == id)
                    .unwrap()
                    .name
                    .clone()
            })
            .collect()
    }

    fn run(
        order: Order,
        names: &[&str],
        pairs: &[(u32, u32, usize)],
        dir: Option<&Path>,
    ) -> Result<Vec<String>> {
        let (images, pairs) = scene(names, pairs);
        let graph = ViewGraph::build(&images, &pairs, 15);
        let input = Input {
            order,
            image_path: dir.map(Path::to_path_buf),
            ..Default::default()
        };
        let computed = compute(&input, &graph, &images, &pairs)?;
        Ok(sequence(&computed, &graph, &images))
    }

    /// Every image paired with every other, the given pairs stronger.
    fn all_pairs(n: u32, strong: impl Fn(u32, u32) -> bool) -> Vec<(u32, u32, usize)> {
        (1..=n)
            .flat_map(|a| (a + 1..=n).map(move |b| (a, b)))
            .map(|(a, b)| (a, b, if strong(a, b) { 200 } else { 20 }))
            .collect()
    }

    #[test]
    fn natural_order_compares_digit_runs_as_numbers() {
        let mut names = vec!["f10.png", "f2.png", "f1.png", "F3.png", "f02.png", "g1.png"];
        names.sort_by(|a, b| natural_cmp(a, b));
        assert_eq!(
            names,
            ["F3.png", "f1.png", "f02.png", "f2.png", "f10.png", "g1.png"]
        );
    }

    #[test]
    fn image_id_and_name_orders() {
        let names = ["img10.jpg", "img9.jpg", "img1.jpg"];
        let pairs = all_pairs(3, |_, _| false);
        assert_eq!(run(Order::ImageId, &names, &pairs, None).unwrap(), names);
        assert_eq!(
            run(Order::Name, &names, &pairs, None).unwrap(),
            ["img1.jpg", "img9.jpg", "img10.jpg"]
        );
    }

    #[test]
    fn graph_order_follows_a_shuffled_walk_with_a_side_branch() {
        // Capture sequence a0..a7; image ids shuffled; a spur x hangs off a3. Consecutive frames
        // share 200 inliers, frames two apart 100, every other pair 20.
        let names = ["a5", "a2", "a7", "x", "a0", "a3", "a6", "a1", "a4"];
        let pos = |k: u32| {
            let name = names[k as usize - 1];
            if name == "x" {
                None
            } else {
                Some(name[1..].parse::<i32>().unwrap())
            }
        };
        let pairs: Vec<_> = all_pairs(9, |_, _| false)
            .into_iter()
            .map(|(a, b, _)| {
                let inliers = match (pos(a), pos(b)) {
                    (Some(p), Some(q)) if (p - q).abs() == 1 => 200,
                    (Some(p), Some(q)) if (p - q).abs() == 2 => 100,
                    (Some(3), None) | (None, Some(3)) => 150,
                    _ => 20,
                };
                (a, b, inliers)
            })
            .collect();
        let mut got = run(Order::Graph, &names, &pairs, None).unwrap();
        if got[0] != "a0" {
            got.reverse();
        }
        assert_eq!(got, ["a0", "a1", "a2", "a3", "x", "a4", "a5", "a6", "a7"]);
    }

    #[test]
    fn graph_order_opens_an_orbit_at_its_weakest_link() {
        // Six frames round an orbit; the link o5-o0 is the weakest of the ring.
        let names = ["o3", "o0", "o5", "o1", "o4", "o2"];
        let pos = |k: u32| names[k as usize - 1][1..].parse::<i32>().unwrap();
        let pairs: Vec<_> = all_pairs(6, |_, _| false)
            .into_iter()
            .map(|(a, b, _)| {
                let d = (pos(a) - pos(b)).abs();
                let inliers = match d {
                    1 => 200 + 10 * pos(a).min(pos(b)) as usize,
                    5 => 150,
                    _ => 20,
                };
                (a, b, inliers)
            })
            .collect();
        let mut got = run(Order::Graph, &names, &pairs, None).unwrap();
        if got[0] != "o0" {
            got.reverse();
        }
        assert_eq!(got, ["o0", "o1", "o2", "o3", "o4", "o5"]);
    }

    /// A TIFF file whose only content is EXIF with the given DateTimeOriginal (and sub-second).
    fn tiff_with_time(path: &Path, time: Option<&str>, subsec: Option<&str>) {
        use exif::{Field, In, Tag, Value};
        let field = |tag, s: &str| Field {
            tag,
            ifd_num: In::PRIMARY,
            value: Value::Ascii(vec![s.as_bytes().to_vec()]),
        };
        let fields: Vec<Field> = [
            time.map(|t| field(Tag::DateTimeOriginal, t)),
            subsec.map(|s| field(Tag::SubSecTimeOriginal, s)),
            Some(field(Tag::Make, "test")),
        ]
        .into_iter()
        .flatten()
        .collect();
        let mut writer = exif::experimental::Writer::new();
        for f in &fields {
            writer.push_field(f);
        }
        let mut bytes = std::io::Cursor::new(Vec::new());
        writer.write(&mut bytes, false).unwrap();
        std::fs::write(path, bytes.into_inner()).unwrap();
    }

    #[test]
    fn exif_order_sorts_by_capture_time_and_puts_images_without_it_last() {
        let dir = tempfile::tempdir().unwrap();
        let files = [
            ("a.tif", Some("2020:01:01 10:00:05"), None),
            ("b.tif", Some("2020:01:01 10:00:01"), Some("5")),
            ("c.tif", None, None),
            ("d.tif", Some("2020:01:01 10:00:01"), Some("25")),
            ("e.tif", Some("2019:12:31 23:59:59"), None),
        ];
        for (name, time, sub) in files {
            tiff_with_time(&dir.path().join(name), time, sub);
        }
        let names: Vec<&str> = files.iter().map(|f| f.0).collect();
        let pairs = all_pairs(5, |_, _| false);
        // b at .5 s comes after d at .25 s.
        assert_eq!(
            run(Order::Exif, &names, &pairs, Some(dir.path())).unwrap(),
            ["e.tif", "d.tif", "b.tif", "a.tif", "c.tif"]
        );
    }

    #[test]
    fn exif_order_needs_the_images_and_some_times() {
        let dir = tempfile::tempdir().unwrap();
        let names = ["a.tif", "b.tif"];
        let pairs = all_pairs(2, |_, _| false);
        let err = run(Order::Exif, &names, &pairs, None)
            .unwrap_err()
            .to_string();
        assert!(err.contains("--image_path"), "{err}");
        let err = run(Order::Exif, &names, &pairs, Some(dir.path()))
            .unwrap_err()
            .to_string();
        assert!(
            err.contains("cannot open image") && err.contains("a.tif"),
            "{err}"
        );
        for name in names {
            tiff_with_time(&dir.path().join(name), None, None);
        }
        let err = run(Order::Exif, &names, &pairs, Some(dir.path()))
            .unwrap_err()
            .to_string();
        assert!(err.contains("no image under"), "{err}");
    }

    #[test]
    fn share_within_counts_pairs_near_in_the_order() {
        let order = CaptureOrder {
            order: Order::Name,
            rank: vec![0, 9, 1, 2, 20],
            images_without_time: 0,
        };
        let edges = [(0, 2), (2, 3), (0, 1), (1, 4)];
        assert_eq!(order.share_within(edges.into_iter(), 5), Some(0.5));
        assert_eq!(order.share_within(edges.into_iter(), 11), Some(1.0));
        assert_eq!(order.share_within(std::iter::empty(), 5), None);
        let order = CaptureOrder {
            rank: vec![0, 3, 1, 2, 4],
            ..order
        };
        let values = ["a", "b", "c", "d", "e"];
        assert_eq!(order.by_rank(&[0, 1, 2, 3, 4]), [0, 2, 3, 1, 4]);
        assert_eq!(order.by_vertex(&order.by_rank(&values)), values);
    }
}
