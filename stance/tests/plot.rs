//! `plot::write_fig3` draws one top-view panel per pass (held hands included) and the
//! swing-height side view.

mod common;

use stance::plot::{Snapshot, write_fig3};
use stance::{AffordanceSet, GenerateOptions, PostProcessor, generate};

#[test]
fn fig3_has_a_panel_per_pass_and_a_side_view() {
    let (robot, params) = common::jvrc1();
    let raw = generate(
        robot,
        &GenerateOptions {
            distance: 4.0,
            affordances: AffordanceSet::FeetRightHand,
            seed: 2,
        },
    )
    .unwrap();
    let mut snapshots = Vec::new();
    PostProcessor::new(robot, params.clone())
        .process_observed(&raw, |pass, poses| {
            snapshots.push(Snapshot {
                pass,
                poses: poses.clone(),
            })
        })
        .unwrap();
    let dir = std::env::temp_dir().join(format!("stance-fig3-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let files = write_fig3(&dir, &snapshots, raw.environment(), &robot.sole, params).unwrap();
    let top = std::fs::read_to_string(&files[0]).unwrap();
    for snapshot in &snapshots {
        assert!(
            top.contains(snapshot.pass.name()),
            "{} missing",
            snapshot.pass.name()
        );
    }
    assert!(top.contains("#FF0000"), "contact poses are marked red");
    assert!(top.contains("#FF00FF"), "held hands are magenta dots");
    let side = std::fs::read_to_string(&files[1]).unwrap();
    assert!(side.contains("swing-foot height"));
    std::fs::remove_dir_all(&dir).unwrap();
}
