"""The PLC side of gripper-twin: a name-based Modbus/TCP client, the `plc` command, a scan-cycle virtual
PLC and the thesis's grip sequence.

    from plc_client import TwinClient, ScanCycle, ClientIO, GripSequence

`RegisterMap` and `MapError` are the server's own (`twin.frontends.modbus.register_map`), re-exported: one map type
and one map error on both sides of the wire.
"""
from .client import ClientIO, RegisterMap, Signal, TwinClient
from .errors import (ConnectionFailedError, MapError, ModbusExceptionError, NotWritableError, OutputRefusedError,
                     PlcClientError, SignalValueError, UnknownSignalError, ValueOutOfRangeError, ValueTypeError)
from .grip_sequence import Fault, GripSequence, Handshake, Phase
from .scan import Combined, InputImage, ScanCycle, TwinIO, plc_logic

__all__ = ["TwinClient", "RegisterMap", "Signal", "ClientIO", "ScanCycle", "Combined", "InputImage", "TwinIO", "plc_logic", "GripSequence",
           "Handshake", "Phase", "Fault", "PlcClientError", "MapError", "UnknownSignalError", "SignalValueError", "ValueTypeError",
           "ValueOutOfRangeError", "NotWritableError", "ModbusExceptionError", "ConnectionFailedError",
           "OutputRefusedError"]
