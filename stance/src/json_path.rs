//! Locating a JSON parse error: the path (`stances[3].q[5]`) of the value at a byte offset, so a
//! syntax error, a NaN or a wrong type is reported with its stance index and field.

use crate::error::Location;

enum Frame {
    Object {
        key: Option<String>,
        expect_key: bool,
    },
    Array {
        index: usize,
    },
}

/// The location of the value containing byte `offset` of `text` (a prefix scan; the text need
/// not be complete or valid after the offset).
pub(crate) fn location_at(text: &str, offset: usize) -> Location {
    let bytes = text.as_bytes();
    let end = offset.min(bytes.len());
    let mut stack: Vec<Frame> = Vec::new();
    let mut i = 0;
    while i < end {
        match bytes[i] {
            b'{' => stack.push(Frame::Object {
                key: None,
                expect_key: true,
            }),
            b'[' => stack.push(Frame::Array { index: 0 }),
            b'}' | b']' => {
                stack.pop();
            }
            b',' => match stack.last_mut() {
                Some(Frame::Array { index }) => *index += 1,
                Some(Frame::Object { key, expect_key }) => {
                    *key = None;
                    *expect_key = true;
                }
                None => {}
            },
            b'"' => {
                let start = i + 1;
                i = start;
                while i < bytes.len() && bytes[i] != b'"' {
                    i += if bytes[i] == b'\\' { 2 } else { 1 };
                }
                if let Some(Frame::Object { key, expect_key }) = stack.last_mut()
                    && *expect_key
                {
                    *key = Some(text[start..i.min(bytes.len())].to_owned());
                    *expect_key = false;
                }
            }
            _ => {}
        }
        i += 1;
    }
    to_location(&stack)
}

fn to_location(stack: &[Frame]) -> Location {
    let mut path = String::new();
    for frame in stack {
        match frame {
            Frame::Object { key: Some(k), .. } => {
                if !path.is_empty() {
                    path.push('.');
                }
                path.push_str(k);
            }
            Frame::Object { key: None, .. } => {}
            Frame::Array { index } => path.push_str(&format!("[{index}]")),
        }
    }
    if let Some(rest) = path.strip_prefix("stances[")
        && let Some((index, field)) = rest.split_once(']')
        && let Ok(index) = index.parse()
    {
        return Location::stance(index, field.trim_start_matches('.'));
    }
    Location::file(path)
}

/// Byte offset of a 1-based `(line, column)` position as reported by serde_json.
pub(crate) fn offset_of(text: &str, line: usize, column: usize) -> usize {
    let line_start: usize = text
        .split_inclusive('\n')
        .take(line.saturating_sub(1))
        .map(str::len)
        .sum();
    (line_start + column.saturating_sub(1)).min(text.len())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn finds_stance_and_field() {
        let text = r#"{"robot": "x", "stances": [{"q": [1, 2]}, {"q": [3, NaN"#;
        let loc = location_at(text, text.len() - 1);
        assert_eq!(loc, Location::stance(1, "q[1]"));
    }

    #[test]
    fn keys_inside_strings_do_not_confuse_it() {
        let text = r#"{"environment": {"surfaces": [{"name": "a,[{b", "pose": 1"#;
        let loc = location_at(text, text.len());
        assert_eq!(loc, Location::file("environment.surfaces[0].pose"));
    }

    #[test]
    fn line_and_column_map_to_offsets() {
        assert_eq!(offset_of("ab\ncd\nef", 3, 2), 7);
    }
}
