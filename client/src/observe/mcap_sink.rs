//! The MCAP sink of `walkctl record`: the Foxglove SDK's MCAP writer on the observer's context,
//! LZ4-compressed chunks, and a summary read back from the finished file's summary section.
//!
//! A write that fails (a full disk, a dead mount) is kept, with the file's name, and ends the
//! recording: the MCAP writer panics when it is used again after a failed write, so the file
//! under it ([`Guarded`]) takes everything after the first failure without writing it, and the
//! recording reports the failure ([`Recording::failed`], [`Recording::finish`]).

use std::collections::BTreeMap;
use std::fs::{File, OpenOptions};
use std::io::{self, BufWriter, Read, Seek, SeekFrom, Write};
use std::path::{Path, PathBuf};
use std::sync::{Arc, OnceLock};

use anyhow::Context as _;
use foxglove::{Context, McapCompression, McapWriteOptions, McapWriterHandle};
use mcap::sans_io::{SummaryReadEvent, SummaryReader, SummaryReaderOptions};

/// Chunk size of the recording (bytes before compression).
const CHUNK_BYTES: u64 = 1024 * 1024;

/// What a recording can write to: a file, or a stand-in in the tests. Read back for the summary.
pub trait Output: Read + Write + Seek + Send + 'static {}

impl<T: Read + Write + Seek + Send + 'static> Output for T {}

/// An MCAP file being written from a context's channels.
pub struct Recording<W: Output = File> {
    path: PathBuf,
    handle: McapWriterHandle<BufWriter<Guarded<W>>>,
    failure: Arc<OnceLock<io::Error>>,
}

/// The output under the MCAP writer: passes everything through until a write, flush or seek
/// fails, keeps that first error, and from then on takes writes and seeks without doing them
/// (tracking the position the writer expects), so the writer never sees an error.
struct Guarded<W> {
    inner: W,
    failure: Arc<OnceLock<io::Error>>,
    position: u64,
    end: u64,
}

impl<W> Guarded<W> {
    fn failed(&self) -> bool {
        self.failure.get().is_some()
    }

    /// Keeps `error` unless it only asks for a retry (which the caller does).
    fn keep(&mut self, error: io::Error) -> io::Result<()> {
        if error.kind() == io::ErrorKind::Interrupted {
            return Err(error);
        }
        let _ = self.failure.set(error);
        Ok(())
    }

    fn moved_to(&mut self, position: u64) -> u64 {
        self.position = position;
        self.end = self.end.max(position);
        position
    }
}

impl<W: Write> Write for Guarded<W> {
    fn write(&mut self, buf: &[u8]) -> io::Result<usize> {
        if !self.failed() {
            match self.inner.write(buf) {
                Ok(n) => {
                    self.moved_to(self.position + n as u64);
                    return Ok(n);
                }
                Err(error) => self.keep(error)?,
            }
        }
        self.moved_to(self.position + buf.len() as u64);
        Ok(buf.len())
    }

    fn flush(&mut self) -> io::Result<()> {
        if !self.failed()
            && let Err(error) = self.inner.flush()
        {
            self.keep(error)?;
        }
        Ok(())
    }
}

impl<W: Seek> Seek for Guarded<W> {
    fn seek(&mut self, to: SeekFrom) -> io::Result<u64> {
        if !self.failed() {
            match self.inner.seek(to) {
                Ok(position) => return Ok(self.moved_to(position)),
                Err(error) => self.keep(error)?,
            }
        }
        let position = match to {
            SeekFrom::Start(offset) => offset,
            SeekFrom::Current(delta) => self.position.saturating_add_signed(delta),
            SeekFrom::End(delta) => self.end.saturating_add_signed(delta),
        };
        Ok(self.moved_to(position))
    }
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
        // Readable too: the summary is read back from the finished file.
        let file = OpenOptions::new()
            .read(true)
            .write(true)
            .create(true)
            .truncate(true)
            .open(path)
            .with_context(|| format!("creating {}", path.display()))?;
        Self::start(path, file, context)
    }
}

impl<W: Output> Recording<W> {
    /// Starts writing the MCAP file `path` names to `output`, from `context`'s channels.
    fn start(path: &Path, output: W, context: &Arc<Context>) -> anyhow::Result<Self> {
        let failure = Arc::new(OnceLock::new());
        let guarded = Guarded {
            inner: output,
            failure: Arc::clone(&failure),
            position: 0,
            end: 0,
        };
        let options = McapWriteOptions::default()
            .compression(Some(McapCompression::Lz4))
            .chunk_size(Some(CHUNK_BYTES));
        let handle = context
            .mcap_writer_with_options(options)
            .create(BufWriter::new(guarded))
            .with_context(|| format!("starting the MCAP writer on {}", path.display()))?;
        let recording = Self {
            path: path.to_owned(),
            handle,
            failure,
        };
        recording.check()?;
        Ok(recording)
    }

    /// Whether a write to the file failed (the recording then writes nothing more).
    pub fn failed(&self) -> bool {
        self.failure.get().is_some()
    }

    /// The first failed write, naming the file and the operating system's reason.
    fn check(&self) -> anyhow::Result<()> {
        written(&self.path, &self.failure)
    }

    /// Adds a metadata record named `name`.
    pub fn metadata(&self, name: &str, values: BTreeMap<String, String>) -> anyhow::Result<()> {
        self.handle
            .write_metadata(name, values)
            .with_context(|| format!("writing metadata to {}", self.path.display()))?;
        self.check()
    }

    /// Finishes the file (summary section, index) and reads its summary back; the first failed
    /// write, if any, instead.
    pub fn finish(self) -> anyhow::Result<RecordingSummary> {
        let Self {
            path,
            handle,
            failure,
        } = self;
        let finishing = || format!("finishing {}", path.display());
        let flushed = handle.close().with_context(finishing)?.into_inner();
        written(&path, &failure)?;
        let mut output = flushed
            .map_err(|e| e.into_error())
            .with_context(finishing)?
            .inner;
        summarize(&mut output, &path)
    }
}

/// `Err` naming `path` and the operating system's reason if a write to it failed.
fn written(path: &Path, failure: &OnceLock<io::Error>) -> anyhow::Result<()> {
    match failure.get() {
        Some(error) => anyhow::bail!("writing {}: {error}", path.display()),
        None => Ok(()),
    }
}

/// Reads the summary section of the MCAP file in `input` (`path` names it): the footer and the
/// section it points to, nothing of the messages.
fn summarize(input: &mut impl Output, path: &Path) -> anyhow::Result<RecordingSummary> {
    let reading = || format!("reading the summary of {}", path.display());
    let bytes = input.seek(SeekFrom::End(0)).with_context(reading)?;
    let mut reader =
        SummaryReader::new_with_options(SummaryReaderOptions::default().with_file_size(bytes));
    while let Some(event) = reader.next_event() {
        match event.with_context(reading)? {
            SummaryReadEvent::ReadRequest(n) => {
                let read = input.read(reader.insert(n)).with_context(reading)?;
                reader.notify_read(read);
            }
            SummaryReadEvent::SeekRequest(to) => {
                reader.notify_seeked(input.seek(to).with_context(reading)?);
            }
        }
    }
    let summary = reader
        .finish()
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
        bytes,
        messages: stats.message_count,
        start_ns: stats.message_start_time,
        end_ns: stats.message_end_time,
        channels,
    })
}

#[cfg(test)]
mod tests {
    use std::io::Cursor;
    use std::sync::atomic::{AtomicU64, Ordering};

    use foxglove::Channel;
    use foxglove::messages::Log;

    use super::*;

    /// A disk in memory with room for `room` bytes (every write beyond fails with ENOSPC) that
    /// counts the bytes read from it.
    struct TestDisk {
        bytes: Cursor<Vec<u8>>,
        room: u64,
        read: Arc<AtomicU64>,
    }

    impl TestDisk {
        fn new(room: u64) -> (Self, Arc<AtomicU64>) {
            let read = Arc::new(AtomicU64::new(0));
            let disk = Self {
                bytes: Cursor::new(Vec::new()),
                room,
                read: Arc::clone(&read),
            };
            (disk, read)
        }
    }

    impl Read for TestDisk {
        fn read(&mut self, buf: &mut [u8]) -> io::Result<usize> {
            let n = self.bytes.read(buf)?;
            self.read.fetch_add(n as u64, Ordering::Relaxed);
            Ok(n)
        }
    }

    impl Write for TestDisk {
        fn write(&mut self, buf: &[u8]) -> io::Result<usize> {
            if self.bytes.position() + buf.len() as u64 > self.room {
                return Err(io::Error::from_raw_os_error(libc::ENOSPC));
            }
            self.bytes.write(buf)
        }

        fn flush(&mut self) -> io::Result<()> {
            Ok(())
        }
    }

    impl Seek for TestDisk {
        fn seek(&mut self, to: SeekFrom) -> io::Result<u64> {
            self.bytes.seek(to)
        }
    }

    /// Logs `count` messages of poorly compressible text on a `/log` channel of `context`.
    fn log_messages(context: &Arc<Context>, count: u64) {
        let channel: Channel<Log> = context.channel_builder("/log").build();
        let mut state = 0x2545_f491_4f6c_dd1d_u64;
        for i in 0..count {
            let message: String = (0..64)
                .map(|_| {
                    state ^= state << 13;
                    state ^= state >> 7;
                    state ^= state << 17;
                    char::from(b'a' + (state % 26) as u8)
                })
                .collect();
            let log = Log {
                message,
                ..Default::default()
            };
            channel.log_with_time(&log, 1_000_000_000 + i);
        }
    }

    #[test]
    fn a_full_disk_ends_the_recording_with_the_file_and_the_os_error() {
        let context = Context::new();
        let (disk, _) = TestDisk::new(20_000);
        let recording = Recording::start(Path::new("walk.mcap"), disk, &context).unwrap();
        log_messages(&context, 5_000);
        assert!(recording.failed());
        let expected = "writing walk.mcap: No space left on device (os error 28)";
        let error = recording
            .metadata(
                "observer",
                BTreeMap::from([("k".to_owned(), "v".to_owned())]),
            )
            .unwrap_err();
        assert_eq!(format!("{error:#}"), expected);
        let error = recording.finish().unwrap_err();
        assert_eq!(format!("{error:#}"), expected);
    }

    #[test]
    fn dev_full_is_a_clear_error_not_a_panic() {
        let context = Context::new();
        let recording = Recording::create(Path::new("/dev/full"), &context).unwrap();
        log_messages(&context, 5_000);
        let error = recording.finish().unwrap_err();
        assert_eq!(
            format!("{error:#}"),
            "writing /dev/full: No space left on device (os error 28)"
        );
    }

    #[test]
    fn the_summary_is_read_from_the_summary_section_only() {
        let context = Context::new();
        let (disk, read) = TestDisk::new(u64::MAX);
        let recording = Recording::start(Path::new("walk.mcap"), disk, &context).unwrap();
        log_messages(&context, 20_000);
        let summary = recording.finish().unwrap();
        assert_eq!(summary.messages, 20_000);
        assert_eq!(summary.channels.len(), 1);
        assert_eq!(summary.channels[0].topic, "/log");
        assert_eq!(summary.channels[0].messages, 20_000);
        let read = read.load(Ordering::Relaxed);
        assert!(
            summary.bytes > 500_000 && read < summary.bytes / 100,
            "read {read} of {} bytes for the summary",
            summary.bytes
        );
    }
}
