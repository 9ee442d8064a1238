#!/usr/bin/env python3
"""Reads a walk recording with the official MCAP reader and reports what it holds.

Independent of the project's Rust code: the file is read with the PyPI packages `mcap` and
`mcap-protobuf-support` (protobuf messages decoded from the schemas stored in the file) and a
JSON decoder; the channel list and rates come from the table in docs/observe.md.

Usage: check_recording.py RECORDING.mcap docs/observe.md [--strict]
With --strict it exits with status 1 when a documented channel is missing or a sequence number
is (the main job's check in .ci/run). Prints one JSON object:
  documented        topics the docs list; missing: documented topics absent from the file
  counts            messages per topic; expected: count the documented rate gives for the
                    walk's duration (span of the per-tick channel x rate); ratio = counts/expected
  rate_hz, duration_s, ticks
  transform         largest distance / angle between an end-effector frame composed along /tf
                    from `world` and the controller's estimate (/controller/end_effectors) at the
                    same time stamp, and how many pairs were compared
  gaps              sequence numbers missing in telemetry, samples and commands
  deadline_misses   walkd's count in the last /status
"""

import json
import math
import re
import sys

from mcap.decoder import DecoderFactory
from mcap.reader import make_reader
from mcap_protobuf.decoder import DecoderFactory as ProtobufDecoderFactory

# The end-effector frames, in the order of /controller/end_effectors (docs/observe.md).
END_EFFECTOR_FRAMES = ["left_foot", "right_foot", "left_hand", "right_hand"]
# The per-tick channel whose time span is the walk's duration.
TICK_TOPIC = "/controller/tick"


class JsonDecoderFactory(DecoderFactory):
    """Decodes `json` messages (the robot description) with the standard library."""

    def decoder_for(self, message_encoding, schema):
        if message_encoding == "json":
            return lambda data: json.loads(data)
        return None


def documented_channels(docs_path):
    """(topic, rate text) of every row of the channel table in docs/observe.md."""
    rows = []
    with open(docs_path, encoding="utf-8") as f:
        for line in f:
            match = re.match(r"^\|\s*`(/[^`]*)`\s*\|([^|]*)\|\s*([^|]*)\|", line)
            if match:
                rows.append((match.group(1), match.group(3).strip()))
    return rows


def rate_of(text, tick_hz):
    """Messages per second a documented rate means; None for event-driven channels."""
    if text.startswith("every tick") or text.startswith("every sample") or text.startswith(
        "every command"
    ):
        return tick_hz
    match = re.match(r"every (\d+)(st|nd|rd|th) tick", text)
    if match:
        return tick_hz / int(match.group(1))
    match = re.search(r"(\d+(\.\d+)?) Hz", text)
    if match:
        return float(match.group(1))
    return None


def stamp_ns(timestamp):
    return timestamp.seconds * 1_000_000_000 + timestamp.nanos


def quat_mul(a, b):
    ax, ay, az, aw = a
    bx, by, bz, bw = b
    return (
        aw * bx + ax * bw + ay * bz - az * by,
        aw * by - ax * bz + ay * bw + az * bx,
        aw * bz + ax * by - ay * bx + az * bw,
        aw * bw - ax * bx - ay * by - az * bz,
    )


def rotate(q, v):
    x, y, z, w = q
    p = quat_mul(quat_mul(q, (v[0], v[1], v[2], 0.0)), (-x, -y, -z, w))
    return p[:3]


def compose(parent, child):
    """Pose (translation, quaternion) of `child` given in `parent`'s frame."""
    pt, pq = parent
    ct, cq = child
    r = rotate(pq, ct)
    return ((pt[0] + r[0], pt[1] + r[1], pt[2] + r[2]), quat_mul(pq, cq))


def world_pose(edges, frame):
    """Composes the /tf edges (child -> (parent, pose)) from `world` down to `frame`."""
    chain = []
    while frame != "world":
        parent, pose = edges[frame]
        chain.append(pose)
        frame = parent
    pose = ((0.0, 0.0, 0.0), (0.0, 0.0, 0.0, 1.0))
    for edge in reversed(chain):
        pose = compose(pose, edge)
    return pose


def angle_between(a, b):
    """Rotation angle between two unit quaternions (x, y, z, w), accurate near zero."""
    ax, ay, az, aw = a
    relative = quat_mul((-ax, -ay, -az, aw), b)
    return 2.0 * math.atan2(math.hypot(*relative[:3]), abs(relative[3]))


def vec(v):
    return (v.x, v.y, v.z)


def quat(q):
    return (q.x, q.y, q.z, q.w)


def gaps(seqs):
    missing = 0
    for previous, current in zip(seqs, seqs[1:]):
        if current > previous:
            missing += current - previous - 1
    return missing


def main(recording, docs):
    counts = {}
    times = {}
    tf_by_time = {}
    estimates = {}
    seqs = {"telemetry": [], "samples": [], "commands": []}
    rate_hz = None
    deadline_misses = None
    with open(recording, "rb") as f:
        reader = make_reader(f, decoder_factories=[ProtobufDecoderFactory(), JsonDecoderFactory()])
        for _schema, channel, message, decoded in reader.iter_decoded_messages():
            topic = channel.topic
            counts[topic] = counts.get(topic, 0) + 1
            times.setdefault(topic, []).append(message.log_time)
            if topic == "/tf":
                edges = {}
                for t in decoded.transforms:
                    edges[t.child_frame_id] = (
                        t.parent_frame_id,
                        (vec(t.translation), quat(t.rotation)),
                    )
                tf_by_time[stamp_ns(decoded.transforms[0].timestamp)] = edges
            elif topic == "/controller/end_effectors":
                estimates[stamp_ns(decoded.timestamp)] = [
                    (vec(p.position), quat(p.orientation)) for p in decoded.poses
                ]
            elif topic == TICK_TOPIC:
                seqs["telemetry"].append(decoded.telemetry_seq)
            elif topic == "/wrenches":
                seqs["samples"].append(decoded.sample_seq)
            elif topic == "/joint_commands/info":
                seqs["commands"].append(decoded.seq)
            elif topic == "/status":
                rate_hz = decoded.rate_hz
                deadline_misses = decoded.deadline_misses
    ticks = times.get(TICK_TOPIC, [])
    duration_s = (max(ticks) - min(ticks)) * 1e-9 if len(ticks) > 1 else 0.0
    documented = documented_channels(docs)
    expected = {}
    for topic, rate_text in documented:
        rate = rate_of(rate_text, rate_hz or 0.0)
        if rate is None:
            continue
        if rate >= 2.0:
            expected[topic] = duration_s * rate
        else:
            # A slow channel (the description) spans the whole recording, not only the ticks.
            span = times.get(topic, [0])
            span_s = (max(span) - min(span)) * 1e-9 if len(span) > 1 else 0.0
            all_times = [t for ts in times.values() for t in ts]
            whole_s = (max(all_times) - min(all_times)) * 1e-9 if all_times else 0.0
            expected[topic] = max(span_s, whole_s) * rate
    ratios = {t: counts.get(t, 0) / e for t, e in expected.items() if e > 0}
    worst_m = 0.0
    worst_rad = 0.0
    pairs = 0
    for t, poses in estimates.items():
        edges = tf_by_time.get(t)
        if edges is None:
            continue
        for frame, (position, orientation) in zip(END_EFFECTOR_FRAMES, poses):
            composed_t, composed_q = world_pose(edges, frame)
            worst_m = max(worst_m, math.dist(composed_t, position))
            worst_rad = max(worst_rad, angle_between(composed_q, orientation))
            pairs += 1
    report = {
        "documented": [t for t, _ in documented],
        "missing": [t for t, _ in documented if t not in counts],
        "counts": counts,
        "expected": expected,
        "ratio": ratios,
        "rate_hz": rate_hz,
        "duration_s": duration_s,
        "ticks": len(ticks),
        "transform": {"max_error_m": worst_m, "max_error_rad": worst_rad, "pairs": pairs},
        "gaps": {k: gaps(v) for k, v in seqs.items()},
        "received": {k: len(v) for k, v in seqs.items()},
        "deadline_misses": deadline_misses,
    }
    print(json.dumps(report))
    return report


if __name__ == "__main__":
    if len(sys.argv) not in (3, 4) or (len(sys.argv) == 4 and sys.argv[3] != "--strict"):
        sys.exit(__doc__)
    result = main(sys.argv[1], sys.argv[2])
    if len(sys.argv) == 4 and (result["missing"] or any(result["gaps"].values())):
        sys.exit(f"{sys.argv[1]}: missing channels {result['missing']}, gaps {result['gaps']}")
