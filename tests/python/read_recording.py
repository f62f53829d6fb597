"""Reads a spacepose MCAP recording with the Python `mcap` reader and
prints what the end-to-end test checks, as one JSON object on stdout.

Usage: read_recording.py RUN.mcap

Output keys:
  channels     {topic: {"schema", "schema_encoding", "message_encoding", "count"}}
  pose_sequences   frame sequences of /spacepose/pose/estimate, in log order
  poses_decoded    /spacepose/pose messages decoded as foxglove.PoseInFrame
                   (protobuf, from the schema in the file)
  pose_frames      distinct frame_id of those poses
  cloud_layout     [name, offset, type] of the first raw cloud's fields,
                   with "stride" and "points"
  cloud_t_matches  whether every raw cloud's per-point t lies in the
                   scan interval of its header
  log_time_sorted  whether the poses' log times increase
  metadata         names of the metadata records
  attachments      names of the attachments
"""

import json
import struct
import sys

from mcap.reader import make_reader
from mcap_protobuf.decoder import DecoderFactory


def main(path):
    with open(path, "rb") as f:
        reader = make_reader(f, decoder_factories=[DecoderFactory()])
        summary = reader.get_summary()
        channels = {}
        for ch in summary.channels.values():
            schema = summary.schemas.get(ch.schema_id)
            count = summary.statistics.channel_message_counts.get(ch.id, 0)
            channels[ch.topic] = {
                "schema": schema.name if schema else "",
                "schema_encoding": schema.encoding if schema else "",
                "message_encoding": ch.message_encoding,
                "count": count,
            }
        out = {
            "channels": channels,
            "metadata": [m.name for m in reader.iter_metadata()],
            "attachments": [a.name for a in reader.iter_attachments()],
        }
        out.update(poses(reader))
        out.update(clouds(reader))
    print(json.dumps(out))


def poses(reader):
    sequences = [
        json.loads(msg.data)["sequence"]
        for _, _, msg in reader.iter_messages(topics=["/spacepose/pose/estimate"])
    ]
    frames, times, decoded = set(), [], 0
    for _, _, msg, pose in reader.iter_decoded_messages(topics=["/spacepose/pose"]):
        decoded += 1
        frames.add(pose.frame_id)
        times.append(msg.log_time)
    return {
        "pose_sequences": sequences,
        "poses_decoded": decoded,
        "pose_frames": sorted(frames),
        "log_time_sorted": times == sorted(times),
    }


def clouds(reader):
    headers = {
        msg.log_time: json.loads(msg.data)
        for _, _, msg in reader.iter_messages(topics=["/spacepose/raw_cloud/header"])
    }
    layout, t_ok = None, True
    for _, _, msg, cloud in reader.iter_decoded_messages(topics=["/spacepose/raw_cloud"]):
        n = len(cloud.data) // cloud.point_stride
        if layout is None:
            layout = {
                "fields": [[f.name, f.offset, f.type] for f in cloud.fields],
                "stride": cloud.point_stride,
                "points": n,
            }
        h = headers[msg.log_time]
        ts = [struct.unpack_from("<d", cloud.data, i * cloud.point_stride + 16)[0] for i in range(n)]
        t_ok = t_ok and n == h["point_count"] and all(
            h["scan_start_s"] - 1e-9 <= t <= h["scan_end_s"] + 1e-9 for t in ts
        )
    return {"cloud_layout": layout, "cloud_t_matches": t_ok}


if __name__ == "__main__":
    main(sys.argv[1])
