from cmdragons.runtime.proto import ssl_tracked_pb2 as _ssl_tracked_pb2
from cmdragons.runtime.proto import ssl_simulation_control_pb2 as _ssl_simulation_control_pb2
from google.protobuf.internal import containers as _containers
from google.protobuf.internal import enum_type_wrapper as _enum_type_wrapper
from google.protobuf import descriptor as _descriptor
from google.protobuf import message as _message
from collections.abc import Iterable as _Iterable, Mapping as _Mapping
from typing import ClassVar as _ClassVar, Optional as _Optional, Union as _Union

DESCRIPTOR: _descriptor.FileDescriptor

class Point(_message.Message):
    __slots__ = ("x", "y")
    X_FIELD_NUMBER: _ClassVar[int]
    Y_FIELD_NUMBER: _ClassVar[int]
    x: float
    y: float
    def __init__(self, x: _Optional[float] = ..., y: _Optional[float] = ...) -> None: ...

class Tick(_message.Message):
    __slots__ = ("frame_number",)
    FRAME_NUMBER_FIELD_NUMBER: _ClassVar[int]
    frame_number: int
    def __init__(self, frame_number: _Optional[int] = ...) -> None: ...

class CameraFrame(_message.Message):
    __slots__ = ("camera_id", "frame_number", "t_capture", "width", "height", "encoding", "data")
    CAMERA_ID_FIELD_NUMBER: _ClassVar[int]
    FRAME_NUMBER_FIELD_NUMBER: _ClassVar[int]
    T_CAPTURE_FIELD_NUMBER: _ClassVar[int]
    WIDTH_FIELD_NUMBER: _ClassVar[int]
    HEIGHT_FIELD_NUMBER: _ClassVar[int]
    ENCODING_FIELD_NUMBER: _ClassVar[int]
    DATA_FIELD_NUMBER: _ClassVar[int]
    camera_id: int
    frame_number: int
    t_capture: float
    width: int
    height: int
    encoding: str
    data: bytes
    def __init__(self, camera_id: _Optional[int] = ..., frame_number: _Optional[int] = ..., t_capture: _Optional[float] = ..., width: _Optional[int] = ..., height: _Optional[int] = ..., encoding: _Optional[str] = ..., data: _Optional[bytes] = ...) -> None: ...

class CameraPixel(_message.Message):
    __slots__ = ("camera_id", "u", "v", "visible_fraction")
    CAMERA_ID_FIELD_NUMBER: _ClassVar[int]
    U_FIELD_NUMBER: _ClassVar[int]
    V_FIELD_NUMBER: _ClassVar[int]
    VISIBLE_FRACTION_FIELD_NUMBER: _ClassVar[int]
    camera_id: int
    u: float
    v: float
    visible_fraction: float
    def __init__(self, camera_id: _Optional[int] = ..., u: _Optional[float] = ..., v: _Optional[float] = ..., visible_fraction: _Optional[float] = ...) -> None: ...

class BallTruth(_message.Message):
    __slots__ = ("x", "y", "z", "vx", "vy", "vz", "cameras")
    X_FIELD_NUMBER: _ClassVar[int]
    Y_FIELD_NUMBER: _ClassVar[int]
    Z_FIELD_NUMBER: _ClassVar[int]
    VX_FIELD_NUMBER: _ClassVar[int]
    VY_FIELD_NUMBER: _ClassVar[int]
    VZ_FIELD_NUMBER: _ClassVar[int]
    CAMERAS_FIELD_NUMBER: _ClassVar[int]
    x: float
    y: float
    z: float
    vx: float
    vy: float
    vz: float
    cameras: _containers.RepeatedCompositeFieldContainer[CameraPixel]
    def __init__(self, x: _Optional[float] = ..., y: _Optional[float] = ..., z: _Optional[float] = ..., vx: _Optional[float] = ..., vy: _Optional[float] = ..., vz: _Optional[float] = ..., cameras: _Optional[_Iterable[_Union[CameraPixel, _Mapping]]] = ...) -> None: ...

class RobotTruth(_message.Message):
    __slots__ = ("team", "id", "x", "y", "theta", "vx", "vy", "omega", "cameras")
    TEAM_FIELD_NUMBER: _ClassVar[int]
    ID_FIELD_NUMBER: _ClassVar[int]
    X_FIELD_NUMBER: _ClassVar[int]
    Y_FIELD_NUMBER: _ClassVar[int]
    THETA_FIELD_NUMBER: _ClassVar[int]
    VX_FIELD_NUMBER: _ClassVar[int]
    VY_FIELD_NUMBER: _ClassVar[int]
    OMEGA_FIELD_NUMBER: _ClassVar[int]
    CAMERAS_FIELD_NUMBER: _ClassVar[int]
    team: _ssl_tracked_pb2.Team
    id: int
    x: float
    y: float
    theta: float
    vx: float
    vy: float
    omega: float
    cameras: _containers.RepeatedCompositeFieldContainer[CameraPixel]
    def __init__(self, team: _Optional[_Union[_ssl_tracked_pb2.Team, str]] = ..., id: _Optional[int] = ..., x: _Optional[float] = ..., y: _Optional[float] = ..., theta: _Optional[float] = ..., vx: _Optional[float] = ..., vy: _Optional[float] = ..., omega: _Optional[float] = ..., cameras: _Optional[_Iterable[_Union[CameraPixel, _Mapping]]] = ...) -> None: ...

class GroundTruth(_message.Message):
    __slots__ = ("frame_number", "t", "ball", "robots")
    FRAME_NUMBER_FIELD_NUMBER: _ClassVar[int]
    T_FIELD_NUMBER: _ClassVar[int]
    BALL_FIELD_NUMBER: _ClassVar[int]
    ROBOTS_FIELD_NUMBER: _ClassVar[int]
    frame_number: int
    t: float
    ball: BallTruth
    robots: _containers.RepeatedCompositeFieldContainer[RobotTruth]
    def __init__(self, frame_number: _Optional[int] = ..., t: _Optional[float] = ..., ball: _Optional[_Union[BallTruth, _Mapping]] = ..., robots: _Optional[_Iterable[_Union[RobotTruth, _Mapping]]] = ...) -> None: ...

class GameState(_message.Message):
    __slots__ = ("t", "command", "for_team", "score_blue", "score_yellow", "blue_defends_negative_x", "placement", "ready", "stage", "stage_time_left", "command_counter", "command_t", "action_time_left", "next_command", "next_for_team", "blue_team", "yellow_team")
    class Command(int, metaclass=_enum_type_wrapper.EnumTypeWrapper):
        __slots__ = ()
        HALT: _ClassVar[GameState.Command]
        STOP: _ClassVar[GameState.Command]
        KICKOFF: _ClassVar[GameState.Command]
        FREE_KICK: _ClassVar[GameState.Command]
        NORMAL: _ClassVar[GameState.Command]
        FORCE_START: _ClassVar[GameState.Command]
        PENALTY: _ClassVar[GameState.Command]
        TIMEOUT: _ClassVar[GameState.Command]
        BALL_PLACEMENT: _ClassVar[GameState.Command]
    HALT: GameState.Command
    STOP: GameState.Command
    KICKOFF: GameState.Command
    FREE_KICK: GameState.Command
    NORMAL: GameState.Command
    FORCE_START: GameState.Command
    PENALTY: GameState.Command
    TIMEOUT: GameState.Command
    BALL_PLACEMENT: GameState.Command
    class Stage(int, metaclass=_enum_type_wrapper.EnumTypeWrapper):
        __slots__ = ()
        PRE_GAME: _ClassVar[GameState.Stage]
        FIRST_HALF: _ClassVar[GameState.Stage]
        HALF_TIME: _ClassVar[GameState.Stage]
        SECOND_HALF: _ClassVar[GameState.Stage]
        PENALTY_SHOOTOUT: _ClassVar[GameState.Stage]
        POST_GAME: _ClassVar[GameState.Stage]
    PRE_GAME: GameState.Stage
    FIRST_HALF: GameState.Stage
    HALF_TIME: GameState.Stage
    SECOND_HALF: GameState.Stage
    PENALTY_SHOOTOUT: GameState.Stage
    POST_GAME: GameState.Stage
    T_FIELD_NUMBER: _ClassVar[int]
    COMMAND_FIELD_NUMBER: _ClassVar[int]
    FOR_TEAM_FIELD_NUMBER: _ClassVar[int]
    SCORE_BLUE_FIELD_NUMBER: _ClassVar[int]
    SCORE_YELLOW_FIELD_NUMBER: _ClassVar[int]
    BLUE_DEFENDS_NEGATIVE_X_FIELD_NUMBER: _ClassVar[int]
    PLACEMENT_FIELD_NUMBER: _ClassVar[int]
    READY_FIELD_NUMBER: _ClassVar[int]
    STAGE_FIELD_NUMBER: _ClassVar[int]
    STAGE_TIME_LEFT_FIELD_NUMBER: _ClassVar[int]
    COMMAND_COUNTER_FIELD_NUMBER: _ClassVar[int]
    COMMAND_T_FIELD_NUMBER: _ClassVar[int]
    ACTION_TIME_LEFT_FIELD_NUMBER: _ClassVar[int]
    NEXT_COMMAND_FIELD_NUMBER: _ClassVar[int]
    NEXT_FOR_TEAM_FIELD_NUMBER: _ClassVar[int]
    BLUE_TEAM_FIELD_NUMBER: _ClassVar[int]
    YELLOW_TEAM_FIELD_NUMBER: _ClassVar[int]
    t: float
    command: GameState.Command
    for_team: _ssl_tracked_pb2.Team
    score_blue: int
    score_yellow: int
    blue_defends_negative_x: bool
    placement: Point
    ready: bool
    stage: GameState.Stage
    stage_time_left: float
    command_counter: int
    command_t: float
    action_time_left: float
    next_command: GameState.Command
    next_for_team: _ssl_tracked_pb2.Team
    blue_team: TeamInfo
    yellow_team: TeamInfo
    def __init__(self, t: _Optional[float] = ..., command: _Optional[_Union[GameState.Command, str]] = ..., for_team: _Optional[_Union[_ssl_tracked_pb2.Team, str]] = ..., score_blue: _Optional[int] = ..., score_yellow: _Optional[int] = ..., blue_defends_negative_x: _Optional[bool] = ..., placement: _Optional[_Union[Point, _Mapping]] = ..., ready: _Optional[bool] = ..., stage: _Optional[_Union[GameState.Stage, str]] = ..., stage_time_left: _Optional[float] = ..., command_counter: _Optional[int] = ..., command_t: _Optional[float] = ..., action_time_left: _Optional[float] = ..., next_command: _Optional[_Union[GameState.Command, str]] = ..., next_for_team: _Optional[_Union[_ssl_tracked_pb2.Team, str]] = ..., blue_team: _Optional[_Union[TeamInfo, _Mapping]] = ..., yellow_team: _Optional[_Union[TeamInfo, _Mapping]] = ...) -> None: ...

class TeamInfo(_message.Message):
    __slots__ = ("red_cards", "yellow_cards", "yellow_card_times", "fouls", "goalkeeper", "timeouts", "timeout_time", "placement_failures", "can_place_ball", "max_robots")
    RED_CARDS_FIELD_NUMBER: _ClassVar[int]
    YELLOW_CARDS_FIELD_NUMBER: _ClassVar[int]
    YELLOW_CARD_TIMES_FIELD_NUMBER: _ClassVar[int]
    FOULS_FIELD_NUMBER: _ClassVar[int]
    GOALKEEPER_FIELD_NUMBER: _ClassVar[int]
    TIMEOUTS_FIELD_NUMBER: _ClassVar[int]
    TIMEOUT_TIME_FIELD_NUMBER: _ClassVar[int]
    PLACEMENT_FAILURES_FIELD_NUMBER: _ClassVar[int]
    CAN_PLACE_BALL_FIELD_NUMBER: _ClassVar[int]
    MAX_ROBOTS_FIELD_NUMBER: _ClassVar[int]
    red_cards: int
    yellow_cards: int
    yellow_card_times: _containers.RepeatedScalarFieldContainer[float]
    fouls: int
    goalkeeper: int
    timeouts: int
    timeout_time: float
    placement_failures: int
    can_place_ball: bool
    max_robots: int
    def __init__(self, red_cards: _Optional[int] = ..., yellow_cards: _Optional[int] = ..., yellow_card_times: _Optional[_Iterable[float]] = ..., fouls: _Optional[int] = ..., goalkeeper: _Optional[int] = ..., timeouts: _Optional[int] = ..., timeout_time: _Optional[float] = ..., placement_failures: _Optional[int] = ..., can_place_ball: _Optional[bool] = ..., max_robots: _Optional[int] = ...) -> None: ...

class GameEvent(_message.Message):
    __slots__ = ("t", "kind", "team", "robot", "value", "limit", "unit", "restart", "for_team")
    T_FIELD_NUMBER: _ClassVar[int]
    KIND_FIELD_NUMBER: _ClassVar[int]
    TEAM_FIELD_NUMBER: _ClassVar[int]
    ROBOT_FIELD_NUMBER: _ClassVar[int]
    VALUE_FIELD_NUMBER: _ClassVar[int]
    LIMIT_FIELD_NUMBER: _ClassVar[int]
    UNIT_FIELD_NUMBER: _ClassVar[int]
    RESTART_FIELD_NUMBER: _ClassVar[int]
    FOR_TEAM_FIELD_NUMBER: _ClassVar[int]
    t: float
    kind: str
    team: _ssl_tracked_pb2.Team
    robot: int
    value: float
    limit: float
    unit: str
    restart: str
    for_team: _ssl_tracked_pb2.Team
    def __init__(self, t: _Optional[float] = ..., kind: _Optional[str] = ..., team: _Optional[_Union[_ssl_tracked_pb2.Team, str]] = ..., robot: _Optional[int] = ..., value: _Optional[float] = ..., limit: _Optional[float] = ..., unit: _Optional[str] = ..., restart: _Optional[str] = ..., for_team: _Optional[_Union[_ssl_tracked_pb2.Team, str]] = ...) -> None: ...

class GameEvents(_message.Message):
    __slots__ = ("t", "events")
    T_FIELD_NUMBER: _ClassVar[int]
    EVENTS_FIELD_NUMBER: _ClassVar[int]
    t: float
    events: _containers.RepeatedCompositeFieldContainer[GameEvent]
    def __init__(self, t: _Optional[float] = ..., events: _Optional[_Iterable[_Union[GameEvent, _Mapping]]] = ...) -> None: ...

class Goal(_message.Message):
    __slots__ = ("t", "scoring_team", "x", "y")
    T_FIELD_NUMBER: _ClassVar[int]
    SCORING_TEAM_FIELD_NUMBER: _ClassVar[int]
    X_FIELD_NUMBER: _ClassVar[int]
    Y_FIELD_NUMBER: _ClassVar[int]
    t: float
    scoring_team: _ssl_tracked_pb2.Team
    x: float
    y: float
    def __init__(self, t: _Optional[float] = ..., scoring_team: _Optional[_Union[_ssl_tracked_pb2.Team, str]] = ..., x: _Optional[float] = ..., y: _Optional[float] = ...) -> None: ...

class BallOut(_message.Message):
    __slots__ = ("t", "x", "y", "last_touch")
    T_FIELD_NUMBER: _ClassVar[int]
    X_FIELD_NUMBER: _ClassVar[int]
    Y_FIELD_NUMBER: _ClassVar[int]
    LAST_TOUCH_FIELD_NUMBER: _ClassVar[int]
    t: float
    x: float
    y: float
    last_touch: _ssl_tracked_pb2.Team
    def __init__(self, t: _Optional[float] = ..., x: _Optional[float] = ..., y: _Optional[float] = ..., last_touch: _Optional[_Union[_ssl_tracked_pb2.Team, str]] = ...) -> None: ...

class Kick(_message.Message):
    __slots__ = ("t", "team", "id", "speed_m_s", "chip")
    T_FIELD_NUMBER: _ClassVar[int]
    TEAM_FIELD_NUMBER: _ClassVar[int]
    ID_FIELD_NUMBER: _ClassVar[int]
    SPEED_M_S_FIELD_NUMBER: _ClassVar[int]
    CHIP_FIELD_NUMBER: _ClassVar[int]
    t: float
    team: _ssl_tracked_pb2.Team
    id: int
    speed_m_s: float
    chip: bool
    def __init__(self, t: _Optional[float] = ..., team: _Optional[_Union[_ssl_tracked_pb2.Team, str]] = ..., id: _Optional[int] = ..., speed_m_s: _Optional[float] = ..., chip: _Optional[bool] = ...) -> None: ...

class Contact(_message.Message):
    __slots__ = ("t_start", "duration_s", "a", "b", "max_depth_m", "relative_speed_m_s", "pushed_by")
    T_START_FIELD_NUMBER: _ClassVar[int]
    DURATION_S_FIELD_NUMBER: _ClassVar[int]
    A_FIELD_NUMBER: _ClassVar[int]
    B_FIELD_NUMBER: _ClassVar[int]
    MAX_DEPTH_M_FIELD_NUMBER: _ClassVar[int]
    RELATIVE_SPEED_M_S_FIELD_NUMBER: _ClassVar[int]
    PUSHED_BY_FIELD_NUMBER: _ClassVar[int]
    t_start: float
    duration_s: float
    a: _ssl_tracked_pb2.RobotId
    b: _ssl_tracked_pb2.RobotId
    max_depth_m: float
    relative_speed_m_s: float
    pushed_by: _ssl_tracked_pb2.RobotId
    def __init__(self, t_start: _Optional[float] = ..., duration_s: _Optional[float] = ..., a: _Optional[_Union[_ssl_tracked_pb2.RobotId, _Mapping]] = ..., b: _Optional[_Union[_ssl_tracked_pb2.RobotId, _Mapping]] = ..., max_depth_m: _Optional[float] = ..., relative_speed_m_s: _Optional[float] = ..., pushed_by: _Optional[_Union[_ssl_tracked_pb2.RobotId, _Mapping]] = ...) -> None: ...

class Event(_message.Message):
    __slots__ = ("goal", "ball_out", "kick", "contact")
    GOAL_FIELD_NUMBER: _ClassVar[int]
    BALL_OUT_FIELD_NUMBER: _ClassVar[int]
    KICK_FIELD_NUMBER: _ClassVar[int]
    CONTACT_FIELD_NUMBER: _ClassVar[int]
    goal: Goal
    ball_out: BallOut
    kick: Kick
    contact: Contact
    def __init__(self, goal: _Optional[_Union[Goal, _Mapping]] = ..., ball_out: _Optional[_Union[BallOut, _Mapping]] = ..., kick: _Optional[_Union[Kick, _Mapping]] = ..., contact: _Optional[_Union[Contact, _Mapping]] = ...) -> None: ...

class SimEvents(_message.Message):
    __slots__ = ("frame_number", "t", "ball", "events")
    FRAME_NUMBER_FIELD_NUMBER: _ClassVar[int]
    T_FIELD_NUMBER: _ClassVar[int]
    BALL_FIELD_NUMBER: _ClassVar[int]
    EVENTS_FIELD_NUMBER: _ClassVar[int]
    frame_number: int
    t: float
    ball: Point
    events: _containers.RepeatedCompositeFieldContainer[Event]
    def __init__(self, frame_number: _Optional[int] = ..., t: _Optional[float] = ..., ball: _Optional[_Union[Point, _Mapping]] = ..., events: _Optional[_Iterable[_Union[Event, _Mapping]]] = ...) -> None: ...

class TeleportRobot(_message.Message):
    __slots__ = ("team", "id", "x", "y", "theta")
    TEAM_FIELD_NUMBER: _ClassVar[int]
    ID_FIELD_NUMBER: _ClassVar[int]
    X_FIELD_NUMBER: _ClassVar[int]
    Y_FIELD_NUMBER: _ClassVar[int]
    THETA_FIELD_NUMBER: _ClassVar[int]
    team: _ssl_tracked_pb2.Team
    id: int
    x: float
    y: float
    theta: float
    def __init__(self, team: _Optional[_Union[_ssl_tracked_pb2.Team, str]] = ..., id: _Optional[int] = ..., x: _Optional[float] = ..., y: _Optional[float] = ..., theta: _Optional[float] = ...) -> None: ...

class Teleport(_message.Message):
    __slots__ = ("t", "robots", "ball")
    T_FIELD_NUMBER: _ClassVar[int]
    ROBOTS_FIELD_NUMBER: _ClassVar[int]
    BALL_FIELD_NUMBER: _ClassVar[int]
    t: float
    robots: _containers.RepeatedCompositeFieldContainer[TeleportRobot]
    ball: Point
    def __init__(self, t: _Optional[float] = ..., robots: _Optional[_Iterable[_Union[TeleportRobot, _Mapping]]] = ..., ball: _Optional[_Union[Point, _Mapping]] = ...) -> None: ...

class RobotReport(_message.Message):
    __slots__ = ("id", "status", "target_x", "target_y", "target_theta", "path", "command", "braking")
    ID_FIELD_NUMBER: _ClassVar[int]
    STATUS_FIELD_NUMBER: _ClassVar[int]
    TARGET_X_FIELD_NUMBER: _ClassVar[int]
    TARGET_Y_FIELD_NUMBER: _ClassVar[int]
    TARGET_THETA_FIELD_NUMBER: _ClassVar[int]
    PATH_FIELD_NUMBER: _ClassVar[int]
    COMMAND_FIELD_NUMBER: _ClassVar[int]
    BRAKING_FIELD_NUMBER: _ClassVar[int]
    id: int
    status: str
    target_x: float
    target_y: float
    target_theta: float
    path: _containers.RepeatedScalarFieldContainer[float]
    command: _ssl_simulation_control_pb2.RobotCommand
    braking: _containers.RepeatedScalarFieldContainer[float]
    def __init__(self, id: _Optional[int] = ..., status: _Optional[str] = ..., target_x: _Optional[float] = ..., target_y: _Optional[float] = ..., target_theta: _Optional[float] = ..., path: _Optional[_Iterable[float]] = ..., command: _Optional[_Union[_ssl_simulation_control_pb2.RobotCommand, _Mapping]] = ..., braking: _Optional[_Iterable[float]] = ...) -> None: ...

class RobotAction(_message.Message):
    __slots__ = ("id", "action")
    ID_FIELD_NUMBER: _ClassVar[int]
    ACTION_FIELD_NUMBER: _ClassVar[int]
    id: int
    action: str
    def __init__(self, id: _Optional[int] = ..., action: _Optional[str] = ...) -> None: ...

class PassReport(_message.Message):
    __slots__ = ("passer", "receiver", "target_x", "target_y", "shoot_x", "shoot_y", "kicked")
    PASSER_FIELD_NUMBER: _ClassVar[int]
    RECEIVER_FIELD_NUMBER: _ClassVar[int]
    TARGET_X_FIELD_NUMBER: _ClassVar[int]
    TARGET_Y_FIELD_NUMBER: _ClassVar[int]
    SHOOT_X_FIELD_NUMBER: _ClassVar[int]
    SHOOT_Y_FIELD_NUMBER: _ClassVar[int]
    KICKED_FIELD_NUMBER: _ClassVar[int]
    passer: int
    receiver: int
    target_x: float
    target_y: float
    shoot_x: float
    shoot_y: float
    kicked: bool
    def __init__(self, passer: _Optional[int] = ..., receiver: _Optional[int] = ..., target_x: _Optional[float] = ..., target_y: _Optional[float] = ..., shoot_x: _Optional[float] = ..., shoot_y: _Optional[float] = ..., kicked: _Optional[bool] = ...) -> None: ...

class TeamReport(_message.Message):
    __slots__ = ("team", "frame_number", "t", "robots", "actions", "pass_points", "pass_values", "passing")
    TEAM_FIELD_NUMBER: _ClassVar[int]
    FRAME_NUMBER_FIELD_NUMBER: _ClassVar[int]
    T_FIELD_NUMBER: _ClassVar[int]
    ROBOTS_FIELD_NUMBER: _ClassVar[int]
    ACTIONS_FIELD_NUMBER: _ClassVar[int]
    PASS_POINTS_FIELD_NUMBER: _ClassVar[int]
    PASS_VALUES_FIELD_NUMBER: _ClassVar[int]
    PASSING_FIELD_NUMBER: _ClassVar[int]
    team: _ssl_tracked_pb2.Team
    frame_number: int
    t: float
    robots: _containers.RepeatedCompositeFieldContainer[RobotReport]
    actions: _containers.RepeatedCompositeFieldContainer[RobotAction]
    pass_points: _containers.RepeatedScalarFieldContainer[float]
    pass_values: _containers.RepeatedScalarFieldContainer[float]
    passing: PassReport
    def __init__(self, team: _Optional[_Union[_ssl_tracked_pb2.Team, str]] = ..., frame_number: _Optional[int] = ..., t: _Optional[float] = ..., robots: _Optional[_Iterable[_Union[RobotReport, _Mapping]]] = ..., actions: _Optional[_Iterable[_Union[RobotAction, _Mapping]]] = ..., pass_points: _Optional[_Iterable[float]] = ..., pass_values: _Optional[_Iterable[float]] = ..., passing: _Optional[_Union[PassReport, _Mapping]] = ...) -> None: ...

class Timing(_message.Message):
    __slots__ = ("stage", "frame_number", "ms")
    class MsEntry(_message.Message):
        __slots__ = ("key", "value")
        KEY_FIELD_NUMBER: _ClassVar[int]
        VALUE_FIELD_NUMBER: _ClassVar[int]
        key: str
        value: float
        def __init__(self, key: _Optional[str] = ..., value: _Optional[float] = ...) -> None: ...
    STAGE_FIELD_NUMBER: _ClassVar[int]
    FRAME_NUMBER_FIELD_NUMBER: _ClassVar[int]
    MS_FIELD_NUMBER: _ClassVar[int]
    stage: str
    frame_number: int
    ms: _containers.ScalarMap[str, float]
    def __init__(self, stage: _Optional[str] = ..., frame_number: _Optional[int] = ..., ms: _Optional[_Mapping[str, float]] = ...) -> None: ...

class StageSummary(_message.Message):
    __slots__ = ("stage", "figures_json")
    STAGE_FIELD_NUMBER: _ClassVar[int]
    FIGURES_JSON_FIELD_NUMBER: _ClassVar[int]
    stage: str
    figures_json: str
    def __init__(self, stage: _Optional[str] = ..., figures_json: _Optional[str] = ...) -> None: ...

class PhysicsFact(_message.Message):
    __slots__ = ("fact", "value", "configured", "samples", "spread", "confident", "used")
    FACT_FIELD_NUMBER: _ClassVar[int]
    VALUE_FIELD_NUMBER: _ClassVar[int]
    CONFIGURED_FIELD_NUMBER: _ClassVar[int]
    SAMPLES_FIELD_NUMBER: _ClassVar[int]
    SPREAD_FIELD_NUMBER: _ClassVar[int]
    CONFIDENT_FIELD_NUMBER: _ClassVar[int]
    USED_FIELD_NUMBER: _ClassVar[int]
    fact: str
    value: float
    configured: float
    samples: int
    spread: float
    confident: bool
    used: bool
    def __init__(self, fact: _Optional[str] = ..., value: _Optional[float] = ..., configured: _Optional[float] = ..., samples: _Optional[int] = ..., spread: _Optional[float] = ..., confident: _Optional[bool] = ..., used: _Optional[bool] = ...) -> None: ...

class PhysicsFacts(_message.Message):
    __slots__ = ("t", "facts")
    T_FIELD_NUMBER: _ClassVar[int]
    FACTS_FIELD_NUMBER: _ClassVar[int]
    t: float
    facts: _containers.RepeatedCompositeFieldContainer[PhysicsFact]
    def __init__(self, t: _Optional[float] = ..., facts: _Optional[_Iterable[_Union[PhysicsFact, _Mapping]]] = ...) -> None: ...

class NodeControl(_message.Message):
    __slots__ = ("node", "command")
    NODE_FIELD_NUMBER: _ClassVar[int]
    COMMAND_FIELD_NUMBER: _ClassVar[int]
    node: str
    command: str
    def __init__(self, node: _Optional[str] = ..., command: _Optional[str] = ...) -> None: ...
