//! The config file's text: the header, the guessed `[robot]` section and the derived sections,
//! in the layout and comment style of configs/jvrc1.toml (a value's rule as its end-of-line
//! comment, or on the line above when the line would pass [`WIDTH`] characters).

use super::derive::{DerivedSections, Line, Value};
use super::dimensions::RobotDimensions;
use super::frames::{FrameSpec, Frames};
use super::groups::JointGroups;

/// Lines are wrapped at this many characters.
pub const WIDTH: usize = 100;
/// End-of-line comments start at this column.
const COMMENT_COLUMN: usize = 32;

/// A number as TOML reads it back as a float: shortest round-trip digits, always with a point
/// or an exponent.
pub fn number(x: f64) -> String {
    let text = format!("{}", x + 0.0);
    if text.contains(['.', 'e', 'E']) || text.contains("inf") || text.contains("NaN") {
        text
    } else {
        format!("{text}.0")
    }
}

/// `text` as `# ` comment lines of at most [`WIDTH`] characters.
pub fn comment(text: &str) -> String {
    let mut out = String::new();
    let mut line = String::from("#");
    for word in text.split_whitespace() {
        if line.len() + 1 + word.chars().count() > WIDTH && line.len() > 1 {
            out.push_str(&line);
            out.push('\n');
            line = String::from("#");
        }
        line.push(' ');
        line.push_str(word);
    }
    out.push_str(&line);
    out.push('\n');
    out
}

/// `key = value  # rule`, or the rule above the key when it does not fit.
fn key_line(assignment: &str, rule: &str) -> String {
    if rule.is_empty() {
        return format!("{assignment}\n");
    }
    let padded = format!("{assignment:<width$}", width = COMMENT_COLUMN - 1);
    let inline = format!("{padded} # {rule}");
    if inline.chars().count() <= WIDTH {
        format!("{inline}\n")
    } else {
        format!("{}{assignment}\n", comment(rule))
    }
}

fn value_text(value: &Value) -> String {
    match value {
        Value::Number(x) => number(*x),
        Value::Exponent(x) => format!("{x:e}"),
        Value::Integer(i) => i.to_string(),
        Value::Switch(b) => b.to_string(),
        Value::Text(s) => format!("\"{s}\""),
    }
}

/// The file's opening comment: what produced it, where `[robot]` comes from (`robot`, a
/// sentence), that the other values are derived, the dimensions they were derived from and the
/// derivation's remarks.
pub fn header(
    command: &str,
    dimensions: &RobotDimensions,
    robot: &str,
    notes: &[String],
) -> String {
    let mut text = format!(
        "# Robot configuration for {name}, written by\n#   {command}\n",
        name = dimensions.name
    );
    text.push_str(&comment(&format!(
        "{robot} Every other value is derived from the robot's dimensions by the rules of \
         docs/new-robot.md, each with its rule beside it. Derived, not tuned: walk the robot in \
         simulation and tune before trusting it on hardware."
    )));
    text.push_str("#\n# One file, one section per consumer:\n");
    text.push_str("#   [robot]       the model and its frames (kinematics crate)\n");
    text.push_str("#   [postprocess] Algorithm 1 parameters (stance crate)\n");
    text.push_str(
        "#   [controller]  QP tasks, gains, weights, state-machine thresholds (daemon crate)\n",
    );
    text.push_str(
        "#   [gait]        static or dynamic walking; the dynamic gait's timing and stabilizer (daemon crate)\n",
    );
    text.push_str(
        "#   [runtime]     rate, IPC service prefix, watchdogs (daemon runtime / adapters)\n",
    );
    text.push_str("# Paths are relative to this file.\n#\n# Dimensions (walkctl init-robot --save-dimensions writes them as a file):\n");
    for (key, value) in dimensions.numbers() {
        if let Some(value) = value {
            text.push_str(&format!(
                "#   {key} = {}\n",
                number(super::frames::round(value, 1e-4))
            ));
        }
    }
    for note in notes {
        text.push_str(&comment(&format!("Note: {note}")));
    }
    text
}

fn frame_text(spec: &FrameSpec, always_pose: bool) -> String {
    let triple = |v: [f64; 3]| {
        format!(
            "[{}]",
            v.iter().map(|&x| number(x)).collect::<Vec<_>>().join(", ")
        )
    };
    let mut text = format!("{{ link = \"{}\"", spec.link);
    if always_pose || spec.translation != [0.0; 3] {
        text.push_str(&format!(", translation = {}", triple(spec.translation)));
    }
    if always_pose || spec.rpy != [0.0; 3] {
        text.push_str(&format!(", rpy = {}", triple(spec.rpy)));
    }
    text.push_str(" }");
    text
}

fn name_list(key: &str, names: &[String]) -> String {
    let mut out = format!("{key} = [");
    let indent = " ".repeat(out.len());
    let mut line_len = out.len();
    for (i, name) in names.iter().enumerate() {
        let item = format!("\"{name}\"{}", if i + 1 < names.len() { "," } else { "" });
        if line_len + item.len() + 1 > WIDTH && i > 0 {
            out.push('\n');
            out.push_str(&indent);
            line_len = indent.len();
        } else if i > 0 {
            out.push(' ');
            line_len += 1;
        }
        out.push_str(&item);
        line_len += item.len();
    }
    out.push_str("]\n");
    out
}

/// The guessed `[robot]` section.
pub struct RobotSection<'a> {
    /// Robot name.
    pub name: &'a str,
    /// The URDF path relative to the config file.
    pub urdf: &'a str,
    /// The guessed frames.
    pub frames: &'a Frames,
    /// The guessed joint groups.
    pub groups: &'a JointGroups,
    /// The standing posture (joint name, angle).
    pub standing: &'a [(String, f64)],
    /// How the standing posture was found.
    pub standing_basis: &'a str,
}

impl RobotSection<'_> {
    /// The section's text.
    pub fn text(&self) -> String {
        let f = self.frames;
        let mut text = String::from("[robot]\n");
        text.push_str(&comment(
            "Guessed by walkctl init-robot from the URDF's link and joint names and its geometry \
             in the standing posture (docs/new-robot.md); check each guess against the robot.",
        ));
        text.push_str(&format!("name = \"{}\"\n", self.name));
        text.push_str(&format!("urdf = \"{}\"\n", self.urdf));
        text.push_str(&key_line(
            &format!("base_link = \"{}\"", f.base_link.value),
            &f.base_link.basis,
        ));
        text.push_str(&comment(&format!(
            "Sole rectangle, centred on the sole frame (x forward, y left): {}.",
            f.sole.basis
        )));
        text.push_str(&format!(
            "sole = {{ length = {}, width = {} }}\n\n",
            number(f.sole.value.0),
            number(f.sole.value.1)
        ));
        text.push_str("[robot.frames]\n");
        text.push_str(&comment(&format!("Soles: {}.", f.feet.basis)));
        for (key, spec) in ["left_foot", "right_foot"].iter().zip(&f.feet.value) {
            text.push_str(&format!("{key} = {}\n", frame_text(spec, true)));
        }
        text.push_str(&comment(&format!("Hands: {}.", f.hands.basis)));
        for (key, spec) in ["left_hand", "right_hand"].iter().zip(&f.hands.value) {
            text.push_str(&format!("{key} = {}\n", frame_text(spec, true)));
        }
        text.push_str("\n[robot.ft_sensors]\n");
        text.push_str(&comment(&format!("FT sensors: {}.", f.ft_sensors.basis)));
        for (key, spec) in ["left", "right"].iter().zip(&f.ft_sensors.value) {
            text.push_str(&format!("{key} = {}\n", frame_text(spec, false)));
        }
        text.push_str("\n[robot.joint_groups]\n");
        text.push_str(&comment(
            "Legs: the joints of the two leg chains; the others by name (docs/new-robot.md).",
        ));
        let g = self.groups;
        text.push_str(&name_list("legs", &g.legs));
        text.push_str(&name_list("arms", &g.arms));
        text.push_str(&name_list("torso", &g.torso));
        text.push_str(&name_list("head", &g.head));
        if !g.unassigned.is_empty() {
            text.push_str(&comment(&format!(
                "In no group (no name rule matched): {}.",
                g.unassigned.join(", ")
            )));
        }
        text.push_str("\n[robot.standing]\n");
        text.push_str(&comment(&format!("Standing: {}.", self.standing_basis)));
        for (joint, angle) in self.standing {
            text.push_str(&format!("{joint} = {}\n", number(*angle)));
        }
        text
    }
}

/// The `[robot]` section of an existing config, verbatim (comments included): the lines from
/// `[robot]` up to the first table that is not `[robot.…]`.
pub fn copied_robot_section(config_text: &str, origin: &str) -> anyhow::Result<String> {
    let mut out = String::new();
    let mut inside = false;
    for line in config_text.lines() {
        let trimmed = line.trim();
        if trimmed.starts_with('[') {
            let table = trimmed.trim_matches(|c| c == '[' || c == ']').trim();
            inside = table == "robot" || table.starts_with("robot.");
        }
        if inside {
            out.push_str(line);
            out.push('\n');
        }
    }
    if out.is_empty() {
        anyhow::bail!("{origin}: --frames-from: the file has no [robot] section");
    }
    // Comment lines just above the next section belong to it.
    let mut lines: Vec<&str> = out.lines().collect();
    while lines
        .last()
        .is_some_and(|l| l.trim().is_empty() || l.trim_start().starts_with('#'))
    {
        lines.pop();
    }
    Ok(format!(
        "{}{}\n",
        comment("[robot] copied from the --frames-from config"),
        lines.join("\n")
    ))
}

/// The derived sections' text.
pub fn derived_sections(derived: &DerivedSections) -> String {
    let mut text = String::new();
    for section in &derived.sections {
        text.push_str(&format!("\n[{}]\n", section.table));
        for line in &section.lines {
            match line {
                Line::Comment(c) => text.push_str(&comment(c)),
                Line::Key { key, value, rule } => {
                    text.push_str(&key_line(&format!("{key} = {}", value_text(value)), rule))
                }
                Line::Commented { key, value, rule } => {
                    text.push_str(&key_line(&format!("# {key} = {}", value_text(value)), rule))
                }
            }
        }
    }
    text
}
