//! `walkctl inspect`: print a robot model's kinematics as one JSON object, so users and tests can
//! check a model (link and frame poses, CoM, mass, optionally the Jacobians).
//!
//! The configuration is the config's standing posture, with joints overridden by `--q` and the
//! base pose by `--base`.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use anyhow::{Context, bail};
use kinematics::{
    Configuration, DMatrix, EndEffector, Isometry3, Kinematics, Robot, Translation3, UnitQuaternion,
};
use serde::{Deserialize, Serialize};

/// Arguments of `walkctl inspect`.
#[derive(Debug, Clone, clap::Args)]
pub struct InspectArgs {
    /// Robot config (TOML with a `[robot]` section), e.g. configs/jvrc1.toml.
    #[arg(long, value_name = "CONFIG")]
    pub robot: PathBuf,
    /// URDF to use instead of the config's `urdf` (required for robots whose model is not shipped).
    #[arg(long, value_name = "PATH")]
    pub urdf: Option<PathBuf>,
    /// JSON file `{"joints": {"NAME": value, ...}}`; joints not named keep the standing posture.
    #[arg(long = "q", value_name = "FILE.json")]
    pub joints: Option<PathBuf>,
    /// Base pose as JSON `{"translation":[x,y,z],"rotation":[x,y,z,w]}` (default: standing pose).
    #[arg(long, value_name = "JSON")]
    pub base: Option<String>,
    /// Also print the end-effector frame Jacobians and the CoM Jacobian.
    #[arg(long)]
    pub jacobians: bool,
}

/// The `--q` file.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct JointsFile {
    joints: BTreeMap<String, f64>,
}

/// A pose as printed and as given with `--base`.
#[derive(Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct Pose {
    translation: [f64; 3],
    rotation: [f64; 4],
}

impl Pose {
    fn from_isometry(pose: &Isometry3<f64>) -> Self {
        let t = pose.translation.vector;
        let q = pose.rotation.coords;
        Self {
            translation: [t.x, t.y, t.z],
            rotation: [q.x, q.y, q.z, q.w],
        }
    }

    fn to_isometry(&self) -> anyhow::Result<Isometry3<f64>> {
        let [x, y, z, w] = self.rotation;
        let quaternion = nalgebra::Quaternion::new(w, x, y, z);
        if ((quaternion.norm() - 1.0).abs()) > 1e-6 {
            bail!(
                "rotation [x, y, z, w] must be a unit quaternion (norm {})",
                quaternion.norm()
            );
        }
        let [tx, ty, tz] = self.translation;
        Ok(Isometry3::from_parts(
            Translation3::new(tx, ty, tz),
            UnitQuaternion::from_quaternion(quaternion),
        ))
    }
}

/// What `walkctl inspect` prints.
#[derive(Debug, Serialize)]
struct Report {
    robot: String,
    dof: usize,
    mass: f64,
    com: [f64; 3],
    links: BTreeMap<String, Pose>,
    frames: BTreeMap<String, Pose>,
    #[serde(skip_serializing_if = "Option::is_none")]
    jacobians: Option<BTreeMap<String, Vec<Vec<f64>>>>,
    #[serde(skip_serializing_if = "Option::is_none")]
    com_jacobian: Option<Vec<Vec<f64>>>,
}

/// Runs `walkctl inspect`: loads the robot, applies `--q` / `--base`, prints the report on stdout.
pub fn run(args: &InspectArgs) -> anyhow::Result<()> {
    let robot = Robot::load(&args.robot, args.urdf.as_deref())?;
    let mut q = robot.standing.clone();
    if let Some(path) = &args.joints {
        apply_joints_file(&robot, &mut q, path)?;
    }
    if let Some(json) = &args.base {
        let pose: Pose = serde_json::from_str(json)
            .context("--base: expected {\"translation\":[x,y,z],\"rotation\":[x,y,z,w]}")?;
        q.base = pose.to_isometry().context("--base")?;
    }
    let report = report(&robot, &q, args.jacobians);
    println!("{}", serde_json::to_string_pretty(&report)?);
    Ok(())
}

fn apply_joints_file(robot: &Robot, q: &mut Configuration, path: &Path) -> anyhow::Result<()> {
    let text = std::fs::read_to_string(path)
        .with_context(|| format!("--q: cannot read {}", path.display()))?;
    let file: JointsFile = serde_json::from_str(&text).with_context(|| {
        format!(
            "--q {}: expected {{\"joints\": {{\"NAME\": value, ...}}}}",
            path.display()
        )
    })?;
    for (name, &value) in &file.joints {
        if !q.set_joint(&robot.model, name, value) {
            bail!(
                "--q {}: joints.{name}: the model has no actuated joint '{name}'",
                path.display()
            );
        }
    }
    Ok(())
}

fn report(robot: &Robot, q: &Configuration, with_jacobians: bool) -> Report {
    let model = &robot.model;
    let mut kinematics = Kinematics::new(model);
    kinematics.update(model, q);
    let links = model
        .link_ids()
        .map(|link| {
            (
                model.link_name(link).to_owned(),
                Pose::from_isometry(kinematics.link_pose(link)),
            )
        })
        .collect();
    let frames = EndEffector::ALL
        .iter()
        .map(|&e| {
            (
                e.name().to_owned(),
                Pose::from_isometry(&kinematics.frame_pose(model, robot.frame(e))),
            )
        })
        .collect();
    let (jacobians, com_jacobian) = if with_jacobians {
        let mut jacobian = DMatrix::zeros(6, model.nv());
        let jacobians = EndEffector::ALL
            .iter()
            .map(|&e| {
                kinematics.frame_jacobian(model, robot.frame(e), &mut jacobian);
                (e.name().to_owned(), rows(&jacobian))
            })
            .collect();
        let mut com_jacobian = DMatrix::zeros(3, model.nv());
        kinematics.com_jacobian(model, &mut com_jacobian);
        (Some(jacobians), Some(rows(&com_jacobian)))
    } else {
        (None, None)
    };
    let com = kinematics.com();
    Report {
        robot: robot.name.clone(),
        dof: model.dof(),
        mass: model.total_mass(),
        com: [com.x, com.y, com.z],
        links,
        frames,
        jacobians,
        com_jacobian,
    }
}

fn rows(matrix: &DMatrix<f64>) -> Vec<Vec<f64>> {
    matrix
        .row_iter()
        .map(|row| row.iter().copied().collect())
        .collect()
}
