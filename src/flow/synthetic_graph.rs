//! The paper's synthetic view graphs (supplement, section III): images along a line (a facade, a
//! street) or a loop (around a building), each linked to neighbours drawn from a Gaussian around
//! it, costs uniform in [-1, 0], labels shuffled as in unordered photo collections. Used by the
//! solver benchmarks; deterministic from a seed.

use crate::named::Named;
use crate::network::{PairArc, SelectionProblem};
use rand::seq::SliceRandom;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, Normal};
use std::collections::HashSet;

/// How the images of a synthetic view graph are laid out.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Arrangement {
    /// Along a line, open at both ends (a facade, a street).
    Linear,
    /// Around a loop, neighbours wrap around (around a building).
    Loop,
}

impl Named for Arrangement {
    const ALL: &'static [Self] = &[Arrangement::Linear, Arrangement::Loop];

    fn name(self) -> &'static str {
        match self {
            Arrangement::Linear => "linear",
            Arrangement::Loop => "loop",
        }
    }

    fn help(self) -> &'static str {
        match self {
            Arrangement::Linear => "images along a line, open at both ends (a facade, a street)",
            Arrangement::Loop => "images around a closed loop (around a building)",
        }
    }
}

/// `images` vertices and exactly `pairs` edges. The neighbourhood spread is the mean degree, so
/// about 95% of an image's neighbours lie within two mean degrees of it along the arrangement.
pub fn generate(
    images: usize,
    pairs: usize,
    arrangement: Arrangement,
    seed: u64,
) -> SelectionProblem {
    assert!(images >= 2, "a view graph needs two images");
    let max_pairs = images * (images - 1) / 2;
    assert!(
        pairs <= max_pairs,
        "{pairs} pairs do not fit {images} images"
    );
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let order = local_edges(images, pairs, arrangement, &mut rng);
    let mut label: Vec<u32> = (0..images as u32).collect();
    label.shuffle(&mut rng);
    let image_costs = (0..images).map(|_| -rng.gen::<f64>()).collect();
    let mut arcs: Vec<PairArc> = order
        .into_iter()
        .map(|(a, b)| {
            let (i, j) = (label[a as usize], label[b as usize]);
            PairArc {
                i: i.min(j),
                j: i.max(j),
                cost: -rng.gen::<f64>(),
            }
        })
        .collect();
    arcs.sort_by_key(|p| (p.i, p.j));
    SelectionProblem {
        image_costs,
        pairs: arcs,
    }
}

/// Distinct edges between images in arrangement order (before shuffling), in drawing order.
fn local_edges(
    images: usize,
    pairs: usize,
    arrangement: Arrangement,
    rng: &mut ChaCha8Rng,
) -> Vec<(u32, u32)> {
    let mean_degree = 2.0 * pairs as f64 / images as f64;
    let offset = Normal::new(0.0, mean_degree.max(1.0)).expect("finite spread");
    let n = images as i64;
    let mut edges: HashSet<(u32, u32)> = HashSet::with_capacity(pairs);
    let mut order: Vec<(u32, u32)> = Vec::with_capacity(pairs);
    while order.len() < pairs {
        let i = rng.gen_range(0..n);
        let mut j = i + offset.sample(rng).round() as i64;
        if j == i {
            j = if rng.gen_bool(0.5) { i - 1 } else { i + 1 };
        }
        j = match arrangement {
            Arrangement::Loop => j.rem_euclid(n),
            // Offsets past an end of the line reflect back into it.
            Arrangement::Linear if j < 0 => (-j).min(n - 1),
            Arrangement::Linear if j >= n => (2 * (n - 1) - j).max(0),
            Arrangement::Linear => j,
        };
        if i == j {
            continue;
        }
        let key = (i.min(j) as u32, i.max(j) as u32);
        if edges.insert(key) {
            order.push(key);
        }
    }
    order
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn exact_sizes_valid_arcs_and_deterministic() {
        for arrangement in [Arrangement::Linear, Arrangement::Loop] {
            let p = generate(300, 10_000, arrangement, 7);
            assert_eq!(p.image_costs.len(), 300);
            assert_eq!(p.pairs.len(), 10_000);
            let distinct: HashSet<(u32, u32)> = p.pairs.iter().map(|a| (a.i, a.j)).collect();
            assert_eq!(distinct.len(), 10_000);
            assert!(p
                .pairs
                .iter()
                .all(|a| a.i < a.j && a.j < 300 && (-1.0..=0.0).contains(&a.cost)));
            assert!(p.image_costs.iter().all(|c| (-1.0..=0.0).contains(c)));
            assert_eq!(p, generate(300, 10_000, arrangement, 7));
            assert_ne!(p, generate(300, 10_000, arrangement, 8));
        }
    }

    #[test]
    fn neighbourhoods_are_local_before_shuffling() {
        let mut rng = ChaCha8Rng::seed_from_u64(1);
        let n = 1000;
        let edges = local_edges(n, 10_000, Arrangement::Loop, &mut rng);
        // Mean degree 20: Gaussian offsets of spread 20 put ~95% of partners within 40 places.
        let near = edges
            .iter()
            .filter(|&&(a, b)| {
                let d = (b - a) as usize;
                d.min(n - d) <= 40
            })
            .count();
        assert!(
            near as f64 > 0.9 * edges.len() as f64,
            "{near} of {}",
            edges.len()
        );
    }
}
