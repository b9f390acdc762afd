//! `check`: is a reconstruction ghosted, and where? One line per model, a JSON report, a top
//! view per model, and an exit status a pipeline can branch on (3: a model is wrong).

use super::args::CheckOptions;
use crate::cli::progress::Progress;
use anyhow::{Context, Result};
use clap::Args;
use std::path::{Path, PathBuf};
use vgsel_colmap::check::evidence::Evidence;
use vgsel_colmap::check::resection::Rejoin;
use vgsel_colmap::check::{self, CheckSettings, ModelCheck, Verdict};
use vgsel_colmap::colmap::database::Database;
use vgsel_colmap::colmap::model::model_dirs;
use vgsel_colmap::colmap::sparse::{read_sparse_model, SparseModel};
use vgsel_colmap::colmap::DEFAULT_MIN_NUM_MATCHES;
use vgsel_colmap::geometry::similarity::Similarity;

/// Exit status of a check that found a model wrong: ghosted, with a misplaced group or image,
/// folded against the capture order (`--sequence`), or with images registered on (next to) no
/// 3D point.
pub const EXIT_GHOSTED: u8 = 3;

/// `--help`'s heading of the scoring options, after the inputs and outputs a user names.
const SETTINGS: &str =
    "The check's settings (all but --threshold for experts; `prune --model` takes the same)";

#[derive(Args)]
#[command(rename_all = "snake_case")]
pub struct CheckArgs {
    /// A COLMAP model folder (binary or text), or a folder of sub-models (mapper's output_path):
    /// each is checked.
    #[arg(long, value_name = "DIR")]
    model: PathBuf,
    /// The database the model was made from: names the verified pairs that join the groups, and
    /// its matches tell the same structure kept as two tracks from two copies (recommended).
    #[arg(long, value_name = "DB")]
    database_path: Option<PathBuf>,
    /// Write the JSON report to FILE.
    #[arg(long, value_name = "FILE")]
    report: Option<PathBuf>,
    /// Write each model's top view (cameras coloured by group) as SVG into DIR.
    #[arg(long, value_name = "DIR")]
    plots: Option<PathBuf>,
    /// Write the images that the database's usable pairs link and no model registered, one name
    /// a line, as `colmap mapper --image_list_path` reads them (empty when there are none):
    /// with COLMAP 3.8, the repair loop maps them on their own into DIR/left after every run
    /// (README).
    #[arg(long, value_name = "FILE", requires = "database_path")]
    unregistered: Option<PathBuf>,
    /// The repair loop's earlier mapper output folders on this database, in the order they ran
    /// (repeatable, as `prune --model` takes them): where a model of theirs was ghosted between
    /// two clean models of this run, it placed one in the other's frame and that was refuted, so
    /// their strongest placement without conflict joins them, unless it puts them where that
    /// ghost had them.
    #[arg(long, value_name = "DIR", requires = "database_path")]
    earlier_model: Vec<PathBuf>,
    /// The images' names sort in capture order, one sequence (a walk, an orbit, a video), each
    /// image overlapping the next: a model that holds the matches of an image and the next as
    /// two surfaces is folded.
    #[arg(long, requires = "database_path")]
    sequence: bool,
    #[command(flatten, next_help_heading = SETTINGS)]
    options: CheckOptions,
}

impl CheckArgs {
    fn settings(&self) -> CheckSettings {
        CheckSettings {
            sequence: self.sequence,
            ..self.options.settings()
        }
    }
}

/// Model `k`'s top view (`dir`'s, checked as `result`) into `plots` as `top_view_K.svg`.
fn plot(plots: &Path, k: usize, dir: &Path, result: &ModelCheck) -> Result<()> {
    let Some(views) = &result.views else {
        return Ok(());
    };
    std::fs::create_dir_all(plots).with_context(|| format!("creating {}", plots.display()))?;
    let title = format!(
        "{}: {} (score {:.2})",
        dir.display(),
        result.verdict().word(),
        result.score
    );
    let path = plots.join(format!("top_view_{k}.svg"));
    check::plot::top_view(views, &result.groups(), &title, &path)
}

/// The line a model gets: its verdict, score and groups; a clean model whose worst split had
/// fewer judged samples than `min_conflicts` says so, as no ghost could have been found there,
/// and one whose image alone scored from the threshold says why it is not ghosted.
fn verdict_line(dir: &Path, c: &ModelCheck, settings: &CheckSettings) -> String {
    let what = match c.verdict() {
        Verdict::Clean => "clean".to_string(),
        wrong => wrong.word().to_uppercase(),
    };
    // A model without points (a failed start) was judged on nothing: no score to give.
    let mut line = match c.points {
        0 => format!("{}: {what} (no 3D point", dir.display()),
        _ => format!("{}: {what} (score {:.2}", dir.display(), c.score),
    };
    if let Some(w) = c.worst.as_ref().filter(|_| c.points > 0) {
        let judged = w.counts.conflicting + w.counts.agreeing;
        line += &format!(
            ", {} conflicting of {judged} judged{}; groups of {} and {} images",
            w.counts.conflicting,
            bare(&w.counts),
            w.groups[0].len(),
            w.groups[1].len()
        );
        if let Some(one) = w.groups.iter().find(|g| g.len() == 1) {
            line += &format!(": {} alone", one[0]);
            if !c.ghosted && c.score >= settings.threshold {
                line += &format!(
                    ", which its matches do not place elsewhere: ghosted from {:.2}",
                    settings.alone_threshold
                );
            }
        }
        if judged < settings.min_conflicts && c.misplaced.is_none() {
            line += "; too few samples to find a ghost";
        }
        if let Some(m) = &c.misplaced {
            line += &placement_text(m);
        }
        if !c.again.is_empty() {
            line += &format!(
                "; where an earlier run's ghost had them: {}",
                c.again
                    .iter()
                    .take(3)
                    .cloned()
                    .collect::<Vec<_>>()
                    .join(" ")
            );
        }
        if c.ghosted {
            line += &format!(
                "; {} joining pairs, e.g. {}",
                w.joining_pairs.len(),
                examples(w.joining_pairs.iter().map(|p| (&p.image1, &p.image2)))
            );
        }
        for inner in &c.inner {
            line += &format!(
                "; within a group, groups of {} and {} images (score {:.2}; {} joining pairs)",
                inner.groups[0].len(),
                inner.groups[1].len(),
                inner.score,
                inner.joining_pairs.len()
            );
        }
        if let Some(m) = &c.ghost_placement {
            line += &placement_text(m);
        }
    }
    line + &images_text(c) + ")"
}

/// What the verdict line says of a model's images apart from its split: those placed
/// elsewhere, neighbours in the capture order held apart, detached parts, unanchored images.
fn images_text(c: &ModelCheck) -> String {
    let mut line = String::new();
    for m in &c.misplaced_images {
        line += &misplaced_image_text(m, c);
    }
    if !c.neighbours_apart.is_empty() {
        let n = c.neighbours_apart.len();
        line += &format!(
            "; {n} pair{} of images next in the capture order held as two surfaces, e.g. {}",
            if n == 1 { "" } else { "s" },
            examples(c.neighbours_apart.iter().map(|[a, b]| (a, b)))
        );
    }
    if let [largest, rest @ ..] = c.detached.as_slice() {
        let sizes: Vec<String> = c.detached.iter().map(|p| p.len().to_string()).collect();
        line += &format!(
            "; {} parts that share no 3D point, of {} images; apart from the {}: {}",
            c.detached.len(),
            sizes.join(" and "),
            largest.len(),
            rest.iter()
                .flatten()
                .take(3)
                .cloned()
                .collect::<Vec<_>>()
                .join(" ")
        );
    }
    if !c.unanchored.is_empty() {
        let n = c.unanchored.len();
        line += &format!(
            "; {n} image{} registered on (next to) no 3D point: {}",
            if n == 1 { "" } else { "s" },
            c.unanchored
                .iter()
                .take(3)
                .cloned()
                .collect::<Vec<_>>()
                .join(" ")
        );
    }
    line
}

/// Where the database's matches place one image of model `c`, the pairs for and against it,
/// and, where they name a third place, why the repair takes its pairs or not
/// ([`ModelCheck::takes`]).
fn misplaced_image_text(m: &check::resection::ImagePlacement, c: &ModelCheck) -> String {
    // A pose far outside the model (RANSAC on few distant points) is no distance worth
    // printing.
    let distance = match m.moved {
        d if d > 10.0 => "over 10 times the model's spread".to_string(),
        d => format!("{:.0}% of the model's spread", 100.0 * d),
    };
    let text = format!(
        "; the database's matches place {} {distance} away ({} of {} correspondences agree, \
         {} with the model's pose); {} pairs place it back, {} against it, {} matches hold it \
         there",
        m.image,
        m.support,
        m.correspondences,
        m.model_support,
        m.links.len(),
        m.against.len(),
        m.holding.iter().map(|h| h.matches.len()).sum::<usize>()
    );
    if !m.third_place() {
        return text;
    }
    let third = format!("; {} more agree with a third pose", m.elsewhere);
    let why = if m.dominates() {
        format!(
            ", but the matches' pose holds {:.1} times the model's and the third's",
            m.dominance()
        )
    } else if !m.held_by_pairs() {
        ": it matches a third place, and no pair holds it where the model put it".to_string()
    } else if c.takes(m) {
        format!(
            ", but {} pairs hold it where the model put it",
            m.against.len()
        )
    } else {
        format!(
            ": it matches a third place, and {} more images of the model are misplaced",
            c.misplaced_images.len() - 1
        )
    };
    let takes = if c.takes(m) { "its" } else { "none of its" };
    format!("{text}{third}{why}: the repair takes {takes} pairs")
}

/// Where the database's matches place a model's second group, and the pairs that link it.
fn placement_text(m: &check::join::Join) -> String {
    let placement = Similarity::from(&m.placement);
    format!(
        "; the database's matches place the second group {:.0}\u{b0} turned, scaled {:.2} (by \
         {} of {} correspondences, after {} refuted); {} pairs link them, e.g. {}",
        placement.rotation.angle().to_degrees(),
        placement.scale,
        m.support,
        m.correspondences,
        m.refuted,
        m.links.len(),
        examples(m.links.iter().map(|l| (&l.image1, &l.image2)))
    ) + &trimmed_text(&m.links)
}

/// The first three `pairs` as `a-b c-d e-f`.
fn examples<'a>(pairs: impl Iterator<Item = (&'a String, &'a String)>) -> String {
    pairs
        .take(3)
        .map(|(a, b)| format!("{a}-{b}"))
        .collect::<Vec<_>>()
        .join(" ")
}

/// The images the database links and no model registered: a line where there are any, and the
/// list written to `path` (`--unregistered`).
fn print_unregistered(names: &[String], path: Option<&Path>) -> Result<()> {
    if !names.is_empty() {
        println!("{}", unregistered_line(names));
    }
    if let Some(path) = path {
        let lines: String = names.iter().map(|n| format!("{n}\n")).collect();
        std::fs::write(path, lines).with_context(|| format!("writing {}", path.display()))?;
    }
    Ok(())
}

/// The ghosts of the `--earlier_model` folders, each checked after the ones before it (as
/// `prune --model` checks its folders).
fn earlier_ghosts(
    dirs: &[PathBuf],
    evidence: Option<&Evidence>,
    settings: &CheckSettings,
) -> Result<Vec<check::join::Glued>> {
    match evidence {
        Some(e) => {
            let runs = check::repair::read_runs(dirs, "--earlier_model")?;
            let found = check::repair::loop_evidence(
                dirs,
                &runs,
                "--earlier_model",
                e,
                settings,
                Vec::new(),
            );
            Ok(found?.1)
        }
        None => Ok(Vec::new()),
    }
}

/// The line for images the database links and no model registered (at least one).
fn unregistered_line(names: &[String]) -> String {
    format!(
        "{} images the database's pairs link are in no model: {} (with COLMAP 3.8, map them \
         on their own: --unregistered FILE, then colmap mapper --image_list_path FILE \
         --Mapper.min_model_size 3)",
        names.len(),
        listed(names)
    )
}

/// The line for the images no model registered that their matches place in a clean model
/// through pairs the database does not offer (`lacked`); none without such a pair.
fn rejoined_line(rejoined: &[Rejoin], lacked: &[[String; 2]]) -> Option<String> {
    let placed: Vec<&Rejoin> = (rejoined.iter())
        .filter(|r| r.links.iter().any(|p| lacked.contains(p)))
        .collect();
    let names: Vec<String> = placed.iter().map(|r| r.image.clone()).collect();
    let second = match placed.iter().filter(|r| r.second_place).count() {
        0 => String::new(),
        n => format!(
            "; {n} at their matches' second place, an earlier run's ghost had them at the first"
        ),
    };
    (!placed.is_empty()).then(|| {
        format!(
            "{} images no model registered are placed by their matches in a clean model: {} \
             (prune --model keeps the {} pairs that place them, which this database does not \
             offer{second})",
            placed.len(),
            listed(&names),
            lacked.len()
        )
    })
}

/// The first five of `names`, and `...` for more.
fn listed(names: &[String]) -> String {
    let shown: Vec<&str> = names.iter().take(5).map(String::as_str).collect();
    let more = if names.len() > shown.len() {
        " ..."
    } else {
        ""
    };
    format!("{}{more}", shown.join(" "))
}

/// The bare samples beside a line's counts, where `--bare_weight` counted any.
fn bare(counts: &check::conflict::Counts) -> String {
    match counts.bare {
        0 => String::new(),
        n => format!(" and {n} bare"),
    }
}

/// The line a join gets: the two models, how many pairs link them and how well they agree.
fn join_line(dirs: &[PathBuf], j: &check::join::Join) -> String {
    let judged = j.counts.conflicting + j.counts.agreeing;
    format!(
        "{} + {}: one scene (placed by {} of {} correspondences, score {:.2}, {} conflicting of \
         {judged} judged{}); {} pairs link them, e.g. {}",
        dirs[j.models[0]].display(),
        dirs[j.models[1]].display(),
        j.support,
        j.correspondences,
        j.score,
        j.counts.conflicting,
        bare(&j.counts),
        j.links.len(),
        examples(j.links.iter().map(|l| (&l.image1, &l.image2)))
    ) + &trimmed_text(&j.links)
}

/// For links kept with only their agreeing matches ([`check::join::Link::dropped`]): how many,
/// how many matches they keep and how many the repair drops.
fn trimmed_text(links: &[check::join::Link]) -> String {
    let trimmed: Vec<_> = links.iter().filter(|l| !l.dropped.is_empty()).collect();
    let dropped: usize = trimmed.iter().map(|l| l.dropped.len()).sum();
    match trimmed.len() {
        0 => String::new(),
        n => format!(
            ", {n} kept with only their {} agreeing matches ({dropped} others dropped)",
            trimmed.iter().map(|l| l.agreeing).sum::<usize>()
        ),
    }
}

/// The line for two clean models left apart that share enough correspondences to be placed:
/// why no placement joins them, so that a scene in pieces is not a mystery.
fn apart_line(dirs: &[PathBuf], a: &check::join::Apart) -> String {
    use check::join::ApartReason;
    // Every reason but `NoPlacement` has a scored placement; that one prints none.
    let score = a.score.map_or_else(String::new, |s| format!("{s:.2}"));
    let why = match a.reason {
        ApartReason::NoPlacement => format!(
            "no placement of their {} correspondences joins them{}; {} refuted",
            a.correspondences,
            tried_counts(&a.tried),
            a.refuted
        ),
        ApartReason::NothingRefuted => format!(
            "their strongest placement does not conflict, score {score}, but nothing \
             stronger was refuted: it may put copies onto each other"
        ),
        ApartReason::Doubtful => format!(
            "their first placement without a conflict scores {score}, too near a ghost's \
             to keep its links"
        ),
        ApartReason::ThirdPlace => format!(
            "their matches place the second in two places the check cannot tell apart, the \
             first scoring {score}"
        ),
    };
    format!(
        "{} + {}: apart ({why})",
        dirs[a.models[0]].display(),
        dirs[a.models[1]].display()
    )
}

/// What became of the placements `tried` for two models left apart, by verdict (", 1 where an
/// earlier run's ghost had them, 2 explaining too few of their pairs"); empty without any.
fn tried_counts(tried: &[check::join::Tried]) -> String {
    use check::join::TriedVerdict::*;
    let said = [
        (Conflicts, "conflicting"),
        (GhostAgain, "where an earlier run's ghost had them"),
        (TooFew, "explaining too few of their pairs"),
        (OneSpot, "on one spot"),
        (Clean, "clean"),
    ];
    let parts: Vec<String> = (said.iter())
        .map(|(v, what)| (tried.iter().filter(|t| t.verdict == *v).count(), what))
        .filter(|(n, _)| *n > 0)
        .map(|(n, what)| format!("{n} {what}"))
        .collect();
    match parts.is_empty() {
        true => String::new(),
        false => format!(": {}", parts.join(", ")),
    }
}

/// `item`'s JSON with the folders of its two `models` (indices of `dirs`) as `model_paths`.
fn with_model_paths(
    item: &impl serde::Serialize,
    models: [usize; 2],
    dirs: &[PathBuf],
) -> Result<serde_json::Value> {
    let mut value = serde_json::to_value(item)?;
    value["model_paths"] = models
        .map(|m| dirs[m].display().to_string())
        .to_vec()
        .into();
    Ok(value)
}

/// What the check reads: the model folders, their models, the database's evidence (with the
/// images no model registered read for placing them) and the images the database links that
/// no model registered.
struct Inputs {
    dirs: Vec<PathBuf>,
    models: Vec<SparseModel>,
    evidence: Option<Evidence>,
    unregistered: Vec<String>,
}

/// Reads the check's [`Inputs`]; `quiet` silences the note without a database.
fn read_inputs(args: &CheckArgs, quiet: bool, progress: &Progress) -> Result<Inputs> {
    let db = match &args.database_path {
        Some(path) => Some(Database::open_read_only(path)?),
        None => None,
    };
    if db.is_some() {
        progress.stage("reading the database's matches");
    }
    let mut evidence = db.as_ref().map(Evidence::load).transpose()?;
    if evidence.is_none() && !quiet {
        eprintln!(
            "vgsel-colmap check: note: without --database_path, a surface that a sparse \
             selection triangulated twice looks like two copies (docs/check.md)"
        );
    }
    let dirs = model_dirs(&args.model)?;
    anyhow::ensure!(
        !dirs.is_empty(),
        "no COLMAP model in {}",
        args.model.display()
    );
    let plural = if dirs.len() == 1 { "" } else { "s" };
    progress.stage(&format!("reading {} model{plural}", dirs.len()));
    let models = dirs
        .iter()
        .map(|dir| read_sparse_model(dir))
        .collect::<Result<Vec<_>>>()?;
    let mut unregistered = Vec::new();
    if let (Some(e), Some(db)) = (&mut evidence, &db) {
        unregistered = e.unregistered(&models, DEFAULT_MIN_NUM_MATCHES);
        let lost = e.lost(&models, DEFAULT_MIN_NUM_MATCHES);
        e.read_lost(db, &lost)?;
    }
    Ok(Inputs {
        dirs,
        models,
        evidence,
        unregistered,
    })
}

/// Runs the check; Ok(true) when some model is wrong (ghosted, misplaced, folded, detached or
/// unanchored).
/// `quiet` silences the note on stderr; `progress` shows the stages (a large model's check
/// takes minutes).
pub fn run(args: &CheckArgs, quiet: bool, progress: &Progress) -> Result<bool> {
    let settings = args.settings();
    let Inputs {
        dirs,
        models,
        evidence,
        unregistered,
    } = read_inputs(args, quiet, progress)?;
    let images: usize = models.iter().map(|m| m.images.len()).sum();
    progress.stage(&format!("checking {images} registered images"));
    let earlier = earlier_ghosts(&args.earlier_model, evidence.as_ref(), &settings)?;
    let run = check::check_run(&models, evidence.as_ref(), &settings, &earlier)?;
    progress.finish();
    let mut reports = Vec::new();
    for (k, (dir, result)) in dirs.iter().zip(&run.models).enumerate() {
        println!("{}", verdict_line(dir, result, &settings));
        if let Some(plots) = &args.plots {
            plot(plots, k, dir, result)?;
        }
        let mut value = serde_json::to_value(result)?;
        value["model"] = dir.display().to_string().into();
        value["verdict"] = serde_json::to_value(result.verdict())?;
        reports.push(value);
    }
    let ghosted = run.models.iter().any(|c| c.ghosted);
    let misplaced = run.models.iter().any(ModelCheck::places_elsewhere);
    let unanchored = run.models.iter().any(|c| !c.unanchored.is_empty());
    let detached = run.models.iter().any(|c| !c.detached.is_empty());
    let folded = run.models.iter().any(|c| !c.neighbours_apart.is_empty());
    // The run's verdict: the first word of the order any model earns.
    let verdict = run.models.iter().map(ModelCheck::verdict).min();
    let verdict = verdict.unwrap_or(Verdict::Clean);
    // Clean models of one run that the database's matches place in one frame without a
    // conflict: `prune --model` keeps the pairs that link them.
    let mut joined = Vec::new();
    for join in &run.joins.joined {
        println!("{}", join_line(&dirs, join));
        joined.push(with_model_paths(join, join.models, &dirs)?);
    }
    // Those left apart, with a line where their matches could have placed them.
    let mut apart = Vec::new();
    for pair in &run.joins.apart {
        if pair.correspondences >= check::join::MIN_SUPPORT {
            println!("{}", apart_line(&dirs, pair));
        }
        apart.push(with_model_paths(pair, pair.models, &dirs)?);
    }
    // What a repair turn would change: pairs that place a lost image and that the mapper
    // already had are no news (a turn would repeat the run), so the loop stops there.
    let mut repair = run.evidence();
    if let Some(e) = &evidence {
        repair
            .rejoin
            .retain(|[a, b]| !e.pairs.contains_key(&(a.clone(), b.clone())));
    }
    print_unregistered(&unregistered, args.unregistered.as_deref())?;
    if let Some(line) = rejoined_line(&run.rejoined, &repair.rejoin) {
        println!("{line}");
    }
    if let Some(path) = &args.report {
        let report = serde_json::json!({
            "verdict": verdict,
            "ghosted": ghosted,
            "misplaced": misplaced,
            "unanchored": unanchored,
            "detached": detached,
            "folded": folded,
            "settings": settings,
            "models": reports,
            "joins": joined,
            "apart": apart,
            "unregistered": unregistered,
            "rejoined": run.rejoined,
            "repair": repair,
        });
        std::fs::write(path, serde_json::to_string_pretty(&report)? + "\n")
            .with_context(|| format!("writing {}", path.display()))?;
    }
    Ok(verdict != Verdict::Clean)
}

#[cfg(test)]
mod tests {
    use super::*;
    use check::{conflict::Counts, Split, DEFAULT_SETTINGS};

    fn checked(conflicting: usize, agreeing: usize) -> ModelCheck<'static> {
        let names = |n: usize| (0..n).map(|k| format!("{k}.png")).collect();
        ModelCheck {
            images: 6,
            points: 10,
            splits_scored: 1,
            worst: Some(Split {
                groups: [names(3), names(3)],
                counts: Counts {
                    conflicting,
                    agreeing,
                    ..Counts::default()
                },
                ratio: 0.0,
                score: 0.0,
                joining_pairs: Vec::new(),
            }),
            ..ModelCheck::default()
        }
    }

    /// A misplaced image's line says what the repair does with its pairs: takes them where its
    /// matches name no third place, their pose dominates it or, alone in its model, pairs hold
    /// the image where the model put it, else none.
    #[test]
    fn a_misplaced_images_line_says_whether_the_repair_takes_its_pairs() {
        let placement = |support: usize, model_support: usize, elsewhere: usize| {
            check::resection::ImagePlacement {
                image: "c.png".into(),
                correspondences: 1000,
                model_support,
                support,
                elsewhere,
                moved: 2.4,
                centre: [0.0; 3],
                links: vec![["c.png".into(), "b.png".into()]],
                against: Vec::new(),
                holding: Vec::new(),
            }
        };
        // `m` with `others` more misplaced images in its model.
        let in_model = |m: &check::resection::ImagePlacement, others: usize| {
            let c = ModelCheck {
                misplaced_images: vec![m.clone(); others + 1],
                ..ModelCheck::default()
            };
            misplaced_image_text(m, &c)
        };
        let placed = |support: usize, model_support: usize, elsewhere: usize| {
            in_model(&placement(support, model_support, elsewhere), 0)
        };
        let head = "; the database's matches place c.png 240% of the model's spread away";
        assert_eq!(
            placed(600, 200, 10),
            format!(
                "{head} (600 of 1000 correspondences agree, 200 with the model's pose); 1 pairs \
                 place it back, 0 against it, 0 matches hold it there"
            )
        );
        let refused = |elsewhere: usize| {
            format!(
                "; {elsewhere} more agree with a third pose: it matches a third place, and no \
                 pair holds it where the model put it: the repair takes none of its pairs"
            )
        };
        assert!(placed(500, 200, 100).ends_with(&refused(100)));
        assert!(placed(869, 300, 200).ends_with(&refused(200)));
        assert!(placed(870, 300, 200).ends_with(
            "; 200 more agree with a third pose, but the matches' pose holds 2.9 times the \
             model's and the third's: the repair takes its pairs"
        ));
        let held = check::resection::ImagePlacement {
            against: vec![
                ["c.png".into(), "d.png".into()],
                ["c.png".into(), "e.png".into()],
            ],
            ..placement(500, 200, 100)
        };
        assert!(in_model(&held, 0).ends_with(
            "0 matches hold it there; 100 more agree with a third pose, but 2 pairs hold it \
             where the model put it: the repair takes its pairs"
        ));
        assert!(in_model(&held, 2).ends_with(
            "0 matches hold it there; 100 more agree with a third pose: it matches a third \
             place, and 2 more images of the model are misplaced: the repair takes none of its \
             pairs"
        ));
    }

    /// A model without points says so instead of a score and groups it never judged.
    #[test]
    fn a_model_without_points_is_said_to_have_none() {
        let c = ModelCheck {
            points: 0,
            unanchored: vec!["0.png".into(), "1.png".into()],
            ..checked(0, 0)
        };
        assert_eq!(
            verdict_line(Path::new("sparse/0"), &c, &DEFAULT_SETTINGS),
            "sparse/0: UNANCHORED (no 3D point; 2 images registered on (next to) no 3D point: \
             0.png 1.png)"
        );
    }

    /// A clean verdict on fewer judged samples than a ghost needs conflicts says so; one on
    /// enough samples does not.
    #[test]
    fn a_clean_verdict_on_too_few_samples_says_so() {
        let line = verdict_line(Path::new("sparse/1"), &checked(2, 10), &DEFAULT_SETTINGS);
        assert_eq!(
            line,
            "sparse/1: clean (score 0.00, 2 conflicting of 12 judged; groups of 3 and 3 \
             images; too few samples to find a ghost)"
        );
        let line = verdict_line(Path::new("sparse/0"), &checked(2, 100), &DEFAULT_SETTINGS);
        assert!(!line.contains("too few"), "{line}");
    }

    /// Unanchored images make the verdict and are named.
    #[test]
    fn unanchored_images_are_named() {
        let mut c = checked(2, 100);
        c.unanchored = vec!["0019.png".into(), "0020.png".into()];
        let line = verdict_line(Path::new("sparse/0"), &c, &DEFAULT_SETTINGS);
        assert!(
            line.starts_with("sparse/0: UNANCHORED (score 0.00"),
            "{line}"
        );
        assert!(
            line.ends_with("; 2 images registered on (next to) no 3D point: 0019.png 0020.png)"),
            "{line}"
        );
    }

    /// Parts that share no point make the verdict, ahead of unanchored images; the parts but
    /// the largest are named.
    #[test]
    fn detached_parts_are_named() {
        let mut c = checked(2, 100);
        c.unanchored = vec!["0019.png".into()];
        let names = |ids: std::ops::Range<usize>| ids.map(|k| format!("{k:04}.png")).collect();
        c.detached = vec![names(0..6), names(6..10), names(10..11)];
        let line = verdict_line(Path::new("sparse/0"), &c, &DEFAULT_SETTINGS);
        assert!(line.starts_with("sparse/0: DETACHED (score 0.00"), "{line}");
        assert!(
            line.ends_with(
                "; 3 parts that share no 3D point, of 6 and 4 and 1 images; apart from the 6: \
                 0006.png 0007.png 0008.png; 1 image registered on (next to) no 3D point: \
                 0019.png)"
            ),
            "{line}"
        );
        // The run's verdict is the first word of the order any model earns.
        assert_eq!(c.verdict(), Verdict::Detached);
        let run = [Verdict::Clean, c.verdict(), Verdict::Unanchored];
        assert_eq!(run.into_iter().min(), Some(Verdict::Detached));
        c.ghosted = true;
        assert_eq!(c.verdict(), Verdict::Ghosted);
    }

    /// An image alone in its group is named on the verdict line.
    #[test]
    fn an_image_alone_is_named() {
        let mut c = checked(600, 400);
        c.ghosted = true;
        c.worst.as_mut().unwrap().groups[1] = vec!["0010.png".into()];
        let line = verdict_line(Path::new("sparse/0"), &c, &DEFAULT_SETTINGS);
        assert!(
            line.contains("groups of 3 and 1 images: 0010.png alone; 0 joining pairs"),
            "{line}"
        );
    }

    /// Two models left apart are named with why, the score of the placement it is about
    /// included, and the JSON beside the line names their folders.
    #[test]
    fn models_left_apart_say_why() {
        use check::join::{Apart, ApartReason};
        let dirs = [PathBuf::from("sparse/0"), PathBuf::from("sparse/1")];
        let apart = |reason, score| Apart {
            models: [0, 1],
            correspondences: 400,
            refuted: 1,
            reason,
            score,
            tried: Vec::new(),
        };
        let line = apart_line(&dirs, &apart(ApartReason::ThirdPlace, Some(0.12)));
        assert!(line.starts_with("sparse/0 + sparse/1: apart (their matches place"));
        assert!(line.contains("two places the check cannot tell apart, the first scoring 0.12"));
        let line = apart_line(&dirs, &apart(ApartReason::NoPlacement, None));
        assert!(
            line.contains("no placement of their 400 correspondences joins them; 1 refuted)"),
            "{line}"
        );
        // The placements tried, counted by what became of them.
        let tried = |verdict| check::join::Tried {
            placement: check::join::Placement {
                scale: 1.0,
                rotation: [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
                translation: [0.0; 3],
            },
            support: 40,
            linked: 0,
            ghost_offset: None,
            verdict,
            score: None,
            trimmed: false,
        };
        use check::join::TriedVerdict::{GhostAgain, TooFew};
        let three = Apart {
            tried: vec![tried(GhostAgain), tried(TooFew), tried(TooFew)],
            ..apart(ApartReason::NoPlacement, None)
        };
        let line = apart_line(&dirs, &three);
        assert!(
            line.contains(
                "joins them: 1 where an earlier run's ghost had them, 2 explaining too few of \
                 their pairs; 1 refuted)"
            ),
            "{line}"
        );
        let line = apart_line(&dirs, &apart(ApartReason::Doubtful, Some(0.45)));
        assert!(line.contains("scores 0.45, too near a ghost's"), "{line}");
        let line = apart_line(&dirs, &apart(ApartReason::NothingRefuted, Some(0.02)));
        assert!(line.contains("score 0.02, but nothing stronger"), "{line}");
        let value = with_model_paths(&apart(ApartReason::ThirdPlace, Some(0.12)), [0, 1], &dirs);
        let value = value.unwrap();
        assert_eq!(value["reason"], "third_place");
        assert_eq!(
            value["model_paths"],
            serde_json::json!(["sparse/0", "sparse/1"])
        );
    }
}
