"""A team outside cmdragons over the league's own protocols: it plays yellow in our simulator.

It hears SSL-Vision packets (SSL_WrapperPacket, millimetres) on 224.5.23.2:10006, joined on the
loopback interface, and answers every camera frame once with a RobotControl (the simulation
protocol: each robot's global velocity, m/s) to the simulator's yellow port, 127.0.0.1:10302: each
robot drives at the ball (chase.py, shared with the zenoh example). Run it beside `cmdragons play
--opponent simulation` (README, "The league's protocols"). Nothing here is cmdragons' own but the
generated protobuf modules; a team in another language compiles the same .proto files.
"""

import argparse
import signal
import socket

from chase import chase, see

from cmdragons.runtime.proto import ssl_simulation_control_pb2, ssl_wrapper_pb2

ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
ap.add_argument("--group", default="224.5.23.2", help="SSL-Vision's multicast group")
ap.add_argument("--vision-port", type=int, default=10006, help="SSL-Vision's port")
ap.add_argument("--port", type=int, default=10302, help="the simulator's RobotControl port for yellow")
ap.add_argument("--speed", type=float, default=1.0, help="driving speed (m/s)")
args = ap.parse_args()
signal.signal(signal.SIGINT, signal.default_int_handler)  # Ctrl-C stops it, even started as a background job

vision = socket.socket(socket.AF_INET, socket.SOCK_DGRAM, socket.IPPROTO_UDP)
vision.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
vision.bind((args.group, args.vision_port))
# join on loopback: a join on any interface hears nothing of a sender pinned to 127.0.0.1
membership = socket.inet_aton(args.group) + socket.inet_aton("127.0.0.1")
vision.setsockopt(socket.IPPROTO_IP, socket.IP_ADD_MEMBERSHIP, membership)
robots = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
robots.bind(("127.0.0.1", 0))
robots.setblocking(False)
seen: dict[str | int, tuple[float, float]] = {}  # the latest position of the ball and each robot (mm)
answered = -1  # the last camera frame answered
print(f"simulation team: yellow, vision {args.group}:{args.vision_port}, commands to 127.0.0.1:{args.port}; "
      "Ctrl-C to stop", flush=True)
try:
    while True:
        packet = ssl_wrapper_pb2.SSL_WrapperPacket.FromString(vision.recv(65536))
        if not packet.HasField("detection"):
            continue  # geometry
        frame = packet.detection
        see(seen, frame)
        if frame.frame_number == answered:  # one answer a frame, on its first camera
            continue
        answered = frame.frame_number
        out = ssl_simulation_control_pb2.RobotControl()
        chase(out, seen, args.speed)
        robots.sendto(out.SerializeToString(), ("127.0.0.1", args.port))
        try:
            while True:
                robots.recv(65536)  # the simulator's answers (RobotControlResponse): not needed here
        except BlockingIOError:
            pass
except KeyboardInterrupt:
    pass
