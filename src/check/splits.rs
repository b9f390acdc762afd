//! Where a model could be two copies glued together: the co-visibility graph of its images and
//! the candidate splits into two groups, one per edge of its maximum spanning tree.
//!
//! Two copies registered onto each other are two groups of images that see much of their own
//! structure and little of the other's; the weakest links of the strongest tree between images
//! are where such groups meet (Heinly et al., ECCV 2014, split along a spanning tree too).

use super::views::Views;
use std::collections::{BTreeMap, HashSet};

/// Shared 3D points per image pair (smaller view index first), and points per view.
#[derive(Clone, Debug)]
pub struct Covisibility {
    /// Points seen by both views of the pair.
    pub shared: BTreeMap<(usize, usize), usize>,
    /// Points seen by each view.
    pub seen: Vec<usize>,
}

impl Covisibility {
    /// Counts shared points over every track.
    pub fn new(views: &Views) -> Covisibility {
        let mut shared = BTreeMap::new();
        let mut seen = vec![0; views.views.len()];
        for track in &views.observers {
            for (i, &a) in track.iter().enumerate() {
                seen[a] += 1;
                for &b in &track[i + 1..] {
                    *shared.entry((a, b)).or_insert(0) += 1;
                }
            }
        }
        Covisibility { shared, seen }
    }

    /// Every pair sharing points as (strength, view, view), in view order.
    pub fn links(&self) -> Vec<(f64, usize, usize)> {
        (self.shared.keys())
            .map(|&(a, b)| (self.strength(a, b), a, b))
            .collect()
    }

    /// The views that observe some point, in groups that share no point with each other:
    /// the connected components of the co-visibility graph, each in view order, the largest
    /// first (ties by first view).
    pub fn parts(&self) -> Vec<Vec<usize>> {
        let roots = Sets::roots(self.seen.len(), self.shared.keys().copied());
        let mut parts: BTreeMap<usize, Vec<usize>> = BTreeMap::new();
        for v in (0..roots.len()).filter(|&v| self.seen[v] > 0) {
            parts.entry(roots[v]).or_default().push(v);
        }
        let mut parts: Vec<Vec<usize>> = parts.into_values().collect();
        parts.sort_by(|x, y| y.len().cmp(&x.len()).then(x[0].cmp(&y[0])));
        parts
    }

    /// The link's strength: shared points over the smaller view's points, in [0, 1].
    pub fn strength(&self, a: usize, b: usize) -> f64 {
        let key = (a.min(b), a.max(b));
        let shared = self.shared.get(&key).copied().unwrap_or(0) as f64;
        shared / self.seen[a].min(self.seen[b]).max(1) as f64
    }
}

/// Union-find over view indices.
pub(super) struct Sets(Vec<usize>);

impl Sets {
    /// `n` views, each a set of its own.
    pub(super) fn new(n: usize) -> Sets {
        Sets((0..n).collect())
    }

    /// Joins the sets of `a` and `b`, under the smaller representative (so that each set's
    /// representative is its smallest view); false where they were one already.
    pub(super) fn union(&mut self, a: usize, b: usize) -> bool {
        let (ra, rb) = (self.find(a), self.find(b));
        self.0[ra.max(rb)] = ra.min(rb);
        ra != rb
    }

    /// Each of `n` views' representative (its component's smallest view) once every pair of
    /// `pairs` is joined.
    pub(super) fn roots(n: usize, pairs: impl IntoIterator<Item = (usize, usize)>) -> Vec<usize> {
        let mut sets = Sets::new(n);
        for (a, b) in pairs {
            sets.union(a, b);
        }
        (0..n).map(|v| sets.find(v)).collect()
    }

    /// The representative of `a`'s set.
    pub(super) fn find(&mut self, a: usize) -> usize {
        let mut r = a;
        while self.0[r] != r {
            r = self.0[r];
        }
        self.0[a] = r;
        r
    }
}

/// The maximum spanning forest of a graph given as (weight, view, view) edges (Kruskal, ties
/// by view indices): the edges it keeps, as given.
pub fn spanning_tree(n: usize, mut edges: Vec<(f64, usize, usize)>) -> Vec<(f64, usize, usize)> {
    edges.sort_by(|x, y| y.0.total_cmp(&x.0).then((x.1, x.2).cmp(&(y.1, y.2))));
    let mut sets = Sets::new(n);
    let mut tree = Vec::new();
    for (w, a, b) in edges {
        if sets.union(a, b) {
            tree.push((w, a, b));
        }
    }
    tree
}

/// Each split the tree offers with both sides at least `min_group` views, once each: `true`
/// marks the side cut off (the one without view 0). In a forest, the other trees stay with
/// view 0's side.
pub fn candidate_splits(
    n: usize,
    tree: &[(f64, usize, usize)],
    min_group: usize,
) -> Vec<Vec<bool>> {
    let mut out = SplitList::default();
    for cut in 0..tree.len() {
        let side = cut_off(n, tree, cut);
        if both_sides(&side, min_group) {
            out.push(side);
        }
    }
    out.into_vec()
}

/// The split at the weakest link of the maximum spanning tree of `links` with at least
/// `min_group` views on both sides (views the links leave apart are joined at strength 0, in
/// view order): where a group the model carried off with its own points meets the rest, as it
/// shares few points with it, whatever the conflicts say (a hall orbit the global mapper turned
/// and scaled: 0.30 of its points shared there, 0.56 and more at every other link).
pub fn weakest_link_split(
    n: usize,
    links: &[(f64, usize, usize)],
    min_group: usize,
) -> Option<Vec<bool>> {
    let mut edges = links.to_vec();
    edges.extend((1..n).map(|v| (0.0, v - 1, v)));
    let tree = spanning_tree(n, edges);
    let mut cuts: Vec<(f64, usize)> = (tree.iter().enumerate())
        .map(|(k, &(w, _, _))| (w, k))
        .collect();
    cuts.sort_by(|x, y| x.0.total_cmp(&y.0).then(x.1.cmp(&y.1)));
    cuts.into_iter()
        .map(|(_, cut)| cut_off(n, &tree, cut))
        .find(|side| both_sides(side, min_group))
        .map(normalised)
}

/// The views on the side of tree edge `cut`'s second view once the edge is cut.
fn cut_off(n: usize, tree: &[(f64, usize, usize)], cut: usize) -> Vec<bool> {
    let mut adjacent = vec![Vec::new(); n];
    for (k, &(_, a, b)) in tree.iter().enumerate() {
        if k != cut {
            adjacent[a].push(b);
            adjacent[b].push(a);
        }
    }
    let mut side = vec![false; n];
    let second = tree[cut].2;
    let mut stack = vec![second];
    side[second] = true;
    while let Some(v) = stack.pop() {
        for &w in &adjacent[v] {
            if !side[w] {
                side[w] = true;
                stack.push(w);
            }
        }
    }
    side
}

/// Whether both sides of `side` hold at least `min_group` views.
fn both_sides(side: &[bool], min_group: usize) -> bool {
    let b = side.iter().filter(|s| **s).count();
    b >= min_group && side.len() - b >= min_group
}

/// The one form every split is kept in: the model's first image in the `false` group, so that a
/// split and its mirror are one.
pub fn normalised(mut side: Vec<bool>) -> Vec<bool> {
    if side[0] {
        side.iter_mut().for_each(|s| *s = !*s);
    }
    side
}

/// Splits in the order found, each once, [`normalised`] (a set beside the list: a model of n
/// images offers some 4n candidates).
#[derive(Default)]
pub struct SplitList {
    list: Vec<Vec<bool>>,
    seen: HashSet<Vec<bool>>,
}

impl SplitList {
    /// Adds `side` unless it is there already.
    pub fn push(&mut self, side: Vec<bool>) {
        let side = normalised(side);
        if self.seen.insert(side.clone()) {
            self.list.push(side);
        }
    }

    /// The splits, in the order found.
    pub fn into_vec(self) -> Vec<Vec<bool>> {
        self.list
    }

    /// The splits, in the order found, kept.
    pub fn as_slice(&self) -> &[Vec<bool>] {
        &self.list
    }

    /// Whether `side` (normalised) is one of them.
    pub fn contains(&self, side: &[bool]) -> bool {
        self.seen.contains(side)
    }
}

/// The sweep cuts of the graph's spectral embedding: images ordered by the Fiedler vector of
/// the normalised Laplacian (Shi and Malik's normalised cut, relaxed), every prefix with at
/// least `min_group` images on both sides. Global where a spanning tree is local: one weak link
/// inside a copy does not hide the copies.
pub fn spectral_splits(
    n: usize,
    edges: &[(f64, usize, usize)],
    min_group: usize,
) -> Vec<Vec<bool>> {
    if n < 2 * min_group.max(1) {
        return Vec::new();
    }
    let mut w = nalgebra::DMatrix::<f64>::zeros(n, n);
    for &(x, a, b) in edges {
        w[(a, b)] += x.max(0.0);
        w[(b, a)] += x.max(0.0);
    }
    let d: Vec<f64> = (0..n).map(|i| w.row(i).sum().max(1e-12)).collect();
    let l = nalgebra::DMatrix::from_fn(n, n, |i, j| {
        f64::from(u8::from(i == j)) - w[(i, j)] / (d[i] * d[j]).sqrt()
    });
    let eigen = l.symmetric_eigen();
    let mut order: Vec<usize> = (0..n).collect();
    order.sort_by(|&a, &b| {
        eigen.eigenvalues[a]
            .total_cmp(&eigen.eigenvalues[b])
            .then(a.cmp(&b))
    });
    let fiedler = eigen.eigenvectors.column(order[1]);
    let y: Vec<f64> = (0..n).map(|i| fiedler[i] / d[i].sqrt()).collect();
    let mut by_value: Vec<usize> = (0..n).collect();
    by_value.sort_by(|&a, &b| y[a].total_cmp(&y[b]).then(a.cmp(&b)));
    let mut out = SplitList::default();
    for k in min_group..=n - min_group {
        let mut side = vec![false; n];
        by_value[k..].iter().for_each(|&v| side[v] = true);
        out.push(side);
    }
    out.into_vec()
}

/// Each connected component of the graph of `edges` with at least `min_group` views, and at
/// least as many outside it, against the rest.
pub fn component_splits(
    n: usize,
    edges: &[(f64, usize, usize)],
    min_group: usize,
) -> Vec<Vec<bool>> {
    let roots = Sets::roots(n, edges.iter().map(|&(_, a, b)| (a, b)));
    let mut out = SplitList::default();
    for root in 0..n {
        let side: Vec<bool> = roots.iter().map(|&r| r == root).collect();
        if both_sides(&side, min_group) {
            out.push(side);
        }
    }
    out.into_vec()
}

/// `side` moved one view at a time to the other side while that raises the signed weight the
/// split cuts (each link's weight counts for the split where the link crosses it, against it
/// where it does not), each time the view that raises it most, both sides kept at `min_group`
/// views at least. With a link's conflicting samples less its agreeing ones as weight, a split
/// that cuts a copy in two is pulled to the copies' own: two copies seen from the same spots
/// conflict across the ghost and agree within each copy, where a spanning tree's cut follows
/// the strongest co-visibility, which crosses between them (the twin's orbits, 13 against 20
/// images where they are 16 and 17; docs/check.md).
pub fn refine(side: &[bool], signed: &[(f64, usize, usize)], min_group: usize) -> Vec<bool> {
    let n = side.len();
    let mut side = side.to_vec();
    let mut adjacent: Vec<Vec<(usize, f64)>> = vec![Vec::new(); n];
    for &(w, a, b) in signed {
        adjacent[a].push((b, w));
        adjacent[b].push((a, w));
    }
    // What moving `v` adds to the cut: links that cross become uncut, and the others cut.
    let gain = |side: &[bool], v: usize| -> f64 {
        (adjacent[v].iter())
            .map(|&(u, w)| if side[u] == side[v] { w } else { -w })
            .sum()
    };
    let first = side.iter().filter(|s| !**s).count();
    let mut sizes = [first, n - first];
    // Every move raises the cut's weight, so no split comes back; the bound is a guard.
    for _ in 0..n * n {
        let best = (0..n)
            .filter(|&v| sizes[usize::from(side[v])] > min_group)
            .map(|v| (gain(&side, v), v))
            .max_by(|x, y| x.0.total_cmp(&y.0).then(y.1.cmp(&x.1)));
        match best {
            Some((g, v)) if g > 0.0 => {
                sizes[usize::from(side[v])] -= 1;
                side[v] = !side[v];
                sizes[usize::from(side[v])] += 1;
            }
            _ => break,
        }
    }
    side
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Two cliques of four views, each link 0.9, joined by links of 0.2 and 0.3: the weakest
    /// link of the tree parts them; with no link between them they part where the views are
    /// left apart; a group under `min_group` is passed over for the next weakest link.
    #[test]
    fn the_weakest_link_parts_two_groups() {
        let clique = |first: usize| {
            (first..first + 4)
                .flat_map(move |a| (a + 1..first + 4).map(move |b| (0.9, a, b)))
                .collect::<Vec<_>>()
        };
        let mut links = [clique(0), clique(4)].concat();
        let apart = weakest_link_split(8, &links, 3);
        let groups = Some(vec![false, false, false, false, true, true, true, true]);
        assert_eq!(apart, groups);
        links.extend([(0.2, 1, 6), (0.3, 2, 5)]);
        assert_eq!(weakest_link_split(8, &links, 3), groups);
        // A ninth view hanging on by 0.1 is a group of one: passed over.
        links.push((0.1, 7, 8));
        let groups = groups.map(|mut g| {
            g.push(true);
            g
        });
        assert_eq!(weakest_link_split(9, &links, 3), groups);
        assert_eq!(weakest_link_split(9, &links, 5), None);
    }

    /// Two copies of four views that pair up view by view (0 with 4, ...) as a ghost's do:
    /// within a copy the links agree (weight -10), between the paired views they conflict
    /// (+10), and views 1 and 5 share one agreeing link (-2). From a split that cuts each copy
    /// in two, the refinement reaches the copies, the one split that cuts every conflicting
    /// link and no agreeing one within a copy; brute force over every split says no other cuts
    /// more weight. A refined split keeps `min_group` views a side, and the copies stay.
    #[test]
    fn refinement_pulls_a_split_to_the_copies() {
        let mut signed = Vec::new();
        for first in [0, 4] {
            for a in first..first + 4 {
                signed.extend((a + 1..first + 4).map(|b| (-10.0, a, b)));
            }
        }
        signed.extend((0..4).map(|a| (10.0, a, a + 4)));
        signed.push((-2.0, 1, 5));
        let copies = vec![false, false, false, false, true, true, true, true];
        let cut = |side: &[bool]| -> f64 {
            (signed.iter())
                .filter(|(_, a, b)| side[*a] != side[*b])
                .map(|(w, _, _)| w)
                .sum()
        };
        let best = (1..256u32)
            .map(|bits| (0..8).map(|v| bits >> v & 1 == 1).collect::<Vec<bool>>())
            .max_by(|x, y| cut(x).total_cmp(&cut(y)))
            .unwrap();
        assert_eq!(normalised(best), copies);
        let mixed = [false, false, true, true, false, false, true, true];
        assert_eq!(normalised(refine(&mixed, &signed, 3)), copies);
        assert_eq!(refine(&copies, &signed, 3), copies);
        // With four views a side required, no view may leave a side of four.
        assert_eq!(refine(&mixed, &signed, 4), mixed);
    }
}
