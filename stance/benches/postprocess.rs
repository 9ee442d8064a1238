//! Criterion benchmark of post-processing (the Table I workload at 25 m) and of its two parts,
//! forward kinematics of the raw stances and the passes, to show what dominates.
//! `walkctl bench-postprocess` prints the full Table I.

use std::hint::black_box;
use std::path::PathBuf;

use criterion::{Criterion, criterion_group, criterion_main};
use kinematics::robot::Robot;
use stance::passes::{ContactGeometry, run_passes};
use stance::{
    AffordanceSet, GenerateOptions, PostProcessParams, PostProcessedSequence, PostProcessor,
    generate,
};

const LENGTH_M: f64 = 25.0;

fn bench_robot(c: &mut Criterion, name: &str) {
    let config = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../configs")
        .join(format!("{name}.toml"));
    let robot = Robot::load(&config, None).expect("vendored robot loads");
    let params = PostProcessParams::from_config_path(&config).expect("config has [postprocess]");
    let options = GenerateOptions {
        distance: LENGTH_M / params.scf,
        affordances: AffordanceSet::Feet,
        seed: 0,
    };
    let raw = generate(&robot, &options).expect("generation succeeds");
    let mut processor = PostProcessor::new(&robot, params.clone());
    let mut out = PostProcessedSequence::empty();
    let mut group = c.benchmark_group(format!("{name}_{LENGTH_M}m_{}_stances", raw.len()));
    group.bench_function("process_into", |b| {
        b.iter(|| {
            processor
                .process_into(black_box(&raw), &mut out)
                .expect("same robot")
        })
    });
    group.bench_function("forward_kinematics", |b| {
        b.iter(|| {
            processor
                .forward_kinematics(black_box(&raw))
                .expect("same robot");
        })
    });
    let poses = processor
        .forward_kinematics(&raw)
        .expect("same robot")
        .clone();
    let mut work = poses.clone();
    group.bench_function("passes", |b| {
        b.iter(|| {
            work.clone_from(&poses);
            run_passes(
                black_box(&mut work),
                raw.environment(),
                &params,
                &ContactGeometry::of(&robot),
            );
        })
    });
    group.finish();
}

fn postprocess(c: &mut Criterion) {
    bench_robot(c, "armar4");
    bench_robot(c, "jvrc1");
}

criterion_group!(benches, postprocess);
criterion_main!(benches);
