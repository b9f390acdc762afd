//! From raw prior values to arc costs in [-1, 0].
//!
//! Each prior goes through g: optionally min-max scaled over all images (or pairs), then a
//! trapezoid that maps it to a fitness in [low, high] ⊂ [0, 1]. An image's cost is minus the
//! weighted mean of its priors' fitness times a node constant; a pair's cost is minus the weighted
//! mean of its priors' fitness, arithmetic as in the paper or geometric ([`Mean`]). Only
//! encouraging costs (<= 0) are used, as the paper does, so the flow F stays the one free
//! parameter.

use crate::named::Named;
use crate::priors::{Prior, PriorValues};
use anyhow::{bail, Result};
use serde::{Deserialize, Serialize};

/// The normalisation g of one prior: a trapezoid with breakpoints k1..k6: `low` below k2, rising
/// linearly to `high` on [k2, k3), `high` on [k3, k4], falling to `low` on (k4, k5), `low` above.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Trapezoid {
    /// Min-max scale the raw values to [0, 1] over all images (or pairs) first.
    pub minmax: bool,
    /// Breakpoints k1..k6, meant non-decreasing (not checked); k1 and k6 record the domain only.
    pub k: [f64; 6],
    /// Fitness on the plateau [k3, k4].
    pub high: f64,
    /// Fitness outside (k2, k5), and of NaN values (a prior that does not apply).
    pub low: f64,
}

impl Trapezoid {
    /// Fitness rising from 0 at 0 to 1 at 1, on min-max scaled values: "more is better".
    pub const RISE: Trapezoid = Trapezoid {
        minmax: true,
        k: [0.0, 0.0, 1.0, 1.0, 1.0, 1.0],
        high: 1.0,
        low: 0.0,
    };
    /// "Less is better" on min-max scaled values (the Hamming context distance).
    pub const FALL: Trapezoid = Trapezoid {
        minmax: true,
        k: [0.0, 0.0, 0.0, 0.0, 1.0, 1.0],
        high: 1.0,
        low: 0.0,
    };
    /// Raw values in [0, 1] taken as they are (a share of consistent triangles).
    pub const FRACTION: Trapezoid = Trapezoid {
        minmax: false,
        ..Trapezoid::RISE
    };
    /// The authors' overlap g: the raw mean hull ratio, rising over [0, 1].
    pub const OVERLAP: Trapezoid = Trapezoid::FRACTION;
    /// Degrees: rise 2 -> 45, flat to 90, fall to 120.
    pub const TRIANGULATION_ANGLE: Trapezoid = Trapezoid {
        minmax: false,
        k: [0.0, 2.0, 45.0, 90.0, 120.0, 180.0],
        high: 1.0,
        low: 0.0,
    };
    /// ‖HᵀH − I‖_F, min-max scaled: rise 0 -> 0.99, high to 1.01, fall to 2.
    pub const HOMOGRAPHY: Trapezoid = Trapezoid {
        minmax: true,
        k: [0.0, 0.0, 0.99, 1.01, 2.0, 2.0],
        high: 1.0,
        low: 0.0,
    };
    /// Degrees between primary and secondary rotations: good to 5, nothing from 75.
    pub const MOTION_ROTATION: Trapezoid = Trapezoid {
        minmax: false,
        k: [0.0, 0.0, 0.0, 5.0, 75.0, 180.0],
        high: 1.0,
        low: 0.0,
    };
    /// Degrees between primary and secondary translation directions: good to 5, nothing from 25.
    pub const MOTION_POSITION: Trapezoid = Trapezoid {
        minmax: false,
        k: [0.0, 0.0, 0.0, 5.0, 25.0, 180.0],
        high: 1.0,
        low: 0.0,
    };

    /// Fitness of one (already scaled) value; NaN gets `low`.
    pub fn at(&self, x: f64) -> f64 {
        let [_, k2, k3, k4, k5, _] = self.k;
        let ramp = |from: f64, to: f64, x: f64| (x - from) / (to - from);
        if x.is_nan() || x < k2 || x > k5 {
            self.low
        } else if x < k3 {
            self.low + (self.high - self.low) * ramp(k2, k3, x)
        } else if x <= k4 {
            self.high
        } else {
            self.high + (self.low - self.high) * ramp(k4, k5, x)
        }
    }

    /// Fitness of every value. When all values are equal the min-max scale is undefined; they
    /// are then all equally fit and get `high`.
    pub fn apply(&self, values: &[f64]) -> Vec<f64> {
        if !self.minmax {
            return values.iter().map(|&x| self.at(x)).collect();
        }
        let finite = values.iter().copied().filter(|x| x.is_finite());
        let min = finite.clone().fold(f64::INFINITY, f64::min);
        let max = finite.fold(f64::NEG_INFINITY, f64::max);
        values
            .iter()
            .map(|&x| match max - min {
                span if span > 0.0 => self.at((x - min) / span),
                _ if x.is_finite() => self.high,
                _ => self.low,
            })
            .collect()
    }
}

/// How one prior enters the cost.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct PriorModel {
    /// The prior, which its [`PriorValues`] carry and `--weights` names.
    #[serde(rename = "name")]
    pub prior: Prior,
    /// Maps the prior's raw values to fitness in [low, high].
    pub g: Trapezoid,
    /// Relative weight in the weighted mean; at 0 the prior has no say and may go uncomputed.
    pub weight: f64,
}

impl PriorModel {
    /// `prior` through `g` at `weight`.
    pub fn new(prior: Prior, g: Trapezoid, weight: f64) -> PriorModel {
        PriorModel { prior, g, weight }
    }
}

/// How a pair's priors' fitness make one fitness.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Mean {
    /// The weighted arithmetic mean, the paper's: a prior that rates a pair highly makes up
    /// for one that rates it low.
    #[default]
    Arithmetic,
    /// The weighted geometric mean: a pair is only as fit as every prior allows, and one prior
    /// at 0 makes it 0. For priors that each miss false pairs of a different kind.
    Geometric,
}

impl Named for Mean {
    const ALL: &'static [Mean] = &[Mean::Arithmetic, Mean::Geometric];

    fn name(self) -> &'static str {
        match self {
            Mean::Arithmetic => "arithmetic",
            Mean::Geometric => "geometric",
        }
    }

    fn help(self) -> &'static str {
        match self {
            Mean::Arithmetic => "The weighted mean of the pair priors' fitness (the paper's)",
            Mean::Geometric => "The weighted geometric mean: every prior must rate a pair well",
        }
    }
}

/// Which priors make the costs, their g and weights (a preset's, [`crate::selection::preset`],
/// with the user's changes).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct CostModel {
    /// Priors of images, which give the costs of the network's image arcs.
    pub image_priors: Vec<PriorModel>,
    /// Priors of pairs, which give the costs of the network's pair arcs.
    pub pair_priors: Vec<PriorModel>,
    /// Scales image costs relative to pair costs (the authors ran 0, 0.5 and 1).
    pub node_constant: f64,
    /// How the pair priors' fitness are averaged. Recorded runs from before it load as
    /// arithmetic, as they ran.
    #[serde(default, skip_serializing_if = "is_arithmetic")]
    pub pair_mean: Mean,
    /// Pairs whose fitness (−cost) is below this are left out of the network, never selected.
    /// Any negative-cost arc lets a flow path run on from one copy of a duplicated structure to
    /// the other, so without a floor the flow keeps false pairs that rank low (docs/priors.md).
    pub min_pair_fitness: f64,
    /// Pairs whose `backbone_tracks` fitness (with [`Trapezoid::FRACTION`], its share: the
    /// inliers that chains of matches through the images' strongest pairs also join) is below
    /// this are not added by the track completion's spanning forests and per-image need
    /// (`selection::track_completion`); 0 is off. The model must list that prior (at weight 0
    /// where it only gates). The rest of the view graph does not corroborate such a pair: on
    /// repeated structure (castle, lego) the false pairs are nearly all of them, but so are a
    /// dense scene's weak long-range true pairs and the seams of the backbone, which the flow
    /// and the track-length need may still select (docs/priors.md). Recorded runs from before
    /// it load with 0, as they ran.
    #[serde(default, skip_serializing_if = "is_off")]
    pub min_backbone_tracks: f64,
}

/// A gate of 0 is not written, so that a record of a run without one reads as before it existed.
fn is_off(gate: &f64) -> bool {
    *gate == 0.0
}

/// Nor is the arithmetic mean, for the same reason.
fn is_arithmetic(mean: &Mean) -> bool {
    *mean == Mean::Arithmetic
}

impl CostModel {
    /// Sets a prior's weight; unknown names are an error listing the model's priors.
    pub fn set_weight(&mut self, name: &str, weight: f64) -> Result<()> {
        let all = self
            .image_priors
            .iter()
            .chain(&self.pair_priors)
            .map(|p| p.prior.name())
            .collect::<Vec<_>>()
            .join(", ");
        match self
            .image_priors
            .iter_mut()
            .chain(self.pair_priors.iter_mut())
            .find(|p| p.prior.name() == name)
        {
            Some(p) => p.weight = weight,
            None => bail!("no prior `{name}` in this preset (it has {all})"),
        }
        Ok(())
    }

    /// The pair priors to compute: those with a weight, or all of them, and `backbone_tracks`
    /// where the gate reads it.
    pub fn pair_priors_to_compute(&self, unweighted: bool) -> Vec<Prior> {
        let mut priors: Vec<Prior> = (self.pair_priors.iter())
            .filter(|p| unweighted || p.weight > 0.0)
            .map(|p| p.prior)
            .collect();
        if self.min_backbone_tracks > 0.0 && !priors.contains(&Prior::BackboneTracks) {
            priors.push(Prior::BackboneTracks);
        }
        priors
    }
}

/// Costs of every image and pair, with each prior's fitness kept for reports.
#[derive(Clone, Debug, PartialEq)]
pub struct Costs {
    /// Cost of each vertex's image arc: minus node constant × weighted mean fitness, in [-1, 0].
    pub image_costs: Vec<f64>,
    /// Cost of each edge's pair arc: minus its weighted mean fitness, in [-1, 0].
    pub pair_costs: Vec<f64>,
    /// Fitness of each image prior per vertex (NaN where the raw value was NaN).
    pub image_fitness: Vec<PriorValues>,
    /// Fitness of each pair prior per edge (NaN where the prior does not apply to the pair).
    pub pair_fitness: Vec<PriorValues>,
}

/// Applies the model to raw prior values (matched to the model by name; a model prior without
/// values is an error of the caller and panics).
pub fn compute(
    model: &CostModel,
    image_priors: &[PriorValues],
    pair_priors: &[PriorValues],
) -> Costs {
    let (image_fitness, image_mean) =
        weighted_fitness(&model.image_priors, image_priors, Mean::Arithmetic);
    let (pair_fitness, pair_mean) =
        weighted_fitness(&model.pair_priors, pair_priors, model.pair_mean);
    Costs {
        image_costs: image_mean
            .iter()
            .map(|f| -(f * model.node_constant).clamp(0.0, 1.0))
            .collect(),
        pair_costs: pair_mean.iter().map(|f| -f.clamp(0.0, 1.0)).collect(),
        image_fitness,
        pair_fitness,
    }
}

/// Each prior's fitness, and their weighted `mean` per item. A NaN raw value means the prior
/// does not apply to that item (no second motion found, no triangle): its fitness is NaN and the
/// mean is taken over the priors that apply. Priors of weight 0 may be left uncomputed.
fn weighted_fitness(
    models: &[PriorModel],
    raw: &[PriorValues],
    mean: Mean,
) -> (Vec<PriorValues>, Vec<f64>) {
    let models: Vec<&PriorModel> = models
        .iter()
        .filter(|m| m.weight > 0.0 || raw.iter().any(|p| p.prior == m.prior))
        .collect();
    let fitness: Vec<PriorValues> = models
        .iter()
        .map(|m| {
            let values = raw
                .iter()
                .find(|p| p.prior == m.prior)
                .unwrap_or_else(|| panic!("no values for prior {}", m.prior.name()));
            let fit = m.g.apply(&values.values);
            PriorValues {
                prior: m.prior,
                values: fit
                    .into_iter()
                    .zip(&values.values)
                    .map(|(f, r)| if r.is_nan() { f64::NAN } else { f })
                    .collect(),
            }
        })
        .collect();
    let n = fitness.first().map_or(0, |f| f.values.len());
    let mean = (0..n)
        .map(|k| {
            // Weight 0 has no say (and 0 × ln 0 would be NaN).
            let weighted = || {
                models
                    .iter()
                    .zip(&fitness)
                    .filter(move |(m, f)| m.weight > 0.0 && !f.values[k].is_nan())
                    .map(move |(m, f)| (m.weight, f.values[k]))
            };
            match weighted().map(|(w, _)| w).sum::<f64>() {
                w if w <= 0.0 => 0.0,
                w => match mean {
                    Mean::Arithmetic => weighted().map(|(v, f)| v * f).sum::<f64>() / w,
                    // exp of the weighted mean log; a fitness of 0 gives -inf, and exp(-inf) 0.
                    Mean::Geometric => (weighted().map(|(v, f)| v * f.ln()).sum::<f64>() / w).exp(),
                },
            }
        })
        .collect();
    (fitness, mean)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn trapezoid_pieces() {
        // The authors' triangulation-angle g: rise 2 -> 45, flat to 90, fall to 120.
        let g = Trapezoid {
            minmax: false,
            k: [0.0, 2.0, 45.0, 90.0, 120.0, 180.0],
            high: 1.0,
            low: 0.0,
        };
        assert_eq!(g.at(1.0), 0.0);
        assert_eq!(g.at(2.0), 0.0);
        assert!((g.at(23.5) - 0.5).abs() < 1e-12);
        assert_eq!(g.at(45.0), 1.0);
        assert_eq!(g.at(90.0), 1.0);
        assert!((g.at(105.0) - 0.5).abs() < 1e-12);
        assert_eq!(g.at(150.0), 0.0);
        assert_eq!(g.at(f64::NAN), 0.0);
    }

    #[test]
    fn minmax_rise_and_constant_values() {
        assert_eq!(
            Trapezoid::RISE.apply(&[10.0, 20.0, 15.0]),
            vec![0.0, 1.0, 0.5]
        );
        assert_eq!(Trapezoid::RISE.apply(&[3.0, 3.0]), vec![1.0, 1.0]);
    }

    #[test]
    fn weighted_mean_and_sign() {
        let mut model = CostModel {
            pair_priors: vec![
                PriorModel::new(Prior::Inliers, Trapezoid::RISE, 1.0),
                PriorModel::new(Prior::Overlap, Trapezoid::OVERLAP, 1.0),
            ],
            image_priors: [Prior::Degree, Prior::TrackFraction, Prior::Clustering]
                .map(|p| PriorModel::new(p, Trapezoid::RISE, 1.0))
                .to_vec(),
            node_constant: 1.0,
            pair_mean: Mean::Arithmetic,
            min_pair_fitness: 0.0,
            min_backbone_tracks: 0.0,
        };
        model.set_weight("overlap", 3.0).unwrap();
        assert!(model.set_weight("nope", 1.0).is_err());
        let pairs = [
            PriorValues {
                prior: Prior::Inliers,
                values: vec![0.0, 10.0],
            },
            PriorValues {
                prior: Prior::Overlap,
                values: vec![1.0, 0.0],
            },
        ];
        let images = [
            PriorValues {
                prior: Prior::Degree,
                values: vec![1.0],
            },
            PriorValues {
                prior: Prior::TrackFraction,
                values: vec![0.5],
            },
            PriorValues {
                prior: Prior::Clustering,
                values: vec![0.0],
            },
        ];
        let c = compute(&model, &images, &pairs);
        assert_eq!(c.pair_costs, vec![-0.75, -0.25]);
        assert_eq!(c.image_costs, vec![-1.0]);
        assert!(c
            .pair_costs
            .iter()
            .chain(&c.image_costs)
            .all(|&x| (-1.0..=0.0).contains(&x)));
    }

    #[test]
    fn absent_values_leave_the_mean() {
        let model = CostModel {
            image_priors: vec![],
            pair_priors: vec![
                PriorModel::new(Prior::LoopFraction, Trapezoid::FRACTION, 1.0),
                PriorModel::new(Prior::MotionRotation, Trapezoid::MOTION_ROTATION, 1.0),
            ],
            node_constant: 0.0,
            pair_mean: Mean::Arithmetic,
            min_pair_fitness: 0.0,
            min_backbone_tracks: 0.0,
        };
        let pairs = [
            PriorValues {
                prior: Prior::LoopFraction,
                values: vec![0.5, 0.5],
            },
            PriorValues {
                prior: Prior::MotionRotation,
                values: vec![f64::NAN, 90.0],
            },
        ];
        let c = compute(&model, &[], &pairs);
        assert_eq!(c.pair_costs, vec![-0.5, -0.25]);
        assert!(c.pair_fitness[1].values[0].is_nan());
    }

    /// Three shares as the disambiguation preset reads them, one of them absent for the third
    /// pair and one weighted 0: the geometric mean is the product's root over the priors that
    /// apply and have a weight, a share of 0 makes the pair 0 whatever the others say, and the
    /// arithmetic mean of the same values lets the other two carry it.
    #[test]
    fn the_geometric_mean_needs_every_prior() {
        let mut model = CostModel {
            image_priors: vec![],
            pair_priors: [
                Prior::BackboneTracks,
                Prior::UniqueTracks,
                Prior::LoopFraction,
                Prior::Context,
            ]
            .map(|p| PriorModel::new(p, Trapezoid::FRACTION, 1.0))
            .to_vec(),
            node_constant: 0.0,
            pair_mean: Mean::Geometric,
            min_pair_fitness: 0.0,
            min_backbone_tracks: 0.0,
        };
        model.set_weight("context", 0.0).unwrap();
        let shares = |prior, values: [f64; 3]| PriorValues {
            prior,
            values: values.to_vec(),
        };
        let pairs = [
            shares(Prior::BackboneTracks, [1.0, 1.0, 0.25]),
            shares(Prior::UniqueTracks, [0.5, 0.0, 1.0]),
            shares(Prior::LoopFraction, [0.25, 1.0, f64::NAN]),
            shares(Prior::Context, [0.0, 0.0, 0.0]),
        ];
        let c = compute(&model, &[], &pairs);
        let expected = [0.125f64.cbrt(), 0.0, 0.5];
        for (cost, want) in c.pair_costs.iter().zip(expected) {
            assert!((cost + want).abs() < 1e-12, "{:?}", c.pair_costs);
        }
        model.pair_mean = Mean::Arithmetic;
        let c = compute(&model, &[], &pairs);
        assert_eq!(c.pair_costs, vec![-1.75 / 3.0, -2.0 / 3.0, -0.625]);
    }
}
