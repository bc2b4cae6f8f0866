"""A team outside cmdragons, in one file: it plays yellow over zenoh with nothing but the schemas.

It hears the league's SSL_DetectionFrame (millimetres) on cmdragons/<field>/detections/<camera>
(or perception/yellow under --perception truth) and answers every camera frame once with a
RobotControl on cmdragons/<field>/commands/yellow: each robot drives at the ball. Run it beside
`cmdragons play --distributed --opponent outside` (README, "An outside team").
"""

import argparse
import json
import signal
import time

import zenoh
from chase import chase, see

from cmdragons.runtime.proto import ssl_detection_pb2, ssl_simulation_control_pb2, ssl_tracked_pb2

ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
ap.add_argument("--router", default="tcp/127.0.0.1:7447", help="the match's zenoh router (configs/runtime.yaml)")
ap.add_argument("--field", default="main", help="the key space's <field> (runtime.field_name)")
ap.add_argument("--speed", type=float, default=1.0, help="driving speed (m/s)")
args = ap.parse_args()
signal.signal(signal.SIGINT, signal.default_int_handler)  # Ctrl-C stops it, even started as a background job
# a client of the router only: no listening socket, no multicast scouting (zenoh's defaults would
# listen on every interface and scout by multicast)
config = {"mode": "client", "connect": {"endpoints": [args.router]}, "listen": {"endpoints": []},
          "scouting": {"multicast": {"enabled": False}, "gossip": {"enabled": False}}}
seen: dict[str | int, tuple[float, float]] = {}  # the latest position of the ball and each robot, any camera (mm)
answered = -1  # the last camera frame answered


def on_detections(sample: zenoh.Sample) -> None:
    global answered
    frame = ssl_detection_pb2.SSL_DetectionFrame.FromString(sample.payload.to_bytes())
    see(seen, frame)
    if frame.frame_number == answered:  # one answer a frame, on its first camera
        return
    answered = frame.frame_number
    out = ssl_simulation_control_pb2.RobotControl(team=ssl_tracked_pb2.YELLOW, frame_number=frame.frame_number,
                                                  t=frame.t_capture)
    chase(out, seen, args.speed)
    session.put(f"cmdragons/{args.field}/commands/yellow", out.SerializeToString())


session = None
while session is None:  # the match may not be there yet
    try:
        session = zenoh.open(zenoh.Config.from_json5(json.dumps(config)))
    except zenoh.ZError:
        print(f"outside team: no router at {args.router} yet, trying again", flush=True)
        time.sleep(1)
with session:
    subscribers = [session.declare_subscriber(f"cmdragons/{args.field}/{key}", on_detections)
                   for key in ("detections/**", "perception/yellow")]
    print(f"outside team: yellow on cmdragons/{args.field} via {args.router}; Ctrl-C to stop", flush=True)
    try:
        while True:
            time.sleep(1)  # nothing to do here: zenoh calls on_detections
    except KeyboardInterrupt:
        pass
