//! The MCAP sink of `walkctl record`: the Foxglove SDK's MCAP writer on the observer's context,
//! LZ4-compressed chunks, and a summary read back from the finished file with the `mcap` crate.

use std::collections::BTreeMap;
use std::fs::File;
use std::io::BufWriter;
use std::path::{Path, PathBuf};
use std::sync::Arc;

use anyhow::Context as _;
use foxglove::{Context, McapCompression, McapWriteOptions, McapWriterHandle};

/// Chunk size of the recording (bytes before compression).
const CHUNK_BYTES: u64 = 1024 * 1024;

/// An MCAP file being written from a context's channels.
pub struct Recording {
    path: PathBuf,
    handle: McapWriterHandle<BufWriter<File>>,
}

/// One channel of a finished recording.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct RecordedChannel {
    /// Topic.
    pub topic: String,
    /// Schema name.
    pub schema: String,
    /// Messages recorded.
    pub messages: u64,
}

/// What a finished recording holds (from the file's summary section).
#[derive(Debug, Clone, PartialEq)]
pub struct RecordingSummary {
    /// The file.
    pub path: PathBuf,
    /// Its size (bytes).
    pub bytes: u64,
    /// Messages in all channels.
    pub messages: u64,
    /// Log time of the first and the last message (ns since the Unix epoch).
    pub start_ns: u64,
    /// See `start_ns`.
    pub end_ns: u64,
    /// Channels by topic.
    pub channels: Vec<RecordedChannel>,
}

impl RecordingSummary {
    /// Recorded time span (s).
    pub fn duration_s(&self) -> f64 {
        self.end_ns.saturating_sub(self.start_ns) as f64 * 1e-9
    }
}

impl std::fmt::Display for RecordingSummary {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        writeln!(
            f,
            "{}: {} messages in {:.1} s, {:.1} MB",
            self.path.display(),
            self.messages,
            self.duration_s(),
            self.bytes as f64 / 1e6
        )?;
        for channel in &self.channels {
            writeln!(
                f,
                "  {:<26} {:<30} {:>8}",
                channel.topic, channel.schema, channel.messages
            )?;
        }
        Ok(())
    }
}

impl Recording {
    /// Starts writing `path` (replacing a file there) from `context`'s channels.
    pub fn create(path: &Path, context: &Arc<Context>) -> anyhow::Result<Self> {
        if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
            std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
        }
        let file = File::create(path).with_context(|| format!("creating {}", path.display()))?;
        let options = McapWriteOptions::default()
            .compression(Some(McapCompression::Lz4))
            .chunk_size(Some(CHUNK_BYTES));
        let handle = context
            .mcap_writer_with_options(options)
            .create(BufWriter::new(file))
            .with_context(|| format!("starting the MCAP writer on {}", path.display()))?;
        Ok(Self {
            path: path.to_owned(),
            handle,
        })
    }

    /// Adds a metadata record named `name`.
    pub fn metadata(&self, name: &str, values: BTreeMap<String, String>) -> anyhow::Result<()> {
        self.handle
            .write_metadata(name, values)
            .with_context(|| format!("writing metadata to {}", self.path.display()))
    }

    /// Finishes the file (summary section, index) and reads its summary back.
    pub fn finish(self) -> anyhow::Result<RecordingSummary> {
        let path = self.path;
        self.handle
            .close()
            .with_context(|| format!("finishing {}", path.display()))?;
        summarize(&path)
    }
}

/// Reads the summary section of the MCAP file at `path`.
pub fn summarize(path: &Path) -> anyhow::Result<RecordingSummary> {
    let bytes = std::fs::read(path).with_context(|| format!("reading {}", path.display()))?;
    let summary = mcap::Summary::read(&bytes)
        .with_context(|| format!("reading the summary of {}", path.display()))?
        .with_context(|| format!("{} has no summary section", path.display()))?;
    let stats = summary
        .stats
        .as_ref()
        .with_context(|| format!("{} has no statistics", path.display()))?;
    let mut channels: Vec<RecordedChannel> = summary
        .channels
        .iter()
        .map(|(id, channel)| RecordedChannel {
            topic: channel.topic.clone(),
            schema: channel
                .schema
                .as_ref()
                .map_or_else(String::new, |s| s.name.clone()),
            messages: stats.channel_message_counts.get(id).copied().unwrap_or(0),
        })
        .collect();
    channels.sort_by(|a, b| a.topic.cmp(&b.topic));
    Ok(RecordingSummary {
        path: path.to_owned(),
        bytes: bytes.len() as u64,
        messages: stats.message_count,
        start_ns: stats.message_start_time,
        end_ns: stats.message_end_time,
        channels,
    })
}
