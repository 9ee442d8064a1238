//! With the `mujoco` feature: checks that the pinned MuJoCo library is where the build looks for
//! it and bakes that directory into the rpath of this package's binaries, tests and benches, so
//! they run without `LD_LIBRARY_PATH`. Without the feature it does nothing.

use std::path::Path;

const LINK_DIR_VAR: &str = "MUJOCO_DYNAMIC_LINK_DIR";
const LIBRARY: &str = "libmujoco.so.3.17.0";

fn main() {
    println!("cargo::rerun-if-env-changed={LINK_DIR_VAR}");
    if std::env::var_os("CARGO_FEATURE_MUJOCO").is_none() {
        return;
    }
    let how_to_install = "Install it with `eval \"$(scripts/setup-mujoco.sh)\"` from the repository root \
         (it fetches MuJoCo 3.17.0 into .deps/mujoco/lib and exports MUJOCO_DYNAMIC_LINK_DIR), \
         then build again.";
    let Some(dir) = std::env::var_os(LINK_DIR_VAR) else {
        panic!("sim-adapter feature `mujoco`: {LINK_DIR_VAR} is not set. {how_to_install}");
    };
    let dir = Path::new(&dir);
    if !dir.join(LIBRARY).is_file() || !dir.join("libmujoco.so").is_file() {
        panic!(
            "sim-adapter feature `mujoco`: {} has no {LIBRARY} (and libmujoco.so link). {how_to_install}",
            dir.display()
        );
    }
    println!("cargo::rerun-if-changed={}", dir.join(LIBRARY).display());
    println!("cargo::rustc-link-arg=-Wl,-rpath,{}", dir.display());
}
