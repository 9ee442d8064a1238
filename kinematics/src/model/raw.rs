//! Facts about a URDF that `urdf-rs` hides, read from the raw XML.
//!
//! urdf-rs fills defaults silently: a revolute joint without `<limit>` gets all-zero limits, a link
//! without `<inertial>` gets mass 0, and every numeric attribute is parsed without a finiteness
//! check. This pass records which elements are really present and refuses non-finite numbers,
//! naming the link or joint and the attribute.

use std::collections::HashSet;

use quick_xml::Reader;
use quick_xml::events::{BytesStart, Event};

use super::ModelError;

/// Which optional elements each link and joint really has.
#[derive(Debug, Default)]
pub(super) struct RawFacts {
    /// Joints that have a `<limit>` element.
    pub joints_with_limit: HashSet<String>,
    /// Links that have an `<inertial>` element.
    pub links_with_inertial: HashSet<String>,
}

/// Attributes whose values are names or paths, never numbers.
const TEXT_ATTRIBUTES: [&str; 7] = [
    "name",
    "link",
    "joint",
    "filename",
    "type",
    "version",
    "reference",
];

/// The `<link>` or `<joint>` element currently open, for error messages and presence facts.
struct Owner {
    kind: &'static str,
    name: String,
    depth: usize,
}

/// Scans `xml` once: presence of `<limit>` / `<inertial>` and finiteness of every number.
pub(super) fn scan(xml: &str) -> Result<RawFacts, ModelError> {
    let mut reader = Reader::from_str(xml);
    let mut facts = RawFacts::default();
    let mut owner: Option<Owner> = None;
    let mut depth = 0usize;
    loop {
        let event = reader.read_event().map_err(|error| ModelError::Xml {
            position: reader.error_position(),
            message: error.to_string(),
        })?;
        match event {
            Event::Start(element) => {
                depth += 1;
                visit(&element, depth, &mut owner, &mut facts)?;
            }
            Event::Empty(element) => {
                visit(&element, depth + 1, &mut owner, &mut facts)?;
            }
            Event::End(_) => {
                if owner.as_ref().is_some_and(|o| o.depth == depth) {
                    owner = None;
                }
                depth = depth.saturating_sub(1);
            }
            Event::Eof => break,
            _ => {}
        }
    }
    Ok(facts)
}

fn visit(
    element: &BytesStart<'_>,
    depth: usize,
    owner: &mut Option<Owner>,
    facts: &mut RawFacts,
) -> Result<(), ModelError> {
    let tag = String::from_utf8_lossy(element.name().as_ref()).into_owned();
    // Only direct children of <robot> (depth 2) own the elements below them.
    if depth == 2 && (tag == "link" || tag == "joint") {
        let name = attribute(element, "name")?.unwrap_or_default();
        *owner = Some(Owner {
            kind: if tag == "link" { "link" } else { "joint" },
            name,
            depth,
        });
    } else if let Some(current) = owner.as_ref() {
        if depth == current.depth + 1 {
            match (current.kind, tag.as_str()) {
                ("joint", "limit") => {
                    facts.joints_with_limit.insert(current.name.clone());
                }
                ("link", "inertial") => {
                    facts.links_with_inertial.insert(current.name.clone());
                }
                _ => {}
            }
        }
    }
    for attr in element.attributes() {
        let attr = attr.map_err(|error| ModelError::Xml {
            position: 0,
            message: format!("<{tag}>: {error}"),
        })?;
        let key = String::from_utf8_lossy(attr.key.as_ref()).into_owned();
        if TEXT_ATTRIBUTES.contains(&key.as_str()) {
            continue;
        }
        let value = attr.unescape_value().map_err(|error| ModelError::Xml {
            position: 0,
            message: format!("<{tag} {key}>: {error}"),
        })?;
        let non_finite = value
            .split_whitespace()
            .filter_map(|token| token.parse::<f64>().ok())
            .any(|number| !number.is_finite());
        if non_finite {
            let owner_text = owner
                .as_ref()
                .map(|o| format!("{} '{}'", o.kind, o.name))
                .unwrap_or_else(|| "robot".to_owned());
            return Err(ModelError::NonFinite {
                owner: owner_text,
                element: tag,
                attribute: key,
                value: value.into_owned(),
            });
        }
    }
    Ok(())
}

fn attribute(element: &BytesStart<'_>, key: &str) -> Result<Option<String>, ModelError> {
    match element.try_get_attribute(key) {
        Ok(Some(attr)) => Ok(Some(
            attr.unescape_value()
                .map_err(|error| ModelError::Xml {
                    position: 0,
                    message: error.to_string(),
                })?
                .into_owned(),
        )),
        Ok(None) => Ok(None),
        Err(error) => Err(ModelError::Xml {
            position: 0,
            message: error.to_string(),
        }),
    }
}
