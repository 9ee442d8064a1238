//! With the `mujoco` feature: bakes the MuJoCo library directory into the rpath of the physics
//! test, as sim-adapter's build script does for its own targets (a link argument does not reach
//! dependent packages). sim-adapter's build script already checked that the library is there.

fn main() {
    println!("cargo::rerun-if-env-changed=MUJOCO_DYNAMIC_LINK_DIR");
    if std::env::var_os("CARGO_FEATURE_MUJOCO").is_none() {
        return;
    }
    if let Some(dir) = std::env::var_os("MUJOCO_DYNAMIC_LINK_DIR") {
        println!("cargo::rustc-link-arg=-Wl,-rpath,{}", dir.to_string_lossy());
    }
}
