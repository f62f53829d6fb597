"""Ground listener for spacepose telemetry (Python, eclipse-zenoh).

Subscribes to the JSON telemetry of one deployment over zenoh and prints one
line per pose (or every sample with --all), optionally appending every sample
to a JSON-lines file. The schema of each key is in
docs/telemetry.md.

    pip install -r tools/ground/requirements.txt
    python tools/ground/listen.py --connect tcp/127.0.0.1:7447 --prefix demo --count 20
"""

import argparse
import json
import sys
import time

import zenoh


def parse_args() -> argparse.Namespace:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--connect", default="tcp/127.0.0.1:7447", help="zenoh endpoint of the suite's telemetry")
    p.add_argument("--prefix", default="demo", help="deployment prefix")
    p.add_argument("--all", action="store_true", help="print every telemetry key, not only poses")
    p.add_argument("--record", help="append every sample as a JSON line to this file")
    p.add_argument("--count", type=int, default=0, help="stop after this many poses (0: never)")
    p.add_argument("--timeout", type=float, default=0.0, help="stop after this many seconds (0: never)")
    return p.parse_args()


def main() -> int:
    args = parse_args()
    conf = zenoh.Config()
    conf.insert_json5("mode", '"client"')
    conf.insert_json5("connect/endpoints", json.dumps([args.connect]))
    conf.insert_json5("scouting/multicast/enabled", "false")
    record = open(args.record, "a", encoding="utf-8") if args.record else None
    poses = 0
    deadline = time.time() + args.timeout if args.timeout > 0 else None
    with zenoh.open(conf) as session:
        sub = session.declare_subscriber(f"spacepose/{args.prefix}/telemetry/**")
        while (args.count == 0 or poses < args.count) and (deadline is None or time.time() < deadline):
            sample = sub.try_recv()
            if sample is None:
                time.sleep(0.01)
                continue
            key = str(sample.key_expr)
            value = json.loads(sample.payload.to_string())
            if record:
                record.write(json.dumps({"key": key, "value": value}) + "\n")
            if key.endswith("/pose"):
                poses += 1
                p = value["p_sensor_target_m"]
                print(f'{value["sequence"]:6d} {value["status"]:9s} p = [{p[0]:7.3f} {p[1]:7.3f} {p[2]:7.3f}] m  '
                      f'euler321 = {[round(a, 2) for a in value["euler_321_deg"]]} deg', flush=True)
            elif args.all:
                print(key, json.dumps(value)[:160], flush=True)
    if record:
        record.close()
    return 0


if __name__ == "__main__":
    sys.exit(main())
