#!/usr/bin/env python3
"""Watches `walkctl view` with a WebSocket client of its own, speaking the Foxglove WebSocket
protocol (https://github.com/foxglove/ws-protocol: JSON `serverInfo` / `advertise` /
`subscribe`, binary message data) with the PyPI package `websockets`. The Foxglove SDK's server
names the protocol `foxglove.sdk.v1` (earlier servers: `foxglove.websocket.v1`); both are
offered.

Usage: watch_live.py URL TOPIC SECONDS
Connects, reads the server's `serverInfo` and `advertise` messages, subscribes to TOPIC, counts
the message-data frames that arrive within SECONDS and decodes the last one with the protobuf
schema the server advertised. Prints one JSON object: server name, advertised topics with their
schemas, the message count, and the child frame names of the last message (for FrameTransforms).
"""

import asyncio
import base64
import json
import struct
import sys

import websockets
from google.protobuf import descriptor_pb2, descriptor_pool, message_factory

SUBPROTOCOLS = ["foxglove.sdk.v1", "foxglove.websocket.v1"]
MESSAGE_DATA = 0x01


def protobuf_class(schema_name, schema_base64):
    """The message class of `schema_name` from an advertised FileDescriptorSet."""
    files = descriptor_pb2.FileDescriptorSet.FromString(base64.b64decode(schema_base64))
    pool = descriptor_pool.DescriptorPool()
    for file in files.file:
        pool.Add(file)
    return message_factory.GetMessageClass(pool.FindMessageTypeByName(schema_name))


async def watch(url, topic, seconds):
    async with websockets.connect(url, subprotocols=SUBPROTOCOLS, max_size=None) as ws:
        server_info = None
        channels = {}
        # serverInfo first, then the advertisements.
        while server_info is None or not channels:
            message = json.loads(await asyncio.wait_for(ws.recv(), 10))
            if message["op"] == "serverInfo":
                server_info = message
            elif message["op"] == "advertise":
                for channel in message["channels"]:
                    channels[channel["topic"]] = channel
        # More advertisements may follow; give them a moment.
        try:
            while True:
                message = await asyncio.wait_for(ws.recv(), 0.5)
                if isinstance(message, str):
                    parsed = json.loads(message)
                    if parsed["op"] == "advertise":
                        for channel in parsed["channels"]:
                            channels[channel["topic"]] = channel
        except asyncio.TimeoutError:
            pass
        watched = channels[topic]
        await ws.send(
            json.dumps({"op": "subscribe", "subscriptions": [{"id": 1, "channelId": watched["id"]}]})
        )
        count = 0
        last = None
        loop = asyncio.get_running_loop()
        end = loop.time() + seconds
        while loop.time() < end:
            try:
                message = await asyncio.wait_for(ws.recv(), max(0.01, end - loop.time()))
            except asyncio.TimeoutError:
                break
            if isinstance(message, bytes) and message[0] == MESSAGE_DATA:
                subscription, _log_time = struct.unpack_from("<IQ", message, 1)
                if subscription == 1:
                    count += 1
                    last = message[13:]
        frames = []
        if last is not None and watched.get("schemaEncoding") == "protobuf":
            decoded = protobuf_class(watched["schemaName"], watched["schema"]).FromString(last)
            frames = [t.child_frame_id for t in getattr(decoded, "transforms", [])]
        return {
            "subprotocol": ws.subprotocol,
            "server": server_info.get("name"),
            "channels": {t: c.get("schemaName") for t, c in channels.items()},
            "messages": count,
            "seconds": seconds,
            "child_frames": frames,
        }


if __name__ == "__main__":
    if len(sys.argv) != 4:
        sys.exit(__doc__)
    print(json.dumps(asyncio.run(watch(sys.argv[1], sys.argv[2], float(sys.argv[3])))))
