//! The n-gram model over stance tokens. A token is a taxonomy class (which feet and hands
//! support) plus a cluster of similar poses within that class (k-means on the root translation
//! and the end-effector positions relative to the root); its prototype is the cluster mean. The
//! model counts token n-grams of order up to `order` and gives probabilities by interpolated
//! absolute discounting, backing off to shorter contexts down to an add-one unigram.

use std::collections::BTreeMap;
use std::path::Path;

use serde::{Deserialize, Serialize};

use super::cluster::cluster;
use super::demo::Demonstration;
use super::error::LearnError;
use super::hands::{HandSupport, count_hand_support};
use super::segment::{Keyframe, RelativePose, SegmentOptions, segment};

/// Token id of the sequence start (context only).
pub const BOS: u32 = 0;
/// Token id of the sequence end.
pub const EOS: u32 = 1;
/// First id of a real stance token.
const FIRST_TOKEN: u32 = 2;
/// Version of the model file format.
const FORMAT_VERSION: u32 = 1;

/// How to train.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TrainOptions {
    /// n of the n-gram (≥ 1; 3 = trigram).
    pub order: usize,
    /// Absolute discount D in (0, 1).
    pub discount: f64,
    /// Largest number of pose clusters per taxonomy class.
    pub max_clusters: usize,
    /// Also learn every demonstration mirrored left ↔ right.
    pub mirror: bool,
    /// Contact detection thresholds.
    pub segment: SegmentOptions,
}

impl Default for TrainOptions {
    fn default() -> Self {
        Self {
            order: 3,
            discount: 0.75,
            max_clusters: 8,
            mirror: true,
            segment: SegmentOptions::default(),
        }
    }
}

/// A stance token: its taxonomy class, label and the prototype (mean) stance of its cluster.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Token {
    /// Taxonomy label and cluster index, e.g. `2F#1`.
    pub label: String,
    /// Contact flags `[lf, rf, lh, rh]`.
    pub contacts: [bool; 4],
    /// Number of training keyframes in the cluster.
    pub count: usize,
    /// Mean stance duration (s).
    pub duration: f64,
    /// Mean pelvis height above the contact feet (m).
    pub root_height: f64,
    /// Mean root translation from the previous stance (previous heading frame) (m).
    pub translation: [f64; 3],
    /// Mean end-effector poses relative to the root (`None`: hand never recorded).
    pub effectors: [Option<RelativePose>; 4],
}

/// Counts of the tokens following one context.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ContextCounts {
    /// The context, oldest token first (may be empty: the unigram).
    pub context: Vec<u32>,
    /// `(token, count)` pairs, sorted by token.
    pub next: Vec<(u32, u32)>,
}

/// A trained n-gram stance model (the JSON file `walkctl learn` writes).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct NgramModel {
    /// File format version.
    pub version: u32,
    /// n of the n-gram.
    pub order: usize,
    /// Absolute discount.
    pub discount: f64,
    /// Median pelvis height above the feet over all double-support keyframes (m): the human
    /// size the retargeting scales from.
    pub human_pelvis_height: f64,
    /// Names of the training trials.
    pub trained_on: Vec<String>,
    /// Tokens; token id `i + 2` is `tokens[i]` (0 = start, 1 = end).
    pub tokens: Vec<Token>,
    /// n-gram counts for every context length 0..order.
    pub counts: Vec<ContextCounts>,
    /// How hands join foot stances where a hand affordance is available.
    pub hand_support: Vec<HandSupport>,
    #[serde(skip)]
    index: BTreeMap<Vec<u32>, usize>,
}

impl NgramModel {
    /// Trains on demonstrations (segmented with `options.segment`).
    pub fn train(demos: &[Demonstration], options: &TrainOptions) -> Result<Self, LearnError> {
        if options.order == 0 || !(options.discount > 0.0 && options.discount < 1.0) {
            return Err(LearnError::Query(format!(
                "order {} and discount {}: need order ≥ 1 and 0 < discount < 1",
                options.order, options.discount
            )));
        }
        let mut sequences: Vec<Vec<Keyframe>> = demos
            .iter()
            .map(|d| segment(d, &options.segment).keyframes)
            .filter(|k| !k.is_empty())
            .collect();
        if options.mirror {
            let mirrored: Vec<Vec<Keyframe>> = sequences
                .iter()
                .map(|s| s.iter().map(Keyframe::mirrored).collect())
                .collect();
            sequences.extend(mirrored);
        }
        if sequences.is_empty() {
            return Err(LearnError::Query(
                "no stance found in the demonstrations".into(),
            ));
        }
        let (tokens, assignment) = cluster(&sequences, options.max_clusters);
        let mut counts: BTreeMap<Vec<u32>, BTreeMap<u32, u32>> = BTreeMap::new();
        for ids in &assignment {
            let mut stream = vec![BOS];
            stream.extend(ids.iter().map(|&i| i + FIRST_TOKEN));
            stream.push(EOS);
            for k in 1..stream.len() {
                for length in 0..options.order {
                    if length > k {
                        break;
                    }
                    let context = stream[k - length..k].to_vec();
                    *counts
                        .entry(context)
                        .or_default()
                        .entry(stream[k])
                        .or_default() += 1;
                }
            }
        }
        let mut heights: Vec<f64> = sequences
            .iter()
            .flatten()
            .filter(|k| k.contacts[0] && k.contacts[1])
            .map(|k| k.root_height)
            .collect();
        heights.sort_by(f64::total_cmp);
        let human_pelvis_height = heights.get(heights.len() / 2).copied().ok_or_else(|| {
            LearnError::Query("no double-support stance in the demonstrations".into())
        })?;
        let mut model = NgramModel {
            version: FORMAT_VERSION,
            order: options.order,
            discount: options.discount,
            human_pelvis_height,
            trained_on: demos.iter().map(|d| d.name.clone()).collect(),
            tokens,
            counts: counts
                .into_iter()
                .map(|(context, next)| ContextCounts {
                    context,
                    next: next.into_iter().collect(),
                })
                .collect(),
            hand_support: count_hand_support(&sequences),
            index: BTreeMap::new(),
        };
        model.build_index();
        Ok(model)
    }

    /// Reads and checks a model file.
    pub fn from_path(path: &Path) -> Result<Self, LearnError> {
        let text = std::fs::read_to_string(path).map_err(|error| LearnError::Io {
            path: path.to_path_buf(),
            error,
        })?;
        Self::from_json_str(&text, path)
    }

    /// Parses and checks a model; `path` only names the source in errors.
    pub fn from_json_str(text: &str, path: &Path) -> Result<Self, LearnError> {
        let error = |message: String| LearnError::Model {
            path: path.to_path_buf(),
            message,
        };
        let mut model: NgramModel = serde_json::from_str(text).map_err(|e| error(e.to_string()))?;
        if model.version != FORMAT_VERSION {
            return Err(error(format!(
                "version {} unsupported (expected {FORMAT_VERSION})",
                model.version
            )));
        }
        if model.order == 0 || model.tokens.is_empty() {
            return Err(error("order 0 or no tokens".into()));
        }
        let limit = model.tokens.len() as u32 + FIRST_TOKEN;
        for (k, entry) in model.counts.iter().enumerate() {
            if entry.context.len() >= model.order
                || entry
                    .context
                    .iter()
                    .chain(entry.next.iter().map(|(t, _)| t))
                    .any(|&t| t >= limit)
            {
                return Err(error(format!(
                    "counts[{k}]: context longer than order − 1 or token id ≥ {limit}"
                )));
            }
        }
        for (k, token) in model.tokens.iter().enumerate() {
            if !(token.contacts[0] || token.contacts[1]) {
                return Err(error(format!(
                    "tokens[{k}] ({}): no foot support",
                    token.label
                )));
            }
        }
        model.build_index();
        Ok(model)
    }

    /// The model as pretty JSON (deterministic for the same training data).
    pub fn to_json_string(&self) -> String {
        serde_json::to_string_pretty(self).expect("model serialises")
    }

    fn build_index(&mut self) {
        self.index = self
            .counts
            .iter()
            .enumerate()
            .map(|(k, c)| (c.context.clone(), k))
            .collect();
    }

    /// Number of token ids (start, end and stance tokens).
    pub fn vocabulary(&self) -> u32 {
        self.tokens.len() as u32 + FIRST_TOKEN
    }

    /// The stance token of id `id` (≥ 2).
    pub fn token(&self, id: u32) -> &Token {
        &self.tokens[(id - FIRST_TOKEN) as usize]
    }

    /// The hand-support entry of a foot support and hand, if the model has one with a grasp pose.
    pub fn hand_support(&self, feet: [bool; 2], hand: usize) -> Option<&HandSupport> {
        self.hand_support
            .iter()
            .find(|h| h.feet == feet && h.hand == hand && h.pose.is_some())
    }

    /// Ids of the stance tokens.
    pub fn token_ids(&self) -> std::ops::Range<u32> {
        FIRST_TOKEN..self.vocabulary()
    }

    /// P(next | history) with interpolated absolute discounting and back-off; only the last
    /// `order − 1` tokens of `history` matter.
    pub fn probability(&self, history: &[u32], next: u32) -> f64 {
        let unigram = self.index.get(&Vec::new()).map(|&k| &self.counts[k]);
        let (total, count) = unigram.map_or((0, 0), |u| (sum(u), find(u, next)));
        // Add-one over the tokens that can follow (not the start symbol).
        let mut p =
            (f64::from(count) + 1.0) / (f64::from(total) + f64::from(self.vocabulary() - 1));
        let longest = history.len().min(self.order - 1);
        for length in 1..=longest {
            let context = &history[history.len() - length..];
            let Some(&k) = self.index.get(context) else {
                continue;
            };
            let entry = &self.counts[k];
            let total = f64::from(sum(entry));
            let seen = entry.next.len() as f64;
            let discounted = (f64::from(find(entry, next)) - self.discount).max(0.0);
            p = discounted / total + self.discount * seen / total * p;
        }
        p
    }
}

fn sum(entry: &ContextCounts) -> u32 {
    entry.next.iter().map(|(_, c)| c).sum()
}

fn find(entry: &ContextCounts, token: u32) -> u32 {
    entry
        .next
        .binary_search_by_key(&token, |(t, _)| *t)
        .map_or(0, |k| entry.next[k].1)
}
