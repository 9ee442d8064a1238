//! Pose clusters within each taxonomy class: the stance tokens of the model. k-means on the root
//! translation and the end-effector positions relative to the root; a token's prototype is the
//! mean of its cluster.

use std::collections::BTreeMap;

use super::model::Token;
use super::segment::{Keyframe, RelativePose, taxonomy_label};

/// Clustering features: root translation and the positions of feet and contact hands.
fn features(keyframe: &Keyframe) -> Vec<f64> {
    let mut f = vec![keyframe.translation[0], keyframe.translation[1]];
    for (e, pose) in keyframe.effectors.iter().enumerate() {
        if e < 2 || keyframe.contacts[e] {
            f.extend(pose.map_or([0.0; 3], |p| p.position));
        }
    }
    f
}

fn distance2(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| (x - y) * (x - y)).sum()
}

/// k-means per taxonomy class (deterministic start at ranks of the forward translation); returns the tokens and, per
/// sequence, the token index of every keyframe.
pub(super) fn cluster(
    sequences: &[Vec<Keyframe>],
    max_clusters: usize,
) -> (Vec<Token>, Vec<Vec<u32>>) {
    let mut by_class: BTreeMap<[bool; 4], Vec<(usize, usize)>> = BTreeMap::new();
    for (s, sequence) in sequences.iter().enumerate() {
        for (k, keyframe) in sequence.iter().enumerate() {
            by_class.entry(keyframe.contacts).or_default().push((s, k));
        }
    }
    let mut tokens = Vec::new();
    let mut assignment: Vec<Vec<u32>> = sequences.iter().map(|s| vec![0; s.len()]).collect();
    for (contacts, members) in by_class {
        let points: Vec<Vec<f64>> = members
            .iter()
            .map(|&(s, k)| features(&sequences[s][k]))
            .collect();
        // About five keyframes per cluster, at most `max_clusters`.
        let k = members.len().div_ceil(5).clamp(1, max_clusters.max(1));
        let labels = kmeans(&points, k);
        for cluster in 0..k {
            let group: Vec<&Keyframe> = members
                .iter()
                .zip(&labels)
                .filter(|(_, l)| **l == cluster)
                .map(|(&(s, k), _)| &sequences[s][k])
                .collect();
            if group.is_empty() {
                continue;
            }
            let id = tokens.len() as u32;
            for (&(s, k), _) in members.iter().zip(&labels).filter(|(_, l)| **l == cluster) {
                assignment[s][k] = id;
            }
            tokens.push(prototype(
                format!("{}#{cluster}", taxonomy_label(contacts)),
                contacts,
                &group,
            ));
        }
    }
    (tokens, assignment)
}

fn kmeans(points: &[Vec<f64>], k: usize) -> Vec<usize> {
    // Deterministic start: centres at evenly spaced ranks of the forward root translation (the
    // first feature), so clusters split the bulk of the data rather than chase outliers.
    let mut order: Vec<usize> = (0..points.len()).collect();
    order.sort_by(|&a, &b| points[a][0].total_cmp(&points[b][0]));
    let mut centres: Vec<Vec<f64>> = (0..k)
        .map(|c| points[order[(2 * c + 1) * points.len() / (2 * k)]].clone())
        .collect();
    let nearest = |p: &[f64], centres: &[Vec<f64>]| {
        (0..centres.len())
            .min_by(|&a, &b| distance2(p, &centres[a]).total_cmp(&distance2(p, &centres[b])))
            .expect("k ≥ 1")
    };
    let mut labels: Vec<usize> = points.iter().map(|p| nearest(p, &centres)).collect();
    for _ in 0..50 {
        for (c, centre) in centres.iter_mut().enumerate() {
            let members: Vec<&Vec<f64>> = points
                .iter()
                .zip(&labels)
                .filter(|(_, l)| **l == c)
                .map(|(p, _)| p)
                .collect();
            if !members.is_empty() {
                for (d, value) in centre.iter_mut().enumerate() {
                    *value = members.iter().map(|p| p[d]).sum::<f64>() / members.len() as f64;
                }
            }
        }
        let next: Vec<usize> = points.iter().map(|p| nearest(p, &centres)).collect();
        if next == labels {
            break;
        }
        labels = next;
    }
    labels
}

fn prototype(label: String, contacts: [bool; 4], group: &[&Keyframe]) -> Token {
    let n = group.len() as f64;
    let mean = |f: &dyn Fn(&Keyframe) -> f64| group.iter().map(|k| f(k)).sum::<f64>() / n;
    let effector = |e: usize| {
        let poses: Vec<RelativePose> = group.iter().filter_map(|k| k.effectors[e]).collect();
        RelativePose::mean(&poses)
    };
    Token {
        label,
        contacts,
        count: group.len(),
        duration: mean(&|k| k.duration),
        root_height: mean(&|k| k.root_height),
        translation: [
            mean(&|k| k.translation[0]),
            mean(&|k| k.translation[1]),
            mean(&|k| k.translation[2]),
        ],
        effectors: [effector(0), effector(1), effector(2), effector(3)],
    }
}
