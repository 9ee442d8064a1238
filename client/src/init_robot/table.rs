//! What `walkctl init-robot` prints on stderr for the user to confirm: every guess with its
//! basis and the option that overrides it, the measured dimensions, and the key derived values.

use super::derive::DerivedSections;
use super::dimensions::RobotDimensions;
use super::frames::{FrameSpec, Frames};
use super::groups::JointGroups;
use super::legs::Legs;
use super::model::UrdfModel;

/// One row: what, the guess, how it was made, the option that overrides it.
type Row = (String, String, String, &'static str);

fn frame(spec: &FrameSpec) -> String {
    let t = spec.translation;
    format!("{} @ [{:.4}, {:.4}, {:.4}]", spec.link, t[0], t[1], t[2])
}

/// The guesses, one row each.
pub fn guesses(
    model: &UrdfModel,
    legs: &Legs,
    frames: &Frames,
    groups: &JointGroups,
    standing_basis: &str,
) -> Vec<Row> {
    let chain = |leg: &super::legs::Leg| {
        leg.joints
            .iter()
            .map(|&j| model.joint_name(j))
            .collect::<Vec<_>>()
            .join(" ")
    };
    let mut rows: Vec<Row> = vec![
        (
            "base link".into(),
            frames.base_link.value.clone(),
            frames.base_link.basis.clone(),
            "--base-link",
        ),
        (
            "left foot".into(),
            model.name(legs.left.foot).into(),
            format!("{}; leg {}", legs.basis, chain(&legs.left)),
            "--left-foot",
        ),
        (
            "right foot".into(),
            model.name(legs.right.foot).into(),
            format!("leg {}", chain(&legs.right)),
            "--right-foot",
        ),
        (
            "forward".into(),
            format!("{:.3?}", legs.axes.forward.as_slice()),
            format!(
                "the knees ({}, {}) bend towards it",
                model.joint_name(legs.left.knee),
                model.joint_name(legs.right.knee)
            ),
            "",
        ),
        (
            "sole".into(),
            format!(
                "{} x {} m",
                super::render::number(frames.sole.value.0),
                super::render::number(frames.sole.value.1)
            ),
            frames.sole.basis.clone(),
            "--sole LxW",
        ),
        (
            "left sole".into(),
            frame(&frames.feet.value[0]),
            frames.feet.basis.clone(),
            "--sole-below M",
        ),
        (
            "right sole".into(),
            frame(&frames.feet.value[1]),
            String::new(),
            "",
        ),
        (
            "left hand".into(),
            frame(&frames.hands.value[0]),
            frames.hands.basis.clone(),
            "--left-hand",
        ),
        (
            "right hand".into(),
            frame(&frames.hands.value[1]),
            String::new(),
            "--right-hand",
        ),
        (
            "FT sensors".into(),
            format!(
                "{} / {}",
                frames.ft_sensors.value[0].link, frames.ft_sensors.value[1].link
            ),
            frames.ft_sensors.basis.clone(),
            "(edit the file)",
        ),
    ];
    type Role = fn(&super::legs::Leg) -> Option<usize>;
    let roles: [(&str, Role); 2] = [
        ("ankle roll", |l| l.ankle_roll),
        ("ankle pitch", |l| l.ankle_pitch),
    ];
    for (name, leg) in roles {
        let joints: Vec<&str> = legs
            .both()
            .iter()
            .filter_map(|l| leg(l))
            .map(|j| model.joint_name(j))
            .collect();
        rows.push((
            name.into(),
            if joints.is_empty() {
                "none".into()
            } else {
                joints.join(" / ")
            },
            "the ankle joint most aligned with that axis".into(),
            "",
        ));
    }
    for (group, names) in [
        ("legs", &groups.legs),
        ("arms", &groups.arms),
        ("torso", &groups.torso),
        ("head", &groups.head),
        ("no group", &groups.unassigned),
    ] {
        rows.push((
            format!("joints: {group}"),
            format!("{} joint(s)", names.len()),
            names.join(" "),
            "(edit the file)",
        ));
    }
    rows.push((
        "standing".into(),
        "legs bent".into(),
        standing_basis.into(),
        "(edit the file)",
    ));
    rows
}

/// The rows as an aligned table (the basis column wraps at the terminal's usual width).
pub fn format(rows: &[Row]) -> String {
    let width = |column: fn(&Row) -> &str| {
        rows.iter()
            .map(|r| column(r).chars().count())
            .max()
            .unwrap_or(0)
    };
    let (w0, w1) = (width(|r| &r.0).max(5), width(|r| &r.1).min(48));
    let mut out = format!(
        "{:<w0$}  {:<w1$}  {:<15}  basis\n",
        "guess", "value", "override"
    );
    for (what, value, basis, option) in rows {
        out.push_str(&format!(
            "{what:<w0$}  {value:<w1$}  {option:<15}  {basis}\n"
        ));
    }
    out
}

/// The dimensions and the key derived values.
pub fn summary(dimensions: &RobotDimensions, derived: &DerivedSections) -> String {
    let mut out = String::from("dimensions:\n");
    for (key, value) in dimensions.numbers() {
        match value {
            Some(value) => out.push_str(&format!("  {key:<24} {value:.4}\n")),
            None => out.push_str(&format!("  {key:<24} -\n")),
        }
    }
    let s = &derived.summary;
    out.push_str(&format!(
        "derived (l/l_ref = {:.3}):\n  dynamic timing           {:.2} s single, {:.2} s double\n  \
         static s_max, scf        {:.3} m, {:.2}\n  dynamic s_max, scf       {:.3} m, {:.2}\n  \
         o_min, o_max             {:.3}-{:.3} m (dynamic {:.3}-{:.3} m)\n  \
         zmp_inward_offset_m      {:.3}\n  max_step_m               {:.3}\n",
        s.scale,
        s.single_support_s,
        s.double_support_s,
        s.s_max,
        s.scf,
        s.s_max_dynamic,
        s.scf_dynamic,
        s.o.0,
        s.o.1,
        s.o_dynamic.0,
        s.o_dynamic.1,
        s.zmp_inward_offset_m,
        s.max_step_m
    ));
    if let Some(roll) = s.roll {
        out.push_str(&format!(
            "  lateral sway             a = {:.4} m at the Froude period, {:.4} m derived; ankle \
             rolls reach c = {:.4} m{}\n",
            roll.froude_sway_m,
            roll.sway_m,
            roll.reach_m,
            if roll.limited { " (roll-limited)" } else { "" }
        ));
    }
    for note in &derived.notes {
        out.push_str(&format!("note: {note}\n"));
    }
    out
}
