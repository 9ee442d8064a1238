//! Querying the n-gram model as in the paper: given the distance to cover and the hand support
//! available along the path (human scale; the caller divides by scf and by the robot scale), the
//! most probable admissible token sequence (beam search) or a sampled one (seeded). A sequence
//! starts in double support, may use a hand only where that hand's affordance is available, and
//! ends in double support once the accumulated forward root translation reaches the distance.

use rand::Rng;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;

use super::error::LearnError;
use super::model::{BOS, NgramModel};

/// How to pick the sequence.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Search {
    /// The most probable sequence, beam search of this width.
    Beam(usize),
    /// A sequence sampled token by token from the model with this seed.
    Sample(u64),
}

/// What to generate (human-scale metres along the path).
#[derive(Clone, Debug, PartialEq)]
pub struct Query {
    /// Distance to cover along the path (m) (> 0).
    pub distance: f64,
    /// Intervals `[from, to]` along the path where the left (0) / right (1) hand may hold on.
    pub hands: [Vec<[f64; 2]>; 2],
    /// Beam search or sampling.
    pub search: Search,
}

/// A generated token sequence with the path position of every stance.
#[derive(Clone, Debug, PartialEq)]
pub struct Generated {
    /// Token ids (≥ 2), one per stance.
    pub tokens: Vec<u32>,
    /// Hand contacts `[left, right]` of every stance: the token's own, or added by the model's
    /// hand-support part where an affordance is available.
    pub hands: Vec<[bool; 2]>,
    /// Along-path root position of each stance (m).
    pub progress: Vec<f64>,
    /// Log-probability of the sequence under the model.
    pub log_probability: f64,
}

#[derive(Clone)]
struct Hypothesis {
    tokens: Vec<u32>,
    hands: Vec<[bool; 2]>,
    progress: Vec<f64>,
    score: f64,
}

impl Hypothesis {
    fn at(&self) -> f64 {
        self.progress.last().copied().unwrap_or(0.0)
    }

    fn history(&self) -> Vec<u32> {
        std::iter::once(BOS)
            .chain(self.tokens.iter().copied())
            .collect()
    }
}

/// Answers a query.
pub fn generate_tokens(model: &NgramModel, query: &Query) -> Result<Generated, LearnError> {
    if !(query.distance > 0.0 && query.distance <= 10_000.0) {
        return Err(LearnError::Query(format!(
            "distance {} m: must be in (0, 10000]",
            query.distance
        )));
    }
    let forward: f64 = model
        .tokens
        .iter()
        .map(|t| t.translation[0].max(0.0) * t.count as f64)
        .sum::<f64>()
        / model.tokens.iter().map(|t| t.count as f64).sum::<f64>();
    if forward <= 0.0 {
        return Err(LearnError::Query(
            "the model's stances do not move forward".into(),
        ));
    }
    let max_stances = (4.0 * query.distance / forward) as usize + 20;
    match query.search {
        Search::Beam(width) => beam(model, query, width.max(1), max_stances),
        Search::Sample(seed) => sample(model, query, seed, max_stances),
    }
}

/// Whether token `id` may follow a hypothesis at path position `at`.
fn admissible(model: &NgramModel, query: &Query, first: bool, at: f64, id: u32) -> bool {
    let token = model.token(id);
    if first && !(token.contacts[0] && token.contacts[1]) {
        return false;
    }
    (0..2).all(|hand| !token.contacts[2 + hand] || available(query, hand, at))
}

/// Whether hand `hand` may hold on at path position `at`.
fn available(query: &Query, hand: usize, at: f64) -> bool {
    query.hands[hand]
        .iter()
        .any(|[from, to]| (*from..=*to).contains(&at))
}

/// The hand contacts token `id` may take at `at`, each with its probability factor: a token
/// with its own hand contacts keeps them; a foot-only token may gain a grasp of each available
/// hand with the model's hand-support probability (given the previous stance's grasp).
fn hand_options(
    model: &NgramModel,
    query: &Query,
    hypothesis: &Hypothesis,
    id: u32,
    at: f64,
) -> Vec<([bool; 2], f64)> {
    let token = model.token(id);
    if token.contacts[2] || token.contacts[3] {
        return vec![([token.contacts[2], token.contacts[3]], 1.0)];
    }
    let previous = hypothesis.hands.last().copied().unwrap_or([false; 2]);
    let mut options = vec![([false; 2], 1.0)];
    for hand in 0..2 {
        let support = model.hand_support([token.contacts[0], token.contacts[1]], hand);
        let Some(support) = support.filter(|_| available(query, hand, at)) else {
            continue;
        };
        let p = support.probability(previous[hand]);
        options = options
            .into_iter()
            .flat_map(|(hands, factor)| {
                let mut with = hands;
                with[hand] = true;
                [(hands, factor * (1.0 - p)), (with, factor * p)]
            })
            .collect();
    }
    options
}

/// Path position after appending token `id` (the first stance stands at 0).
fn advance(model: &NgramModel, hypothesis: &Hypothesis, id: u32) -> f64 {
    if hypothesis.tokens.is_empty() {
        0.0
    } else {
        hypothesis.at() + model.token(id).translation[0]
    }
}

fn complete(model: &NgramModel, query: &Query, hypothesis: &Hypothesis) -> bool {
    hypothesis.tokens.last().is_some_and(|&id| {
        let c = model.token(id).contacts;
        c[0] && c[1] && hypothesis.at() >= query.distance
    })
}

fn beam(
    model: &NgramModel,
    query: &Query,
    width: usize,
    max_stances: usize,
) -> Result<Generated, LearnError> {
    let mut beams = vec![Hypothesis {
        tokens: Vec::new(),
        hands: Vec::new(),
        progress: Vec::new(),
        score: 0.0,
    }];
    let mut best: Option<Hypothesis> = None;
    for _ in 0..max_stances {
        let mut candidates: Vec<Hypothesis> = Vec::new();
        for hypothesis in &beams {
            let history = hypothesis.history();
            let first = hypothesis.tokens.is_empty();
            for id in model.token_ids() {
                let at = advance(model, hypothesis, id);
                if !admissible(model, query, first, at, id) {
                    continue;
                }
                let p = model.probability(&history, id);
                for (hands, factor) in hand_options(model, query, hypothesis, id, at) {
                    let mut next = hypothesis.clone();
                    next.score += (p * factor).ln();
                    next.tokens.push(id);
                    next.hands.push(hands);
                    next.progress.push(at);
                    candidates.push(next);
                }
            }
        }
        candidates.sort_by(|a, b| b.score.total_cmp(&a.score));
        beams.clear();
        for candidate in candidates {
            if complete(model, query, &candidate) {
                if best.as_ref().is_none_or(|b| candidate.score > b.score) {
                    best = Some(candidate);
                }
            } else if beams.len() < width {
                beams.push(candidate);
            }
        }
        // Every open hypothesis already scores below the best complete one: done.
        let bound = best.as_ref().map_or(f64::NEG_INFINITY, |b| b.score);
        beams.retain(|h| h.score > bound);
        if beams.is_empty() {
            break;
        }
    }
    best.map(finish).ok_or_else(|| {
        LearnError::Query(format!(
            "no admissible sequence reaches {:.2} m within {max_stances} stances",
            query.distance
        ))
    })
}

fn sample(
    model: &NgramModel,
    query: &Query,
    seed: u64,
    max_stances: usize,
) -> Result<Generated, LearnError> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let mut hypothesis = Hypothesis {
        tokens: Vec::new(),
        hands: Vec::new(),
        progress: Vec::new(),
        score: 0.0,
    };
    while hypothesis.tokens.len() < max_stances {
        let history = hypothesis.history();
        let first = hypothesis.tokens.is_empty();
        let options: Vec<(u32, [bool; 2], f64, f64)> = model
            .token_ids()
            .flat_map(|id| {
                let at = advance(model, &hypothesis, id);
                let options = if admissible(model, query, first, at, id) {
                    hand_options(model, query, &hypothesis, id, at)
                } else {
                    Vec::new()
                };
                let p = model.probability(&history, id);
                options
                    .into_iter()
                    .map(move |(hands, factor)| (id, hands, at, p * factor))
            })
            .collect();
        let total: f64 = options.iter().map(|o| o.3).sum();
        if options.is_empty() || total <= 0.0 {
            break;
        }
        let mut pick = rng.random_range(0.0..total);
        let &(id, hands, at, p) = options
            .iter()
            .find(|o| {
                pick -= o.3;
                pick < 0.0
            })
            .unwrap_or(options.last().expect("non-empty"));
        hypothesis.score += p.ln();
        hypothesis.tokens.push(id);
        hypothesis.hands.push(hands);
        hypothesis.progress.push(at);
        if complete(model, query, &hypothesis) {
            return Ok(finish(hypothesis));
        }
    }
    Err(LearnError::Query(format!(
        "sampling (seed {seed}) did not reach {:.2} m within {max_stances} stances",
        query.distance
    )))
}

fn finish(hypothesis: Hypothesis) -> Generated {
    Generated {
        tokens: hypothesis.tokens,
        hands: hypothesis.hands,
        progress: hypothesis.progress,
        log_probability: hypothesis.score,
    }
}
