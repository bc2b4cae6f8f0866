"""What both example teams play: every robot drives at the ball (the examples' one shared piece)."""

import math

from cmdragons.runtime.proto import ssl_detection_pb2, ssl_simulation_control_pb2


def see(seen: dict[str | int, tuple[float, float]], frame: ssl_detection_pb2.SSL_DetectionFrame) -> None:
    """Keep the latest position (mm) of the ball and of each yellow robot from one camera frame."""
    if frame.balls:
        seen["ball"] = (frame.balls[0].x, frame.balls[0].y)
    seen.update({r.robot_id: (r.x, r.y) for r in frame.robots_yellow})


def chase(out: ssl_simulation_control_pb2.RobotControl, seen: dict[str | int, tuple[float, float]],
          speed: float) -> None:
    """Add to ``out`` a global velocity (m/s) at the ball for every robot seen, slower near it."""
    bx, by = seen.get("ball", (0.0, 0.0))
    for robot_id, (x, y) in seen.items():
        if robot_id == "ball":
            continue
        dx, dy = (bx - x) / 1000, (by - y) / 1000  # mm -> m
        d = math.hypot(dx, dy)
        v = min(speed, 2 * d) / max(d, 1e-6)
        move = out.robot_commands.add(id=int(robot_id)).move_command.global_velocity
        move.vel_x, move.vel_y, move.vel_angular = v * dx, v * dy, 0.0
