from cmdragons.runtime.proto import ssl_tracked_pb2 as _ssl_tracked_pb2
from cmdragons.runtime.proto import ssl_geometry_pb2 as _ssl_geometry_pb2
from google.protobuf.internal import containers as _containers
from google.protobuf.internal import enum_type_wrapper as _enum_type_wrapper
from google.protobuf import descriptor as _descriptor
from google.protobuf import message as _message
from collections.abc import Iterable as _Iterable, Mapping as _Mapping
from typing import ClassVar as _ClassVar, Optional as _Optional, Union as _Union

DESCRIPTOR: _descriptor.FileDescriptor

class SimulatorCapability(int, metaclass=_enum_type_wrapper.EnumTypeWrapper):
    __slots__ = ()
    SIMULATOR_CAPABILITY_UNKNOWN: _ClassVar[SimulatorCapability]
    SIMULATOR_CAPABILITY_MOVE_WHEEL_VELOCITY: _ClassVar[SimulatorCapability]
    SIMULATOR_CAPABILITY_MOVE_LOCAL_VELOCITY: _ClassVar[SimulatorCapability]
    SIMULATOR_CAPABILITY_MOVE_GLOBAL_VELOCITY: _ClassVar[SimulatorCapability]
SIMULATOR_CAPABILITY_UNKNOWN: SimulatorCapability
SIMULATOR_CAPABILITY_MOVE_WHEEL_VELOCITY: SimulatorCapability
SIMULATOR_CAPABILITY_MOVE_LOCAL_VELOCITY: SimulatorCapability
SIMULATOR_CAPABILITY_MOVE_GLOBAL_VELOCITY: SimulatorCapability

class TeleportBall(_message.Message):
    __slots__ = ("x", "y", "z", "vx", "vy", "vz", "teleport_safely", "roll", "by_force")
    X_FIELD_NUMBER: _ClassVar[int]
    Y_FIELD_NUMBER: _ClassVar[int]
    Z_FIELD_NUMBER: _ClassVar[int]
    VX_FIELD_NUMBER: _ClassVar[int]
    VY_FIELD_NUMBER: _ClassVar[int]
    VZ_FIELD_NUMBER: _ClassVar[int]
    TELEPORT_SAFELY_FIELD_NUMBER: _ClassVar[int]
    ROLL_FIELD_NUMBER: _ClassVar[int]
    BY_FORCE_FIELD_NUMBER: _ClassVar[int]
    x: float
    y: float
    z: float
    vx: float
    vy: float
    vz: float
    teleport_safely: bool
    roll: bool
    by_force: bool
    def __init__(self, x: _Optional[float] = ..., y: _Optional[float] = ..., z: _Optional[float] = ..., vx: _Optional[float] = ..., vy: _Optional[float] = ..., vz: _Optional[float] = ..., teleport_safely: _Optional[bool] = ..., roll: _Optional[bool] = ..., by_force: _Optional[bool] = ...) -> None: ...

class TeleportRobot(_message.Message):
    __slots__ = ("id", "x", "y", "orientation", "v_x", "v_y", "v_angular", "present", "by_force")
    ID_FIELD_NUMBER: _ClassVar[int]
    X_FIELD_NUMBER: _ClassVar[int]
    Y_FIELD_NUMBER: _ClassVar[int]
    ORIENTATION_FIELD_NUMBER: _ClassVar[int]
    V_X_FIELD_NUMBER: _ClassVar[int]
    V_Y_FIELD_NUMBER: _ClassVar[int]
    V_ANGULAR_FIELD_NUMBER: _ClassVar[int]
    PRESENT_FIELD_NUMBER: _ClassVar[int]
    BY_FORCE_FIELD_NUMBER: _ClassVar[int]
    id: _ssl_tracked_pb2.RobotId
    x: float
    y: float
    orientation: float
    v_x: float
    v_y: float
    v_angular: float
    present: bool
    by_force: bool
    def __init__(self, id: _Optional[_Union[_ssl_tracked_pb2.RobotId, _Mapping]] = ..., x: _Optional[float] = ..., y: _Optional[float] = ..., orientation: _Optional[float] = ..., v_x: _Optional[float] = ..., v_y: _Optional[float] = ..., v_angular: _Optional[float] = ..., present: _Optional[bool] = ..., by_force: _Optional[bool] = ...) -> None: ...

class SimulatorControl(_message.Message):
    __slots__ = ("teleport_ball", "teleport_robot", "simulation_speed")
    TELEPORT_BALL_FIELD_NUMBER: _ClassVar[int]
    TELEPORT_ROBOT_FIELD_NUMBER: _ClassVar[int]
    SIMULATION_SPEED_FIELD_NUMBER: _ClassVar[int]
    teleport_ball: TeleportBall
    teleport_robot: _containers.RepeatedCompositeFieldContainer[TeleportRobot]
    simulation_speed: float
    def __init__(self, teleport_ball: _Optional[_Union[TeleportBall, _Mapping]] = ..., teleport_robot: _Optional[_Iterable[_Union[TeleportRobot, _Mapping]]] = ..., simulation_speed: _Optional[float] = ...) -> None: ...

class SimulatorConfig(_message.Message):
    __slots__ = ("geometry", "vision_port")
    GEOMETRY_FIELD_NUMBER: _ClassVar[int]
    VISION_PORT_FIELD_NUMBER: _ClassVar[int]
    geometry: _ssl_geometry_pb2.SSL_GeometryData
    vision_port: int
    def __init__(self, geometry: _Optional[_Union[_ssl_geometry_pb2.SSL_GeometryData, _Mapping]] = ..., vision_port: _Optional[int] = ...) -> None: ...

class SimulatorCommand(_message.Message):
    __slots__ = ("control", "config")
    CONTROL_FIELD_NUMBER: _ClassVar[int]
    CONFIG_FIELD_NUMBER: _ClassVar[int]
    control: SimulatorControl
    config: SimulatorConfig
    def __init__(self, control: _Optional[_Union[SimulatorControl, _Mapping]] = ..., config: _Optional[_Union[SimulatorConfig, _Mapping]] = ...) -> None: ...

class SimulatorError(_message.Message):
    __slots__ = ("code", "message")
    CODE_FIELD_NUMBER: _ClassVar[int]
    MESSAGE_FIELD_NUMBER: _ClassVar[int]
    code: str
    message: str
    def __init__(self, code: _Optional[str] = ..., message: _Optional[str] = ...) -> None: ...

class SimulatorResponse(_message.Message):
    __slots__ = ("errors",)
    ERRORS_FIELD_NUMBER: _ClassVar[int]
    errors: _containers.RepeatedCompositeFieldContainer[SimulatorError]
    def __init__(self, errors: _Optional[_Iterable[_Union[SimulatorError, _Mapping]]] = ...) -> None: ...

class RobotFeedback(_message.Message):
    __slots__ = ("id", "dribbler_ball_contact")
    ID_FIELD_NUMBER: _ClassVar[int]
    DRIBBLER_BALL_CONTACT_FIELD_NUMBER: _ClassVar[int]
    id: int
    dribbler_ball_contact: bool
    def __init__(self, id: _Optional[int] = ..., dribbler_ball_contact: _Optional[bool] = ...) -> None: ...

class RobotControlResponse(_message.Message):
    __slots__ = ("errors", "feedback")
    ERRORS_FIELD_NUMBER: _ClassVar[int]
    FEEDBACK_FIELD_NUMBER: _ClassVar[int]
    errors: _containers.RepeatedCompositeFieldContainer[SimulatorError]
    feedback: _containers.RepeatedCompositeFieldContainer[RobotFeedback]
    def __init__(self, errors: _Optional[_Iterable[_Union[SimulatorError, _Mapping]]] = ..., feedback: _Optional[_Iterable[_Union[RobotFeedback, _Mapping]]] = ...) -> None: ...

class EarlierSimulatorError(_message.Message):
    __slots__ = ("code", "unsupported_capability", "message")
    CODE_FIELD_NUMBER: _ClassVar[int]
    UNSUPPORTED_CAPABILITY_FIELD_NUMBER: _ClassVar[int]
    MESSAGE_FIELD_NUMBER: _ClassVar[int]
    code: str
    unsupported_capability: SimulatorCapability
    message: str
    def __init__(self, code: _Optional[str] = ..., unsupported_capability: _Optional[_Union[SimulatorCapability, str]] = ..., message: _Optional[str] = ...) -> None: ...

class EarlierRobotFeedback(_message.Message):
    __slots__ = ("id", "dribbler_ball_contact")
    ID_FIELD_NUMBER: _ClassVar[int]
    DRIBBLER_BALL_CONTACT_FIELD_NUMBER: _ClassVar[int]
    id: _ssl_tracked_pb2.RobotId
    dribbler_ball_contact: bool
    def __init__(self, id: _Optional[_Union[_ssl_tracked_pb2.RobotId, _Mapping]] = ..., dribbler_ball_contact: _Optional[bool] = ...) -> None: ...
