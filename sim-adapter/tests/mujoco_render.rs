//! MuJoCo's offscreen renderer draws the robot (feature `render`; needs EGL with Mesa, which
//! scripts/setup-observe.sh installs): a picture of each robot standing shows its stick figure —
//! limb-coloured pixels in a column around the image centre, the sky above and the floor below.

#![cfg(feature = "render")]

use std::path::{Path, PathBuf};
use std::sync::Arc;

use kinematics::robot::Robot;
use sim_adapter::mujoco::render::{SnapshotOptions, Snapshots};
use sim_adapter::mujoco::{MujocoOptions, MujocoSim};

fn standing(name: &str) -> MujocoSim {
    let config = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../configs")
        .join(format!("{name}.toml"));
    let robot = Arc::new(Robot::load(&config, None).unwrap());
    let (initial, urdf) = (robot.standing.clone(), robot.urdf.clone());
    MujocoSim::new(robot, &urdf, &initial, MujocoOptions::default()).unwrap()
}

/// Decodes an 8-bit RGB PNG: (width, height, pixels).
fn read_png(path: &Path) -> (usize, usize, Vec<u8>) {
    let decoder = png::Decoder::new(std::io::BufReader::new(std::fs::File::open(path).unwrap()));
    let mut reader = decoder.read_info().unwrap();
    let mut pixels = vec![0; reader.output_buffer_size().unwrap()];
    let info = reader.next_frame(&mut pixels).unwrap();
    assert_eq!(info.color_type, png::ColorType::Rgb);
    (info.width as usize, info.height as usize, pixels)
}

/// A limb pixel: the bluish grey of the skeleton (blue clearly above red), lit or shaded.
fn is_limb(p: &[u8]) -> bool {
    let (r, g, b) = (i32::from(p[0]), i32::from(p[1]), i32::from(p[2]));
    b - r >= 12 && b > g && (40..=230).contains(&b)
}

#[test]
fn the_renderer_draws_each_robot_standing() {
    for name in ["armar4", "jvrc1"] {
        let mut sim = standing(name);
        let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join(format!("render-{name}"));
        let options = SnapshotOptions::side_view(dir.clone(), 1.0, [0.0, 0.0, 0.8]);
        let mut snapshots = Snapshots::new(&sim, options).unwrap_or_else(|e| panic!("{e}"));
        let file = dir.join("standing.png");
        snapshots.capture(&mut sim, &file).unwrap();
        let (width, height, pixels) = read_png(&file);
        let limb = |x: usize, y: usize| is_limb(&pixels[3 * (y * width + x)..]);
        // The robot stands in the middle third, from the floor to well above the image centre.
        let middle = (width / 3)..(2 * width / 3);
        let rows_with_limbs = (0..height)
            .filter(|&y| middle.clone().any(|x| limb(x, y)))
            .count();
        let outside = (0..height)
            .flat_map(|y| (0..width / 8).map(move |x| (x, y)))
            .filter(|&(x, y)| limb(x, y))
            .count();
        assert!(
            rows_with_limbs > height / 3,
            "{name}: limbs in only {rows_with_limbs} of {height} rows ({})",
            file.display()
        );
        assert!(
            outside < height,
            "{name}: limb colour at the image edge ({})",
            file.display()
        );
    }
}
