//! The paper's Fig. 5 as a filmstrip: pictures of the robot at evenly spaced moments of a walk,
//! side by side. The pictures are MuJoCo's (`walk-sim --snapshots`, named by simulated time); this
//! module picks the ones nearest to evenly spaced times of the walk, halves them and tiles them
//! left to right into one PNG.

use std::fs::File;
use std::io::{BufReader, BufWriter};
use std::path::Path;

use anyhow::{Context, bail};

/// Pictures in a filmstrip.
pub const FRAMES: usize = 8;
/// Width of the white gap between two pictures (pixels, after halving).
const GAP: usize = 4;

/// An 8-bit RGB picture.
struct Picture {
    width: usize,
    height: usize,
    rgb: Vec<u8>,
}

/// The simulated time of a picture named `t000012.500.png` (s).
fn frame_time(name: &str) -> Option<f64> {
    name.strip_prefix('t')?.strip_suffix(".png")?.parse().ok()
}

/// The pictures in `dir` by simulated time.
fn frames(dir: &Path) -> anyhow::Result<Vec<(f64, std::path::PathBuf)>> {
    let mut frames = Vec::new();
    for entry in std::fs::read_dir(dir).with_context(|| format!("reading {}", dir.display()))? {
        let path = entry?.path();
        if let Some(t) = path
            .file_name()
            .and_then(|n| n.to_str())
            .and_then(frame_time)
        {
            frames.push((t, path));
        }
    }
    frames.sort_by(|a, b| a.0.total_cmp(&b.0));
    Ok(frames)
}

fn read(path: &Path) -> anyhow::Result<Picture> {
    let file = File::open(path).with_context(|| format!("opening {}", path.display()))?;
    let mut reader = png::Decoder::new(BufReader::new(file))
        .read_info()
        .with_context(|| format!("reading {}", path.display()))?;
    let mut rgb = vec![0; reader.output_buffer_size().context("picture too large")?];
    let info = reader.next_frame(&mut rgb)?;
    if info.color_type != png::ColorType::Rgb || info.bit_depth != png::BitDepth::Eight {
        bail!("{} is not an 8-bit RGB picture", path.display());
    }
    rgb.truncate(info.buffer_size());
    Ok(Picture {
        width: info.width as usize,
        height: info.height as usize,
        rgb,
    })
}

/// The picture at half size (each pixel the mean of a 2 × 2 block).
fn halved(p: &Picture) -> Picture {
    let (width, height) = (p.width / 2, p.height / 2);
    let mut rgb = vec![0; width * height * 3];
    for y in 0..height {
        for x in 0..width {
            for c in 0..3 {
                let at = |dx: usize, dy: usize| {
                    u32::from(p.rgb[((2 * y + dy) * p.width + 2 * x + dx) * 3 + c])
                };
                let sum = at(0, 0) + at(1, 0) + at(0, 1) + at(1, 1);
                rgb[(y * width + x) * 3 + c] = ((sum + 2) / 4) as u8;
            }
        }
    }
    Picture { width, height, rgb }
}

/// Writes the filmstrip of the walk between simulated times `start_s` and `end_s` from the
/// pictures in `dir` to `out`: [`FRAMES`] pictures at evenly spaced times from the start to the
/// end (each the picture taken nearest to its time). Returns the pictures' times.
pub fn write_filmstrip(
    dir: &Path,
    start_s: f64,
    end_s: f64,
    out: &Path,
) -> anyhow::Result<Vec<f64>> {
    let all = frames(dir)?;
    if all.is_empty() {
        bail!(
            "no pictures in {} (walk-sim --snapshots saves them)",
            dir.display()
        );
    }
    let mut picked: Vec<&(f64, std::path::PathBuf)> = Vec::with_capacity(FRAMES);
    for i in 0..FRAMES {
        let t = start_s + (end_s - start_s) * i as f64 / (FRAMES - 1) as f64;
        let nearest = all
            .iter()
            .min_by(|a, b| (a.0 - t).abs().total_cmp(&(b.0 - t).abs()))
            .expect("not empty");
        picked.push(nearest);
    }
    let pictures: Vec<Picture> = picked
        .iter()
        .map(|(_, path)| read(path).map(|p| halved(&p)))
        .collect::<anyhow::Result<_>>()?;
    let (width, height) = (pictures[0].width, pictures[0].height);
    if pictures
        .iter()
        .any(|p| p.width != width || p.height != height)
    {
        bail!("the pictures in {} differ in size", dir.display());
    }
    let strip_width = FRAMES * width + (FRAMES - 1) * GAP;
    let mut strip = vec![255u8; strip_width * height * 3];
    for (i, picture) in pictures.iter().enumerate() {
        let x0 = i * (width + GAP);
        for y in 0..height {
            let row = &picture.rgb[y * width * 3..(y + 1) * width * 3];
            let at = (y * strip_width + x0) * 3;
            strip[at..at + width * 3].copy_from_slice(row);
        }
    }
    if let Some(parent) = out.parent().filter(|p| !p.as_os_str().is_empty()) {
        std::fs::create_dir_all(parent)?;
    }
    let file = File::create(out).with_context(|| format!("creating {}", out.display()))?;
    let mut encoder = png::Encoder::new(BufWriter::new(file), strip_width as u32, height as u32);
    encoder.set_color(png::ColorType::Rgb);
    encoder.set_depth(png::BitDepth::Eight);
    encoder.set_compression(png::Compression::High);
    let mut writer = encoder.write_header()?;
    writer.write_image_data(&strip)?;
    writer.finish()?;
    Ok(picked.iter().map(|(t, _)| *t).collect())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn write(path: &Path, width: u32, height: u32, value: u8) {
        let file = File::create(path).unwrap();
        let mut encoder = png::Encoder::new(BufWriter::new(file), width, height);
        encoder.set_color(png::ColorType::Rgb);
        encoder.set_depth(png::BitDepth::Eight);
        let mut writer = encoder.write_header().unwrap();
        writer
            .write_image_data(&vec![value; (width * height * 3) as usize])
            .unwrap();
        writer.finish().unwrap();
    }

    #[test]
    fn the_pictures_nearest_to_evenly_spaced_times_are_tiled() {
        let dir = std::env::temp_dir().join(format!("filmstrip-test-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        for k in 0..=20 {
            let t = k as f64 * 0.5;
            write(&dir.join(format!("t{t:010.3}.png")), 8, 6, (k * 10) as u8);
        }
        let out = dir.join("strip.png");
        let times = write_filmstrip(&dir, 1.0, 8.0, &out).unwrap();
        assert_eq!(times, [1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0]);
        let strip = read(&out).unwrap();
        assert_eq!(
            (strip.width, strip.height),
            (FRAMES * 4 + (FRAMES - 1) * GAP, 3)
        );
        // The first picture is the one taken at 1.0 s (value 20), the gap after it white.
        assert_eq!(strip.rgb[0], 20);
        assert_eq!(strip.rgb[4 * 3], 255);
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
