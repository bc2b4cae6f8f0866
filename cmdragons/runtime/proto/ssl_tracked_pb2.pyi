from google.protobuf.internal import containers as _containers
from google.protobuf.internal import enum_type_wrapper as _enum_type_wrapper
from google.protobuf import descriptor as _descriptor
from google.protobuf import message as _message
from collections.abc import Iterable as _Iterable, Mapping as _Mapping
from typing import ClassVar as _ClassVar, Optional as _Optional, Union as _Union

DESCRIPTOR: _descriptor.FileDescriptor

class Team(int, metaclass=_enum_type_wrapper.EnumTypeWrapper):
    __slots__ = ()
    UNKNOWN: _ClassVar[Team]
    YELLOW: _ClassVar[Team]
    BLUE: _ClassVar[Team]
UNKNOWN: Team
YELLOW: Team
BLUE: Team

class RobotId(_message.Message):
    __slots__ = ("id", "team")
    ID_FIELD_NUMBER: _ClassVar[int]
    TEAM_FIELD_NUMBER: _ClassVar[int]
    id: int
    team: Team
    def __init__(self, id: _Optional[int] = ..., team: _Optional[_Union[Team, str]] = ...) -> None: ...

class Vector2(_message.Message):
    __slots__ = ("x", "y")
    X_FIELD_NUMBER: _ClassVar[int]
    Y_FIELD_NUMBER: _ClassVar[int]
    x: float
    y: float
    def __init__(self, x: _Optional[float] = ..., y: _Optional[float] = ...) -> None: ...

class Vector3(_message.Message):
    __slots__ = ("x", "y", "z")
    X_FIELD_NUMBER: _ClassVar[int]
    Y_FIELD_NUMBER: _ClassVar[int]
    Z_FIELD_NUMBER: _ClassVar[int]
    x: float
    y: float
    z: float
    def __init__(self, x: _Optional[float] = ..., y: _Optional[float] = ..., z: _Optional[float] = ...) -> None: ...

class TrackedBall(_message.Message):
    __slots__ = ("pos", "vel", "visibility")
    POS_FIELD_NUMBER: _ClassVar[int]
    VEL_FIELD_NUMBER: _ClassVar[int]
    VISIBILITY_FIELD_NUMBER: _ClassVar[int]
    pos: Vector3
    vel: Vector3
    visibility: float
    def __init__(self, pos: _Optional[_Union[Vector3, _Mapping]] = ..., vel: _Optional[_Union[Vector3, _Mapping]] = ..., visibility: _Optional[float] = ...) -> None: ...

class TrackedRobot(_message.Message):
    __slots__ = ("robot_id", "pos", "orientation", "vel", "vel_angular", "visibility")
    ROBOT_ID_FIELD_NUMBER: _ClassVar[int]
    POS_FIELD_NUMBER: _ClassVar[int]
    ORIENTATION_FIELD_NUMBER: _ClassVar[int]
    VEL_FIELD_NUMBER: _ClassVar[int]
    VEL_ANGULAR_FIELD_NUMBER: _ClassVar[int]
    VISIBILITY_FIELD_NUMBER: _ClassVar[int]
    robot_id: RobotId
    pos: Vector2
    orientation: float
    vel: Vector2
    vel_angular: float
    visibility: float
    def __init__(self, robot_id: _Optional[_Union[RobotId, _Mapping]] = ..., pos: _Optional[_Union[Vector2, _Mapping]] = ..., orientation: _Optional[float] = ..., vel: _Optional[_Union[Vector2, _Mapping]] = ..., vel_angular: _Optional[float] = ..., visibility: _Optional[float] = ...) -> None: ...

class TrackedFrame(_message.Message):
    __slots__ = ("frame_number", "timestamp", "balls", "robots")
    FRAME_NUMBER_FIELD_NUMBER: _ClassVar[int]
    TIMESTAMP_FIELD_NUMBER: _ClassVar[int]
    BALLS_FIELD_NUMBER: _ClassVar[int]
    ROBOTS_FIELD_NUMBER: _ClassVar[int]
    frame_number: int
    timestamp: float
    balls: _containers.RepeatedCompositeFieldContainer[TrackedBall]
    robots: _containers.RepeatedCompositeFieldContainer[TrackedRobot]
    def __init__(self, frame_number: _Optional[int] = ..., timestamp: _Optional[float] = ..., balls: _Optional[_Iterable[_Union[TrackedBall, _Mapping]]] = ..., robots: _Optional[_Iterable[_Union[TrackedRobot, _Mapping]]] = ...) -> None: ...
