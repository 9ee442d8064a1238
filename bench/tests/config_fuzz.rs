//! Every number of a robot config, fuzzed: for every numeric key of every section (the tables the
//! loaders check against), random and hostile values (0, negative, 1e-300, 1e300, NaN, the
//! infinities, u32::MAX, integers past i64, floats past f64, the range's ends and just past them)
//! are written into a copy of a real robot config, which is then loaded through the loaders
//! walkd, walk-sim, walk-bench and walkctl use. None may panic; each value is either accepted,
//! and then inside its documented range, or refused by an error naming the file and the key.
//! The docs page that owns each section lists the same ranges as the tables (checked here too).

use std::collections::BTreeMap;
use std::panic::{AssertUnwindSafe, catch_unwind};
use std::path::{Path, PathBuf};

use daemon::controller::{ControllerConfig, DynamicGaitConfig, GaitConfig, StabilizerConfig};
use kinematics::ConfigFile;
use kinematics::robot::{Robot, SoleRectangle};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use shm_types::RuntimeConfig;
use stance::{Gait, PostProcessParams};

mod fuzz_values;

/// Random values tried per key, besides the fixed hostile ones.
const RANDOM_VALUES: usize = 24;

/// A numeric key of a section and its documented range.
#[derive(Clone, Debug)]
struct Key {
    /// The TOML table, e.g. `gait.dynamic.stabilizer`.
    table: &'static str,
    /// The key, e.g. `dcm_gain`, or `sole.length` inside `[robot]`.
    name: &'static str,
    min: f64,
    max: f64,
}

/// Every numeric key of every section, from the tables the loaders check against.
fn keys(config: &ConfigFile) -> Vec<Key> {
    let from = |table, bounds: Vec<kinematics::bounds::Bound>| {
        bounds.into_iter().map(move |b| Key {
            table,
            name: b.key,
            min: b.range.min,
            max: b.range.max,
        })
    };
    let runtime = RuntimeConfig::from_section(config.section("runtime"), "config").unwrap();
    let postprocess = PostProcessParams::from_config(config).unwrap();
    let sole = SoleRectangle {
        length: 0.2,
        width: 0.1,
    };
    let mut keys: Vec<Key> = from("robot", sole.bounds().to_vec())
        .chain(from("controller", ControllerConfig::default().bounds()))
        .chain(from("gait.dynamic", DynamicGaitConfig::default().bounds()))
        .chain(from(
            "gait.dynamic.stabilizer",
            StabilizerConfig::default().bounds(),
        ))
        .chain(from("postprocess", postprocess.bounds()))
        .chain(from("postprocess.dynamic", postprocess.bounds()))
        .collect();
    keys.extend(runtime.bounds().into_iter().map(|b| Key {
        table: "runtime",
        name: b.key,
        min: b.min,
        max: b.max,
    }));
    keys
}

/// The TOML literals tried for `key`: the hostile ones, the range's ends and just past them,
/// and random values over many magnitudes (integers too).
fn literals(key: &Key, rng: &mut ChaCha8Rng) -> Vec<String> {
    let mut literals: Vec<String> = fuzz_values::HOSTILE.map(str::to_owned).to_vec();
    let float = |value: f64| format!("{value:?}");
    for edge in [key.min, key.max] {
        literals.push(float(edge));
        literals.push(float(edge * (1.0 + 1e-9) + 1e-12));
        literals.push(float(edge * (1.0 - 1e-9) - 1e-12));
    }
    literals.extend(fuzz_values::random(rng, RANDOM_VALUES));
    literals
}

/// `text` (a robot config) with `key = literal` in its table: the line replaced if the file has
/// the key, else added under the table's header; `[robot] sole.*` rewrites the sole's inline table.
fn with_value(text: &str, key: &Key, literal: &str) -> String {
    if let Some(extent) = key.name.strip_prefix("sole.") {
        let line = text
            .lines()
            .find(|l| l.starts_with("sole = {"))
            .expect("[robot] sole");
        let other = if extent == "length" {
            "width"
        } else {
            "length"
        };
        return text.replace(
            line,
            &format!("sole = {{ {extent} = {literal}, {other} = 0.1 }}"),
        );
    }
    let header = format!("[{}]", key.table);
    let start = text.find(&format!("\n{header}\n")).expect("table") + header.len() + 2;
    let end = text[start..]
        .find("\n[")
        .map_or(text.len(), |i| start + i + 1);
    let table = &text[start..end];
    let assignment = format!("{} = {literal}", key.name);
    let table = match table
        .lines()
        .find(|l| l.starts_with(&format!("{} =", key.name)))
    {
        Some(line) => table.replace(line, &assignment),
        None => format!("{assignment}\n{table}"),
    };
    format!("{}{table}{}", &text[..start], &text[end..])
}

/// What loading a config through every loader gave: the first refusal, if any.
fn load_everything(path: &Path, robot_too: bool) -> Result<(), String> {
    let file = ConfigFile::load(path).map_err(|e| e.to_string())?;
    RuntimeConfig::from_section(file.section("runtime"), &file.origin())
        .map_err(|e| e.to_string())?;
    ControllerConfig::from_config(&file).map_err(|e| e.to_string())?;
    GaitConfig::from_config(&file).map_err(|e| e.to_string())?;
    for gait in [Gait::Static, Gait::Dynamic] {
        PostProcessParams::from_config_for(&file, gait).map_err(|e| e.to_string())?;
    }
    if robot_too {
        Robot::from_config(&file, None).map_err(|e| e.to_string())?;
    }
    Ok(())
}

/// The number a TOML literal stands for, if TOML reads it as one.
fn number_of(literal: &str) -> Option<f64> {
    let table: toml::Table = format!("v = {literal}").parse().ok()?;
    match table["v"] {
        toml::Value::Float(value) => Some(value),
        toml::Value::Integer(value) => Some(value as f64),
        _ => None,
    }
}

/// A config of `robot` with its URDF path made absolute, so copies load from anywhere.
fn config_text(robot: &str) -> String {
    let configs = Path::new(env!("CARGO_MANIFEST_DIR")).join("../configs");
    let configs = configs.canonicalize().unwrap();
    std::fs::read_to_string(configs.join(format!("{robot}.toml")))
        .unwrap()
        .replace(
            "urdf = \"robots/",
            &format!("urdf = \"{}/robots/", configs.display()),
        )
}

#[test]
fn every_config_number_is_in_range_or_refused_by_name_and_nothing_panics() {
    let mut rng = ChaCha8Rng::seed_from_u64(20);
    let dir = std::env::temp_dir().join(format!("walk-config-fuzz-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let mut tried = 0;
    let mut panics = Vec::new();
    let mut wrong = Vec::new();
    let mut refused_by_table: BTreeMap<&str, usize> = BTreeMap::new();
    for robot in ["jvrc1", "armar4"] {
        let text = config_text(robot);
        let path: PathBuf = dir.join(format!("{robot}.toml"));
        std::fs::write(&path, &text).unwrap();
        load_everything(&path, true).expect("the committed config loads");
        let file = ConfigFile::load(&path).unwrap();
        for key in keys(&file) {
            for literal in literals(&key, &mut rng) {
                tried += 1;
                std::fs::write(&path, with_value(&text, &key, &literal)).unwrap();
                let robot_too = key.table == "robot";
                let outcome = catch_unwind(AssertUnwindSafe(|| load_everything(&path, robot_too)));
                let case = format!("{robot}: [{}] {} = {literal}", key.table, key.name);
                match outcome {
                    Err(_) => panics.push(case),
                    Ok(Ok(())) => {
                        let inside =
                            number_of(&literal).is_some_and(|v| key.min <= v && v <= key.max);
                        if !inside {
                            wrong.push(format!(
                                "{case}: accepted outside [{}, {}]",
                                key.min, key.max
                            ));
                        }
                    }
                    Ok(Err(error)) => {
                        *refused_by_table.entry(key.table).or_default() += 1;
                        // A TOML syntax error quotes the line: `sole = { length = 1e400, ... }`.
                        let leaf = key.name.rsplit('.').next().unwrap();
                        if !(error.contains(&path.display().to_string()) && error.contains(leaf)) {
                            wrong.push(format!("{case}: the error names no file or key: {error}"));
                        }
                    }
                }
            }
        }
    }
    std::fs::remove_dir_all(&dir).unwrap();
    eprintln!(
        "config fuzzing: {tried} values tried, {} panics, refused per table {refused_by_table:?}",
        panics.len()
    );
    fuzz_values::assert_clean(&panics, &wrong);
}

/// The `[min, max]` of the row of `key` in the docs page `text` (`| `key` | [min, max] ...`).
fn documented_range(text: &str, key: &str) -> Option<(f64, f64)> {
    let row = text
        .lines()
        .find(|line| line.starts_with(&format!("| `{key}` |")))?;
    let range = &row[row.find('[')? + 1..];
    let (min, max) = range[..range.find(']')?].split_once(", ")?;
    Some((min.trim().parse().ok()?, max.trim().parse().ok()?))
}

#[test]
fn every_range_is_documented_in_the_page_that_owns_its_section() {
    let docs = Path::new(env!("CARGO_MANIFEST_DIR")).join("../docs");
    let page = |name: &str| std::fs::read_to_string(docs.join(name)).unwrap();
    let config = ConfigFile::parse(&config_text("jvrc1"), Path::new("jvrc1.toml")).unwrap();
    let mut ranges: Vec<(String, &str, f64, f64)> = keys(&config)
        .into_iter()
        .filter(|key| key.table != "robot")
        .map(|key| {
            let page = match key.table {
                "runtime" => "ipc.md",
                "postprocess" | "postprocess.dynamic" => "stance.md",
                _ => "controller.md",
            };
            (page.to_owned(), key.name, key.min, key.max)
        })
        .collect();
    #[cfg(feature = "mujoco")]
    ranges.extend(
        sim_adapter::mujoco::MujocoOptions::default()
            .bounds()
            .into_iter()
            .map(|b| ("mujoco.md".to_owned(), b.key, b.range.min, b.range.max)),
    );
    let close = |a: f64, b: f64| (a - b).abs() <= 1e-4 * b.abs().max(1e-12);
    let mut wrong = Vec::new();
    for (name, key, min, max) in ranges {
        match documented_range(&page(&name), key) {
            Some((a, b)) if close(a, min) && close(b, max) => {}
            documented => wrong.push(format!(
                "docs/{name}: `{key}` documented as {documented:?}, checked as [{min}, {max}]"
            )),
        }
    }
    assert!(wrong.is_empty(), "{}", wrong.join("\n"));
}
