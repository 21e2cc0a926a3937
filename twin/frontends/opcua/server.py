"""An OPC UA server (asyncua) that serves a station's address space. It knows nothing of physics.

Like the Modbus server, it answers from what the cell published after the last completed step and hands
validated writes to the cell, which applies them at the start of the next step:

- `publish(values, applied, t)` (awaited for every step's snapshot, in order, in the OPC UA process's loop: see
  `cell_link`) writes every value that changed into the address space (`Server.write_attribute_value`), one
  DataValue per variable, which asyncua queues for every monitored item on it: a subscription sees the value
  of every step, even one that lasts a single step. Its SourceTimestamp is the step's simulated time on the
  server's clock: simulated seconds from an anchor, the UTC wall time less the simulated time when the clock
  was started (`start_clock`: `cell_link` starts it again at the first step in real time, so at speed 1 a
  timestamp is its step's due time, give or take the link). Timestamps advance by exactly one step per step
  however fast the steps run. ServerTimestamp is the wall clock when the value was published.
- A client's write of a signal is taken by asyncua's PreWrite callback (`_pre_write`): outputs are read-only
  (BadNotWritable), a Variant of another type is BadTypeMismatch, a value outside the signal's range (or NaN,
  or a text that is none of an enumeration's choices) BadOutOfRange, a read-only user BadUserAccessDenied, a
  faulted simulation BadDeviceFailure; a refused write changes nothing. Accepted writes of one request are
  submitted to the cell together and read back at once as written; the twin applies them at the next step.
  asyncua itself never stores a client's value of a signal: the signal's items are pointed at no node while
  asyncua runs the request, and the PostWrite callback puts them back with their status codes.
- Subscriptions are asyncua's: a monitored item's RevisedSamplingInterval is at least the step (a value
  changes at most once a step; -1 is the publishing interval); the publishing interval and the queue size
  are what the client asked (asyncua's queue of 0 is its maximum, 10000: every step of a publishing interval).
- Reads in lockstep (`sync`): a Read of a signal's value first waits, in asyncua's PreRead callback, until
  every step the cell had run when the read came has been published here (steps another front end asked
  for, a Modbus client's `sim.advance`, included): a client that saw an advance done anywhere reads its
  last step. In real time a read answers from the last step published, at once.
- `Sim.Advance(steps)` (lockstep only) runs that many steps and returns the step count when they are done.
  asyncua answers a connection's requests in order, so the call holds that connection's other requests until
  its steps are done (an asyncua client's keep-alive probe gives up after 1 s: advance in shorter chunks).
- Every request of an activated session is reported to `on_request` (the comm-loss watchdog) from asyncua's
  permission check (`_asyncua_roles.Roles`); sessions coming and going to `on_client` (`sessions`).

Only asyncua's public API: `Server`, its user manager and permission ruleset, server callbacks, ua types and
the standard `logging` module (docs/opcua.md, "What asyncua decides").
"""
from __future__ import annotations

import logging
import math
import socket
from collections.abc import Awaitable, Callable, Mapping, Sequence
from datetime import datetime, timedelta, timezone

from asyncua import Server, ua
from asyncua.common.callback import CallbackType
from asyncua.ua.ua_binary import struct_from_binary

from .address_space import (ADVANCE_METHOD, BOOLEAN, DOUBLE, INT32, INT64, SIM_FOLDER, STRING, UINT32, AddressSpace,
                            Variable)
from twin.core.errors import TwinError
from twin.core.signal_table import SIM_ADVANCE

from .errors import AdvanceRefused
from .security import Security
from .serve import DEFAULT_PORT  # 4840, IANA's opcua-tcp (defined with the --opcua option; a light module)
from .sessions import OnClient, SessionWatcher

VARIANT = {BOOLEAN: ua.VariantType.Boolean, DOUBLE: ua.VariantType.Double, INT32: ua.VariantType.Int32,
           UINT32: ua.VariantType.UInt32, INT64: ua.VariantType.Int64, STRING: ua.VariantType.String}
DATA_TYPE_ID = {BOOLEAN: ua.ObjectIds.Boolean, DOUBLE: ua.ObjectIds.Double, INT32: ua.ObjectIds.Int32,
                UINT32: ua.ObjectIds.UInt32, INT64: ua.ObjectIds.Int64, STRING: ua.ObjectIds.String}
INTEGER_VARIANTS = frozenset({ua.VariantType.SByte, ua.VariantType.Byte, ua.VariantType.Int16, ua.VariantType.UInt16,
                              ua.VariantType.Int32, ua.VariantType.UInt32, ua.VariantType.Int64,
                              ua.VariantType.UInt64})
LIMITS = {INT32: (-2**31, 2**31 - 1), UINT32: (0, 2**32 - 1), INT64: (-2**63, 2**63 - 1)}
MAX_ADVANCE = 2**32 - 1

Submit = Callable[[Sequence[tuple[Variable, object]]], Awaitable[str | None]]  # -> None, or a Bad status code's name
Advance = Callable[[int], Awaitable[int]]  # lockstep: run n steps, return the step count when done
Sync = Callable[[], Awaitable[object]]  # lockstep: returns once every step the cell has run is published here
OnRequest = Callable[[str, bool], None]  # (source, clock_only): a session's request came (the comm-loss watchdog)

log = logging.getLogger("twin.frontends.opcua")


class PublishedValue(ua.DataValue):
    """A DataValue as the server publishes it: never changed afterwards (a new one per change), so a copy of it
    is itself, as of any immutable value. asyncua deep-copies a value for each monitored item it notifies
    (about 70 us each, most of the OPC UA process's work with a thousand items); this one costs nothing."""

    __slots__ = ()

    def __copy__(self):
        return self

    def __deepcopy__(self, memo):
        return self


def free_port(host: str) -> int:
    """A TCP port free on `host` now (asyncua advertises its endpoint URL, so port 0 is chosen up front)."""
    family = socket.AF_INET6 if ":" in host else socket.AF_INET
    with socket.socket(family, socket.SOCK_STREAM) as s:
        s.bind((host, 0))
        return s.getsockname()[1]


def _status(name: str) -> ua.StatusCode:
    return ua.StatusCode(getattr(ua.StatusCodes, name))


def variant_value(var: Variable, value):
    """A value as the cell publishes it (SI number, bool, enumeration text or index) -> the variable's value."""
    t = var.data_type
    if t == BOOLEAN:
        return bool(value)
    if t == DOUBLE:
        return float(value)
    if t == STRING:
        if isinstance(value, int) and not isinstance(value, bool):
            choices = var.spec.choices
            return choices[value] if 0 <= value < len(choices) else str(value)
        return "" if value is None else str(value)
    lo, hi = LIMITS[t]
    if isinstance(value, float) and math.isnan(value):
        return 0
    v = int(round(value))
    return lo if v < lo else hi if v > hi else v


class OpcUaServer:
    """Serves an `AddressSpace`; the cell's link awaits `publish` after each step (see the module docstring)."""

    def __init__(self, space: AddressSpace, *, step_s: float, submit: Submit, advance: Advance | None = None,
                 security: Security | None = None, server_name: str | None = None,
                 on_request: OnRequest | None = None, clock_requests: bool = False, on_client: OnClient | None = None,
                 sync: Sync | None = None):
        """`on_request(source, clock_only)` is called for every request of an activated session (source:
        "opcua HOST:PORT" and the account's "user 'NAME'"); with `clock_requests` (lockstep), `clock_only` tells
        a request that only drives or reads simulated time (Sim.Advance calls, reads and writes of
        `sim.advance`). `on_client(kind, **fields)`: a client connected or gone (`sessions`). `sync`
        (lockstep): awaited before a read of a signal is answered (see the module docstring)."""
        self.space = space
        self.on_request, self.clock_requests = on_request, clock_requests
        self.step_ms = step_s * 1000.0
        self._submit = submit
        self._advance = advance
        self._sync = sync
        self.security = security or Security()
        self.server = Server(user_manager=self.security.user_manager())
        self.server_name = server_name or f"gripper-twin {space.station}"
        self.sessions = SessionWatcher(on_client)
        self.ns = 0
        self.endpoint = ""
        self.host, self.port = "", 0
        self._nodes: dict[ua.NodeId, Variable] = {}
        self._nid: dict[str, ua.NodeId] = {}  # signal name -> its NodeId
        self._last: dict[str, object] = {}  # signal name -> the value last published
        self._var = {v.name: v for v in space}
        self.requests = 0  # writes and calls answered
        self.accepted = 0  # write batches accepted (handed to the cell)
        self._held: dict[str, int] = {}  # input written -> the batch that wrote it, until a step applied it
        self._writing: dict[int, tuple] = {}  # id(WriteParameters) -> (them, the signals' WriteValues, statuses)
        self._epoch = datetime.now(timezone.utc)  # the wall time of simulated time 0 (`start_clock`)
        self._t = 0.0  # the simulated time last published
        self._started = False

    # -- start and stop ---------------------------------------------------------------------------------
    async def start(self, host: str = "127.0.0.1", port: int = DEFAULT_PORT) -> tuple[str, int]:
        """Build the address space and listen. Port 0: any free port. Returns the bound host and port."""
        srv = self.server
        await srv.init()
        if port == 0:
            port = free_port(host)
        url_host = f"[{host}]" if ":" in host else host
        self.endpoint = f"opc.tcp://{url_host}:{port}/gripper-twin/"
        srv.set_endpoint(self.endpoint)
        srv.set_server_name(self.server_name)
        await srv.set_application_uri(self.security.application_uri)
        srv.product_uri = "urn:gripper-twin"
        srv.manufacturer_name = "gripper-twin"
        await self.security.apply(srv, host, on_request=self._request_seen)
        self.ns = await srv.register_namespace(self.space.namespace_uri)
        await self._build()
        srv.subscribe_server_callback(CallbackType.PreWrite, self._pre_write)
        srv.subscribe_server_callback(CallbackType.PostWrite, self._post_write)
        srv.subscribe_server_callback(CallbackType.ItemSubscriptionCreated, self._revise_sampling)
        srv.subscribe_server_callback(CallbackType.ItemSubscriptionModified, self._revise_sampling)
        if self._sync is not None:
            srv.subscribe_server_callback(CallbackType.PreRead, self._pre_read)
        if any(a.read_only for a in self.security.accounts):
            srv.subscribe_server_callback(CallbackType.PostRead, self._user_access_level)
        self.sessions.install()
        await srv.start()
        self._started = True
        self.host, self.port = host, port
        return host, port

    async def close(self) -> None:
        self.sessions.stopping = True
        if self._started:
            self._started = False
            await self.server.stop()
        self.sessions.uninstall()

    # -- the address space ----------------------------------------------------------------------------
    def node_id(self, name: str) -> ua.NodeId:
        return ua.NodeId(name, self.ns)

    async def _build(self) -> None:
        srv, ns = self.server, self.ns
        objects = srv.nodes.objects
        folders = {}
        for name in self.space.folders:
            folders[name] = await objects.add_folder(self.node_id(name), ua.QualifiedName(name, ns))
        items = []
        for var in self.space:
            items.append(self._variable_item(var, folders[var.folder].nodeid))
            items += self._property_items(var)
        results = await objects.session.add_nodes(items)  # the AddNodes service, as a client would call it
        for item, res in zip(items, results):
            if not res.StatusCode.is_good():
                raise RuntimeError(f"OPC UA node {item.RequestedNewNodeId.to_string()}: {res.StatusCode}")
        for var in self.space:
            nid = self.node_id(var.name)
            self._nodes[nid] = var
            self._nid[var.name] = nid
        steps = ua.Argument(Name="steps", DataType=ua.NodeId(ua.ObjectIds.UInt32), ValueRank=ua.ValueRank.Scalar,
                            Description=ua.LocalizedText("how many simulation steps to run"))
        step = ua.Argument(Name="step", DataType=ua.NodeId(ua.ObjectIds.UInt32), ValueRank=ua.ValueRank.Scalar,
                           Description=ua.LocalizedText("sim.step when the steps are done"))
        method = await folders[SIM_FOLDER].add_method(self.node_id(ADVANCE_METHOD), ua.QualifiedName("Advance", ns),
                                                     self._call_advance, [steps], [step])
        await method.write_attribute(ua.AttributeIds.Description, ua.DataValue(ua.Variant(ua.LocalizedText(
            "lockstep: run this many steps and return when they are done (sim.step after them); "
            "real time: BadInvalidState"))))

    def _variable_item(self, var: Variable, parent: ua.NodeId) -> ua.AddNodesItem:
        item = ua.AddNodesItem()
        item.RequestedNewNodeId = self.node_id(var.name)
        item.BrowseName = ua.QualifiedName(var.name, self.ns)
        item.NodeClass = ua.NodeClass.Variable
        item.ParentNodeId = parent
        item.ReferenceTypeId = ua.NodeId(ua.ObjectIds.Organizes)
        item.TypeDefinition = ua.NodeId(ua.ObjectIds.AnalogItemType if var.numeric else ua.ObjectIds.BaseDataVariableType)
        attrs = ua.VariableAttributes()
        attrs.DisplayName = ua.LocalizedText(var.name)
        attrs.Description = ua.LocalizedText(var.description)
        attrs.DataType = ua.NodeId(DATA_TYPE_ID[var.data_type])
        attrs.Value = ua.Variant(variant_value(var, "" if var.data_type == STRING else 0), VARIANT[var.data_type])
        attrs.ValueRank = ua.ValueRank.Scalar
        attrs.ArrayDimensions = None
        access = ua.AccessLevel.CurrentRead.mask | (ua.AccessLevel.CurrentWrite.mask if var.writable else 0)
        attrs.AccessLevel = attrs.UserAccessLevel = access
        attrs.MinimumSamplingInterval = self.step_ms
        attrs.Historizing = False
        attrs.WriteMask = attrs.UserWriteMask = 0
        item.NodeAttributes = attrs
        return item

    def _property_items(self, var: Variable) -> list[ua.AddNodesItem]:
        props = []
        if var.numeric:
            props.append(("EURange", ua.ObjectIds.Range,
                          ua.Variant(ua.Range(Low=var.low, High=var.high), ua.VariantType.ExtensionObject)))
        if var.unit is not None:
            eu = ua.EUInformation(NamespaceUri="http://www.opcfoundation.org/UA/units/un/cefact",
                                  UnitId=var.unit.unit_id, DisplayName=ua.LocalizedText(var.unit.symbol),
                                  Description=ua.LocalizedText(var.unit.description))
            props.append(("EngineeringUnits", ua.ObjectIds.EUInformation,
                          ua.Variant(eu, ua.VariantType.ExtensionObject)))
        items = []
        for name, dtype, value in props:
            item = ua.AddNodesItem()
            item.RequestedNewNodeId = ua.NodeId(f"{var.name}#{name}", self.ns)
            item.BrowseName = ua.QualifiedName(name, 0)
            item.NodeClass = ua.NodeClass.Variable
            item.ParentNodeId = self.node_id(var.name)
            item.ReferenceTypeId = ua.NodeId(ua.ObjectIds.HasProperty)
            item.TypeDefinition = ua.NodeId(ua.ObjectIds.PropertyType)
            attrs = ua.VariableAttributes()
            attrs.DisplayName = ua.LocalizedText(name)
            attrs.DataType = ua.NodeId(dtype)
            attrs.Value = value
            attrs.ValueRank = ua.ValueRank.Scalar
            attrs.AccessLevel = attrs.UserAccessLevel = ua.AccessLevel.CurrentRead.mask
            item.NodeAttributes = attrs
            items.append(item)
        return items

    # -- publishing (the cell's side) -----------------------------------------------------------------
    def start_clock(self, t: float) -> None:
        """Simulated time `t` is now: SourceTimestamps are this wall time plus simulated seconds since."""
        self._epoch = datetime.now(timezone.utc) - timedelta(seconds=t)

    def source_timestamp(self) -> datetime:
        """The simulated time last published, as a SourceTimestamp (see the module docstring)."""
        return self._epoch + timedelta(seconds=self._t)

    async def publish(self, values: Mapping[str, object], applied: int | None = None, t: float | None = None) -> None:
        """After a step: write every changed value into the address space (asyncua queues it for its monitored
        items).

        `applied`: how many write batches this server accepted the step had applied (the adapter's count);
        an input written since keeps reading as written until a step has applied it. `t`: the step's
        simulated time (the SourceTimestamp; see the module docstring)."""
        if t is not None:
            self._t = t
        now = source = None
        last, variables, held, nid = self._last, self._var, self._held, self._nid
        write = self.server.write_attribute_value
        for name, raw in values.items():
            var = variables.get(name)
            if var is None:
                continue
            if held and name in held:
                if applied is not None and held[name] > applied:
                    continue
                del held[name]
            value = variant_value(var, raw)
            if name in last and last[name] == value and type(last[name]) is type(value):
                continue
            last[name] = value
            if now is None:
                now, source = datetime.now(timezone.utc), self.source_timestamp()
            await write(nid[name], PublishedValue(ua.Variant(value, VARIANT[var.data_type]), SourceTimestamp=source,
                                                  ServerTimestamp=now))

    async def show_written(self, var: Variable, value) -> None:
        """An accepted write reads back at once (as Modbus shows written coils and registers), and keeps
        reading so until a step has applied it."""
        value = variant_value(var, value)
        self._held[var.name] = self.accepted
        self._last[var.name] = value
        await self.server.write_attribute_value(self._nid[var.name], PublishedValue(
            ua.Variant(value, VARIANT[var.data_type]), SourceTimestamp=self.source_timestamp(),
            ServerTimestamp=datetime.now(timezone.utc)))

    # -- writes (the client's side) -------------------------------------------------------------------
    async def _pre_write(self, event, _dispatcher) -> None:
        """asyncua's PreWrite callback: the signals' items of a Write request are checked and submitted here;
        asyncua sees them pointed at no node (so it stores nothing of them) until `_post_write`."""
        params = event.request_params
        items = params.NodesToWrite or []
        mine = {i: wv for i, wv in enumerate(items) if wv.NodeId in self._nodes}
        if not mine:
            return
        for i, wv in mine.items():
            items[i] = ua.WriteValue(NodeId=_NOWHERE, AttributeId=wv.AttributeId, Value=wv.Value)
        statuses: dict[int, ua.StatusCode] = {}
        self._writing[id(params)] = (params, mine, statuses)
        self.requests += 1
        try:
            accepted: list[tuple[int, Variable, object]] = []
            for i, wv in mine.items():
                var = self._nodes[wv.NodeId]
                status, value = self._check_write(wv, var, event.user)
                if status is not None:
                    statuses[i] = _status(status)
                else:
                    accepted.append((i, var, value))
            if accepted:
                refused = await self._submit([(var, value) for _, var, value in accepted])
                if not refused:
                    self.accepted += 1
                for i, var, value in accepted:
                    statuses[i] = _status(refused) if refused else ua.StatusCode()
                if not refused:
                    for _, var, value in accepted:
                        if var.writable:
                            await self.show_written(var, value)
        except Exception as exc:  # noqa: BLE001 - answered (BadInternalError), said in one line
            log.error("a write could not be handed to the simulation: %s: %s", type(exc).__name__, exc)

    def _post_write(self, event, _dispatcher) -> None:
        """asyncua's PostWrite callback: the signals' items back in the request, their status codes in the answer."""
        params, mine, statuses = self._writing.pop(id(event.request_params), (None, {}, {}))
        if params is not event.request_params:
            return
        items, results = params.NodesToWrite, event.response_params
        for i, wv in mine.items():
            items[i] = wv
            results[i] = statuses.get(i) or _status("BadInternalError")

    async def _pre_read(self, event, _dispatcher) -> None:
        """asyncua's PreRead callback (lockstep): a Read of a signal's value waits until this process has
        published every step the cell had run when it came (see the module docstring)."""
        nodes = self._nodes
        if any(rv.NodeId in nodes for rv in event.request_params.NodesToRead or ()):
            try:
                await self._sync()
            except TwinError:  # the simulation is gone: its last published step it is
                pass

    def _revise_sampling(self, event, _dispatcher) -> None:
        """asyncua's ItemSubscriptionCreated/Modified callback: no item samples faster than the step (values
        change once a step); -1, the publishing interval (asyncua's answer for a new item), the same."""
        params = event.request_params
        requested = getattr(params, "ItemsToCreate", None) or getattr(params, "ItemsToModify", None) or []
        for item, res in zip(requested, event.response_params or []):
            interval = item.RequestedParameters.SamplingInterval
            if interval == -1 or interval is None or not interval >= 0:
                interval = res.RevisedSamplingInterval if isinstance(params, ua.CreateMonitoredItemsParameters) \
                    else self.step_ms
            if interval is None or not interval >= self.step_ms:
                interval = self.step_ms
            res.RevisedSamplingInterval = interval

    def _check_write(self, wv: ua.WriteValue, var: Variable, user) -> tuple[str | None, object]:
        """None and the value (as the twin takes it), or the name of the Bad status code refusing the write."""
        if wv.AttributeId != ua.AttributeIds.Value:
            return "BadNotWritable", None
        if self.security.read_only(user):
            return "BadUserAccessDenied", None
        if not var.writable:
            return "BadNotWritable", None
        if wv.IndexRange:
            return "BadWriteNotSupported", None
        variant = wv.Value.Value if wv.Value is not None else None
        if variant is None or variant.Value is None or variant.is_array or variant.Dimensions:
            return "BadTypeMismatch", None
        vt, value = variant.VariantType, variant.Value
        dtype = var.data_type
        if dtype in LIMITS:
            if vt not in INTEGER_VARIANTS:
                return "BadTypeMismatch", None
        elif vt != VARIANT[dtype]:
            return "BadTypeMismatch", None
        if dtype == DOUBLE and not math.isfinite(value):
            return "BadOutOfRange", None
        return _validate(var, value)

    # -- sessions: the watchdog, and what a user may do ----------------------------------------------
    def _request_seen(self, user, typeid: ua.NodeId, body) -> None:
        """A request of an activated session (from `_asyncua_roles.Roles`, before asyncua processes it): report it.
        Never raises (a watchdog's trouble must not refuse a client's request)."""
        if self.on_request is None:
            return
        try:
            source = user.source or f"opcua user {user.name!r}"
            self.on_request(source, self.clock_requests and self._clock_only(typeid, body))
        except Exception as exc:  # noqa: BLE001
            log.error("the request hook failed: %s: %s", type(exc).__name__, exc)

    def _clock_only(self, typeid: ua.NodeId, body) -> bool:
        """The request only drives or reads simulated time: Sim.Advance calls, reads or writes of sim.advance
        (a lockstep harness's clock, as `twin.frontends.modbus.pdu.PduHandler.clock_only`; see `twin.runtime.watchdog`). `body`:
        the request's parameters."""
        if typeid not in (_CALL_REQUEST, _READ_REQUEST, _WRITE_REQUEST):
            return False
        b = body.copy()
        if typeid == _CALL_REQUEST:
            advance = self.node_id(ADVANCE_METHOD)
            calls = struct_from_binary(ua.CallParameters, b).MethodsToCall or []
            return bool(calls) and all(c.MethodId == advance for c in calls)
        clock = self.node_id(SIM_ADVANCE)
        if typeid == _READ_REQUEST:
            items = struct_from_binary(ua.ReadParameters, b).NodesToRead or []
        else:
            items = struct_from_binary(ua.WriteParameters, b).NodesToWrite or []
        return bool(items) and all(i.NodeId == clock for i in items)

    def _user_access_level(self, event, _dispatcher) -> None:
        """asyncua's PostRead callback: a read-only user's session reads the UserAccessLevel of an input as
        CurrentRead only (the node's own attribute, the same for every session, says CurrentWrite)."""
        if not self.security.read_only(event.user):
            return
        results = event.response_params
        for i, rv in enumerate(event.request_params.NodesToRead or []):
            if rv.AttributeId == ua.AttributeIds.UserAccessLevel and rv.NodeId in self._nodes:
                dv = results[i]
                if dv.Value is not None and dv.Value.Value is not None:
                    level = int(dv.Value.Value) & ~ua.AccessLevel.CurrentWrite.mask
                    results[i] = ua.DataValue(ua.Variant(level, ua.VariantType.Byte), StatusCode=dv.StatusCode)

    # -- Sim.Advance -----------------------------------------------------------------------------------
    async def _call_advance(self, parent: ua.NodeId, *args) -> ua.CallMethodResult | list[ua.Variant]:
        self.requests += 1
        result = ua.CallMethodResult()
        if len(args) != 1:
            result.StatusCode = _status("BadArgumentsMissing" if not args else "BadTooManyArguments")
            return result
        arg = args[0]
        if not isinstance(arg, ua.Variant) or arg.VariantType not in INTEGER_VARIANTS or arg.is_array:
            result.StatusCode = _status("BadInvalidArgument")
            result.InputArgumentResults = [_status("BadTypeMismatch")]
            return result
        n = int(arg.Value)
        if not 0 <= n <= MAX_ADVANCE:
            result.StatusCode = _status("BadInvalidArgument")
            result.InputArgumentResults = [_status("BadOutOfRange")]
            return result
        if self._advance is None:
            result.StatusCode = _status("BadInvalidState")
            return result
        try:
            step = await self._advance(n)
        except AdvanceRefused as exc:
            result.StatusCode = _status(exc.status)
            return result
        result.InputArgumentResults = [ua.StatusCode()]
        result.OutputArguments = [ua.Variant(min(int(step), MAX_ADVANCE), ua.VariantType.UInt32)]
        return result


def _validate(var: Variable, value) -> tuple[str | None, object]:
    """The signal table's own check of a written value, as Modbus applies it: range (and choices)."""
    spec = var.spec
    check = getattr(spec, "check", None)
    if check is not None:
        from .errors import status_of

        try:
            return None, check(value)
        except TwinError as exc:  # by the error's type, as the exchange's refusals are
            return status_of(exc), None
    if var.data_type == STRING:
        return (None, value) if value in spec.choices else ("BadOutOfRange", None)
    if var.data_type in LIMITS:
        lo, hi = LIMITS[var.data_type]
        if not lo <= value <= hi:
            return "BadOutOfRange", None
    if var.numeric:
        if spec.min is not None and value < spec.min or spec.max is not None and value > spec.max:
            return "BadOutOfRange", None
    return None, value


_CALL_REQUEST = ua.NodeId(ua.ObjectIds.CallRequest_Encoding_DefaultBinary)
_READ_REQUEST = ua.NodeId(ua.ObjectIds.ReadRequest_Encoding_DefaultBinary)
_WRITE_REQUEST = ua.NodeId(ua.ObjectIds.WriteRequest_Encoding_DefaultBinary)
_NOWHERE = ua.NodeId("gripper-twin: a signal's write, taken by the twin", 0)  # no node has it
