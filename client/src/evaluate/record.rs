//! One walk of the paper's evaluation matrix, and the summary of the walks of one affordance set
//! and distance, as both matrix commands report them: `walkctl evaluate` (walkd and walk-sim as
//! processes) and walk-bench's `physics-matrix` (in process).

use anyhow::Context;
use serde::{Serialize, Serializer};
use stance::{AffordanceSet, Scene, WalkRequest};

use crate::args::DISTANCE_M;
use crate::evaluate::actuators::ActuatorReport;

/// The cells of the matrix a command walks: affordance sets × distances × runs (the command-line
/// arguments both matrix commands share).
#[derive(Debug, Clone, clap::Args)]
pub struct MatrixCells {
    /// Affordance sets.
    #[arg(
        long,
        value_delimiter = ',',
        default_value = "feet,feet+left-hand,feet+right-hand"
    )]
    pub affordances: Vec<AffordanceSet>,
    /// Distances to walk (m, each 0.01-1000; default 1,5). Through a scene: the first D m of
    /// its path, at most its length (default the whole path).
    #[arg(long, value_delimiter = ',', value_parser = DISTANCE_M.parser())]
    pub distances: Option<Vec<f64>>,
    /// Runs per affordance set and distance, 1-100000; run i uses generator seed
    /// `first_seed + i`.
    #[arg(long, default_value_t = 10, value_parser = clap::value_parser!(u64).range(1..=100_000))]
    pub runs: u64,
    /// Seed of the first run.
    #[arg(long, default_value_t = 0)]
    pub first_seed: u64,
}

/// The distances walked when `--distances` is not given on the flat floor (m).
const DEFAULT_DISTANCES_M: [f64; 2] = [1.0, 5.0];

impl MatrixCells {
    /// Every walk, in matrix order: affordance set, then distance, then seed; through `scene`
    /// if any. Refuses no runs, no cells, distances outside their range or longer than the
    /// scene's path, and seeds past `u64::MAX`.
    pub fn requests(&self, scene: Option<&Scene>) -> anyhow::Result<Vec<WalkRequest>> {
        let distances = self.distances.clone().unwrap_or_else(|| match scene {
            Some(scene) => vec![scene.path_length()],
            None => DEFAULT_DISTANCES_M.to_vec(),
        });
        anyhow::ensure!(self.runs > 0, "--runs must be at least 1");
        anyhow::ensure!(
            !self.affordances.is_empty() && !distances.is_empty(),
            "--affordances and --distances need at least one value each"
        );
        anyhow::ensure!(
            distances.iter().all(|&d| DISTANCE_M.contains(d)),
            "--distances {distances:?}: each {}",
            DISTANCE_M.requirement()
        );
        let distances = match scene {
            Some(scene) => distances
                .iter()
                .map(|&distance| scene.walk_length(Some(distance)))
                .collect::<Result<Vec<_>, _>>()
                .context("--distances")?,
            None => distances,
        };
        anyhow::ensure!(
            self.first_seed.checked_add(self.runs - 1).is_some(),
            "--first-seed {} with --runs {}: the last seed would pass {}",
            self.first_seed,
            self.runs,
            u64::MAX
        );
        Ok(self
            .affordances
            .iter()
            .flat_map(|&affordances| {
                distances.iter().flat_map(move |&distance| {
                    (0..self.runs).map(move |i| WalkRequest {
                        distance,
                        affordances,
                        seed: self.first_seed + i,
                        speed: None,
                    })
                })
            })
            .collect())
    }
}

/// What one walk of the matrix measured, however it ran.
#[derive(Clone, Debug, Serialize)]
pub struct WalkRecord {
    /// Affordance set (serialised as its name).
    #[serde(serialize_with = "affordance_name")]
    pub affordances: AffordanceSet,
    /// Requested distance (m).
    pub distance_m: f64,
    /// Generator seed (the run number of `walkctl evaluate`).
    pub seed: u64,
    /// `done`, `fell …`, `fault: …`, `time_limit`, …
    pub outcome: String,
    /// `done` and the simulator's fall rule never fired.
    pub success: bool,
    /// Stances in the walk.
    pub stances: usize,
    /// Horizontal distance the simulated soles' midpoint travelled (m).
    pub walked_m: f64,
    /// `walked_m` over the simulated time from the first step to the end (m/s); `None` if no
    /// step was seen.
    pub speed_m_s: Option<f64>,
    /// Simulated time to the end (s).
    pub sim_s: f64,
    /// Largest controller-vs-simulator distance of the CoM or a sole over the walk (m); `None`
    /// when it could not be measured.
    pub drift_m: Option<f64>,
    /// Largest tilt of the simulated base link from the vertical (rad).
    pub max_tilt_rad: f64,
    /// How hard the walk worked the motors (`None` without actuator dynamics: kinematic
    /// physics).
    pub actuators: Option<ActuatorReport>,
    /// Planned hand contacts the walk went on without: the static gait gives up a reach that
    /// does not get there in time, and the hand stays free for the rest of that contact run
    /// (docs/controller.md, "Hands on a railing"). `None` when not measured.
    pub reaches_given_up: Option<u32>,
}

impl WalkRecord {
    /// `, N hand reaches given up` when the walk went on without a planned hand contact, else
    /// nothing: a walk that is `done` without all its hands says so in its line.
    pub fn reaches_given_up_note(&self) -> String {
        match self.reaches_given_up {
            Some(n) if n > 0 => format!(", {n} hand reaches given up"),
            _ => String::new(),
        }
    }
}

fn affordance_name<S: Serializer>(set: &AffordanceSet, serializer: S) -> Result<S::Ok, S::Error> {
    serializer.serialize_str(set.name())
}

/// The walks of one affordance set and distance, summed up.
#[derive(Clone, Debug, Serialize)]
pub struct GroupSummary {
    /// Affordance set (serialised as its name).
    #[serde(serialize_with = "affordance_name")]
    pub affordances: AffordanceSet,
    /// Requested distance (m).
    pub distance_m: f64,
    /// Walks that succeeded.
    pub done: usize,
    /// Walks in all.
    pub runs: usize,
    /// Mean speed of the walks that succeeded (m/s).
    pub speed_mean_m_s: Option<f64>,
    /// Smallest speed of a walk that succeeded (m/s).
    pub speed_min_m_s: Option<f64>,
    /// Largest drift of a walk (m).
    pub drift_max_m: f64,
    /// Each joint group's largest peak torque and speed fraction over the walks, and the longest
    /// saturation (`None` without actuator dynamics).
    pub actuators: Option<ActuatorReport>,
}

/// `items` split into groups of one affordance set and distance (in the order the groups first
/// appear), each with its summary; `record` picks an item's [`WalkRecord`].
pub fn group_by_cell<T>(
    items: &[T],
    record: impl Fn(&T) -> &WalkRecord,
) -> Vec<(GroupSummary, Vec<&T>)> {
    let mut cells: Vec<(AffordanceSet, f64)> = Vec::new();
    for item in items {
        let r = record(item);
        if !cells.contains(&(r.affordances, r.distance_m)) {
            cells.push((r.affordances, r.distance_m));
        }
    }
    cells
        .into_iter()
        .map(|(affordances, distance_m)| {
            let members: Vec<&T> = items
                .iter()
                .filter(|item| {
                    let r = record(item);
                    r.affordances == affordances && r.distance_m == distance_m
                })
                .collect();
            let records: Vec<&WalkRecord> = members.iter().map(|item| record(item)).collect();
            (summary(affordances, distance_m, &records), members)
        })
        .collect()
}

fn summary(affordances: AffordanceSet, distance_m: f64, records: &[&WalkRecord]) -> GroupSummary {
    let speeds: Vec<f64> = records
        .iter()
        .filter(|r| r.success)
        .filter_map(|r| r.speed_m_s)
        .collect();
    GroupSummary {
        affordances,
        distance_m,
        done: records.iter().filter(|r| r.success).count(),
        runs: records.len(),
        speed_mean_m_s: (!speeds.is_empty())
            .then(|| speeds.iter().sum::<f64>() / speeds.len() as f64),
        speed_min_m_s: speeds.iter().copied().reduce(f64::min),
        drift_max_m: records.iter().filter_map(|r| r.drift_m).fold(0.0, f64::max),
        actuators: records
            .iter()
            .filter_map(|r| r.actuators.clone())
            .reduce(|worst, next| worst.worst(&next)),
    }
}

/// A speed for a table: `0.123` m/s to three decimals, or `-` when there is none.
pub fn speed_cell(speed_m_s: Option<f64>) -> String {
    speed_m_s.map_or_else(|| "-".to_owned(), |v| format!("{v:.3}"))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn record(
        affordances: AffordanceSet,
        distance_m: f64,
        speed: f64,
        success: bool,
    ) -> WalkRecord {
        WalkRecord {
            affordances,
            distance_m,
            seed: 0,
            outcome: if success { "done" } else { "fell" }.to_owned(),
            success,
            stances: 10,
            walked_m: distance_m,
            speed_m_s: Some(speed),
            sim_s: 10.0,
            drift_m: Some(speed / 10.0),
            max_tilt_rad: 0.0,
            actuators: None,
            reaches_given_up: None,
        }
    }

    #[test]
    fn requests_are_in_matrix_order_and_bad_cells_are_refused() {
        let cells = MatrixCells {
            affordances: vec![AffordanceSet::Feet, AffordanceSet::FeetRightHand],
            distances: None,
            runs: 2,
            first_seed: 10,
        };
        let requests = cells.requests(None).unwrap();
        assert_eq!(requests.len(), 8);
        assert_eq!(requests[0], WalkRequest::feet(1.0, 10));
        assert_eq!(requests[1], WalkRequest::feet(1.0, 11));
        assert_eq!(requests[2], WalkRequest::feet(5.0, 10));
        assert_eq!(requests[4].affordances, AffordanceSet::FeetRightHand);
        for bad in [
            MatrixCells {
                runs: 0,
                ..cells.clone()
            },
            MatrixCells {
                distances: Some(vec![1.0, -5.0]),
                ..cells.clone()
            },
            MatrixCells {
                distances: Some(vec![f64::NAN]),
                ..cells.clone()
            },
            MatrixCells {
                affordances: vec![],
                ..cells.clone()
            },
        ] {
            assert!(bad.requests(None).is_err(), "{bad:?} was accepted");
        }
    }

    #[test]
    fn through_a_scene_the_path_is_walked_whole_or_its_first_metres_never_further() {
        let scene = Scene::from_path(
            &std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
                .join("../configs/scenes/railing.toml"),
        )
        .unwrap();
        let cells = MatrixCells {
            affordances: vec![AffordanceSet::FeetRightHand],
            distances: None,
            runs: 1,
            first_seed: 0,
        };
        let whole = cells.requests(Some(&scene)).unwrap();
        assert_eq!(whole.len(), 1);
        assert!((whole[0].distance - 5.0).abs() < 1e-12);
        let parts = MatrixCells {
            distances: Some(vec![1.0, 5.0]),
            ..cells.clone()
        };
        let distances: Vec<f64> = parts
            .requests(Some(&scene))
            .unwrap()
            .iter()
            .map(|request| request.distance)
            .collect();
        assert_eq!(distances, [1.0, 5.0]);
        let error = MatrixCells {
            distances: Some(vec![1.0, 5.5]),
            ..cells
        }
        .requests(Some(&scene))
        .unwrap_err();
        let error = format!("{error:#}");
        assert!(
            error.contains("--distances")
                && error.contains("\"railing\"")
                && error.contains("5.5 m")
                && error.contains("5.000 m"),
            "{error}"
        );
    }

    #[test]
    fn groups_keep_first_seen_order_and_count_only_successes_for_speed() {
        let records = [
            record(AffordanceSet::Feet, 1.0, 0.2, true),
            record(AffordanceSet::FeetLeftHand, 1.0, 0.1, true),
            record(AffordanceSet::Feet, 1.0, 0.4, true),
            record(AffordanceSet::Feet, 1.0, 0.9, false),
        ];
        let groups = group_by_cell(&records, |r| r);
        assert_eq!(groups.len(), 2);
        let (feet, members) = &groups[0];
        assert_eq!(feet.affordances, AffordanceSet::Feet);
        assert_eq!((feet.done, feet.runs, members.len()), (2, 3, 3));
        assert!((feet.speed_mean_m_s.unwrap() - 0.3).abs() < 1e-12);
        assert_eq!(feet.speed_min_m_s, Some(0.2));
        assert!(
            (feet.drift_max_m - 0.09).abs() < 1e-12,
            "the failed walk's drift counts"
        );
        assert_eq!(groups[1].0.affordances, AffordanceSet::FeetLeftHand);
    }
}
