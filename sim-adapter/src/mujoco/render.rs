//! Pictures of the simulated walk: MuJoCo's own renderer (`mujoco-rs`'s `MjRenderer`) drawing
//! offscreen through EGL — on a machine without a GPU, Mesa's software rasteriser (Debian
//! `libegl1`, `libegl-mesa0`, `libgl1-mesa-dri`; `scripts/setup-observe.sh` installs them).
//! Behind the cargo feature `render`, so the rest builds without EGL.
//!
//! [`Snapshots`] saves a PNG of the robot every `period_s` of simulated time, named by that time
//! (`t000012.500.png`), seen by a fixed side camera; `walkctl evaluate --snapshots` turns them into
//! a filmstrip. The model needs its visual geoms (`MujocoOptions::visual_geoms`).

use std::fs::File;
use std::io::BufWriter;
use std::path::{Path, PathBuf};

use mujoco_rs::prelude::MjtCamera;
use mujoco_rs::renderer::MjRenderer;
use mujoco_rs::wrappers::mj_visualization::MjvCamera;

use std::sync::Arc;

use kinematic_sim::{SafetySummary, SimMeasurement, Simulator};
use kinematics::robot::{EndEffector, Robot};
use nalgebra::Isometry3;

use super::{MujocoError, MujocoSim};

/// Where and how pictures are taken.
#[derive(Debug, Clone, PartialEq)]
pub struct SnapshotOptions {
    /// Directory the PNGs go to (created if missing).
    pub dir: PathBuf,
    /// Simulated time between two pictures (s).
    pub period_s: f64,
    /// Point the camera looks at (world, m).
    pub lookat: [f64; 3],
    /// Camera distance from `lookat` (m).
    pub distance: f64,
    /// Camera azimuth (degrees; 90: looking along +y, so a walk along +x goes left to right).
    pub azimuth_deg: f64,
    /// Camera elevation (degrees; negative looks down).
    pub elevation_deg: f64,
    /// Picture size (pixels), at most the model's offscreen buffer.
    pub width: u32,
    /// See `width`.
    pub height: u32,
}

impl SnapshotOptions {
    /// A side view of a walk along +x centred at `lookat`, every `period_s`, into `dir`.
    pub fn side_view(dir: PathBuf, period_s: f64, lookat: [f64; 3]) -> Self {
        Self {
            dir,
            period_s,
            lookat,
            distance: 3.2,
            azimuth_deg: 90.0,
            elevation_deg: -8.0,
            width: 640,
            height: 720,
        }
    }
}

/// Takes a picture every `period_s` of simulated time.
pub struct Snapshots {
    renderer: MjRenderer,
    options: SnapshotOptions,
    next_s: f64,
    saved: usize,
}

impl Snapshots {
    /// A renderer for `sim`'s model (fails with what is missing if EGL cannot open a context).
    pub fn new(sim: &MujocoSim, options: SnapshotOptions) -> Result<Self, MujocoError> {
        let render_error =
            |what: &str, e: &dyn std::fmt::Display| MujocoError::Render(format!("{what}: {e}"));
        if !(options.period_s.is_finite() && options.period_s > 0.0) {
            return Err(MujocoError::Render(format!(
                "the snapshot period {} s must be positive",
                options.period_s
            )));
        }
        std::fs::create_dir_all(&options.dir)
            .map_err(|e| render_error(&format!("creating {}", options.dir.display()), &e))?;
        let mut camera = MjvCamera::new_free(sim.model());
        camera.type_ = MjtCamera::mjCAMERA_FREE as i32;
        camera.lookat = options.lookat;
        camera.distance = options.distance;
        camera.azimuth = options.azimuth_deg;
        camera.elevation = options.elevation_deg;
        let renderer = MjRenderer::builder()
            .width(options.width)
            .height(options.height)
            .camera(camera)
            .build(sim.model())
            .map_err(|e| {
                render_error(
                    "MuJoCo's offscreen renderer could not start (it needs EGL with Mesa: \
                     apt-get install libegl1 libegl-mesa0 libgl1-mesa-dri, or run \
                     scripts/setup-observe.sh)",
                    &e,
                )
            })?;
        Ok(Self {
            renderer,
            options,
            next_s: 0.0,
            saved: 0,
        })
    }

    /// Pictures saved so far.
    pub fn saved(&self) -> usize {
        self.saved
    }

    /// Saves a picture if one is due at `sim`'s current time.
    pub fn capture_due(&mut self, sim: &mut MujocoSim) -> Result<(), MujocoError> {
        let t = sim.time();
        if t + 1e-9 < self.next_s {
            return Ok(());
        }
        while self.next_s <= t + 1e-9 {
            self.next_s += self.options.period_s;
        }
        let path = self.options.dir.join(frame_name(t));
        self.capture(sim, &path)
    }

    /// Renders `sim`'s current state and saves it as a PNG at `path`.
    pub fn capture(&mut self, sim: &mut MujocoSim, path: &Path) -> Result<(), MujocoError> {
        let render = |e: mujoco_rs::renderer::RendererError| MujocoError::Render(e.to_string());
        self.renderer.sync_data(sim.data_mut()).map_err(render)?;
        self.renderer.render().map_err(render)?;
        let rgb = self
            .renderer
            .rgb_flat()
            .ok_or_else(|| MujocoError::Render("the renderer drew no RGB image".to_owned()))?;
        write_png(path, rgb, self.options.width, self.options.height)?;
        self.saved += 1;
        Ok(())
    }
}

/// A MuJoCo simulation that takes a picture every `period_s` of simulated time as it steps
/// (`walk-sim --snapshots`); otherwise the same simulator.
pub struct PhotographedSim {
    sim: MujocoSim,
    snapshots: Snapshots,
}

impl PhotographedSim {
    /// `sim`, photographed as `options` say (fails if the renderer cannot start).
    pub fn new(mut sim: MujocoSim, options: SnapshotOptions) -> Result<Self, MujocoError> {
        let mut snapshots = Snapshots::new(&sim, options)?;
        snapshots.capture_due(&mut sim)?;
        Ok(Self { sim, snapshots })
    }

    /// Pictures saved so far.
    pub fn saved(&self) -> usize {
        self.snapshots.saved()
    }
}

impl crate::MotorLoad for PhotographedSim {
    fn actuator_load(&self) -> shm_types::ActuatorLoad {
        crate::MotorLoad::actuator_load(&self.sim)
    }
}

impl crate::TerrainContacts for PhotographedSim {
    fn terrain_collision_count(&self) -> u64 {
        crate::TerrainContacts::terrain_collision_count(&self.sim)
    }
}

impl Simulator for PhotographedSim {
    type Error = MujocoError;

    fn robot(&self) -> &Arc<Robot> {
        self.sim.robot()
    }

    fn step(&mut self, q_des: &[f64], qd_des: &[f64], dt: f64) -> Result<(), MujocoError> {
        self.sim.step(q_des, qd_des, dt)?;
        self.snapshots.capture_due(&mut self.sim)
    }

    fn measurement(&self) -> &SimMeasurement {
        self.sim.measurement()
    }

    fn summary(&self) -> &SafetySummary {
        self.sim.summary()
    }

    fn end_effector_pose(&self, effector: EndEffector) -> Isometry3<f64> {
        self.sim.end_effector_pose(effector)
    }

    fn base_link_pose(&self) -> Isometry3<f64> {
        self.sim.base_link_pose()
    }

    fn time(&self) -> f64 {
        self.sim.time()
    }
}

/// The file name of a picture taken at simulated time `t` (s): `t000012.500.png`, so names sort
/// by time.
pub fn frame_name(t: f64) -> String {
    format!("t{:010.3}.png", t.max(0.0))
}

/// The simulated time of a picture named by [`frame_name`].
pub fn frame_time(name: &str) -> Option<f64> {
    name.strip_prefix('t')?.strip_suffix(".png")?.parse().ok()
}

/// Writes 8-bit RGB pixels as a PNG.
pub fn write_png(path: &Path, rgb: &[u8], width: u32, height: u32) -> Result<(), MujocoError> {
    let io =
        |e: &dyn std::fmt::Display| MujocoError::Render(format!("writing {}: {e}", path.display()));
    let file = File::create(path).map_err(|e| io(&e))?;
    let mut encoder = png::Encoder::new(BufWriter::new(file), width, height);
    encoder.set_color(png::ColorType::Rgb);
    encoder.set_depth(png::BitDepth::Eight);
    encoder.set_compression(png::Compression::Fast);
    let mut writer = encoder.write_header().map_err(|e| io(&e))?;
    writer.write_image_data(rgb).map_err(|e| io(&e))?;
    writer.finish().map_err(|e| io(&e))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn frame_names_sort_by_time_and_parse_back() {
        let names = [frame_name(0.5), frame_name(12.25), frame_name(3.0)];
        let mut sorted = names.clone();
        sorted.sort();
        assert_eq!(
            sorted,
            [frame_name(0.5), frame_name(3.0), frame_name(12.25)]
        );
        assert_eq!(frame_time(&frame_name(12.25)), Some(12.25));
        assert_eq!(frame_time("other.png"), None);
    }
}
