//! A tiny reader for NumPy `.npy` arrays (format 1.0–3.0, little-endian f4/f8, C order), enough
//! for joint-position recordings shaped `(frames, joints, 3)`.

use std::path::Path;

use super::error::LearnError;

/// A dense array of f64 values with its shape (C order).
#[derive(Clone, Debug, PartialEq)]
pub struct NpyArray {
    /// Dimensions, outermost first.
    pub shape: Vec<usize>,
    /// Values in C order.
    pub data: Vec<f64>,
}

/// Reads a `.npy` file.
pub fn read(path: &Path) -> Result<NpyArray, LearnError> {
    let bytes = std::fs::read(path).map_err(|error| LearnError::Io {
        path: path.to_path_buf(),
        error,
    })?;
    parse(&bytes, path)
}

/// Parses `.npy` bytes; `path` only names the source in errors.
pub fn parse(bytes: &[u8], path: &Path) -> Result<NpyArray, LearnError> {
    if bytes.len() < 10 || &bytes[..6] != b"\x93NUMPY" {
        return Err(LearnError::corrupt(path, "not a .npy file (bad magic)"));
    }
    let (header_len, header_start) = match bytes[6] {
        1 => (u16::from_le_bytes([bytes[8], bytes[9]]) as usize, 10),
        2 | 3 if bytes.len() >= 12 => (
            u32::from_le_bytes([bytes[8], bytes[9], bytes[10], bytes[11]]) as usize,
            12,
        ),
        v => {
            return Err(LearnError::corrupt(
                path,
                format!(".npy format version {v} unsupported"),
            ));
        }
    };
    let header = bytes
        .get(header_start..header_start + header_len)
        .ok_or_else(|| LearnError::Truncated {
            path: path.to_path_buf(),
            what: ".npy header".into(),
            offset: header_start + header_len,
            len: bytes.len(),
        })?;
    let header = String::from_utf8_lossy(header);
    let descr = dict_value(&header, "descr")
        .ok_or_else(|| LearnError::corrupt(path, ".npy header has no 'descr'"))?;
    let width = match descr.trim_matches(['\'', '"']) {
        "<f4" => 4,
        "<f8" => 8,
        other => {
            return Err(LearnError::corrupt(
                path,
                format!(".npy dtype {other} unsupported (use <f4 or <f8)"),
            ));
        }
    };
    if dict_value(&header, "fortran_order").is_some_and(|v| v.starts_with("True")) {
        return Err(LearnError::corrupt(
            path,
            "Fortran-ordered .npy unsupported",
        ));
    }
    let shape_text = header
        .split_once("'shape':")
        .and_then(|(_, rest)| rest.split_once('(')?.1.split_once(')'))
        .map(|(inside, _)| inside)
        .ok_or_else(|| LearnError::corrupt(path, ".npy header has no 'shape'"))?;
    let shape = shape_text
        .split(',')
        .map(str::trim)
        .filter(|s| !s.is_empty())
        .map(|s| {
            s.parse::<usize>()
                .map_err(|_| LearnError::corrupt(path, format!(".npy shape entry `{s}` invalid")))
        })
        .collect::<Result<Vec<_>, _>>()?;
    let count: usize = shape.iter().product();
    let start = header_start + header_len;
    let payload = bytes
        .get(start..start + count * width)
        .ok_or_else(|| LearnError::Truncated {
            path: path.to_path_buf(),
            what: format!(".npy data of shape {shape:?}"),
            offset: start + count * width,
            len: bytes.len(),
        })?;
    let data = payload
        .chunks(width)
        .map(|c| match width {
            4 => f64::from(f32::from_le_bytes([c[0], c[1], c[2], c[3]])),
            _ => f64::from_le_bytes(c.try_into().expect("8 bytes")),
        })
        .collect();
    Ok(NpyArray { shape, data })
}

/// The raw text after `'key':` in a Python dict literal, up to the next comma.
fn dict_value<'a>(header: &'a str, key: &str) -> Option<&'a str> {
    let (_, rest) = header.split_once(&format!("'{key}':"))?;
    Some(rest.trim_start().split(',').next()?.trim())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn npy(header: &str, payload: &[u8]) -> Vec<u8> {
        let mut bytes = b"\x93NUMPY\x01\x00".to_vec();
        bytes.extend_from_slice(&(header.len() as u16).to_le_bytes());
        bytes.extend_from_slice(header.as_bytes());
        bytes.extend_from_slice(payload);
        bytes
    }

    #[test]
    fn reads_f4_array() {
        let payload: Vec<u8> = [1.0f32, 2.0, 3.0, 4.0, 5.0, 6.0]
            .iter()
            .flat_map(|v| v.to_le_bytes())
            .collect();
        let bytes = npy(
            "{'descr': '<f4', 'fortran_order': False, 'shape': (1, 2, 3), }\n",
            &payload,
        );
        let array = parse(&bytes, Path::new("t.npy")).unwrap();
        assert_eq!(array.shape, vec![1, 2, 3]);
        assert_eq!(array.data, vec![1.0, 2.0, 3.0, 4.0, 5.0, 6.0]);
    }

    #[test]
    fn refuses_truncated_payload_and_bad_dtype() {
        let bytes = npy(
            "{'descr': '<f4', 'fortran_order': False, 'shape': (2, 3), }\n",
            &[0; 8],
        );
        let error = parse(&bytes, Path::new("t.npy")).unwrap_err().to_string();
        assert!(error.contains("truncated"), "{error}");
        let bytes = npy(
            "{'descr': '<i8', 'fortran_order': False, 'shape': (1,), }\n",
            &[0; 8],
        );
        let error = parse(&bytes, Path::new("t.npy")).unwrap_err().to_string();
        assert!(error.contains("<i8"), "{error}");
    }
}
