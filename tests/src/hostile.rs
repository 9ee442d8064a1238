//! Hostile peers for the e2e tests: a process that talks to walkd's services with raw message
//! bytes, as another program (or another language's bindings) could, instead of through the
//! typed port wrappers of `shm-types`.
//!
//! [`Raw<T>`] has exactly the size, alignment and iceoryx2 type name of the message `T`, so it
//! opens `T`'s services, but its bytes are written field by field at their offsets
//! (`std::mem::offset_of!`), so a test can put any bit pattern where the contract expects an
//! enum or a flag. [`RawAdapter`] publishes raw sensor samples and reads walkd's commands;
//! [`RawPublisher`] publishes on any of walkd's streams (a second telemetry publisher);
//! [`Tap`] keeps every message of a stream; [`RawClient`] sends raw control requests and
//! submissions; [`PortHog`] and [`MonitorHog`] hold ports to exhaust a service's capacity.

use std::mem::{MaybeUninit, offset_of, size_of};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

use anyhow::Context;
use iceoryx2::port::client::Client;
use iceoryx2::port::notifier::Notifier;
use iceoryx2::port::publisher::Publisher;
use iceoryx2::port::subscriber::Subscriber;
use iceoryx2::prelude::*;
use iceoryx2::service::port_factory::{publish_subscribe, request_response};
use kinematics::robot::{EndEffector, Robot};
use shm_types::services::{TELEMETRY_BUFFER, capacity};
use shm_types::{
    ControlReply, ControlRequest, DaemonStatus, JointCommand, MAX_JOINTS, SensorSample,
    SubmitReply, Telemetry,
};

/// The bytes of a message `T`, written and read at field offsets; never read as a `T`.
#[repr(C)]
pub struct Raw<T> {
    bytes: MaybeUninit<T>,
}

// SAFETY: `Raw<T>` has the layout of `T` (repr(C), one field) and `T` is a self-contained
// shared-memory message; the type name is `T`'s, so both open the same services.
unsafe impl<T: ZeroCopySend> ZeroCopySend for Raw<T> {
    unsafe fn type_name() -> &'static str {
        // SAFETY: forwards to the message type's own name.
        unsafe { <T as ZeroCopySend>::type_name() }
    }
}

impl<T> core::fmt::Debug for Raw<T> {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        write!(f, "Raw<{}>", std::any::type_name::<T>())
    }
}

impl<T: Copy> Raw<T> {
    /// The bytes of `value`.
    pub fn of(value: T) -> Self {
        Self {
            bytes: MaybeUninit::new(value),
        }
    }

    /// Panics unless a `V` at byte `offset` lies inside the message (`access`: read or write).
    fn assert_inside<V>(offset: usize, access: &str) {
        assert!(
            offset + size_of::<V>() <= size_of::<T>(),
            "{access} past the message"
        );
    }

    /// Writes `value` at byte `offset`, whatever the field there is declared as.
    pub fn put<V: Copy>(&mut self, offset: usize, value: V) {
        Self::assert_inside::<V>(offset, "write");
        let at = self
            .bytes
            .as_mut_ptr()
            .wrapping_byte_add(offset)
            .cast::<V>();
        // SAFETY: in bounds (checked above); unaligned write of plain bytes into owned memory.
        unsafe { at.write_unaligned(value) }
    }

    /// Writes the monotonic clock's now (ns) at byte `offset`: a message's `timestamp_ns`.
    pub fn stamp(&mut self, offset: usize) {
        self.put(offset, shm_types::monotonic_ns());
    }

    /// Reads a `V` at byte `offset` (any bit pattern is a valid `V` for the integer and float
    /// types used here).
    pub fn get<V: Copy>(&self, offset: usize) -> V {
        Self::assert_inside::<V>(offset, "read");
        let at = self.bytes.as_ptr().wrapping_byte_add(offset).cast::<V>();
        // SAFETY: in bounds (checked above); the bytes were written by a sender or `put`.
        unsafe { at.read_unaligned() }
    }

    /// Reads a `FixedText` field at `offset` (its `len: u32` then the bytes), lossily.
    pub fn text(&self, offset: usize, capacity: usize) -> String {
        let len = (self.get::<u32>(offset) as usize).min(capacity);
        let bytes: Vec<u8> = (0..len).map(|i| self.get::<u8>(offset + 4 + i)).collect();
        String::from_utf8_lossy(&bytes).into_owned()
    }
}

impl<T: Copy> Clone for Raw<T> {
    fn clone(&self) -> Self {
        Self { bytes: self.bytes }
    }
}

fn node(name: &str) -> anyhow::Result<Node<ipc::Service>> {
    NodeBuilder::new()
        .name(&NodeName::new(name)?)
        .signal_handling_mode(SignalHandlingMode::Disabled)
        .create::<ipc::Service>()
        .context("creating an iceoryx2 node")
}

fn service_name(prefix: &str, kind: &str) -> anyhow::Result<ServiceName> {
    Ok(ServiceName::new(&format!("{prefix}/{kind}"))?)
}

/// Opens the publish-subscribe service `kind` under `prefix` (its owner created it) for raw `T`
/// messages.
fn open_stream<T: Copy + ZeroCopySend + 'static>(
    node: &Node<ipc::Service>,
    prefix: &str,
    kind: &str,
) -> anyhow::Result<publish_subscribe::PortFactory<ipc::Service, Raw<T>, ()>> {
    node.service_builder(&service_name(prefix, kind)?)
        .publish_subscribe::<Raw<T>>()
        .open()
        .map_err(|e| anyhow::anyhow!("opening {kind}: {e:?}"))
}

/// Opens walkd's `control` service under `prefix` for raw requests and replies.
fn open_control(node: &Node<ipc::Service>, prefix: &str) -> anyhow::Result<RawControlService> {
    node.service_builder(&service_name(prefix, "control")?)
        .request_response::<Raw<ControlRequest>, Raw<ControlReply>>()
        .open()
        .map_err(|e| anyhow::anyhow!("opening control: {e:?}"))
}

/// A sample of `robot` standing still in its configured posture, its weight shared by the feet.
pub fn standing_sample(robot: &Robot) -> SensorSample {
    let mut sample = SensorSample::ZERO;
    let dof = robot.model.dof();
    sample.joint_count = dof as u32;
    sample.q[..dof].copy_from_slice(robot.standing.joints.as_slice());
    let weight = robot.model.total_mass() * 9.81;
    for foot in [EndEffector::LeftFoot, EndEffector::RightFoot] {
        sample.wrenches[foot as usize][2] = weight / 2.0;
    }
    sample
}

/// The sending end of one of walkd's services, with raw messages: a publisher and, for the
/// streams with a wake-up event (`sensors`, `commands`), its notifier; numbers what it sends.
struct RawSender<T: Copy + ZeroCopySend + 'static> {
    publisher: Publisher<ipc::Service, Raw<T>, ()>,
    notifier: Option<Notifier<ipc::Service>>,
    seq: u64,
}

impl<T: Copy + ZeroCopySend + 'static> RawSender<T> {
    /// Opens the service `kind` under `prefix` (its other end created it), and its event if
    /// `wakes`.
    fn open(
        node: &Node<ipc::Service>,
        prefix: &str,
        kind: &str,
        wakes: bool,
    ) -> anyhow::Result<Self> {
        let stream = open_stream::<T>(node, prefix, kind)?;
        let notifier = if wakes {
            let event = node
                .service_builder(&service_name(prefix, kind)?)
                .event()
                .open()
                .map_err(|e| anyhow::anyhow!("opening the {kind} event: {e:?}"))?;
            Some(
                event
                    .notifier_builder()
                    .create()
                    .map_err(|e| anyhow::anyhow!("notifier on {kind}: {e:?}"))?,
            )
        } else {
            None
        };
        Ok(Self {
            publisher: stream
                .publisher_builder()
                .create()
                .map_err(|e| anyhow::anyhow!("publisher on {kind}: {e:?}"))?,
            notifier,
            seq: 0,
        })
    }

    /// Sends `raw` with the next sequence number written at `seq_offset`; returns the number.
    fn send(&mut self, mut raw: Raw<T>, seq_offset: usize) -> u64 {
        self.seq += 1;
        raw.put(seq_offset, self.seq);
        self.send_as_is(raw);
        self.seq
    }

    /// Sends `raw` as it is (and wakes the subscribers if the service has an event).
    fn send_as_is(&mut self, raw: Raw<T>) {
        let loan = self.publisher.loan_uninit().expect("loan a message");
        loan.write_payload(raw).send().expect("send a message");
        if let Some(notifier) = &self.notifier {
            notifier.notify().expect("notify");
        }
    }
}

/// An adapter that publishes raw sensor samples and reads walkd's commands.
pub struct RawAdapter {
    sensors: RawSender<SensorSample>,
    commands: Subscriber<ipc::Service, Raw<JointCommand>, ()>,
    _node: Node<ipc::Service>,
}

impl RawAdapter {
    /// Opens walkd's `sensors` and `commands` services under `prefix` (walkd created them).
    pub fn open(prefix: &str) -> anyhow::Result<Self> {
        let node = node("hostile-adapter")?;
        let commands = open_stream::<JointCommand>(&node, prefix, "commands")?;
        Ok(Self {
            sensors: RawSender::open(&node, prefix, "sensors", true)?,
            commands: commands
                .subscriber_builder()
                .create()
                .map_err(|e| anyhow::anyhow!("subscriber on commands: {e:?}"))?,
            _node: node,
        })
    }

    /// Opens the services once walkd created them (waits up to `timeout`).
    pub fn open_when_ready(prefix: &str, timeout: Duration) -> anyhow::Result<Self> {
        crate::wait_until("walkd's sensor and command services", timeout, || {
            Self::open(prefix).ok()
        })
    }

    /// Publishes `sample` with the next sequence number, stamped now, after `edit` changed its
    /// raw bytes; returns the sequence number.
    pub fn publish(
        &mut self,
        sample: &SensorSample,
        edit: impl FnOnce(&mut Raw<SensorSample>),
    ) -> u64 {
        let mut raw = Raw::of(*sample);
        raw.stamp(offset_of!(SensorSample, timestamp_ns));
        edit(&mut raw);
        self.publish_raw(raw)
    }

    /// Publishes `raw` with the next sequence number (its other bytes as they are; a zero
    /// timestamp is replaced by now); returns the sequence number.
    pub fn publish_raw(&mut self, mut raw: Raw<SensorSample>) -> u64 {
        if raw.get::<u64>(offset_of!(SensorSample, timestamp_ns)) == 0 {
            raw.stamp(offset_of!(SensorSample, timestamp_ns));
        }
        self.sensors.send(raw, offset_of!(SensorSample, seq))
    }

    /// Every command received since the last call, oldest first.
    pub fn commands(&self) -> Vec<Raw<JointCommand>> {
        let mut out = Vec::new();
        while let Some(sample) = self.commands.receive().expect("receive commands") {
            out.push(sample.payload().clone());
        }
        out
    }

    /// Publishes `sample` every `period` for `duration` (stamped now, otherwise unchanged),
    /// collecting the commands that come back.
    pub fn stream(
        &mut self,
        sample: &SensorSample,
        period: Duration,
        duration: Duration,
    ) -> Vec<Raw<JointCommand>> {
        let start = Instant::now();
        let mut commands = Vec::new();
        while start.elapsed() < duration {
            self.publish(sample, |_| {});
            std::thread::sleep(period);
            commands.extend(self.commands());
        }
        commands
    }
}

/// A [`RawAdapter`] on a thread of its own that publishes a sample every period (the current
/// template, freshly numbered and stamped) and keeps every command that comes back, so a test
/// can make blocking requests meanwhile (iceoryx2 ports cannot move between threads).
pub struct Feeder {
    template: Arc<Mutex<Raw<SensorSample>>>,
    commands: Arc<Mutex<Vec<Raw<JointCommand>>>>,
    _thread: PeerThread,
}

impl Feeder {
    /// Starts publishing `sample` every `period` on walkd's services under `prefix`.
    pub fn start(prefix: &str, sample: SensorSample, period: Duration) -> anyhow::Result<Self> {
        let template = Arc::new(Mutex::new(Raw::of(sample)));
        let commands = Arc::new(Mutex::new(Vec::new()));
        let thread = {
            let (prefix, template, commands) =
                (prefix.to_owned(), template.clone(), commands.clone());
            PeerThread::start(
                move || RawAdapter::open_when_ready(&prefix, Duration::from_secs(20)),
                move |adapter: &mut RawAdapter| {
                    let raw = template.lock().unwrap().clone();
                    adapter.publish_raw(raw);
                    std::thread::sleep(period);
                    commands.lock().unwrap().extend(adapter.commands());
                },
            )?
        };
        Ok(Self {
            template,
            commands,
            _thread: thread,
        })
    }

    /// Changes the bytes of the samples published from now on.
    pub fn edit(&self, edit: impl FnOnce(&mut Raw<SensorSample>)) {
        edit(&mut self.template.lock().unwrap());
    }

    /// The commands received since the last call.
    pub fn take_commands(&self) -> Vec<Raw<JointCommand>> {
        std::mem::take(&mut *self.commands.lock().unwrap())
    }
}

/// A raw peer on a thread of its own (iceoryx2 ports cannot move between threads): its ports are
/// opened there, then one round of its work runs after the other until it is dropped.
struct PeerThread {
    stop: Arc<AtomicBool>,
    thread: Option<std::thread::JoinHandle<()>>,
}

impl PeerThread {
    /// Opens the peer's ports with `open` on a new thread and returns once they are open (or
    /// failed to); then calls `round` with them until dropped (`round` paces itself).
    fn start<P>(
        open: impl FnOnce() -> anyhow::Result<P> + Send + 'static,
        mut round: impl FnMut(&mut P) + Send + 'static,
    ) -> anyhow::Result<Self> {
        let stop = Arc::new(AtomicBool::new(false));
        let (ready_tx, ready_rx) = std::sync::mpsc::channel();
        let stopped = stop.clone();
        let thread = std::thread::spawn(move || {
            let mut ports = match open() {
                Ok(ports) => {
                    let _ = ready_tx.send(Ok(()));
                    ports
                }
                Err(error) => {
                    let _ = ready_tx.send(Err(error));
                    return;
                }
            };
            while !stopped.load(Ordering::Relaxed) {
                round(&mut ports);
            }
        });
        ready_rx.recv()??;
        Ok(Self {
            stop,
            thread: Some(thread),
        })
    }
}

impl Drop for PeerThread {
    fn drop(&mut self) {
        self.stop.store(true, Ordering::Relaxed);
        if let Some(thread) = self.thread.take() {
            let _ = thread.join();
        }
    }
}

/// A daemon that publishes raw joint commands to an adapter.
pub struct RawDaemon {
    commands: RawSender<JointCommand>,
    _node: Node<ipc::Service>,
}

impl RawDaemon {
    /// Opens the adapter's `commands` service under `prefix` (the adapter created it).
    pub fn open(prefix: &str) -> anyhow::Result<Self> {
        let node = node("hostile-daemon")?;
        Ok(Self {
            commands: RawSender::open(&node, prefix, "commands", true)?,
            _node: node,
        })
    }

    /// Publishes `command` (numbered and stamped) after `edit` changed its raw bytes.
    pub fn publish(&mut self, command: &JointCommand, edit: impl FnOnce(&mut Raw<JointCommand>)) {
        let mut raw = Raw::of(*command);
        raw.stamp(offset_of!(JointCommand, timestamp_ns));
        edit(&mut raw);
        self.commands.send(raw, offset_of!(JointCommand, seq));
    }
}

/// A second publisher on one of walkd's services (e.g. `telemetry`), sending raw messages
/// without a wake-up event.
pub struct RawPublisher<T: Copy + ZeroCopySend + 'static> {
    sender: RawSender<T>,
    _node: Node<ipc::Service>,
}

impl<T: Copy + ZeroCopySend + 'static> RawPublisher<T> {
    /// Opens the service `kind` under `prefix` (walkd created it) and publishes on it.
    pub fn open(prefix: &str, kind: &str) -> anyhow::Result<Self> {
        let node = node("hostile-publisher")?;
        Ok(Self {
            sender: RawSender::open(&node, prefix, kind, false)?,
            _node: node,
        })
    }

    /// Publishes `message` after `edit` changed its raw bytes (sequence number included).
    pub fn publish(&mut self, message: T, edit: impl FnOnce(&mut Raw<T>)) {
        let mut raw = Raw::of(message);
        edit(&mut raw);
        self.sender.send_as_is(raw);
    }
}

/// A subscriber of one of walkd's streams on a thread of its own that keeps every message (it
/// drains every millisecond), so a test sees a whole stretch of the stream while it makes
/// blocking requests.
pub struct Tap<T: Copy + ZeroCopySend + Send + 'static> {
    messages: Arc<Mutex<Vec<Raw<T>>>>,
    _thread: PeerThread,
}

impl<T: Copy + ZeroCopySend + Send + 'static> Tap<T> {
    /// Subscribes to the stream `kind` under `prefix` (holding up to `buffer` unread messages).
    pub fn start(prefix: &str, kind: &str, buffer: usize) -> anyhow::Result<Self> {
        let messages = Arc::new(Mutex::new(Vec::new()));
        let thread = {
            let (prefix, kind, messages) = (prefix.to_owned(), kind.to_owned(), messages.clone());
            PeerThread::start(
                move || {
                    let node = node("hostile-tap")?;
                    let subscriber = open_stream::<T>(&node, &prefix, &kind)?
                        .subscriber_builder()
                        .buffer_size(buffer)
                        .create()
                        .map_err(|e| anyhow::anyhow!("subscriber on {kind}: {e:?}"))?;
                    Ok((node, subscriber))
                },
                move |(_, subscriber): &mut (
                    Node<ipc::Service>,
                    Subscriber<ipc::Service, Raw<T>, ()>,
                )| {
                    while let Ok(Some(sample)) = subscriber.receive() {
                        messages.lock().unwrap().push(sample.payload().clone());
                    }
                    std::thread::sleep(Duration::from_millis(1));
                },
            )?
        };
        Ok(Self {
            messages,
            _thread: thread,
        })
    }

    /// The messages received since the last call, oldest first.
    pub fn take(&self) -> Vec<Raw<T>> {
        std::mem::take(&mut *self.messages.lock().unwrap())
    }
}

/// The `q_des` of a command (its first `dof` entries).
pub fn command_q(command: &Raw<JointCommand>, dof: usize) -> Vec<f64> {
    let q: [f64; MAX_JOINTS] = command.get(offset_of!(JointCommand, q_des));
    q[..dof].to_vec()
}

/// The sample sequence number a command answers.
pub fn command_answers(command: &Raw<JointCommand>) -> u64 {
    command.get(offset_of!(JointCommand, answers_seq))
}

/// A client port of `control` with raw messages.
type RawControlClient = Client<ipc::Service, Raw<ControlRequest>, (), Raw<ControlReply>, ()>;
/// walkd's `control` service with raw messages.
type RawControlService =
    request_response::PortFactory<ipc::Service, Raw<ControlRequest>, (), Raw<ControlReply>, ()>;

/// A client that sends raw control requests and raw submissions.
pub struct RawClient {
    control: RawControlClient,
    stances: Client<ipc::Service, [u8], (), Raw<SubmitReply>, ()>,
    _node: Node<ipc::Service>,
}

impl RawClient {
    /// Opens walkd's `control` and `stances` services under `prefix`.
    pub fn connect(prefix: &str) -> anyhow::Result<Self> {
        let node = node("hostile-client")?;
        let control = open_control(&node, prefix)?;
        let stances = node
            .service_builder(&service_name(prefix, "stances")?)
            .request_response::<[u8], Raw<SubmitReply>>()
            .open()
            .map_err(|e| anyhow::anyhow!("opening stances: {e:?}"))?;
        Ok(Self {
            control: control
                .client_builder()
                .create()
                .map_err(|e| anyhow::anyhow!("client on control: {e:?}"))?,
            stances: stances
                .client_builder()
                .initial_max_slice_len(1 << 16)
                .allocation_strategy(AllocationStrategy::PowerOfTwo)
                .create()
                .map_err(|e| anyhow::anyhow!("client on stances: {e:?}"))?,
            _node: node,
        })
    }

    /// Sends a control request whose command field holds `command` (any value) and waits for
    /// the reply: (accepted, message).
    pub fn control(&self, command: u32, timeout: Duration) -> anyhow::Result<(bool, String)> {
        let mut request = Raw::of(ControlRequest::default());
        request.put(offset_of!(ControlRequest, command), command);
        let pending = self
            .control
            .loan_uninit()
            .map_err(|e| anyhow::anyhow!("loan: {e:?}"))?
            .write_payload(request)
            .send()
            .map_err(|e| anyhow::anyhow!("send: {e:?}"))?;
        let reply = wait_for_reply(timeout, || pending.receive().ok().flatten())?;
        Ok((
            reply.get::<u8>(offset_of!(ControlReply, accepted)) != 0,
            reply.text(offset_of!(ControlReply, message), 160),
        ))
    }

    /// Submits `bytes` (no size check on this side) and waits for the verdict: (accepted, reason).
    pub fn submit(&self, bytes: &[u8], timeout: Duration) -> anyhow::Result<(bool, String)> {
        let pending = self
            .stances
            .loan_slice_uninit(bytes.len())
            .map_err(|e| anyhow::anyhow!("loan {} bytes: {e:?}", bytes.len()))?
            .write_from_slice(bytes)
            .send()
            .map_err(|e| anyhow::anyhow!("send: {e:?}"))?;
        let reply = wait_for_reply(timeout, || pending.receive().ok().flatten())?;
        Ok((
            reply.get::<u8>(offset_of!(SubmitReply, accepted)) != 0,
            reply.text(offset_of!(SubmitReply, reason), 512),
        ))
    }
}

/// Waits up to `timeout` for `receive` to deliver the reply, and copies it.
fn wait_for_reply<T: Copy + ZeroCopySend>(
    timeout: Duration,
    mut receive: impl FnMut() -> Option<iceoryx2::response::Response<ipc::Service, Raw<T>, ()>>,
) -> anyhow::Result<Raw<T>> {
    crate::wait_until("the reply", timeout, || {
        receive().map(|r| r.payload().clone())
    })
}

/// Holds ports of walkd's services as a greedy or leaking process would: up to `limit`
/// `control` clients and `status` subscribers, and `publishers` publishers on `sensors` (a
/// second adapter).
pub struct PortHog {
    _control: Vec<RawControlClient>,
    _status: Vec<Subscriber<ipc::Service, Raw<DaemonStatus>, ()>>,
    _sensors: Vec<Publisher<ipc::Service, Raw<SensorSample>, ()>>,
    /// Ports taken: (control clients, status subscribers, sensor publishers).
    pub taken: (usize, usize, usize),
    _node: Node<ipc::Service>,
}

impl PortHog {
    /// Takes the ports under `prefix`.
    pub fn take(prefix: &str, limit: usize, publishers: usize) -> anyhow::Result<Self> {
        let node = node("hostile-hog")?;
        let control = open_control(&node, prefix)?;
        let status = open_stream::<DaemonStatus>(&node, prefix, "status")?;
        let sensors = open_stream::<SensorSample>(&node, prefix, "sensors")?;
        let control: Vec<_> = (0..limit)
            .map_while(|_| control.client_builder().create().ok())
            .collect();
        let status: Vec<_> = (0..limit)
            .map_while(|_| status.subscriber_builder().create().ok())
            .collect();
        let sensors: Vec<_> = (0..publishers)
            .map_while(|_| sensors.publisher_builder().create().ok())
            .collect();
        Ok(Self {
            taken: (control.len(), status.len(), sensors.len()),
            _control: control,
            _status: status,
            _sensors: sensors,
            _node: node,
        })
    }
}

/// Holds every publisher slot of walkd's monitoring services (`telemetry` and `status`), created
/// before walkd starts with settings walkd accepts, as a process that got there first would.
pub struct MonitorHog {
    _telemetry: Vec<Publisher<ipc::Service, Raw<Telemetry>, ()>>,
    _status: Vec<Publisher<ipc::Service, Raw<DaemonStatus>, ()>>,
    /// Publisher slots taken: (telemetry, status).
    pub taken: (usize, usize),
    _node: Node<ipc::Service>,
}

impl MonitorHog {
    /// Publisher slots of each service the hog creates (the ones walkd asks for).
    pub const SLOTS: usize = 2;

    /// Creates (or opens) `telemetry` and `status` under `prefix` and takes their publisher slots.
    pub fn take(prefix: &str) -> anyhow::Result<Self> {
        let node = node("hostile-monitor-hog")?;
        let telemetry = Self::slots::<Telemetry>(&node, prefix, "telemetry")?;
        let status = Self::slots::<DaemonStatus>(&node, prefix, "status")?;
        Ok(Self {
            taken: (telemetry.len(), status.len()),
            _telemetry: telemetry,
            _status: status,
            _node: node,
        })
    }

    /// Every publisher slot of the service `kind`, created with room for what walkd asks of it.
    fn slots<T: Copy + ZeroCopySend + 'static>(
        node: &Node<ipc::Service>,
        prefix: &str,
        kind: &str,
    ) -> anyhow::Result<Vec<Publisher<ipc::Service, Raw<T>, ()>>> {
        let service = node
            .service_builder(&service_name(prefix, kind)?)
            .publish_subscribe::<Raw<T>>()
            .enable_safe_overflow(true)
            .history_size(1)
            .subscriber_max_buffer_size(TELEMETRY_BUFFER)
            .subscriber_max_borrowed_samples(4)
            .max_publishers(Self::SLOTS)
            .max_subscribers(capacity::STATUS_SUBSCRIBERS)
            .max_nodes(capacity::NODES)
            .open_or_create()
            .map_err(|e| anyhow::anyhow!("creating {kind}: {e:?}"))?;
        Ok((0..Self::SLOTS)
            .map_while(|_| service.publisher_builder().create().ok())
            .collect())
    }
}
