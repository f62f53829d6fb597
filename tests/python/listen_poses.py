"""Ground client in Python: listens on a zenoh endpoint (the suite connects
to it) and collects the JSON pose telemetry of one deployment.

usage: listen_poses.py ENDPOINT PREFIX COUNT TIMEOUT_S
Prints "ready" once subscribed, then one JSON object:
{"sequences": [...], "statuses": [...], "schema_versions": [...]}.
"""

import json
import sys
import time

import zenoh


def main() -> int:
    endpoint, prefix, count, timeout_s = sys.argv[1], sys.argv[2], int(sys.argv[3]), float(sys.argv[4])
    conf = zenoh.Config()
    conf.insert_json5("mode", '"peer"')
    conf.insert_json5("listen/endpoints", json.dumps([endpoint]))
    conf.insert_json5("scouting/multicast/enabled", "false")
    seen = {"sequences": [], "statuses": [], "schema_versions": []}
    with zenoh.open(conf) as session:
        sub = session.declare_subscriber(f"spacepose/{prefix}/telemetry/pose")
        print("ready", flush=True)
        deadline = time.time() + timeout_s
        while len(seen["sequences"]) < count and time.time() < deadline:
            sample = sub.try_recv()
            if sample is None:
                time.sleep(0.005)
                continue
            pose = json.loads(sample.payload.to_string())
            seen["sequences"].append(pose["sequence"])
            seen["statuses"].append(pose["status"])
            seen["schema_versions"].append(pose["schema_version"])
    print(json.dumps(seen), flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
