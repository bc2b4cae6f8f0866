from cmdragons.runtime.proto import ssl_tracked_pb2 as _ssl_tracked_pb2
from google.protobuf.internal import containers as _containers
from google.protobuf import descriptor as _descriptor
from google.protobuf import message as _message
from collections.abc import Iterable as _Iterable, Mapping as _Mapping
from typing import ClassVar as _ClassVar, Optional as _Optional, Union as _Union

DESCRIPTOR: _descriptor.FileDescriptor

class MoveWheelVelocity(_message.Message):
    __slots__ = ("front_right", "back_right", "back_left", "front_left")
    FRONT_RIGHT_FIELD_NUMBER: _ClassVar[int]
    BACK_RIGHT_FIELD_NUMBER: _ClassVar[int]
    BACK_LEFT_FIELD_NUMBER: _ClassVar[int]
    FRONT_LEFT_FIELD_NUMBER: _ClassVar[int]
    front_right: float
    back_right: float
    back_left: float
    front_left: float
    def __init__(self, front_right: _Optional[float] = ..., back_right: _Optional[float] = ..., back_left: _Optional[float] = ..., front_left: _Optional[float] = ...) -> None: ...

class MoveLocalVelocity(_message.Message):
    __slots__ = ("forward", "left", "angular")
    FORWARD_FIELD_NUMBER: _ClassVar[int]
    LEFT_FIELD_NUMBER: _ClassVar[int]
    ANGULAR_FIELD_NUMBER: _ClassVar[int]
    forward: float
    left: float
    angular: float
    def __init__(self, forward: _Optional[float] = ..., left: _Optional[float] = ..., angular: _Optional[float] = ...) -> None: ...

class MoveGlobalVelocity(_message.Message):
    __slots__ = ("vel_x", "vel_y", "vel_angular")
    VEL_X_FIELD_NUMBER: _ClassVar[int]
    VEL_Y_FIELD_NUMBER: _ClassVar[int]
    VEL_ANGULAR_FIELD_NUMBER: _ClassVar[int]
    vel_x: float
    vel_y: float
    vel_angular: float
    def __init__(self, vel_x: _Optional[float] = ..., vel_y: _Optional[float] = ..., vel_angular: _Optional[float] = ...) -> None: ...

class RobotMoveCommand(_message.Message):
    __slots__ = ("wheel_velocity", "local_velocity", "global_velocity")
    WHEEL_VELOCITY_FIELD_NUMBER: _ClassVar[int]
    LOCAL_VELOCITY_FIELD_NUMBER: _ClassVar[int]
    GLOBAL_VELOCITY_FIELD_NUMBER: _ClassVar[int]
    wheel_velocity: MoveWheelVelocity
    local_velocity: MoveLocalVelocity
    global_velocity: MoveGlobalVelocity
    def __init__(self, wheel_velocity: _Optional[_Union[MoveWheelVelocity, _Mapping]] = ..., local_velocity: _Optional[_Union[MoveLocalVelocity, _Mapping]] = ..., global_velocity: _Optional[_Union[MoveGlobalVelocity, _Mapping]] = ...) -> None: ...

class RobotCommand(_message.Message):
    __slots__ = ("id", "move_command", "kick_speed", "kick_angle", "dribbler_speed", "chip", "dribbler_power")
    ID_FIELD_NUMBER: _ClassVar[int]
    MOVE_COMMAND_FIELD_NUMBER: _ClassVar[int]
    KICK_SPEED_FIELD_NUMBER: _ClassVar[int]
    KICK_ANGLE_FIELD_NUMBER: _ClassVar[int]
    DRIBBLER_SPEED_FIELD_NUMBER: _ClassVar[int]
    CHIP_FIELD_NUMBER: _ClassVar[int]
    DRIBBLER_POWER_FIELD_NUMBER: _ClassVar[int]
    id: int
    move_command: RobotMoveCommand
    kick_speed: float
    kick_angle: float
    dribbler_speed: float
    chip: bool
    dribbler_power: float
    def __init__(self, id: _Optional[int] = ..., move_command: _Optional[_Union[RobotMoveCommand, _Mapping]] = ..., kick_speed: _Optional[float] = ..., kick_angle: _Optional[float] = ..., dribbler_speed: _Optional[float] = ..., chip: _Optional[bool] = ..., dribbler_power: _Optional[float] = ...) -> None: ...

class RobotControl(_message.Message):
    __slots__ = ("robot_commands", "team", "frame_number", "t")
    ROBOT_COMMANDS_FIELD_NUMBER: _ClassVar[int]
    TEAM_FIELD_NUMBER: _ClassVar[int]
    FRAME_NUMBER_FIELD_NUMBER: _ClassVar[int]
    T_FIELD_NUMBER: _ClassVar[int]
    robot_commands: _containers.RepeatedCompositeFieldContainer[RobotCommand]
    team: _ssl_tracked_pb2.Team
    frame_number: int
    t: float
    def __init__(self, robot_commands: _Optional[_Iterable[_Union[RobotCommand, _Mapping]]] = ..., team: _Optional[_Union[_ssl_tracked_pb2.Team, str]] = ..., frame_number: _Optional[int] = ..., t: _Optional[float] = ...) -> None: ...
