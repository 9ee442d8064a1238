//! A small reader for C3D motion-capture files (Intel byte order, integer or float point data):
//! header, parameter section and 3D point data; analog data is skipped. Enough to read Vicon
//! trials such as the gaitalytics corpus file, and strict about truncation and bad fields.

use std::collections::HashMap;
use std::path::Path;

use super::error::LearnError;

/// Processor type of little-endian (Intel) C3D files, the only one supported.
const PROCESSOR_INTEL: u8 = 84;
/// Size of a C3D block.
const BLOCK: usize = 512;

/// One parameter value.
#[derive(Clone, Debug, PartialEq)]
pub enum ParameterValue {
    /// Character data split into strings along the first dimension (trailing blanks trimmed).
    Text(Vec<String>),
    /// Signed bytes.
    Bytes(Vec<i8>),
    /// 16-bit integers.
    Integers(Vec<i16>),
    /// 32-bit floats.
    Floats(Vec<f32>),
}

/// A C3D trial: point labels, rate, per-frame positions (NaN where a marker is invalid) and the
/// parameters by `GROUP:NAME`.
#[derive(Clone, Debug)]
pub struct C3dFile {
    /// Point labels (POINT:LABELS, LABELS2, … concatenated), trimmed.
    pub labels: Vec<String>,
    /// Point frame rate (Hz).
    pub rate: f64,
    /// Number of the first frame (header word 4, 1-based).
    pub first_frame: usize,
    /// `points[frame][point]` in the file's units; NaN for invalid samples (negative residual).
    pub points: Vec<Vec<[f64; 3]>>,
    parameters: HashMap<String, ParameterValue>,
}

struct Bytes<'a> {
    data: &'a [u8],
    path: &'a Path,
}

impl Bytes<'_> {
    fn slice(&self, offset: usize, len: usize, what: &str) -> Result<&[u8], LearnError> {
        self.data
            .get(offset..offset + len)
            .ok_or_else(|| LearnError::Truncated {
                path: self.path.to_path_buf(),
                what: what.to_owned(),
                offset: offset + len,
                len: self.data.len(),
            })
    }

    fn u8(&self, offset: usize, what: &str) -> Result<u8, LearnError> {
        Ok(self.slice(offset, 1, what)?[0])
    }

    fn i16(&self, offset: usize, what: &str) -> Result<i16, LearnError> {
        let b = self.slice(offset, 2, what)?;
        Ok(i16::from_le_bytes([b[0], b[1]]))
    }

    fn u16(&self, offset: usize, what: &str) -> Result<u16, LearnError> {
        let b = self.slice(offset, 2, what)?;
        Ok(u16::from_le_bytes([b[0], b[1]]))
    }

    fn f32(&self, offset: usize, what: &str) -> Result<f32, LearnError> {
        let b = self.slice(offset, 4, what)?;
        Ok(f32::from_le_bytes([b[0], b[1], b[2], b[3]]))
    }
}

impl C3dFile {
    /// Reads and parses a C3D file.
    pub fn read(path: &Path) -> Result<Self, LearnError> {
        let data = std::fs::read(path).map_err(|error| LearnError::Io {
            path: path.to_path_buf(),
            error,
        })?;
        Self::parse(&data, path)
    }

    /// Parses C3D bytes; `path` only names the source in errors.
    pub fn parse(data: &[u8], path: &Path) -> Result<Self, LearnError> {
        let bytes = Bytes { data, path };
        let parameter_block = bytes.u8(0, "header")? as usize;
        if bytes.u8(1, "header")? != 0x50 || parameter_block == 0 {
            return Err(LearnError::corrupt(
                path,
                "not a C3D file (header byte 2 is not 0x50)",
            ));
        }
        let point_count = bytes.u16(2, "header point count")? as usize;
        let analog_per_frame = bytes.u16(4, "header analog count")? as usize;
        let first_frame = bytes.u16(6, "header first frame")? as usize;
        let last_frame = bytes.u16(8, "header last frame")? as usize;
        let scale = bytes.f32(12, "header scale factor")?;
        let data_block = bytes.u16(16, "header data block")? as usize;
        let header_rate = bytes.f32(20, "header frame rate")?;
        let parameter_start = (parameter_block - 1) * BLOCK;
        let processor = bytes.u8(parameter_start + 3, "parameter section header")?;
        if processor != PROCESSOR_INTEL {
            return Err(LearnError::corrupt(
                path,
                format!("processor type {processor} unsupported (only Intel, 84)"),
            ));
        }
        let parameters = parse_parameters(&bytes, parameter_start + 4)?;
        let mut file = C3dFile {
            labels: Vec::new(),
            rate: f64::from(header_rate),
            first_frame,
            points: Vec::new(),
            parameters,
        };
        if let Some(rate) = file.float("POINT", "RATE") {
            file.rate = f64::from(rate);
        }
        if !(file.rate > 0.0 && file.rate.is_finite()) {
            return Err(LearnError::corrupt(
                path,
                format!("point rate {} Hz is not positive", file.rate),
            ));
        }
        let used = file
            .integer("POINT", "USED")
            .map_or(point_count, |u| u as u16 as usize);
        let labels: Vec<String> = ["LABELS", "LABELS2", "LABELS3", "LABELS4"]
            .iter()
            .filter_map(|key| file.text("POINT", key))
            .flatten()
            .cloned()
            .collect();
        file.labels = labels;
        if file.labels.len() < used {
            return Err(LearnError::corrupt(
                path,
                format!(
                    "POINT:LABELS has {} labels for {used} points",
                    file.labels.len()
                ),
            ));
        }
        file.labels.truncate(used);
        if last_frame < first_frame || data_block == 0 {
            return Err(LearnError::corrupt(
                path,
                format!(
                    "frame range {first_frame}..{last_frame}, data block {data_block} are invalid"
                ),
            ));
        }
        let frames = last_frame - first_frame + 1;
        let is_float = scale < 0.0;
        let word = if is_float { 4 } else { 2 };
        let frame_size = (4 * used + analog_per_frame) * word;
        let start = (data_block - 1) * BLOCK;
        bytes.slice(start, frames * frame_size, "point data")?;
        let point_scale = f64::from(scale.abs());
        file.points = (0..frames)
            .map(|f| {
                (0..used)
                    .map(|p| {
                        let at = start + f * frame_size + p * 4 * word;
                        let value = |k: usize| -> f64 {
                            let offset = at + k * word;
                            if is_float {
                                f64::from(f32::from_le_bytes(
                                    data[offset..offset + 4].try_into().expect("4 bytes"),
                                ))
                            } else {
                                f64::from(i16::from_le_bytes([data[offset], data[offset + 1]]))
                                    * point_scale
                            }
                        };
                        if value(3) < 0.0 {
                            [f64::NAN; 3]
                        } else {
                            [value(0), value(1), value(2)]
                        }
                    })
                    .collect()
            })
            .collect();
        Ok(file)
    }

    /// A parameter by group and name (case-insensitive).
    pub fn parameter(&self, group: &str, name: &str) -> Option<&ParameterValue> {
        self.parameters
            .get(&format!("{}:{}", group.to_uppercase(), name.to_uppercase()))
    }

    /// The first value of an integer parameter.
    pub fn integer(&self, group: &str, name: &str) -> Option<i16> {
        match self.parameter(group, name)? {
            ParameterValue::Integers(v) => v.first().copied(),
            ParameterValue::Bytes(v) => v.first().map(|&b| i16::from(b)),
            _ => None,
        }
    }

    /// The first value of a float parameter.
    pub fn float(&self, group: &str, name: &str) -> Option<f32> {
        match self.parameter(group, name)? {
            ParameterValue::Floats(v) => v.first().copied(),
            _ => None,
        }
    }

    /// The strings of a text parameter.
    pub fn text(&self, group: &str, name: &str) -> Option<&[String]> {
        match self.parameter(group, name)? {
            ParameterValue::Text(v) => Some(v),
            _ => None,
        }
    }

    /// All values of a float parameter.
    pub fn floats(&self, group: &str, name: &str) -> Option<&[f32]> {
        match self.parameter(group, name)? {
            ParameterValue::Floats(v) => Some(v),
            _ => None,
        }
    }

    /// All values of an integer parameter.
    pub fn integers(&self, group: &str, name: &str) -> Option<&[i16]> {
        match self.parameter(group, name)? {
            ParameterValue::Integers(v) => Some(v),
            _ => None,
        }
    }

    /// Index of a point label (exact match after trimming).
    pub fn label_index(&self, label: &str) -> Option<usize> {
        self.labels.iter().position(|l| l == label)
    }
}

/// Walks the parameter records: groups first give id → name, parameters are keyed `GROUP:NAME`.
fn parse_parameters(
    bytes: &Bytes<'_>,
    mut offset: usize,
) -> Result<HashMap<String, ParameterValue>, LearnError> {
    let mut groups: HashMap<i8, String> = HashMap::new();
    let mut raw: Vec<(i8, String, ParameterValue)> = Vec::new();
    loop {
        let name_len = (bytes.u8(offset, "parameter record")? as i8).unsigned_abs() as usize;
        if name_len == 0 {
            break;
        }
        let id = bytes.u8(offset + 1, "parameter record")? as i8;
        let name = String::from_utf8_lossy(bytes.slice(offset + 2, name_len, "parameter name")?)
            .trim()
            .to_uppercase();
        let next_field = offset + 2 + name_len;
        let next = bytes.i16(next_field, "parameter record")?;
        let body = next_field + 2;
        if id < 0 {
            groups.insert(-id, name);
        } else {
            let value = parse_value(bytes, body, &name)?;
            raw.push((id, name, value));
        }
        if next <= 0 {
            break;
        }
        offset = next_field + next as usize;
    }
    Ok(raw
        .into_iter()
        .filter_map(|(id, name, value)| {
            groups
                .get(&id)
                .map(|group| (format!("{group}:{name}"), value))
        })
        .collect())
}

fn parse_value(bytes: &Bytes<'_>, at: usize, name: &str) -> Result<ParameterValue, LearnError> {
    let kind = bytes.u8(at, name)? as i8;
    let dimension_count = bytes.u8(at + 1, name)? as usize;
    let dimensions: Vec<usize> = bytes
        .slice(at + 2, dimension_count, name)?
        .iter()
        .map(|&d| d as usize)
        .collect();
    let count: usize = dimensions.iter().product();
    let start = at + 2 + dimension_count;
    let width = (kind as i16).unsigned_abs() as usize;
    if !matches!(kind, -1 | 1 | 2 | 4) {
        return Err(LearnError::corrupt(
            bytes.path,
            format!("C3D parameter {name}: unknown element type {kind}"),
        ));
    }
    let data = bytes.slice(start, count * width, name)?;
    Ok(match kind {
        -1 => {
            let len = dimensions.first().copied().unwrap_or(0).max(1);
            ParameterValue::Text(
                data.chunks(len)
                    .map(|c| String::from_utf8_lossy(c).trim().to_owned())
                    .collect(),
            )
        }
        1 => ParameterValue::Bytes(data.iter().map(|&b| b as i8).collect()),
        2 => ParameterValue::Integers(
            data.chunks(2)
                .map(|c| i16::from_le_bytes([c[0], c[1]]))
                .collect(),
        ),
        _ => ParameterValue::Floats(
            data.chunks(4)
                .map(|c| f32::from_le_bytes([c[0], c[1], c[2], c[3]]))
                .collect(),
        ),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A parameter record: name, group id, then `body` (type, dimensions, data, description).
    fn record(name: &str, id: i8, body: &[u8]) -> Vec<u8> {
        let mut r = vec![name.len() as u8, id as u8];
        r.extend_from_slice(name.as_bytes());
        r.extend_from_slice(&((body.len() + 2) as i16).to_le_bytes());
        r.extend_from_slice(body);
        r
    }

    /// A two-frame, two-point C3D with integer point data (scale 0.5) at 50 Hz.
    fn tiny_integer_c3d() -> Vec<u8> {
        let mut file = vec![0u8; 3 * BLOCK];
        file[0] = 2; // parameters in block 2
        file[1] = 0x50;
        file[2..4].copy_from_slice(&2u16.to_le_bytes()); // points
        file[6..8].copy_from_slice(&1u16.to_le_bytes()); // first frame
        file[8..10].copy_from_slice(&2u16.to_le_bytes()); // last frame
        file[12..16].copy_from_slice(&0.5f32.to_le_bytes()); // integer data, scale 0.5
        file[16..18].copy_from_slice(&3u16.to_le_bytes()); // data in block 3
        file[20..24].copy_from_slice(&50.0f32.to_le_bytes());
        let mut parameters = vec![0, 0, 1, PROCESSOR_INTEL];
        parameters.extend(record("POINT", -1, &[0]));
        let mut labels = vec![(-1i8) as u8, 2, 4, 2];
        labels.extend_from_slice(b"LHEERHEE");
        labels.push(0);
        parameters.extend(record("LABELS", 1, &labels));
        let mut rate = vec![4, 0];
        rate.extend_from_slice(&50.0f32.to_le_bytes());
        rate.push(0);
        parameters.extend(record("RATE", 1, &rate));
        parameters.extend([0, 0]);
        file[BLOCK..BLOCK + parameters.len()].copy_from_slice(&parameters);
        let samples: [[i16; 4]; 4] = [[2, 4, 6, 0], [8, 10, 12, 0], [1, 1, 1, -1], [0, 2, 4, 0]];
        let data: Vec<u8> = samples
            .iter()
            .flatten()
            .flat_map(|v| v.to_le_bytes())
            .collect();
        file[2 * BLOCK..2 * BLOCK + data.len()].copy_from_slice(&data);
        file
    }

    #[test]
    fn reads_integer_points_labels_and_rate() {
        let file = C3dFile::parse(&tiny_integer_c3d(), Path::new("tiny.c3d")).unwrap();
        assert_eq!(file.labels, ["LHEE", "RHEE"]);
        assert_eq!(file.rate, 50.0);
        assert_eq!(file.points[0], vec![[1.0, 2.0, 3.0], [4.0, 5.0, 6.0]]);
        assert!(
            file.points[1][0][0].is_nan(),
            "negative residual = invalid sample"
        );
        assert_eq!(file.points[1][1], [0.0, 1.0, 2.0]);
    }

    #[test]
    fn refuses_big_endian_files_and_truncated_parameters() {
        let mut bytes = tiny_integer_c3d();
        bytes[BLOCK + 3] = 86;
        let error = C3dFile::parse(&bytes, Path::new("mips.c3d")).unwrap_err();
        assert!(error.to_string().contains("processor type 86"), "{error}");
        let bytes = tiny_integer_c3d();
        let error = C3dFile::parse(&bytes[..BLOCK + 12], Path::new("cut.c3d")).unwrap_err();
        assert!(matches!(error, LearnError::Truncated { .. }), "{error}");
    }
}
