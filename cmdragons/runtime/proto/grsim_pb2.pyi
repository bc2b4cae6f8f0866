from google.protobuf.internal import containers as _containers
from google.protobuf import descriptor as _descriptor
from google.protobuf import message as _message
from collections.abc import Iterable as _Iterable, Mapping as _Mapping
from typing import ClassVar as _ClassVar, Optional as _Optional, Union as _Union

DESCRIPTOR: _descriptor.FileDescriptor

class grSim_Robot_Command(_message.Message):
    __slots__ = ("id", "kickspeedx", "kickspeedz", "veltangent", "velnormal", "velangular", "spinner", "wheelsspeed", "wheel1", "wheel2", "wheel3", "wheel4")
    ID_FIELD_NUMBER: _ClassVar[int]
    KICKSPEEDX_FIELD_NUMBER: _ClassVar[int]
    KICKSPEEDZ_FIELD_NUMBER: _ClassVar[int]
    VELTANGENT_FIELD_NUMBER: _ClassVar[int]
    VELNORMAL_FIELD_NUMBER: _ClassVar[int]
    VELANGULAR_FIELD_NUMBER: _ClassVar[int]
    SPINNER_FIELD_NUMBER: _ClassVar[int]
    WHEELSSPEED_FIELD_NUMBER: _ClassVar[int]
    WHEEL1_FIELD_NUMBER: _ClassVar[int]
    WHEEL2_FIELD_NUMBER: _ClassVar[int]
    WHEEL3_FIELD_NUMBER: _ClassVar[int]
    WHEEL4_FIELD_NUMBER: _ClassVar[int]
    id: int
    kickspeedx: float
    kickspeedz: float
    veltangent: float
    velnormal: float
    velangular: float
    spinner: bool
    wheelsspeed: bool
    wheel1: float
    wheel2: float
    wheel3: float
    wheel4: float
    def __init__(self, id: _Optional[int] = ..., kickspeedx: _Optional[float] = ..., kickspeedz: _Optional[float] = ..., veltangent: _Optional[float] = ..., velnormal: _Optional[float] = ..., velangular: _Optional[float] = ..., spinner: _Optional[bool] = ..., wheelsspeed: _Optional[bool] = ..., wheel1: _Optional[float] = ..., wheel2: _Optional[float] = ..., wheel3: _Optional[float] = ..., wheel4: _Optional[float] = ...) -> None: ...

class grSim_Commands(_message.Message):
    __slots__ = ("timestamp", "isteamyellow", "robot_commands")
    TIMESTAMP_FIELD_NUMBER: _ClassVar[int]
    ISTEAMYELLOW_FIELD_NUMBER: _ClassVar[int]
    ROBOT_COMMANDS_FIELD_NUMBER: _ClassVar[int]
    timestamp: float
    isteamyellow: bool
    robot_commands: _containers.RepeatedCompositeFieldContainer[grSim_Robot_Command]
    def __init__(self, timestamp: _Optional[float] = ..., isteamyellow: _Optional[bool] = ..., robot_commands: _Optional[_Iterable[_Union[grSim_Robot_Command, _Mapping]]] = ...) -> None: ...

class grSim_RobotReplacement(_message.Message):
    __slots__ = ("x", "y", "dir", "id", "yellowteam", "turnon")
    X_FIELD_NUMBER: _ClassVar[int]
    Y_FIELD_NUMBER: _ClassVar[int]
    DIR_FIELD_NUMBER: _ClassVar[int]
    ID_FIELD_NUMBER: _ClassVar[int]
    YELLOWTEAM_FIELD_NUMBER: _ClassVar[int]
    TURNON_FIELD_NUMBER: _ClassVar[int]
    x: float
    y: float
    dir: float
    id: int
    yellowteam: bool
    turnon: bool
    def __init__(self, x: _Optional[float] = ..., y: _Optional[float] = ..., dir: _Optional[float] = ..., id: _Optional[int] = ..., yellowteam: _Optional[bool] = ..., turnon: _Optional[bool] = ...) -> None: ...

class grSim_BallReplacement(_message.Message):
    __slots__ = ("x", "y", "vx", "vy")
    X_FIELD_NUMBER: _ClassVar[int]
    Y_FIELD_NUMBER: _ClassVar[int]
    VX_FIELD_NUMBER: _ClassVar[int]
    VY_FIELD_NUMBER: _ClassVar[int]
    x: float
    y: float
    vx: float
    vy: float
    def __init__(self, x: _Optional[float] = ..., y: _Optional[float] = ..., vx: _Optional[float] = ..., vy: _Optional[float] = ...) -> None: ...

class grSim_Replacement(_message.Message):
    __slots__ = ("ball", "robots")
    BALL_FIELD_NUMBER: _ClassVar[int]
    ROBOTS_FIELD_NUMBER: _ClassVar[int]
    ball: grSim_BallReplacement
    robots: _containers.RepeatedCompositeFieldContainer[grSim_RobotReplacement]
    def __init__(self, ball: _Optional[_Union[grSim_BallReplacement, _Mapping]] = ..., robots: _Optional[_Iterable[_Union[grSim_RobotReplacement, _Mapping]]] = ...) -> None: ...

class grSim_Packet(_message.Message):
    __slots__ = ("commands", "replacement")
    COMMANDS_FIELD_NUMBER: _ClassVar[int]
    REPLACEMENT_FIELD_NUMBER: _ClassVar[int]
    commands: grSim_Commands
    replacement: grSim_Replacement
    def __init__(self, commands: _Optional[_Union[grSim_Commands, _Mapping]] = ..., replacement: _Optional[_Union[grSim_Replacement, _Mapping]] = ...) -> None: ...
