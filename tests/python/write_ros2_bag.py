"""Writes a ROS 2 bag (MCAP storage, sensor_msgs/msg/PointCloud2) from a
directory of PCD frames written by `spacepose sim`, with the third-party
`rosbags` library, for the end-to-end test tests/tests/ros2_bag.rs.

usage: write_ros2_bag.py FRAMES_DIR OUT_BAG --time {t,offset_time,none} [--topic /points]

Each frame_NNNNNN.pcd becomes one message; its header stamp is the frame's
scan_start_s from truth.csv. Fields: x y z intensity FLOAT32 at 0 4 8 12,
then by --time:
  t            FLOAT64 at 16, absolute seconds (the PCD's t, unchanged);
  offset_time  UINT32 at 16, ns relative to the stamp (Livox style);
  none         no time field.
"""

import argparse
import csv
import math
import pathlib

import numpy as np
from rosbags.rosbag2 import StoragePlugin, Writer
from rosbags.typesys import Stores, get_typestore

PCD_TYPES = {("F", 4): "<f4", ("F", 8): "<f8", ("U", 1): "<u1", ("U", 2): "<u2",
             ("U", 4): "<u4", ("I", 1): "<i1", ("I", 2): "<i2", ("I", 4): "<i4"}


def read_pcd(path):
    """The points of a PCD file (DATA ascii or binary) as a structured array."""
    raw = path.read_bytes()
    header = {}
    pos = 0
    while True:
        end = raw.index(b"\n", pos)
        line = raw[pos:end].decode().strip()
        pos = end + 1
        if not line or line.startswith("#"):
            continue
        key, *values = line.split()
        header[key] = values
        if key == "DATA":
            break
    names = header["FIELDS"]
    dtype = np.dtype([(n, PCD_TYPES[(t, int(s))])
                      for n, s, t in zip(names, header["SIZE"], header["TYPE"])])
    count = int(header["POINTS"][0])
    if header["DATA"][0] == "binary":
        return np.frombuffer(raw, dtype=dtype, count=count, offset=pos)
    rows = [line.split() for line in raw[pos:].decode().splitlines() if line.strip()]
    return np.array([tuple(float(v) for v in r) for r in rows], dtype=dtype)


def scan_starts(frames_dir):
    with open(frames_dir / "truth.csv", newline="") as f:
        return {int(r["frame"]): float(r["scan_start_s"]) for r in csv.DictReader(f)}


def stamp_of(seconds):
    sec = math.floor(seconds)
    nanosec = round((seconds - sec) * 1e9)
    if nanosec >= 1_000_000_000:
        sec, nanosec = sec + 1, nanosec - 1_000_000_000
    return int(sec), int(nanosec)


def message(store, points, start_s, time_mode):
    types = store.types
    PointField = types["sensor_msgs/msg/PointField"]
    sec, nanosec = stamp_of(start_s)
    fields = [PointField(name=n, offset=4 * k, datatype=7, count=1)
              for k, n in enumerate(["x", "y", "z", "intensity"])]
    columns = [("x", "<f4"), ("y", "<f4"), ("z", "<f4"), ("intensity", "<f4")]
    if time_mode == "t":
        fields.append(PointField(name="t", offset=16, datatype=8, count=1))
        columns.append(("t", "<f8"))
    elif time_mode == "offset_time":
        fields.append(PointField(name="offset_time", offset=16, datatype=6, count=1))
        columns.append(("offset_time", "<u4"))
    packed = np.zeros(len(points), dtype=np.dtype(columns))
    for name in ("x", "y", "z", "intensity"):
        packed[name] = points[name]
    stamp_s = sec + nanosec * 1e-9
    if time_mode == "t":
        packed["t"] = points["t"]
    elif time_mode == "offset_time":
        packed["offset_time"] = np.round((points["t"] - stamp_s) * 1e9).astype("<u4")
    step = packed.dtype.itemsize
    header = types["std_msgs/msg/Header"](
        stamp=types["builtin_interfaces/msg/Time"](sec=sec, nanosec=nanosec), frame_id="lidar")
    return types["sensor_msgs/msg/PointCloud2"](
        header=header, height=1, width=len(points), fields=fields, is_bigendian=False,
        point_step=step, row_step=step * len(points),
        data=np.frombuffer(packed.tobytes(), dtype=np.uint8), is_dense=True)


def main():
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("frames_dir", type=pathlib.Path)
    parser.add_argument("out_bag", type=pathlib.Path)
    parser.add_argument("--time", choices=["t", "offset_time", "none"], default="t")
    parser.add_argument("--topic", default="/points")
    args = parser.parse_args()
    store = get_typestore(Stores.ROS2_HUMBLE)
    msgtype = "sensor_msgs/msg/PointCloud2"
    starts = scan_starts(args.frames_dir)
    frames = sorted(args.frames_dir.glob("frame_*.pcd"))
    with Writer(args.out_bag, version=9, storage_plugin=StoragePlugin.MCAP) as writer:
        connection = writer.add_connection(args.topic, msgtype, typestore=store)
        for path in frames:
            index = int(path.stem.removeprefix("frame_"))
            msg = message(store, read_pcd(path), starts[index], args.time)
            stamp_ns = msg.header.stamp.sec * 1_000_000_000 + msg.header.stamp.nanosec
            writer.write(connection, stamp_ns, store.serialize_cdr(msg, msgtype))
    print(f"wrote {len(frames)} messages to {args.out_bag}")


if __name__ == "__main__":
    main()
